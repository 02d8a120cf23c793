//! The figures that say what a jump did: how high the root (pelvis) rose above standing, how long
//! both feet were off the floor, and how far any foot went below the floor. The flight comes from
//! foot contact ([`crate::analysis::clip_contacts`]: a flight is when no point of either foot
//! touches), not from the root, so a deeper crouch without a higher flight shows as such. Jumps
//! compared with one another are measured against one reference ([`jump_figures_against`]): the
//! floor and foot-point rest heights of one of them.

use serde::Serialize;

use crate::analysis::{
    ContactConfig, ContactReference, Contacts, Span, clip_contacts, clip_contacts_against,
};
use crate::humanoid::FigureClip;
use crate::signal::median;

/// Height above the floor under which a foot point counts as touching it, metres (as
/// `marionette inspect` and the show scenes use).
pub const CONTACT_THRESHOLD_M: f64 = 0.03;

/// Shortest span without contact that counts as a flight, seconds (shorter ones are noise).
pub const MIN_FLIGHT_S: f64 = 0.1;

/// Length of the standing window at a clip's start, seconds: the standing root height is the
/// median of the root heights in it.
pub const STANDING_WINDOW_S: f64 = 0.2;

/// What one jump did, measured on its clip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct JumpFigures {
    /// Root height while standing (the median over the first [`STANDING_WINDOW_S`]), metres.
    pub standing_root_m: f64,
    /// Highest root height, metres.
    pub apex_root_m: f64,
    /// `apex_root_m − standing_root_m`: the jump height, metres.
    pub apex_above_standing_m: f64,
    /// When the root is highest, seconds from the clip's start.
    pub apex_time_s: f64,
    /// The longest span with both feet off the floor (`None`: the figure never leaves it).
    pub flight: Option<Span>,
    /// Its length, seconds (0 without a flight).
    pub flight_s: f64,
    /// The longest flight found with the clip's own floor and foot rest heights, as
    /// `marionette inspect` finds it in the clip written as BVH (the same as `flight` unless the
    /// figures were measured against another jump's, [`jump_figures_against`]).
    pub own_contacts_flight: Option<Span>,
    /// The lowest any foot point (ankle or toe) comes relative to `floor_y`, metres: negative is
    /// how deep a foot went through the floor.
    pub lowest_foot_above_floor_m: f64,
}

/// Measures a jump on `clip`, with the floor at height `floor_y` (metres) for the feet's lowest
/// point; the flight is the longest span in which [`clip_contacts`] (threshold
/// [`CONTACT_THRESHOLD_M`], shortest flight [`MIN_FLIGHT_S`]) finds no foot touching, the
/// clip's own floor and rest heights found in it.
pub fn jump_figures(clip: &FigureClip, floor_y: f64) -> JumpFigures {
    let contacts = clip_contacts(&clip.to_clip(), CONTACT_THRESHOLD_M, MIN_FLIGHT_S);
    let own = longest_flight(contacts.as_ref());
    figures(clip, floor_y, own, own)
}

/// [`jump_figures`] against `reference` (the floor and foot-point rest heights of another jump
/// of the same model, [`contact_reference`]): a foot point touches while within
/// [`CONTACT_THRESHOLD_M`] of its reference rest height, and the lowest foot point is measured
/// from the reference floor. So two jumps are compared by one standard: with rest heights
/// estimated per clip, a point that rests just under the estimate's height limit in one jump and
/// just over it in the other touches in one only, which moves the flight's ends.
pub fn jump_figures_against(clip: &FigureClip, reference: &ContactReference) -> JumpFigures {
    let c = clip.to_clip();
    let against = clip_contacts_against(&c, &contact_config(), reference);
    let own = clip_contacts(&c, CONTACT_THRESHOLD_M, MIN_FLIGHT_S);
    figures(
        clip,
        reference.floor_y_m,
        longest_flight(against.as_ref()),
        longest_flight(own.as_ref()),
    )
}

