//! Whole-feature checks of the foundation on clips the project makes itself: known joint angles
//! survive BVH output in every Euler order, reading, and mapping back onto the model; End Sites
//! land where they should; left and right are not swapped.

use marionette::bvh;
use marionette::clips::KeyframeClip;
use marionette::humanoid::{Figure, FigureClip};
use marionette::mapping::{Mapping, effector_errors, retarget};
use marionette::skeleton::Clip;

/// A clip with known angles: the left knee swings 0 → 95 → 30°, the right knee stays at 10°,
/// the hips, shoulders and waist move too, and the pelvis turns and travels.
fn known_clip() -> FigureClip {
    let text = r#"(format_version: 1, name: "known", model: "humanoid24", fps: 60.0, duration: 2.0,
        keys: [
          (t: 0.0, forward: 0.0, turn: 0.0, dofs: {"left_knee": 0.0, "right_knee": 10.0, "left_hip_flexion": 0.0,
               "right_hip_abduction": 0.0, "waist_flexion": 0.0, "left_shoulder_abduction": 10.0, "right_elbow_flexion": 20.0}),
          (t: 0.8, forward: 0.3, turn: 40.0, dofs: {"left_knee": 95.0, "left_hip_flexion": 60.0, "right_hip_abduction": 15.0,
               "waist_flexion": 20.0, "left_shoulder_abduction": 80.0, "right_elbow_flexion": 100.0}),
          (t: 2.0, forward: 0.5, turn: -20.0, dofs: {"left_knee": 30.0, "right_knee": 10.0, "left_hip_flexion": 10.0,
               "right_hip_abduction": 5.0, "waist_flexion": 5.0, "left_shoulder_abduction": 30.0, "right_elbow_flexion": 45.0}),
        ])"#;
    KeyframeClip::parse(text, "known").unwrap().to_figure_clip()
}

fn through_bvh(clip: &Clip, order: [usize; 3]) -> Clip {
    let text = bvh::to_string(&clip.to_bvh_with_order(order));
    let (b, warnings) = bvh::parse(text.as_bytes()).unwrap();
    assert!(warnings.is_empty());
    Clip::from_bvh(&b, Some(1.0)).unwrap()
}

const ORDERS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

#[test]
fn every_euler_order_reproduces_the_positions() {
    let original = known_clip().to_clip();
    let expected = original.point_frames();
    for order in ORDERS {
        let back = through_bvh(&original, order);
        let got = back.point_frames();
        for (f, (a, b)) in expected.iter().zip(&got).enumerate() {
            for (p, q) in a.iter().zip(b) {
                // The writer prints shortest round-trip decimals, so only rounding of the
                // Euler decomposition remains.
                assert!(
                    (*p - *q).length() < 1e-9,
                    "order {order:?} frame {f}: {p} vs {q}"
                );
            }
        }
    }
}

#[test]
fn reading_with_the_wrong_euler_order_is_detected_by_positions() {
    // The same numbers read as another order put the hands elsewhere: a reader that ignored
    // the CHANNELS order would fail the test above.
    let original = known_clip().to_clip();
    let bvh_zxy = original.to_bvh_with_order([2, 0, 1]);
    let text = bvh::to_string(&bvh_zxy).replace(
        "Zrotation Xrotation Yrotation",
        "Xrotation Yrotation Zrotation",
    );
    let (wrong, _) = bvh::parse(text.as_bytes()).unwrap();
    let wrong = Clip::from_bvh(&wrong, Some(1.0)).unwrap().point_frames();
    let right = original.point_frames();
    let worst = wrong
        .iter()
        .zip(&right)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(p, q)| (*p - *q).length()))
        .fold(0.0, f64::max);
    assert!(
        worst > 0.05,
        "a wrong order moved no point by more than {worst} m"
    );
}

#[test]
fn known_knee_angles_survive_bvh_and_mapping_within_a_degree() {
    let model = Figure::by_name("humanoid24").unwrap();
    let known = known_clip();
    let read = through_bvh(&known.to_clip(), [2, 1, 0]);
    let mapping = Mapping::detect(&read.skeleton).unwrap();
    assert_eq!(mapping.name, "marionette_humanoid24");
    let mapped = retarget(&read, &mapping, &model).unwrap();
    for name in [
        "left_knee",
        "right_knee",
        "left_hip_flexion",
        "right_elbow_flexion",
        "waist_flexion",
    ] {
        let d = model.dof_index(name).unwrap();
        let (a, b) = (known.dof_series(d), mapped.dof_series(d));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs().to_degrees())
            .fold(0.0, f64::max);
        assert!(worst < 1.0, "{name}: off by {worst:.3} degrees");
    }
    // Left stays left: the left knee bends to 95°, the right one stays at 10°.
    let lk = mapped.dof_series(model.dof_index("left_knee").unwrap());
    let rk = mapped.dof_series(model.dof_index("right_knee").unwrap());
    assert!(lk.iter().copied().fold(0.0, f64::max).to_degrees() > 94.0);
    assert!(rk.iter().all(|a| (a.to_degrees() - 10.0).abs() < 1.0));
    // And the end effectors are where the source has them.
    for e in effector_errors(&read, &mapping, &mapped).unwrap() {
        assert!(e.max_m < 0.01, "{}: {} m", e.effector, e.max_m);
    }
}

#[test]
fn a_swapped_left_right_mapping_is_caught_by_the_feet() {
    let model = Figure::by_name("humanoid24").unwrap();
    let read = through_bvh(&known_clip().to_clip(), [2, 0, 1]);
    let mut swapped = Mapping::detect(&read.skeleton).unwrap();
    let original = swapped.landmarks.clone();
    for (k, v) in original.iter() {
        if let Some(rest) = k.strip_prefix("left_") {
            swapped
                .landmarks
                .insert(k.clone(), original[&format!("right_{rest}")].clone());
            swapped.landmarks.insert(format!("right_{rest}"), v.clone());
        }
    }
    let mapped = retarget(&read, &swapped, &model).unwrap();
    let errs = effector_errors(&read, &Mapping::detect(&read.skeleton).unwrap(), &mapped).unwrap();
    let foot = errs.iter().find(|e| e.effector == "left_foot").unwrap();
    assert!(
        foot.max_m > 0.1,
        "swapped mapping went unnoticed: left foot off by only {} m",
        foot.max_m
    );
}

#[test]
fn end_sites_are_placed_by_their_parent_joint() {
    // The head top is the neck's End Site: at rest straight above the neck by its offset, and it
    // turns with the neck.
    let model = Figure::by_name("humanoid24").unwrap();
    let clip = known_clip().to_clip();
    let read = through_bvh(&clip, [2, 0, 1]);
    let neck = read.skeleton.index("neck").unwrap();
    let end = read.skeleton.joints[neck].end_site.unwrap();
    let model_end = model.joints[model.joint_index("neck").unwrap()]
        .end_site
        .unwrap();
    assert!((end - model_end).length() < 1e-9, "{end} vs {model_end}");
    let names = read.skeleton.point_names();
    let head_top = names.iter().position(|n| n == "neck_end").unwrap();
    let mut g = vec![];
    for (f, pts) in read.point_frames().iter().enumerate().step_by(17) {
        read.globals(f, &mut g);
        let expected = g[neck].translation + g[neck].rotation * end;
        assert!((pts[head_top] - expected).length() < 1e-12);
        assert!(
            pts[head_top].y > g[neck].translation.y,
            "the head top is above the neck"
        );
    }
}
