//! BVH reading and writing throughput (bytes of BVH text per second).
//!
//! Reads the largest public data file (`cmu/acrnn_indian_13.bvh`, 2.5 MB) from `$MARIONETTE_DATA`
//! or `../shared/data` (from the working directory, see `marionette::io::data_dir`); when that is absent it says so and measures a generated file of the same
//! size and shape (43 joints, 132 channels, values with about six significant digits) instead.
//!
//! `number_conversion_only` times just `str::parse::<f64>` over the file's motion values (split
//! beforehand) with the same byte count, the floor `parse` can approach.
//!
//! Run: `cargo bench --bench bvh_parse`

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use marionette::bvh::{self, Bvh, BvhJoint, Channel};

fn data_file() -> Option<PathBuf> {
    let dir = marionette::io::data_dir();
    let path = dir.join("cmu/acrnn_indian_13.bvh");
    if path.is_file() {
        Some(path)
    } else {
        println!(
            "MARIONETTE_DATA not found at {}; benchmarking a generated 2.5 MB file instead",
            dir.display()
        );
        None
    }
}

/// A skeleton of 43 joints (6 root channels + 42 × 3 = 132 channels) with `frames` frames of
/// values rounded to 6 significant digits, as exporters write them.
fn generated(frames: usize) -> Bvh {
    use Channel::*;
    let mut joints = Vec::new();
    let mut first = 0;
    for i in 0..43 {
        let channels = if i == 0 {
            vec![
                Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation,
            ]
        } else {
            vec![Zrotation, Xrotation, Yrotation]
        };
        // Five chains of eight joints and one of two, all hanging off the root.
        let parent = match i {
            0 => None,
            _ if (i - 1) % 8 == 0 => Some(0),
            _ => Some(i - 1),
        };
        let leaf = i == 42 || i % 8 == 0;
        joints.push(BvhJoint {
            name: format!("joint{i}"),
            parent,
            offset: DVec3::new(0.5 * i as f64, 7.07133, -0.48768),
            first_channel: first,
            end_site: leaf.then_some(DVec3::new(0.0, 3.2, 0.0)),
            channels,
        });
        first += joints[i].channels.len();
    }
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut motion = Vec::with_capacity(frames * first);
    for _ in 0..frames * first {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u = (state >> 11) as f64 / (1u64 << 53) as f64; // [0, 1)
        let v = (u - 0.5) * 360.0 * 10f64.powi((state % 4) as i32 - 3);
        let digits = 5 - v.abs().log10().floor().clamp(-10.0, 5.0) as i32;
        let scale = 10f64.powi(digits);
        motion.push((v * scale).round() / scale);
    }
    Bvh {
        joints,
        frame_time: 0.00833333,
        channel_count: first,
        motion,
    }
}

fn bench(c: &mut Criterion) {
    let bytes = match data_file() {
        Some(p) => std::fs::read(p).expect("read data file"),
        None => bvh::to_string(&generated(2000)).into_bytes(),
    };
    let (parsed, _) = bvh::parse(&bytes).expect("bench input parses");

    let mut g = c.benchmark_group("bvh");
    g.throughput(Throughput::Bytes(bytes.len() as u64));
    g.bench_function("parse", |b| {
        b.iter(|| bvh::parse(black_box(&bytes)).unwrap())
    });
    // Baseline: only the text → f64 conversions of the motion values (tokens split beforehand),
    // to show how much of `parse` is number conversion.
    let text = std::str::from_utf8(&bytes).expect("UTF-8");
    let motion_text = text.rsplit_once("Frame Time:").expect("MOTION block").1;
    let tokens: Vec<&str> = motion_text.split_ascii_whitespace().skip(1).collect();
    assert_eq!(tokens.len(), parsed.motion.len());
    g.bench_function("number_conversion_only", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for t in black_box(&tokens) {
                sum += t.parse::<f64>().unwrap();
            }
            sum
        })
    });
    let written = bvh::to_string(&parsed);
    g.throughput(Throughput::Bytes(written.len() as u64));
    g.bench_function("to_string", |b| {
        b.iter(|| bvh::to_string(black_box(&parsed)))
    });
    let gen_bytes = bvh::to_string(&generated(2000)).into_bytes();
    g.throughput(Throughput::Bytes(gen_bytes.len() as u64));
    g.bench_function("parse_generated", |b| {
        b.iter(|| bvh::parse(black_box(&gen_bytes)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
