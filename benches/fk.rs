//! Forward-kinematics throughput: global transforms of every joint of every frame of a clip,
//! in joint transforms per second (criterion `Throughput::Elements`).
//!
//! Inputs: the project's keyframed normal jump on humanoid24 (17 joints, 240 frames), and the
//! CMU forward jumps from `MARIONETTE_DATA` (31 joints, 2752 frames) when present.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use marionette::clips::KeyframeClip;
use marionette::skeleton::{Clip, Transform, forward_kinematics};

fn fk_all_frames(clip: &Clip, out: &mut [Transform]) {
    let n = clip.joint_count();
    for f in 0..clip.frame_count() {
        forward_kinematics(
            &clip.skeleton,
            clip.frame_translations(f),
            clip.frame_rotations(f),
            &mut out[..n],
        );
        black_box(&out[..n]);
    }
}

fn bench(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut clips = vec![(
        "normal_jump_humanoid24",
        KeyframeClip::load(&root.join("scenes/clips/normal_jump.ron"))
            .unwrap()
            .to_figure_clip()
            .to_clip(),
    )];
    let data = marionette::io::data_dir();
    let jumps = data.join("cmu/cmu_01_01_forward_jumps.bvh");
    match marionette::bvh::parse_file(&jumps) {
        Ok((b, _)) => clips.push(("cmu_forward_jumps", Clip::from_bvh(&b, None).unwrap())),
        Err(_) => eprintln!(
            "MARIONETTE_DATA not found at {}; benchmarking the generated clip only",
            data.display()
        ),
    }
    let mut group = c.benchmark_group("forward_kinematics");
    for (name, clip) in &clips {
        let mut out = vec![Transform::IDENTITY; clip.joint_count()];
        group.throughput(Throughput::Elements(
            (clip.joint_count() * clip.frame_count()) as u64,
        ));
        group.bench_function(*name, |b| {
            b.iter(|| fk_all_frames(black_box(clip), &mut out))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
