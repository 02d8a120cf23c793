//! Which side of the body a joint is on, from its name alone (any skeleton's naming).

/// Which side of the body a point belongs to, as told by its name (see [`side_from_name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The figure's left (+X in its rest frame).
    Left,
    /// The figure's right (−X).
    Right,
    /// On the mid-line (spine, head) or undecidable from the name.
    Centre,
}

/// The left/right rule, in one place. A name is on the figure's **left** when (case as shown):
///
/// 1. it contains `left` in any case (`LeftArm`, `mixamorig:LeftHand`, `hand_left`, `HandLeft`);
/// 2. it starts with `l`/`L` followed by a separator `_ . - : ␣` (`l_hip`, `L.knee`); or with a
///    lower-case `l` followed by a capital (`lShldr`, `lHIP`); or with a capital `L` followed by
///    a capitalised word, i.e. a capital then a lower-case letter (`LHipJoint`; an all-capitals
///    name such as `LOWERBACK` is *not* read as left);
/// 3. it ends with a separator followed by `l`/`L` (`hip_L`, `knee.l`, `Arm-L`).
///
/// The same with `right` / `r` / `R` gives **right**; a name that matches both or neither is
/// [`Side::Centre`]. `render::StickFigure::sides` additionally lets a point whose own name is
/// undecided inherit its parent's side (end sites, `Site`).
pub fn side_from_name(name: &str) -> Side {
    let left = names_side(name, "left", 'l');
    let right = names_side(name, "right", 'r');
    match (left, right) {
        (true, false) => Side::Left,
        (false, true) => Side::Right,
        _ => Side::Centre,
    }
}

/// Whether `name` names one side: contains `word`, or has the one-letter prefix/suffix `letter`
/// as described in [`side_from_name`].
fn names_side(name: &str, word: &str, letter: char) -> bool {
    if name.to_lowercase().contains(word) {
        return true;
    }
    let is_sep = |c: char| matches!(c, '_' | '.' | '-' | ':' | ' ');
    let chars: Vec<char> = name.chars().collect();
    let n = chars.len();
    if n >= 2 && chars[0].to_ascii_lowercase() == letter {
        if is_sep(chars[1]) {
            return true;
        }
        if n >= 3 && chars[1].is_uppercase() && chars[2].is_lowercase() {
            return true;
        }
        // `lShldr`, `lHIP`: lower-case side letter then a capital.
        if chars[0].is_lowercase() && chars[1].is_uppercase() {
            return true;
        }
    }
    n >= 2 && chars[n - 1].to_ascii_lowercase() == letter && is_sep(chars[n - 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn left_right_rule_covers_common_skeleton_conventions() {
        for name in [
            "LeftArm",
            "mixamorig:LeftHand",
            "hand_left",
            "HandLeft",
            "lShldr",
            "lHand",
            "LHipJoint",
            "l_hip",
            "L.knee",
            "hip_L",
            "knee.l",
            "Arm-L",
            "Shoulder_L",
            "leftEye",
            "lPinky2",
            "lButtock",
        ] {
            assert_eq!(side_from_name(name), Side::Left, "{name}");
        }
        for name in [
            "RightArm",
            "RightUpLeg",
            "rShldr",
            "RHipJoint",
            "r_hip",
            "hip_R",
            "foot.r",
            "Hand_R",
            "rCollar",
            "rightEye",
        ] {
            assert_eq!(side_from_name(name), Side::Right, "{name}");
        }
        for name in [
            "Hips",
            "Root",
            "root",
            "LowerBack",
            "LOWERBACK",
            "Spine",
            "Neck",
            "Head",
            "Ribs",
            "joint_Root",
            "abdomen",
            "hip",
            "End Site",
            "",
            "l",
            "LeftRight",
        ] {
            assert_eq!(side_from_name(name), Side::Centre, "{name}");
        }
    }
}
