//! The kernel that runs a table's lookups ([`SimdPath`]), chosen once per table.

#[cfg(target_arch = "x86_64")]
use crate::avx2;

/// The code path (kernel) that runs the lookups, chosen once when a [`crate::Brdf`] is built.
///
/// Both follow the same rules with the same operations in each lane; the AVX2 kernel fuses
/// multiply-adds and sums in another order, so the two agree to about 1e-5 relative (tested),
/// not bit for bit. Each is deterministic: the same lookup gives the same bits every time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimdPath {
    /// Plain Rust (SSE2 on x86-64; any target).
    Portable,
    /// x86-64 with AVX2, FMA and F16C, detected at run time.
    Avx2,
}

impl SimdPath {
    /// True when this processor can run the kernel.
    pub fn is_available(self) -> bool {
        match self {
            SimdPath::Portable => true,
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2 => avx2::available(),
            #[cfg(not(target_arch = "x86_64"))]
            SimdPath::Avx2 => false,
        }
    }

    /// The fastest kernel this processor runs (the default of every [`crate::Brdf`]).
    pub fn best() -> SimdPath {
        if SimdPath::Avx2.is_available() {
            SimdPath::Avx2
        } else {
            SimdPath::Portable
        }
    }
}
