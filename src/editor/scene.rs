//! The scene file `marionette edit` opens and saves: the project's `Dance` scene
//! ([`crate::scene::DanceScene`], the same file `marionette run` reads: song, database, pins,
//! fill, and the editor's search parameters). There is one scene format, not two.
//!
//! Saving writes the file back with the edit's pins and nothing else changed: the value of the
//! scene's top-level `pins:` field is replaced in the file's own text (comments, layout and
//! every other field kept; the field is added when the scene had none), the result parsed again
//! and checked to be the scene with the new pins, then written atomically (a temporary file
//! renamed over the old one). Should the text not read back as the scene with the new pins,
//! nothing is written and the save is refused.

use std::path::{Path, PathBuf};

use super::EditorError;
use crate::scene::{DanceScene, Pin, Scene};

/// A `Dance` scene file as the editor holds it: its path, its text and its value.
#[derive(Debug, Clone)]
pub struct DanceFile {
    path: PathBuf,
    text: String,
    scene: DanceScene,
}

impl DanceFile {
    /// Parses `text` (from `path`) as a `Dance` scene: file, line and column on a syntax or
    /// field error, a clear refusal for a scene of another kind.
    pub fn parse(text: &str, path: &Path) -> Result<DanceFile, EditorError> {
        let name = path.display().to_string();
        let scene = match Scene::parse(text, &name)? {
            Scene::Dance(d) => *d,
            other => {
                return Err(EditorError::Scene {
                    path: name,
                    message: format!(
                        "`marionette edit` opens a Dance scene (song, database, pins); '{}' is \
                         another kind of scene",
                        other.name()
                    ),
                });
            }
        };
        crate::scene::validate_dance(&scene)?;
        Ok(DanceFile {
            path: path.to_path_buf(),
            text: text.to_string(),
            scene,
        })
    }

    /// Reads and parses the scene file at `path`.
    pub fn load(path: &Path) -> Result<DanceFile, EditorError> {
        let text = std::fs::read_to_string(path).map_err(|e| EditorError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        DanceFile::parse(&text, path)
    }

    /// The scene.
    pub fn scene(&self) -> &DanceScene {
        &self.scene
    }

    /// The scene file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The folder relative paths of the scene start from.
    pub fn base(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new("."))
    }

    /// The file's text with `pins` in place of the scene's pins (module docs), checked by
    /// parsing it again.
    pub fn text_with_pins(&self, pins: &[Pin]) -> Result<String, EditorError> {
        let mut want = self.scene.clone();
        want.pins = pins.to_vec();
        let same = |text: &str| matches!(Scene::parse(text, "saved scene"), Ok(Scene::Dance(d)) if *d == want);
        replace_pins(&self.text, &pins_ron(pins))
            .filter(|t| same(t))
            .ok_or_else(|| EditorError::Scene {
                path: self.path.display().to_string(),
                message: "the scene's text does not take the new pins in its `pins:` field \
                          (not saved; the file is unchanged)"
                    .into(),
            })
    }

    /// Writes the scene with `pins` to its file atomically and keeps it as the new text.
    pub fn save(&mut self, pins: &[Pin]) -> Result<(), EditorError> {
        let text = self.text_with_pins(pins)?;
        crate::io::write_atomic(&self.path, text.as_bytes()).map_err(|e| EditorError::Io {
            path: self.path.display().to_string(),
            message: e.to_string(),
        })?;
        self.text = text;
        self.scene.pins = pins.to_vec();
        Ok(())
    }
}

/// The pins as the RON value of a `pins:` field, one pin a line.
fn pins_ron(pins: &[Pin]) -> String {
    if pins.is_empty() {
        return "[]".into();
    }
    let mut out = String::from("[\n");
    for p in pins {
        let what = match (p.segment, &p.clip, p.clip_bar) {
            (Some(s), _, _) => format!("segment: {s}"),
            (None, Some(c), Some(b)) => format!(
                "clip: {}, clip_bar: {b}",
                ron::to_string(c).unwrap_or_else(|_| format!("{c:?}"))
            ),
            _ => String::new(),
        };
        out += &format!("        (bar: {}, {what}),\n", p.bar);
    }
    out + "    ]"
}

/// `text` (a RON value `Kind( … )`) with the value of its top-level field `pins` replaced by
/// `value`, or the field added before the closing parenthesis; `None` when the text does not
/// have that shape. Strings, characters and (nested) comments are skipped.
fn replace_pins(text: &str, value: &str) -> Option<String> {
    let b = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    // The end of the last significant byte at depth 1, and the start of the `pins` value.
    let mut last_sig = None;
    let mut pins_at: Option<usize> = None;
    let mut value_span: Option<(usize, usize)> = None;
    while i < b.len() {
        let c = b[i];
        if let Some(end) = comment_end(text, i) {
            i = end;
            continue;
        }
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        match c {
            b'"' | b'\'' => i = quoted_end(b, i),
            b'r' if matches!(b.get(i + 1), Some(b'"' | b'#')) => i = raw_string_end(text, i)?,
            b'(' | b'[' | b'{' => {
                depth += 1;
                i += 1;
            }
            b')' | b']' | b'}' => {
                depth = depth.checked_sub(1)?;
                i += 1;
                if let Some(v) = pins_at.filter(|_| depth == 1 && value_span.is_none()) {
                    value_span = Some((v, i));
                }
                if depth == 0 {
                    // The scene's closing parenthesis.
                    return with_pins(text, value, value_span, last_sig);
                }
            }
            _ if c.is_ascii_alphanumeric() || c == b'_' => {
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                if depth == 1
                    && &text[start..i] == "pins"
                    && value_span.is_none()
                    && let Some(v) = list_after_colon(text, i)
                {
                    pins_at = Some(v);
                }
            }
            _ => i += 1,
        }
        if depth >= 1 {
            last_sig = Some(i.min(b.len()));
        }
    }
    None
}

