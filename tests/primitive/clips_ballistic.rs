//! The whole-body centre of mass of the project's keyframed jumps: their flights keep the root,
//! not the centre of mass, on a ballistic arc; [`make_flights_ballistic`] puts the centre of
//! mass on it (the root then moves against the limbs' swing), and what is left is the take-off
//! and landing, where the keyed ground motion's centre of mass does not move as the flight's
//! does (measured and printed).

use std::path::PathBuf;

use marionette::clips::ballistic::{
    centre_of_mass_track, make_flights_ballistic, max_downward_pull_bw,
};
use marionette::clips::{GRAVITY, KeyframeClip};

fn clip(file: &str) -> KeyframeClip {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/clips")
        .join(file);
    KeyframeClip::load(&path).unwrap()
}

#[test]
fn making_the_keyframed_flights_ballistic_puts_the_centre_of_mass_on_its_arc() {
    for file in ["low_jump.ron", "normal_jump.ron"] {
        let k = clip(file);
        let mut m = k.to_figure_clip();
        let (keyed_pull, keyed_at) = max_downward_pull_bw(&m).unwrap();
        let moved = make_flights_ballistic(&mut m, &k.flights).unwrap();
        let com = centre_of_mass_track(&m).unwrap();
        let dt = m.frame_time;
        let &(a, b) = k.flights.first().unwrap();
        let (fa, fb) = ((a / dt).round() as usize, (b / dt).round() as usize);
        for f in fa + 1..fb - 1 {
            let acc = (com[f + 1] - 2.0 * com[f] + com[f - 1]) / (dt * dt);
            assert!(
                (acc.y + GRAVITY).abs() < 1e-6 && acc.x.abs() < 1e-6 && acc.z.abs() < 1e-6,
                "{file} frame {f}: {acc}"
            );
        }
        // The pelvis is not on a parabola: it moves against the limbs' swing.
        let root_acc = |f: usize| {
            (m.root_translation[f + 1].y - 2.0 * m.root_translation[f].y
                + m.root_translation[f - 1].y)
                / (dt * dt)
        };
        let off = (fa + 1..fb - 1)
            .map(|f| (root_acc(f) + GRAVITY).abs())
            .fold(0.0, f64::max);
        let v = |f: usize| (com[f + 1].y - com[f - 1].y) / (2.0 * dt);
        let (pull, at) = max_downward_pull_bw(&m).unwrap();
        println!(
            "{file}: as keyed, downward pull {keyed_pull:.3} body weights at {keyed_at:.3} s; \
             with the centre of mass ballistic (root moved up to {moved:.3} m) the root's \
             acceleration is off g by up to {off:.2} m/s² in flight, the centre of mass's \
             vertical velocity goes {:.3} → {:.3} m/s at take-off and {:.3} → {:.3} m/s at \
             landing, downward pull {pull:.3} body weights at {at:.3} s",
            v(fa - 1),
            v(fa + 1),
            v(fb - 1),
            v(fb + 1)
        );
        assert!(off > 0.5, "{file}: {off}");
    }
}
