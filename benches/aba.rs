//! One articulated-body-algorithm call on the fall21 human (27 velocity DOF: 21 + a 6-DOF
//! floating base), at a generic pose and velocity with contact-like external forces.
//! Run: `cargo bench --bench aba`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DQuat, DVec3};
use marionette::dynamics::{Data, ForceVec, aba};
use marionette::humanoid::body::fall21_body;
use std::hint::black_box;

fn bench_aba(c: &mut Criterion) {
    let body = fall21_body(1.70, 65.0, 9.81).expect("fall21 body");
    let model = &body.model;
    let angles: Vec<f64> = (0..21).map(|k| 0.3 * ((k as f64) * 0.7).sin()).collect();
    let q = body.configuration(
        &angles,
        DVec3::new(0.1, 0.9, -0.2),
        DQuat::from_axis_angle(DVec3::new(0.2, 1.0, 0.1).normalize(), 0.4),
    );
    let v: Vec<f64> = (0..model.nv)
        .map(|k| 0.5 * ((k as f64) * 1.3).cos())
        .collect();
    let tau: Vec<f64> = (0..model.nv)
        .map(|k| {
            if k < 6 {
                0.0
            } else {
                10.0 * ((k as f64) * 0.9).sin()
            }
        })
        .collect();
    let f_ext: Vec<ForceVec> = (0..model.nbodies())
        .map(|i| {
            ForceVec::new(
                DVec3::new(0.1, 0.0, 0.2) * i as f64,
                DVec3::new(0.0, 50.0, 3.0),
            )
        })
        .collect();
    let mut data = Data::new(model);
    assert_eq!(model.nv, 27);
    c.bench_function("aba_fall21_27dof", |b| {
        b.iter(|| {
            let qdd = aba(
                model,
                &mut data,
                black_box(&q),
                black_box(&v),
                black_box(&tau),
                black_box(&f_ext),
            );
            black_box(qdd[6])
        })
    });
}

criterion_group!(benches, bench_aba);
criterion_main!(benches);
