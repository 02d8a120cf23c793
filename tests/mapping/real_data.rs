//! Mapping the real motion capture in `MARIONETTE_DATA` onto the engine's models: every file
//! maps onto both models and renders, and the mapped humanoid24 puts head, hands and feet where the source
//! does (feet within 5 cm on the CMU jumps).

use marionette::bvh;
use marionette::humanoid::Figure;
use marionette::mapping::{Mapping, effector_errors, retarget};
use marionette::render::StickFigure;
use marionette::skeleton::Clip;

use crate::common::data_dir;

const FILES: [&str; 6] = [
    "cmu/cmu_01_01_forward_jumps.bvh",
    "cmu/acrnn_martial_04.bvh",
    "cmu/acrnn_salsa_05.bvh",
    "cmu/acrnn_indian_13.bvh",
    "bandai/bandai1_kick_normal_001.bvh",
    "bandai/bandai1_punch_normal_001.bvh",
];

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn every_data_file_maps_onto_both_models_and_looks_like_itself() {
    let Some(dir) = data_dir() else { return };
    for file in FILES {
        let (b, _) = bvh::parse_file(&dir.join(file)).unwrap();
        let clip = Clip::from_bvh(&b, None).unwrap();
        let mapping = Mapping::detect(&clip.skeleton).unwrap();
        for model in ["humanoid24", "fall21"] {
            let m = Figure::by_name(model).unwrap();
            let mapped = retarget(&clip, &mapping, &m).unwrap();
            assert_eq!(mapped.frame_count(), clip.frame_count());
            assert!(
                mapped.angles.iter().all(|a| a.is_finite()),
                "{file} {model}"
            );
            // It renders: a filmstrip of the mapped clip.
            let shown = mapped.to_clip();
            let figure = StickFigure::of(&shown.skeleton);
            let frames = shown.point_frames();
            let track = marionette::render::Track {
                figure: &figure,
                frames: &frames,
                label: file.into(),
                frame_time: shown.frame_time,
            };
            let png = std::env::temp_dir()
                .join(format!("marionette-map-{}-{model}.png", std::process::id()));
            marionette::render::filmstrip_png(&[track], 4, &png).unwrap();
            assert!(std::fs::metadata(&png).unwrap().len() > 1000);
            std::fs::remove_file(&png).ok();
            let errs = effector_errors(&clip, &mapping, &mapped).unwrap();
            for e in &errs {
                println!(
                    "{file} {model} {:>10}: mean {:5.1} mm, worst {:5.1} mm",
                    e.effector,
                    e.mean_m * 1e3,
                    e.max_m * 1e3
                );
            }
            if model == "humanoid24" {
                for e in &errs {
                    let limit = match e.effector.as_str() {
                        "left_foot" | "right_foot" if file.contains("jumps") => 0.05,
                        // humanoid24 has no neck DOF: its head follows the chest.
                        "head" => 0.25,
                        _ => 0.15,
                    };
                    assert!(
                        e.max_m < limit,
                        "{file} {model} {}: worst {:.3} m",
                        e.effector,
                        e.max_m
                    );
                }
            }
        }
    }
}
