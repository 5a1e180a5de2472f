//! Square roots, correctly rounded on every target (IEEE 754 asks it of a square root, so every
//! implementation gives the same bits), in the instruction encoding the build allows.
//!
//! Why not `libm`'s directly: on x86-64 `libm::sqrtf` and `libm::sqrt` are the `sqrtss` and
//! `sqrtsd` instructions written as inline assembly, which the compiler cannot re-encode. In a
//! build for a processor with AVX (`-C target-cpu=native`), that is a legacy SSE instruction
//! among VEX ones, and on an AMD EPYC (Zen 3) the cut's walk ran 2.2x slower for it, most of its
//! time waiting on those square roots. There the SSE intrinsic, the same instruction, is used,
//! which the compiler encodes as `vsqrtss`. Without AVX `libm`'s assembly is kept: the intrinsic
//! would be the same instruction with a register cleared before it, 1.8% more instructions in
//! the walk. Other targets use `libm`'s (an instruction on aarch64 and on a Cortex-M with a
//! floating-point unit, software elsewhere), the same bits.

/// The square root of `x`, correctly rounded (NaN below zero, as `libm::sqrtf`).
///
/// ```
/// use vdlod_core::root::sqrtf;
/// assert_eq!(sqrtf(2.25), 1.5);
/// assert_eq!(sqrtf(2.0), libm::sqrtf(2.0));
/// assert!(sqrtf(-1.0).is_nan());
/// ```
#[inline(always)]
#[must_use]
pub fn sqrtf(x: f32) -> f32 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    #[allow(unsafe_code)]
    // SAFETY: the intrinsics need SSE, which the build's target has (it has AVX); they touch
    // no memory.
    unsafe {
        use core::arch::x86_64::{_mm_cvtss_f32, _mm_set_ss, _mm_sqrt_ss};
        _mm_cvtss_f32(_mm_sqrt_ss(_mm_set_ss(x)))
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    libm::sqrtf(x)
}

/// The square root of `x` in double precision, correctly rounded (as `libm::sqrt`).
///
/// ```
/// use vdlod_core::root::sqrt;
/// assert_eq!(sqrt(6.25), 2.5);
/// assert_eq!(sqrt(2.0), libm::sqrt(2.0));
/// ```
#[inline(always)]
#[must_use]
pub fn sqrt(x: f64) -> f64 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    #[allow(unsafe_code)]
    // SAFETY: the intrinsics need SSE2, which the build's target has (it has AVX); they touch
    // no memory.
    unsafe {
        use core::arch::x86_64::{_mm_cvtsd_f64, _mm_set_sd, _mm_sqrt_sd};
        let v = _mm_set_sd(x);
        _mm_cvtsd_f64(_mm_sqrt_sd(v, v))
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    libm::sqrt(x)
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    /// The correctly rounded root, as `std` computes it (in double precision for a single, which
    /// rounds twice and still lands on the correctly rounded single: a double has more than twice
    /// a single's bits), for every class of input: zeros, subnormals, exact squares and their
    /// neighbours, the largest finite, infinities, negative numbers and NaN, and a hundred
    /// thousand bit patterns besides; in a build with AVX and without.
    #[test]
    fn correctly_rounded() {
        let check = |s: f32| {
            let want = f64::from(s).sqrt() as f32;
            assert_eq!(sqrtf(s).to_bits(), want.to_bits(), "{s:e}");
            let d = f64::from(s) * 1.000_000_1;
            assert_eq!(sqrt(d).to_bits(), d.sqrt().to_bits(), "{d:e}");
        };
        for s in [
            0.0f32,
            -0.0,
            f32::MIN_POSITIVE,
            f32::MIN_POSITIVE / 3.0,
            1.0,
            2.0,
            4.0,
            f32::from_bits(4.0f32.to_bits() - 1),
            f32::from_bits(4.0f32.to_bits() + 1),
            0.25,
            f32::MAX,
            f32::INFINITY,
        ] {
            check(s);
        }
        let mut x = 0x2545_F491u32;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            check(f32::from_bits(x & 0x7FFF_FFFF));
        }
        for s in [-1.0f32, f32::NEG_INFINITY, f32::NAN] {
            assert!(sqrtf(s).is_nan() && sqrt(f64::from(s)).is_nan(), "{s}");
        }
        assert_eq!(sqrtf(-0.0).to_bits(), (-0.0f32).to_bits());
    }
}
