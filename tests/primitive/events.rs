//! Jump events on plain data: exact on a clean synthetic jump, robust on noisy data.

use marionette::primitive::synthetic::jump_root_height;
use marionette::primitive::{EventConfig, PrimitiveError, find_jump_events};

/// Deterministic Gaussian noise (SplitMix64 + Box–Muller), σ in metres.
fn noisy(x: &[f64], sigma: f64, seed: u64) -> Vec<f64> {
    let mut st = seed;
    let mut next = || {
        st = st.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = st;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    x.iter()
        .map(|v| {
            let (u1, u2) = (next(), next());
            v + sigma * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        })
        .collect()
}

#[test]
fn events_of_a_clean_and_of_noisy_synthetic_jumps() {
    let fps = 120.0;
    let (root, foot, truth) = jump_root_height(fps);
    for (label, seed, sigma) in [
        ("clean", 0, 0.0),
        ("noisy", 1, 0.003),
        ("noisy", 2, 0.003),
        ("noisy", 3, 0.005),
    ] {
        let y = if sigma > 0.0 {
            noisy(&root, sigma, seed)
        } else {
            root.clone()
        };
        let f = if sigma > 0.0 {
            noisy(&foot, sigma, seed + 100)
        } else {
            foot.clone()
        };
        for feet in [None, Some(vec![f.clone()])] {
            let e =
                find_jump_events(&y, 1.0 / fps, feet.as_deref(), &EventConfig::default()).unwrap();
            eprintln!(
                "{label} σ={sigma} feet={}: {e:?} (truth {truth:?})",
                feet.is_some()
            );
            assert!(
                (e.bend - truth.bend).abs() < 0.04,
                "{label}: bend {}",
                e.bend
            );
            assert!(
                (e.leap - truth.leap).abs() < 0.03,
                "{label}: leap {}",
                e.leap
            );
            assert!(
                (e.land - truth.land).abs() < 0.025,
                "{label}: land {}",
                e.land
            );
            assert!(
                (e.take_off - truth.take_off).abs() < 0.03,
                "{label}: take-off {}",
                e.take_off
            );
            assert!(
                e.start >= truth.start - 0.02 && e.start < truth.start + 0.1,
                "{label}: start {}",
                e.start
            );
            assert!(
                e.start < e.bend && e.bend < e.take_off && e.take_off < e.leap && e.leap < e.land
            );
        }
    }
}

#[test]
fn clips_without_a_jump_or_landing_are_clear_errors() {
    let fps = 120.0;
    let (root, _, truth) = jump_root_height(fps);
    // Cut in mid-air, after the peak: no landing.
    let cut = ((truth.leap + 0.1) * fps) as usize;
    let e = find_jump_events(&root[..cut], 1.0 / fps, None, &EventConfig::default()).unwrap_err();
    assert!(matches!(e, PrimitiveError::EventsNotFound { .. }), "{e}");
    assert!(e.to_string().contains("landing"), "{e}");
    // Cut before the peak: highest at the last frame.
    let e = find_jump_events(
        &root[..(1.3 * fps) as usize],
        1.0 / fps,
        None,
        &EventConfig::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("no flight peak"), "{e}");
    assert!(find_jump_events(&root, 0.0, None, &EventConfig::default()).is_err());
    let mut bad = root.clone();
    bad[10] = f64::NAN;
    assert!(matches!(
        find_jump_events(&bad, 1.0 / fps, None, &EventConfig::default()),
        Err(PrimitiveError::NonFinite { .. })
    ));
}