/// The longest flight of `contacts`.
fn longest_flight(contacts: Option<&Contacts>) -> Option<Span> {
    contacts.and_then(|c| {
        c.flights
            .iter()
            .copied()
            .max_by(|a, b| a.duration().total_cmp(&b.duration()))
    })
}

/// The floor and foot-point rest heights of `clip` (as [`jump_figures`] finds them), to measure
/// other jumps of its model against ([`jump_figures_against`]); `None` when the model has no
/// feet.
pub fn contact_reference(clip: &FigureClip) -> Option<ContactReference> {
    clip_contacts(&clip.to_clip(), CONTACT_THRESHOLD_M, MIN_FLIGHT_S).map(|c| c.reference())
}

fn contact_config() -> ContactConfig {
    ContactConfig {
        threshold_m: CONTACT_THRESHOLD_M,
        min_flight_s: MIN_FLIGHT_S,
        ..ContactConfig::default()
    }
}

/// The figures of `clip` with its flight found (`own`: with its own contacts).
fn figures(
    clip: &FigureClip,
    floor_y: f64,
    flight: Option<Span>,
    own: Option<Span>,
) -> JumpFigures {
    let root: Vec<f64> = clip.root_translation.iter().map(|t| t.y).collect();
    let standing_root_m = standing_root_m(clip);
    let (apex_frame, apex_root_m) =
        root.iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |m, (k, y)| if y > m.1 { (k, y) } else { m },
            );
    let lowest_foot_above_floor_m = clip
        .foot_heights()
        .iter()
        .flatten()
        .fold(f64::INFINITY, |m, h| m.min(*h))
        - floor_y;
    JumpFigures {
        standing_root_m,
        apex_root_m,
        apex_above_standing_m: apex_root_m - standing_root_m,
        apex_time_s: apex_frame as f64 * clip.frame_time,
        flight,
        flight_s: flight.map_or(0.0, |f| f.duration()),
        own_contacts_flight: own,
        lowest_foot_above_floor_m,
    }
}

/// Root height of `clip` while standing: the median over its first [`STANDING_WINDOW_S`],
/// metres.
pub fn standing_root_m(clip: &FigureClip) -> f64 {
    let root: Vec<f64> = clip.root_translation.iter().map(|t| t.y).collect();
    let window = ((STANDING_WINDOW_S / clip.frame_time).round() as usize).clamp(1, root.len());
    median(&root[..window])
}

/// The floor a clip stands on: the height [`clip_contacts`] finds its feet touching, metres
/// (`None` when the clip has no feet).
pub fn floor_of(clip: &FigureClip) -> Option<f64> {
    clip_contacts(&clip.to_clip(), CONTACT_THRESHOLD_M, MIN_FLIGHT_S).map(|c| c.floor_y_m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clips::KeyframeClip;

    #[test]
    fn a_keyframed_jump_rises_by_its_ballistic_arc_and_flies_as_long_as_keyed() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/clips/normal_jump.ron"
        ))
        .unwrap();
        let clip = KeyframeClip::parse(&text, "normal_jump.ron")
            .unwrap()
            .to_figure_clip();
        let f = jump_figures(&clip, 0.0);
        // Keyed flight 0.92–1.32 s: the feet are more than 3 cm up for nearly all of it.
        let fl = f.flight.unwrap();
        assert!(
            (fl.start_s - 0.92).abs() < 0.03 && (fl.end_s - 1.32).abs() < 0.03,
            "{fl:?}"
        );
        // The arc g T²/8 = 0.196 m over the take-off height, which is near standing.
        assert!(
            f.apex_above_standing_m > 0.1 && f.apex_above_standing_m < 0.3,
            "{f:?}"
        );
        // The keyframed clip's feet never go below its floor.
        assert!(f.lowest_foot_above_floor_m > -1e-9, "{f:?}");
    }
}
