//! How closely a mapped motion reproduces its source: end-effector distances per frame.

use serde::Serialize;

use super::{Mapping, MappingError};
use crate::humanoid::FigureClip;
use crate::skeleton::Clip;

/// Distance between where the source and the mapped model put one end effector, metres.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectorError {
    /// `head`, `left_hand`, `right_hand`, `left_foot` or `right_foot`.
    pub effector: String,
    /// Mean over frames, metres.
    pub mean_m: f64,
    /// Worst frame, metres.
    pub max_m: f64,
}

/// End effectors compared: (name, model joint, use its End Site, source landmark).
const EFFECTORS: [(&str, &str, bool, &str); 5] = [
    ("head", "neck", true, "head"),
    ("left_hand", "left_wrist", false, "left_wrist"),
    ("right_hand", "right_wrist", false, "right_wrist"),
    ("left_foot", "left_ankle", false, "left_ankle"),
    ("right_foot", "right_ankle", false, "right_ankle"),
];

/// Mean and worst distance per end effector between `source` (through `mapping`'s landmarks)
/// and `mapped` (the model's joints: head top, wrists, ankles), over all frames.
pub fn effector_errors(
    source: &Clip,
    mapping: &Mapping,
    mapped: &FigureClip,
) -> Result<Vec<EffectorError>, MappingError> {
    let model_clip = mapped.to_clip();
    let mut out = vec![];
    let frames = source.frame_count().min(mapped.frame_count());
    let (mut gs, mut gm) = (vec![], vec![]);
    let mut sums = [0.0; 5];
    let mut maxes = [0.0f64; 5];
    let resolved: Vec<_> = EFFECTORS
        .iter()
        .map(|e| mapping.resolve(&source.skeleton, e.3))
        .collect::<Result<_, _>>()?;
    let model_joints: Vec<usize> = EFFECTORS
        .iter()
        .map(|e| {
            model_clip
                .skeleton
                .index(e.1)
                .ok_or_else(|| MappingError::Landmarks {
                    mapping: mapping.name.clone(),
                    message: format!("model {} has no joint '{}'", mapped.model.name, e.1),
                })
        })
        .collect::<Result<_, _>>()?;
    for f in 0..frames {
        source.globals(f, &mut gs);
        model_clip.globals(f, &mut gm);
        for (k, e) in EFFECTORS.iter().enumerate() {
            let lm = resolved[k];
            let ts = gs[lm.joint];
            let src_end = if lm.end_site {
                source.skeleton.joints[lm.joint]
                    .end_site
                    .unwrap_or_default()
            } else {
                Default::default()
            };
            let ps = ts.translation + ts.rotation * src_end;
            let tm = gm[model_joints[k]];
            let model_end = if e.2 {
                model_clip.skeleton.joints[model_joints[k]]
                    .end_site
                    .unwrap_or_default()
            } else {
                Default::default()
            };
            let pm = tm.translation + tm.rotation * model_end;
            let d = (ps - pm).length();
            sums[k] += d;
            maxes[k] = maxes[k].max(d);
        }
    }
    for (k, e) in EFFECTORS.iter().enumerate() {
        out.push(EffectorError {
            effector: e.0.into(),
            mean_m: sums[k] / frames.max(1) as f64,
            max_m: maxes[k],
        });
    }
    Ok(out)
}
