//! Seeds of parallel streams: one run seed and an index (a World in a pool, a GA generation)
//! give an unrelated stream each, the same on any number of threads.

/// The seed of stream `index` of a run seeded with `seed`: SplitMix64 finalisation of
/// `seed ⊕ golden·(index + 1)`, so neighbouring indices get unrelated streams.
pub fn world_seed(seed: u64, index: u64) -> u64 {
    let mut z = seed ^ 0x9E37_79B9_7F4A_7C15u64.wrapping_mul(index.wrapping_add(1));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_seeds_and_indices_give_other_streams() {
        assert_ne!(world_seed(7, 0), world_seed(8, 0));
        assert_ne!(world_seed(7, 0), world_seed(7, 1));
    }
}
