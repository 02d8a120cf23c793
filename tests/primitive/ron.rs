//! Primitive files: versioned RON round trips, and clear errors (line, column, field) for newer
//! versions and broken files.

use marionette::primitive::synthetic::knee_jump;
use marionette::primitive::{
    Formulation, LearnConfig, PRIMITIVE_FORMAT_VERSION, Primitive, PrimitiveError, Trajectory,
};

fn knee(formulation: Formulation) -> Primitive {
    let demo = Trajectory::from_columns(
        1.0 / 120.0,
        vec!["left_knee".into(), "root_ty".into()],
        &[knee_jump(1.9, 1.0, 120.0), knee_jump(0.2, 1.0, 120.0)],
    )
    .unwrap();
    let cfg = LearnConfig {
        formulation,
        ..LearnConfig::default()
    };
    Primitive::learn("knee", &demo, &cfg).unwrap().primitive
}

#[test]
fn every_formulation_round_trips_exactly_and_is_named_in_the_file() {
    for f in [
        Formulation::default(),
        Formulation::ijspeert2013(),
        Formulation::hoffmann2009(),
    ] {
        let p = knee(f).with_goal("left_knee", 0.4).unwrap();
        let text = p.to_ron().unwrap();
        assert!(text.contains(f.name()), "{text}");
        assert!(text.contains(&format!("format_version: {PRIMITIVE_FORMAT_VERSION}")));
        let back = Primitive::from_ron(&text, "knee.ron").unwrap();
        assert_eq!(back, p);
        let times = [0.0, 0.3, 0.77, 1.0];
        assert_eq!(
            back.sample(&times, None).unwrap(),
            p.sample(&times, None).unwrap()
        );
    }
}

#[test]
fn save_and_load_through_a_file() {
    let dir = std::env::temp_dir().join(format!("marionette-prim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("knee.ron");
    let p = knee(Formulation::default());
    p.save(&path).unwrap();
    assert_eq!(Primitive::load(&path).unwrap(), p);
    let e = Primitive::load(&dir.join("missing.ron")).unwrap_err();
    assert!(matches!(e, PrimitiveError::Io { .. }), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_newer_version_is_refused_by_name() {
    let text = knee(Formulation::default()).to_ron().unwrap().replace(
        &format!("format_version: {PRIMITIVE_FORMAT_VERSION}"),
        "format_version: 99",
    );
    // Even with a field this build does not know about.
    let text = text.replacen("name:", "new_field: 1, name:", 1);
    let e = Primitive::from_ron(&text, "future.ron").unwrap_err();
    assert_eq!(
        e,
        PrimitiveError::UnsupportedVersion {
            source_name: "future.ron".into(),
            found: 99,
            supported: PRIMITIVE_FORMAT_VERSION
        }
    );
    assert!(e.to_string().contains("newer"), "{e}");
}

#[test]
fn broken_files_name_the_line_column_and_field() {
    let good = knee(Formulation::default()).to_ron().unwrap();
    // A missing field.
    let lines: Vec<&str> = good.lines().collect();
    let no_duration: String = lines
        .iter()
        .filter(|l| !l.trim_start().starts_with("duration:"))
        .map(|l| format!("{l}\n"))
        .collect();
    let e = Primitive::from_ron(&no_duration, "a.ron").unwrap_err();
    match &e {
        PrimitiveError::Parse { message, line, .. } => {
            assert!(message.contains("duration"), "{e}");
            assert!(*line >= 1);
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    // An unknown field, on a known line.
    let typo = good.replacen("goal:", "gaol:", 1);
    let typo_line = typo.lines().position(|l| l.contains("gaol:")).unwrap() + 1;
    let e = Primitive::from_ron(&typo, "b.ron").unwrap_err();
    match &e {
        PrimitiveError::Parse {
            message,
            line,
            column,
            ..
        } => {
            assert!(message.contains("gaol"), "{e}");
            assert_eq!(*line, typo_line, "{e}");
            assert!(*column > 1);
            assert!(
                e.to_string().starts_with(&format!("b.ron:{typo_line}:")),
                "{e}"
            );
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    // Truncated.
    let e = Primitive::from_ron(&good[..good.len() / 2], "c.ron").unwrap_err();
    assert!(matches!(e, PrimitiveError::Parse { .. }), "{e}");
    // Well-formed but inconsistent: a weight missing.
    let mut p = knee(Formulation::default());
    p.dofs[1].weights.pop();
    let e = Primitive::from_ron(&p.to_ron().unwrap(), "d.ron").unwrap_err();
    assert!(e.to_string().contains("dofs[1].weights"), "{e}");
    // Non-positive duration.
    let mut p = knee(Formulation::default());
    p.duration = -1.0;
    let e = Primitive::from_ron(&p.to_ron().unwrap(), "e.ron").unwrap_err();
    assert!(e.to_string().contains("duration"), "{e}");
}
