//! Landmarks by name: joint names normalised (namespace, prefix, side word, case, separators,
//! numbering) and compared with the synonyms of each landmark across skeleton conventions
//! (`builtin/synonyms.ron`, extendable by the user).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

use serde::Deserialize;

use super::MappingError;
use crate::skeleton::Side;

/// The side-less roles a name can stand for: the centre landmarks and, for both sides, the
/// limb landmarks (`hip` names `left_hip` on a left chain).
pub const ROLES: [&str; 13] = [
    "pelvis", "waist", "neck", "head", "clavicle", "shoulder", "elbow", "wrist", "hand", "hip",
    "knee", "ankle", "toe",
];

/// Words that name a side, lower case: `left`/`right` and their usual abbreviations.
const LEFT_WORDS: [&str; 3] = ["left", "l", "lft"];
const RIGHT_WORDS: [&str; 3] = ["right", "r", "rgt"];

/// A joint name reduced to what it says: its side and its base (lower case, no separators,
/// numbers without leading zeros).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NormalName {
    /// The side named by a side word at either end, else [`Side::Centre`].
    pub side: Side,
    /// The remaining words joined: `"upleg"`, `"spine1"`, `"handmiddle1"`.
    pub base: String,
}

/// The words of a name: split at separators (`_ . - : | ␣`), at lower→upper case changes, before
/// the last capital of a capital run followed by a lower-case letter (`LHip` → `L`, `Hip`), and
/// between letters and digits; numbers lose their leading zeros (`01` → `1`).
pub fn words(name: &str) -> Vec<String> {
    let mut out: Vec<String> = vec![];
    let chars: Vec<char> = name.chars().collect();
    let mut cur = String::new();
    let flush = |cur: &mut String, out: &mut Vec<String>| {
        if !cur.is_empty() {
            let w = if cur.chars().all(|c| c.is_ascii_digit()) {
                let t = cur.trim_start_matches('0');
                if t.is_empty() { "0" } else { t }.to_string()
            } else {
                cur.clone()
            };
            out.push(w);
            cur.clear();
        }
    };
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_alphanumeric() {
            flush(&mut cur, &mut out);
            continue;
        }
        if let Some(&p) = cur.chars().last().as_ref() {
            let next_lower = chars.get(i + 1).is_some_and(|n| n.is_lowercase());
            let boundary = (p.is_lowercase() && c.is_uppercase())
                || (p.is_uppercase() && c.is_uppercase() && next_lower)
                || (p.is_ascii_digit() != c.is_ascii_digit());
            if boundary {
                flush(&mut cur, &mut out);
            }
        }
        cur.push(c);
    }
    flush(&mut cur, &mut out);
    out
}

/// Normalises a joint name: drops the namespace (up to the last `:` or `|`), splits it into
/// [`words`], takes a side word off either end (`Left…`, `…_l`, `l…`, `….R`, and a capital side
/// letter glued to an abbreviation, `LUArm`, `RFoot`), drops a leading `prefix` (given as word
/// lists, e.g. `["bip", "1"]`) and joins the rest in lower case.
pub fn normalise(name: &str, prefixes: &[Vec<String>]) -> NormalName {
    let bare = name.rsplit([':', '|']).next().unwrap_or(name);
    let mut w = words(bare);
    let lower: Vec<String> = w.iter().map(|s| s.to_lowercase()).collect();
    // Prefixes first (longest first), so that "Bip01 L Thigh" keeps its side word.
    let mut lw = lower;
    if let Some(p) = prefixes
        .iter()
        .filter(|p| p.len() < lw.len() && lw[..p.len()] == p[..])
        .max_by_key(|p| p.len())
    {
        let n = p.len();
        lw.drain(..n);
        w.drain(..n);
    }
    let side_of = |s: &str| {
        if LEFT_WORDS.contains(&s) {
            Side::Left
        } else if RIGHT_WORDS.contains(&s) {
            Side::Right
        } else {
            Side::Centre
        }
    };
    let mut side = Side::Centre;
    if lw.len() >= 2 {
        let first = side_of(&lw[0]);
        let last = side_of(&lw[lw.len() - 1]);
        if first != Side::Centre {
            side = first;
            lw.remove(0);
        } else if last != Side::Centre {
            side = last;
            lw.pop();
        } else {
            // `LUArm`, `RFArm`: an upper-case abbreviation whose first letter is the side.
            let f = &w[0];
            if f.len() >= 2 && f.chars().all(|c| c.is_ascii_uppercase()) {
                let s = side_of(&lw[0][..1]);
                if s != Side::Centre {
                    side = s;
                    lw[0] = lw[0][1..].to_string();
                }
            }
        }
    }
    // Full side words anywhere (`Character1_LeftUpLeg`, `hand_left_1`).
    if side == Side::Centre
        && let Some(i) = lw.iter().position(|s| s == "left" || s == "right")
    {
        side = side_of(&lw[i]);
        lw.remove(i);
    }
    NormalName {
        side,
        base: lw.concat(),
    }
}

