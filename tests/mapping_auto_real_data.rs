//! The automatic mapping on the real motion capture in `MARIONETTE_DATA`: without consulting the
//! built-in mapping files it finds landmarks that give the same angles (to 1e-9) as the
//! hand-written files, on both models, so those files are optional.

use marionette::bvh;
use marionette::humanoid::Model;
use marionette::mapping::{Mapping, Synonyms, retarget};
use marionette::skeleton::Clip;

mod common;
use common::data_dir;

#[test]
fn every_real_file_maps_automatically_as_with_its_hand_written_file() {
    let Some(dir) = data_dir() else { return };
    let mut files: Vec<_> = ["cmu", "bandai", "dance"]
        .iter()
        .flat_map(|d| std::fs::read_dir(dir.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    assert!(files.len() >= 6, "{files:?}");
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
            let m = Model::by_name(model).unwrap();
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
