//! What the processor running this supports, for the kernels that keep a copy compiled for an
//! instruction-set extension ([`crate::dynamics::pipeline::step`], the choreography fill's DP
//! minimum). Every such copy gives the same bits as the portable one.

/// True if the kernels take their AVX2 copies: the processor supports AVX2 and the environment
/// variable `MARIONETTE_PORTABLE` is not set (set it to run the portable copies, e.g. under
/// valgrind, whose decoder lacks some AVX encodings). Decided once per process.
#[inline]
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        static AVX2: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        *AVX2.get_or_init(|| {
            std::arch::is_x86_feature_detected!("avx2")
                && std::env::var_os("MARIONETTE_PORTABLE").is_none()
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