/// The synonyms file as written (see `builtin/synonyms.ron`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SynonymsFile {
    format_version: u32,
    prefixes: Vec<String>,
    #[serde(deserialize_with = "crate::io::unique_keys")]
    landmarks: BTreeMap<String, Vec<String>>,
}

/// Names of each role ([`ROLES`]) and the prefixes to drop, all normalised.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Synonyms {
    /// Prefixes as word lists, lower case.
    pub prefixes: Vec<Vec<String>>,
    /// Role → normalised bases that name it.
    pub roles: BTreeMap<String, Vec<String>>,
}

const BUILTIN_SYNONYMS: &str = include_str!("builtin/synonyms.ron");

impl Synonyms {
    /// Parses a synonyms file (RON, see `builtin/synonyms.ron`); `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Synonyms, MappingError> {
        let f: SynonymsFile =
            crate::io::parse_ron(text, origin).map_err(crate::io::FileError::from)?;
        crate::io::check_version(origin, f.format_version, super::FORMAT_VERSION)?;
        let mut s = Synonyms {
            prefixes: f
                .prefixes
                .iter()
                .map(|p| words(p).iter().map(|w| w.to_lowercase()).collect())
                .filter(|p: &Vec<String>| !p.is_empty())
                .collect(),
            roles: BTreeMap::new(),
        };
        for (role, names) in f.landmarks {
            if !ROLES.contains(&role.as_str()) {
                return Err(MappingError::Landmarks {
                    mapping: origin.into(),
                    message: format!(
                        "'{role}' is not a landmark role; expected one of {}",
                        ROLES.join(", ")
                    ),
                });
            }
            let bases = names
                .iter()
                .map(|n| normalise(n, &[]).base)
                .filter(|b| !b.is_empty())
                .collect();
            s.roles.insert(role, bases);
        }
        Ok(s)
    }

    /// Reads a synonyms file.
    pub fn load(path: &Path) -> Result<Synonyms, MappingError> {
        let text = crate::io::read_text(path)?;
        Synonyms::parse(&text, &path.display().to_string())
    }

    /// The built-in synonyms (`builtin/synonyms.ron`), parsed once.
    pub fn builtin() -> &'static Synonyms {
        static PARSED: OnceLock<Synonyms> = OnceLock::new();
        PARSED.get_or_init(|| {
            Synonyms::parse(BUILTIN_SYNONYMS, "synonyms.ron").expect("built-in synonyms are valid")
        })
    }

    /// These synonyms with `more`'s prefixes and names added.
    pub fn extended(&self, more: &Synonyms) -> Synonyms {
        let mut s = self.clone();
        for p in &more.prefixes {
            if !s.prefixes.contains(p) {
                s.prefixes.push(p.clone());
            }
        }
        for (role, names) in &more.roles {
            let e = s.roles.entry(role.clone()).or_default();
            for n in names {
                if !e.contains(n) {
                    e.push(n.clone());
                }
            }
        }
        s
    }

    /// Whether the normalised base names `role`.
    pub fn names(&self, role: &str, base: &str) -> bool {
        self.roles
            .get(role)
            .is_some_and(|v| v.iter().any(|b| b == base))
    }

    /// `name` normalised with these prefixes ([`normalise`]); a one-word lower-case name whose
    /// first letter is `l` or `r` and whose rest is a synonym takes that letter as its side
    /// (the CMU/Vicon ASF names `lfemur`, `rhumerus`, `lhand`).
    pub fn normalise(&self, name: &str) -> NormalName {
        let mut n = normalise(name, &self.prefixes);
        if n.side == Side::Centre && n.base.len() > 2 {
            let (first, rest) = n.base.split_at(1);
            let side = match first {
                "l" => Side::Left,
                "r" => Side::Right,
                _ => Side::Centre,
            };
            if side != Side::Centre && self.roles.values().any(|v| v.iter().any(|b| b == rest)) {
                n = NormalName {
                    side,
                    base: rest.to_string(),
                };
            }
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn n(name: &str) -> (Side, String) {
        let s = Synonyms::builtin().normalise(name);
        (s.side, s.base)
    }

    #[test]
    fn names_of_every_convention_normalise_to_side_and_base() {
        use Side::{Centre as C, Left as L, Right as R};
        for (name, side, base) in [
            ("mixamorig:LeftUpLeg", L, "upleg"),
            ("mixamorig:RightHandMiddle1", R, "handmiddle1"),
            ("Bip01 L Thigh", L, "thigh"),
            ("Bip001 R Forearm", R, "forearm"),
            ("Bip01 Spine1", C, "spine1"),
            ("CC_Base_L_Upperarm", L, "upperarm"),
            ("DEF-upper_arm.L", L, "upperarm"),
            ("DEF-spine.001", C, "spine1"),
            ("thigh_l", L, "thigh"),
            ("lowerarm_r", R, "lowerarm"),
            ("spine_01", C, "spine1"),
            ("lShldr", L, "shldr"),
            ("rButtock", R, "buttock"),
            ("LHipJoint", L, "hipjoint"),
            ("LeftToeBase", L, "toebase"),
            ("Shoulder_L", L, "shoulder"),
            ("UpperLeg_R", R, "upperleg"),
            ("left_hip", L, "hip"),
            ("LUArm", L, "uarm"),
            ("RFArm", R, "farm"),
            ("LThigh", L, "thigh"),
            ("joint_Root", C, "root"),
            ("Hips", C, "hips"),
            ("LOWERBACK", C, "lowerback"),
            ("HeadTop_End", C, "headtopend"),
            ("Armature|hand.R", R, "hand"),
            ("Character1_LeftUpLeg", L, "upleg"),
            ("lfemur", L, "femur"),
            ("rhumerus", R, "humerus"),
            ("lowerback", C, "lowerback"),
            ("root", C, "root"),
        ] {
            assert_eq!(n(name), (side, base.to_string()), "{name}");
        }
    }

    #[test]
    fn words_split_case_digits_and_separators() {
        assert_eq!(words("LHipJoint"), ["L", "Hip", "Joint"]);
        assert_eq!(words("spine.001"), ["spine", "1"]);
        assert_eq!(words("Toe0"), ["Toe", "0"]);
        assert_eq!(words("HIPS"), ["HIPS"]);
    }

    #[test]
    fn synonyms_parse_extend_and_refuse_unknown_roles() {
        let b = Synonyms::builtin();
        assert!(
            b.names("hip", "upleg") && b.names("knee", "calf") && b.names("clavicle", "collar")
        );
        let more = Synonyms::parse(
            "(format_version: 1, prefixes: [\"MyRig\"], landmarks: {\"knee\": [\"Genou\"]})",
            "more.ron",
        )
        .unwrap();
        let e = b.extended(&more);
        assert!(e.names("knee", "genou") && !b.names("knee", "genou"));
        assert_eq!(e.normalise("MyRig_L_Genou").base, "genou");
        let err = Synonyms::parse(
            "(format_version: 1, prefixes: [], landmarks: {\"tail\": [\"Tail\"]})",
            "bad.ron",
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("'tail' is not a landmark role"),
            "{err}"
        );
    }
}
