//! The automatic mapping on the real motion capture in `MARIONETTE_DATA`: without consulting the
//! built-in mapping files it finds landmarks that give the same angles (to 1e-9) as the
//! hand-written files, on both models, so those files are optional; and with every joint name
//! replaced by a meaningless one (structure alone) the mapped figure still puts head, hands and
//! feet as closely as the hand-written files do (to a millimetre).

use marionette::bvh;
use marionette::humanoid::Figure;
use marionette::mapping::{Mapping, Synonyms, effector_errors, retarget};
use marionette::skeleton::Clip;

use crate::common::data_dir;

/// Every BVH file of the shared data.
fn real_files() -> Option<Vec<std::path::PathBuf>> {
    let dir = data_dir()?;
    let mut files: Vec<_> = ["cmu", "bandai", "dance"]
        .iter()
        .flat_map(|d| std::fs::read_dir(dir.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    assert!(files.len() >= 6, "{files:?}");
    Some(files)
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn every_real_file_maps_automatically_as_with_its_hand_written_file() {
    let Some(files) = real_files() else { return };
    for file in &files {
        let (b, _) = bvh::parse_file(file).unwrap();
        let clip = Clip::from_bvh(&b, None).unwrap();
        let builtin = Mapping::builtin_for(&clip.skeleton)
            .unwrap_or_else(|| panic!("{}: a built-in mapping fits", file.display()));
        let auto = Mapping::automatic(&clip, Synonyms::builtin()).unwrap();
        // Landmark by landmark: the same point, or one at the same place in every frame.
        let mut different = vec![];
        for (l, src) in &builtin.landmarks {
            if &auto.mapping.landmarks[l] != src {
                different.push(format!("{l}: {} vs {src}", auto.mapping.landmarks[l]));
            }
        }
        for f in &auto.findings {
            println!(
                "{} {:<15} {:<14} {:.2} {}",
                file.file_name().unwrap().to_string_lossy(),
                f.landmark,
                f.source,
                f.confidence,
                f.reason
            );
        }
        for model in ["humanoid24", "fall21"] {
            let m = Figure::by_name(model).unwrap();
            let a = retarget(&clip, &auto.mapping, &m).unwrap();
            let h = retarget(&clip, builtin, &m).unwrap();
            let worst = a
                .angles
                .iter()
                .zip(&h.angles)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(
                worst <= 1e-9,
                "{} on {model}: angles differ by {worst:e} rad; landmarks that differ: {different:?}",
                file.display()
            );
            let worst_root = a
                .root_translation
                .iter()
                .zip(&h.root_translation)
                .map(|(x, y)| (*x - *y).length())
                .fold(0.0, f64::max);
            assert!(worst_root <= 1e-9, "{}: root {worst_root}", file.display());
        }
    }
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn real_files_with_meaningless_joint_names_map_by_structure_within_the_same_bounds() {
    let Some(files) = real_files() else { return };
    let model = Figure::by_name("humanoid24").unwrap();
    for file in &files {
        let (b, _) = bvh::parse_file(file).unwrap();
        let clip = Clip::from_bvh(&b, None).unwrap();
        let builtin = Mapping::builtin_for(&clip.skeleton).unwrap();
        let known =
            effector_errors(&clip, builtin, &retarget(&clip, builtin, &model).unwrap()).unwrap();
        let mut anon = clip.clone();
        for (i, j) in anon.skeleton.joints.iter_mut().enumerate() {
            j.name = format!("j{i}");
        }
        let auto = Mapping::automatic(&anon, Synonyms::builtin()).unwrap();
        assert!(auto.notes.iter().any(|n| n.contains("legs: by geometry")));
        let mapped = retarget(&anon, &auto.mapping, &model).unwrap();
        let errs = effector_errors(&anon, &auto.mapping, &mapped).unwrap();
        let name = file.file_name().unwrap().to_string_lossy();
        for (e, k) in errs.iter().zip(&known) {
            println!(
                "{name} {:>10}: structure alone worst {:5.1} mm, hand-written file {:5.1} mm",
                e.effector,
                e.max_m * 1e3,
                k.max_m * 1e3
            );
            // The bounds of tests/mapping/real_data.rs.
            let limit = match e.effector.as_str() {
                "left_foot" | "right_foot" if name.contains("jumps") => 0.05,
                "head" => 0.25,
                _ => 0.15,
            };
            assert!(
                e.max_m < limit,
                "{name} {}: worst {:.3} m",
                e.effector,
                e.max_m
            );
            // As good as the hand-written file, to a millimetre.
            assert!(
                e.max_m <= k.max_m + 1e-3,
                "{name} {}: structure alone {:.4} m, hand-written {:.4} m",
                e.effector,
                e.max_m,
                k.max_m
            );
        }
    }
}