/// The end of the comment (`//` to the line's end, or a nested `/* … */`) that starts at byte
/// `i` of `text`; `None` when none starts there.
fn comment_end(text: &str, i: usize) -> Option<usize> {
    let b = text.as_bytes();
    if b[i] != b'/' {
        return None;
    }
    match b.get(i + 1) {
        Some(b'/') => Some(text[i..].find('\n').map_or(b.len(), |n| i + n)),
        Some(b'*') => {
            let mut nest = 1;
            let mut i = i + 2;
            while i < b.len() && nest > 0 {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    nest += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    nest -= 1;
                    i += 2;
                } else {
                    i += 1;
                }
            }
            Some(i)
        }
        _ => None,
    }
}

/// The end (past the closing quote) of the string or character whose opening quote is byte `i`
/// of `b`, escapes skipped.
fn quoted_end(b: &[u8], i: usize) -> usize {
    let c = b[i];
    let mut i = i + 1;
    while i < b.len() && b[i] != c {
        i += if b[i] == b'\\' { 2 } else { 1 };
    }
    i + 1
}

/// The end of the raw string `r#"…"#` that starts at byte `i` of `text`; `None` when unclosed.
fn raw_string_end(text: &str, i: usize) -> Option<usize> {
    let b = text.as_bytes();
    let hashes = b[i + 1..].iter().take_while(|&&h| h == b'#').count();
    let close = format!("\"{}", "#".repeat(hashes));
    let open = i + 1 + hashes + 1;
    text.get(open..)?
        .find(&close)
        .map(|n| open + n + close.len())
}

/// Where the list value starts after a field name that ends at byte `i` of `text`: its `[`
/// after the colon; `None` when no colon and list follow.
fn list_after_colon(text: &str, i: usize) -> Option<usize> {
    let rest = &text[i..];
    let colon = rest.len() - rest.trim_start().len();
    if !rest.trim_start().starts_with(':') {
        return None;
    }
    let after = i + colon + 1;
    let ws = text[after..].len() - text[after..].trim_start().len();
    text[after + ws..].starts_with('[').then_some(after + ws)
}

/// `text` with the pins' value at `value_span` replaced by `value`, or with no pins field the
/// field added after the last significant byte `last_sig` before the closing parenthesis.
fn with_pins(
    text: &str,
    value: &str,
    value_span: Option<(usize, usize)>,
    last_sig: Option<usize>,
) -> Option<String> {
    if let Some((a, z)) = value_span {
        return Some(format!("{}{value}{}", &text[..a], &text[z..]));
    }
    let at = last_sig?;
    let comma = if text[..at].ends_with([',', '(']) {
        ""
    } else {
        ","
    };
    Some(format!(
        "{}{comma}\n    pins: {value},{}",
        &text[..at],
        &text[at..]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "// A dance (the pins: are below).\nDance(\n    format_version: 1,\n    \
        name: \"d /* not a comment */ pins: [\",\n    song: Synth(bpm: 120.0, bars: 8),\n    \
        database: File(\"d.json\"), /* pins: [] */\n    pins: [\n        (bar: 0, segment: 3), \
        // first\n    ],\n    render: (gif: false),\n)\n";

    fn pin(bar: usize, seg: usize) -> Pin {
        Pin {
            bar,
            segment: Some(seg),
            clip: None,
            clip_bar: None,
        }
    }

    #[test]
    fn saving_replaces_only_the_pins_and_keeps_comments() {
        let f = DanceFile::parse(SCENE, Path::new("t.ron")).unwrap();
        assert_eq!(f.scene().pins, vec![pin(0, 3)]);
        let by_clip = Pin {
            bar: 5,
            segment: None,
            clip: Some("a \"quoted\" clip".into()),
            clip_bar: Some(2),
        };
        let text = f.text_with_pins(&[pin(1, 7), by_clip.clone()]).unwrap();
        assert!(
            text.starts_with("// A dance (the pins: are below).\n"),
            "{text}"
        );
        assert!(text.contains("/* pins: [] */") && text.contains("render: (gif: false)"));
        let back = DanceFile::parse(&text, Path::new("t.ron")).unwrap();
        assert_eq!(back.scene().pins, vec![pin(1, 7), by_clip]);
        assert_eq!(back.scene().name, f.scene().name);
        // No pins field: added; no pins: an empty list.
        let bare = "Dance(format_version: 1, name: \"x\", song: Synth(bpm: 100.0, bars: 4), \
            database: File(\"d.json\") // no pins\n)";
        let f = DanceFile::parse(bare, Path::new("b.ron")).unwrap();
        let text = f.text_with_pins(&[pin(2, 1)]).unwrap();
        assert!(text.contains("// no pins"), "{text}");
        let back = DanceFile::parse(&text, Path::new("b.ron")).unwrap();
        assert_eq!(back.scene().pins, vec![pin(2, 1)]);
        let none = back.text_with_pins(&[]).unwrap();
        assert!(
            DanceFile::parse(&none, Path::new("b.ron"))
                .unwrap()
                .scene()
                .pins
                .is_empty()
        );
    }

    #[test]
    fn refuses_other_scenes_and_reports_positions() {
        let e = DanceFile::parse(
            "Dance(format_version: 1,\n name: \"x\", extra: 1)",
            Path::new("bad.ron"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("bad.ron") && e.contains("extra"), "{e}");
        let fall =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/fall.ron"))
                .unwrap();
        let e = DanceFile::parse(&fall, Path::new("fall.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("opens a Dance scene"), "{e}");
    }
}
