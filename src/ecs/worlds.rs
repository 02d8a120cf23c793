//! A pool of parallel Worlds: one World per experiment (a fall, an individual of a population),
//! each with its own seeded random number generator, run in parallel with rayon. Worlds share
//! nothing mutable and every World's seed comes from the run's seed and the World's index, never
//! from completion order, so results are bit-identical on any number of threads.

use bevy_ecs::prelude::*;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use rayon::prelude::*;

pub use crate::seed::world_seed;

/// The World's index in its pool and the seed its generator started from.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorldSeed {
    /// Index in the pool.
    pub index: usize,
    /// Seed of [`WorldRng`].
    pub seed: u64,
}

/// The World's random number generator (PCG64), seeded by [`world_seed`].
#[derive(Resource, Clone, Debug)]
pub struct WorldRng(pub Pcg64);

/// Worlds that run side by side.
#[derive(Default)]
pub struct WorldPool {
    worlds: Vec<World>,
}

impl WorldPool {
    /// `n` Worlds, each given its [`WorldSeed`] and [`WorldRng`] from `seed`, then filled by
    /// `init(index, world)` (in parallel).
    pub fn new<E: Send>(
        n: usize,
        seed: u64,
        init: impl Fn(usize, &mut World) -> Result<(), E> + Sync,
    ) -> Result<Self, E> {
        let worlds = (0..n)
            .into_par_iter()
            .map(|index| {
                let s = world_seed(seed, index as u64);
                let mut w = World::new();
                w.insert_resource(WorldSeed { index, seed: s });
                w.insert_resource(WorldRng(Pcg64::seed_from_u64(s)));
                init(index, &mut w)?;
                Ok(w)
            })
            .collect::<Result<Vec<_>, E>>()?;
        Ok(Self { worlds })
    }

    /// Runs `f` on every World in parallel; the results are in World order.
    pub fn run<T: Send>(&mut self, f: impl Fn(&mut World) -> T + Sync + Send) -> Vec<T> {
        self.worlds.par_iter_mut().map(f).collect()
    }

    /// The Worlds.
    pub fn worlds(&self) -> &[World] {
        &self.worlds
    }

    /// The Worlds, mutably.
    pub fn worlds_mut(&mut self) -> &mut [World] {
        &mut self.worlds
    }

    /// Number of Worlds.
    pub fn len(&self) -> usize {
        self.worlds.len()
    }

    /// True when the pool holds no World.
    pub fn is_empty(&self) -> bool {
        self.worlds.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn every_world_gets_its_own_stream_whatever_the_thread_count() {
        let draw = |threads: usize| -> Vec<u64> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut p = WorldPool::new(16, 7, |_, _| Ok::<(), ()>(())).unwrap();
                p.run(|w| w.resource_mut::<WorldRng>().0.random::<u64>())
            })
        };
        let one = draw(1);
        assert_eq!(one, draw(2));
        let mut unique = one.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), 16, "streams repeat: {one:?}");
        assert_ne!(world_seed(7, 0), world_seed(8, 0));
    }
}
