//! Learning: a 24-DOF primitive reproduces a smooth synthetic demonstration; every formulation
//! and both regressions fit; degenerate DOFs (g = s, tiny |g − s|) and clips starting
//! mid-motion are handled.

use marionette::primitive::synthetic::{knee_jump, smooth_humanoid24};
use marionette::primitive::{
    Formulation, KernelCount, LearnConfig, Primitive, Regression, SpatialScaling, Trajectory,
};

const DEG: f64 = std::f64::consts::PI / 180.0;

#[test]
fn learned_24_dof_primitive_reproduces_a_1000_frame_demo() {
    let demo = smooth_humanoid24(1000, 120.0, 7).unwrap();
    assert_eq!((demo.frames(), demo.dofs()), (1000, 24));
    let learned = Primitive::learn("smooth", &demo, &LearnConfig::default()).unwrap();
    let median = learned.fit.median_angle_rmse_deg().unwrap();
    let max = learned.fit.max_angle_rmse_deg().unwrap();
    eprintln!("24-DOF ridge: median RMSE {median:.4} deg, max {max:.4} deg");
    assert!(median < 0.5, "median RMSE {median} deg");
}

#[test]
fn every_formulation_and_regression_fits_the_demo() {
    let demo = smooth_humanoid24(1000, 120.0, 11).unwrap();
    for formulation in [
        Formulation::default(),
        Formulation::ijspeert2013(),
        Formulation::hoffmann2009(),
    ] {
        for regression in [
            Regression::LocallyWeighted,
            Regression::Ridge { lambda: 1e-6 },
        ] {
            let cfg = LearnConfig {
                formulation,
                regression,
                ..LearnConfig::default()
            };
            let l = Primitive::learn("smooth", &demo, &cfg).unwrap();
            let median = l.fit.median_angle_rmse_deg().unwrap();
            let max = l.fit.max_angle_rmse_deg().unwrap();
            eprintln!(
                "{} {regression:?}: median {median:.4} deg, max {max:.4} deg",
                formulation.name()
            );
            assert!(
                median < 1.0,
                "{} {regression:?}: {median}",
                formulation.name()
            );
        }
    }
}
