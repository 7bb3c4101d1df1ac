//! The correctly rounded `f32` and `f64` square roots the kernel uses everywhere.
//!
//! IEEE 754 requires `sqrt` to be correctly rounded, so every implementation gives the same bits.
//! Hosted x86 targets use the SSE square root through its intrinsic, which the compiler encodes
//! as the AVX form when the build enables AVX: `libm` reaches the same instruction through
//! inline assembly in its legacy SSE encoding, and a legacy SSE instruction among AVX code
//! costs a state transition on every call (measured: ray construction several times slower in
//! an `x86-64-v3` build). Other hosted targets call `libm`, an instruction on aarch64 and
//! wasm32. Bare-metal
//! ARM cores with a floating-point unit (the `eabihf` targets, e.g. the Cortex-M4F) run their
//! `vsqrt.f32` instruction for `f32`, reached through inline assembly (`unsafe`: stable Rust
//! exposes no square root in `core`). Other bare-metal roots run the digit-by-digit integer
//! root below: `libm`'s portable routines are larger in flash and carry a lookup table.

/// `√x`, correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for `x < 0`.
#[cfg(all(not(target_os = "none"), target_feature = "sse2"))]
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn sqrtf(x: f32) -> f32 {
    use x86::{_mm_cvtss_f32, _mm_set_ss, _mm_sqrt_ss};
    // SAFETY: these intrinsics need only SSE, which `target_feature = "sse2"` guarantees at
    // compile time; they touch no memory.
    unsafe { _mm_cvtss_f32(_mm_sqrt_ss(_mm_set_ss(x))) }
}

/// `√x`, correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for `x < 0`.
#[cfg(all(not(target_os = "none"), not(target_feature = "sse2")))]
#[inline(always)]
#[allow(clippy::disallowed_methods)] // the one place that names it
pub(crate) fn sqrtf(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// The x86 intrinsics of both widths.
#[cfg(all(not(target_os = "none"), target_feature = "sse2", target_arch = "x86"))]
use core::arch::x86;
#[cfg(all(
    not(target_os = "none"),
    target_feature = "sse2",
    target_arch = "x86_64"
))]
use core::arch::x86_64 as x86;

/// `√x`, correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for `x < 0`.
#[cfg(all(target_os = "none", target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
pub(crate) fn sqrtf(x: f32) -> f32 {
    let mut bits = x.to_bits();
    // SAFETY: the instructions read and write the general register holding `bits` and the
    // one named `_`, and `s0`, which they restore before the end; they touch no memory, no
    // stack and no condition flags. Every `eabihf` target has `vsqrt.f32` (VFPv2 and later),
    // rounding to nearest as reset leaves the FPSCR. (The registers go through general ones:
    // the single-precision register class needs a target feature the Cortex-M4F's
    // single-precision unit does not name.)
    unsafe {
        core::arch::asm!(
            "vmov {saved}, s0",
            "vmov s0, {bits}",
            "vsqrt.f32 s0, s0",
            "vmov {bits}, s0",
            "vmov s0, {saved}",
            bits = inout(reg) bits,
            saved = out(reg) _,
            options(pure, nomem, nostack, preserves_flags),
        );
    }
    f32::from_bits(bits)
}

/// `√x`, correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for `x < 0`.
#[cfg(all(
    target_os = "none",
    not(all(target_arch = "arm", target_abi = "eabihf"))
))]
#[inline(never)]
pub(crate) fn sqrtf(x: f32) -> f32 {
    integer_sqrt(x)
}

/// `√x` (`f64`), correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for
/// `x < 0`.
#[cfg(all(not(target_os = "none"), target_feature = "sse2"))]
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn sqrt(x: f64) -> f64 {
    use x86::{_mm_cvtsd_f64, _mm_set_sd, _mm_sqrt_pd};
    // SAFETY: these intrinsics need only SSE2, which `target_feature = "sse2"` guarantees at
    // compile time; they touch no memory. (The upper lane is zero, whose root is zero.)
    unsafe { _mm_cvtsd_f64(_mm_sqrt_pd(_mm_set_sd(x))) }
}

/// `√x` (`f64`), correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for
/// `x < 0`.
#[cfg(all(not(target_os = "none"), not(target_feature = "sse2")))]
#[inline(always)]
#[allow(clippy::disallowed_methods)] // the one place that names it
pub(crate) fn sqrt(x: f64) -> f64 {
    libm::sqrt(x)
}

/// `√x` (`f64`), correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for
/// `x < 0`.
#[cfg(target_os = "none")]
#[inline(never)]
pub(crate) fn sqrt(x: f64) -> f64 {
    integer_sqrt_f64(x)
}

/// `√x` (`f64`) by integer arithmetic only, as [`root_bits`].
#[cfg_attr(not(target_os = "none"), allow(dead_code))]
#[inline(always)]
fn integer_sqrt_f64(x: f64) -> f64 {
    f64::from_bits(root_bits(x.to_bits(), 64, 52))
}

/// `√x` (`f32`) by integer arithmetic only, as [`root_bits`].
#[cfg_attr(
    any(
        not(target_os = "none"),
        all(target_arch = "arm", target_abi = "eabihf")
    ),
    allow(dead_code)
)]
fn integer_sqrt(x: f32) -> f32 {
    // The root of a 32-bit float fits in its 32 bits.
    f32::from_bits(root_bits(u64::from(x.to_bits()), 32, 23) as u32)
}

