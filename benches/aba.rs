//! One articulated-body-algorithm call on the fall21 human (27 velocity DOF: 21 + a 6-DOF
//! floating base), at a generic pose and velocity with contact-like external forces.
//! Run: `cargo bench --bench aba`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DQuat, DVec3};
use marionette::dynamics::{Data, ForceVec, aba, aba_passes, kinematics};
use marionette::dynamics::{LaneData, LaneInput, aba_passes_lanes};
use marionette::humanoid::fall21_body;
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
    let v: Vec<f64> = (0..model.nv())
        .map(|k| 0.5 * ((k as f64) * 1.3).cos())
        .collect();
    let tau: Vec<f64> = (0..model.nv())
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
    assert_eq!(model.nv(), 27);
    c.bench_function("aba_fall21_27dof", |b| {
        b.iter(|| {
            let qdd = aba(
                model,
                &mut data,
                black_box(&q),
                black_box(&v),
                black_box(&tau),
                black_box(&f_ext),
            )
            .unwrap();
            black_box(qdd[6])
        })
    });
    // Passes 2 and 3 only (kinematics done once beforehand), four bodies: one by one, and in
    // the lanes of one vector call.
    let mut datas: Vec<Data> = (0..4).map(|_| Data::new(model)).collect();
    for d in &mut datas {
        kinematics(model, d, &q, &v);
    }
    c.bench_function("aba_passes_fall21_x4_one_by_one", |b| {
        b.iter(|| {
            for d in &mut datas {
                aba_passes(model, d, black_box(&tau), black_box(&f_ext), None, &[]);
            }
            black_box(datas[3].qdd[6])
        })
    });
    let mut lanes = LaneData::new(model);
    c.bench_function("aba_passes_fall21_x4_lanes", |b| {
        b.iter(|| {
            let mut bodies: Vec<LaneInput> = datas
                .iter_mut()
                .map(|data| LaneInput {
                    data,
                    tau: black_box(&tau[..]),
                    f_ext: black_box(&f_ext[..]),
                    armature: None,
                })
                .collect();
            aba_passes_lanes(model, &mut lanes, &mut bodies);
            black_box(datas[3].qdd[6])
        })
    });
}

criterion_group!(benches, bench_aba);
criterion_main!(benches);
