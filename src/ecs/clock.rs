//! The one clock of a World: a schedule run is one tick of `tick_s` seconds, in which physics
//! takes `substeps` steps of `tick_s / substeps` seconds. Clip playback and primitive players
//! advance by a tick, simulated bodies by their substeps.

use bevy_ecs::prelude::*;

/// The World's clock (a resource).
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct Clock {
    /// Seconds per tick (one schedule run).
    pub tick_s: f64,
    /// Physics steps per tick (≥ 1).
    pub substeps: u32,
    /// Ticks completed.
    pub tick: u64,
    /// Time at the start of the current tick (s): `tick · tick_s`.
    pub time_s: f64,
}

impl Clock {
    /// A clock of `tick_s` seconds per tick with `substeps` physics steps per tick.
    pub fn new(tick_s: f64, substeps: u32) -> Self {
        Self {
            tick_s,
            substeps: substeps.max(1),
            tick: 0,
            time_s: 0.0,
        }
    }

    /// A clock whose tick is one physics step of `dt` seconds.
    pub fn physics(dt: f64) -> Self {
        Self::new(dt, 1)
    }

    /// The physics step (s): `tick_s / substeps`.
    pub fn physics_dt(&self) -> f64 {
        self.tick_s / self.substeps as f64
    }
}

/// Advances the clock by one tick.
pub fn advance_clock(mut clock: ResMut<Clock>) {
    clock.tick += 1;
    clock.time_s = clock.tick as f64 * clock.tick_s;
}