/// The bits of `√x`, correctly rounded (round to nearest; a tie cannot occur), for the bits of
/// an IEEE float `width` bits wide with `p` fraction bits (`f32`: 32, 23; `f64`: 64, 52):
/// `±0` and `+inf` as given, NaN for NaN and below zero. Decided on the bits alone, so a core
/// without a double-precision unit calls no soft-float comparison.
///
/// `x = y·2^e` with `e` even and `y = m·2^-p` in `[1, 4)`. The digit-by-digit root decides
/// `q = ⌊√y·2^(p+1)⌋` one bit at a time, from `2^(p+1)` down: with the remainder
/// `y - (q·2^-(p+1))²` kept as the integer `r = (y - (q·2^-(p+1))²)·2^(p+1+i)` at step `i`,
/// the bit `b = 2^(p+1-i)` is taken when `r >= 2q + b`. `q` holds the significand and one
/// bit more, which alone decides the rounding: `√y·2^(p+1)` is never an odd integer exactly
/// (its square `m·2^(p+2)` is even), so the discarded remainder cannot make a tie.
#[cfg_attr(not(target_os = "none"), allow(dead_code))]
fn root_bits(bits: u64, width: u32, p: u32) -> u64 {
    let exponent_ones = (1u64 << (width - 1 - p)) - 1;
    let magnitude = bits & ((1u64 << (width - 1)) - 1);
    if magnitude == 0 {
        return bits; // ±0
    }
    if bits != magnitude {
        return exponent_ones << p | 1 << (p - 1); // the quiet NaN, for x < 0, -inf and -NaN
    }
    if magnitude >> p == exponent_ones {
        return bits; // +inf, +NaN
    }
    let bias = (exponent_ones >> 1) as i32;
    let fraction = bits & ((1 << p) - 1);
    let biased = (bits >> p) as i32;
    let (mut m, mut e) = if biased == 0 {
        // Subnormal: normalise so the leading bit sits at bit `p`.
        let shift = fraction.leading_zeros() as i32 - (63 - p as i32);
        (fraction << shift, 1 - bias - shift)
    } else {
        (fraction | 1 << p, biased - bias)
    };
    if e & 1 != 0 {
        m <<= 1;
        e -= 1;
    }
    // r < 2q + b at every step, so it stays below 2^(p+4).
    let (mut r, mut q, mut b) = (m << 1, 0u64, 1u64 << (p + 1));
    while b != 0 {
        let t = (q << 1) + b;
        if r >= t {
            r -= t;
            q += b;
        }
        r <<= 1;
        b >>= 1;
    }
    // `q` is in [2^(p+1), 2^(p+2)); rounded, the significand lies in `[2^p, 2^(p+1)]` (a carry
    // into the exponent at 2^(p+1) is what adding to the exponent field does).
    let significand = (q + 1) >> 1;
    let exponent = (e / 2 + bias - 1) as u64;
    (exponent << p) + significand
}

#[cfg(test)]
#[allow(clippy::disallowed_methods)] // `libm` is the reference here
mod tests {
    use super::{integer_sqrt, integer_sqrt_f64, sqrt, sqrtf};

    /// The integer root and the host's root (the intrinsic on x86) both give `libm`'s bits.
    fn same(x: f32) {
        let reference = libm::sqrtf(x);
        for (name, a) in [("integer", integer_sqrt(x)), ("host", sqrtf(x))] {
            assert!(
                a.to_bits() == reference.to_bits() || (a.is_nan() && reference.is_nan()),
                "{name} sqrt({x:e}): {a:e} vs {reference:e}"
            );
        }
    }

    #[test]
    fn every_significand_of_two_binades_matches_libm() {
        // [1, 4): both exponent parities, every significand.
        let (lo, hi) = (1.0f32.to_bits(), 4.0f32.to_bits());
        for bits in lo..hi {
            same(f32::from_bits(bits));
        }
    }

    #[test]
    fn special_values_subnormals_and_a_sample_of_all_floats_match_libm() {
        for x in [
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -1.0,
            f32::MAX,
        ] {
            same(x);
        }
        for bits in 1..=0x0010_0000u32 {
            same(f32::from_bits(bits)); // subnormals from the smallest up
        }
        let mut state = 0x5eed_0000_0000_0001u64;
        for _ in 0..2_000_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            same(f32::from_bits((state >> 32) as u32));
        }
    }

    #[test]
    fn the_f64_root_matches_libm_on_subnormals_squares_and_random_bits() {
        let same = |x: f64| {
            let reference = libm::sqrt(x);
            for (name, a) in [("integer", integer_sqrt_f64(x)), ("host", sqrt(x))] {
                assert!(
                    a.to_bits() == reference.to_bits() || (a.is_nan() && reference.is_nan()),
                    "{name} sqrt({x:e}): {a:e} vs {reference:e}"
                );
            }
        };
        for x in [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -1.0,
            f64::MAX,
        ] {
            same(x);
        }
        for bits in (1..=0x000f_ffff_ffff_ffffu64).step_by(0x0000_0100_0000_0001) {
            same(f64::from_bits(bits)); // subnormals
        }
        for k in 1..=1_000_000u32 {
            let r = f64::from(k);
            for x in [r * r, r * r - 1.0, r * r + 1.0] {
                same(x);
            }
        }
        let mut state = 0x5eed_0000_0000_0002u64;
        for _ in 0..2_000_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            same(f64::from_bits(state));
            same(f64::from_bits(state >> 2)); // positive, small and subnormal exponents
        }
    }
}
