//! The correctly rounded `f32` square root the kernel uses everywhere.
//!
//! IEEE 754 requires `sqrt` to be correctly rounded, so every implementation gives the same bits.
//! Hosted targets call `libm::sqrtf`, an instruction on x86_64, aarch64 and wasm32. Bare-metal
//! ARM cores with a floating-point unit (the `eabihf` targets, e.g. the Cortex-M4F) run their
//! `vsqrt.f32` instruction, reached through inline assembly (`unsafe`: stable Rust exposes
//! no square root in `core`). Other bare-metal targets run the digit-by-digit integer root
//! below: `libm`'s portable routine is larger in flash and carries a lookup table.

/// `√x`, correctly rounded: `-0` for `-0`, `+inf` for `+inf`, NaN for NaN and for `x < 0`.
#[cfg(not(target_os = "none"))]
#[inline(always)]
pub(crate) fn sqrtf(x: f32) -> f32 {
    libm::sqrtf(x)
}

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

/// `√x` by integer arithmetic only, correctly rounded (round to nearest; a tie cannot occur).
///
/// `x = y·2^e` with `e` even and `y = m·2^-23` in `[1, 4)`. The digit-by-digit root decides
/// `q = ⌊√y·2^24⌋` one bit at a time, from 2^24 down: with the remainder `y - (q·2^-24)²`
/// kept as the integer `r = (y - (q·2^-24)²)·2^(24+i)` at step `i`, the bit `b = 2^(24-i)` is
/// taken when `r >= 2q + b`. `q` holds the 24-bit significand and one bit more, which alone
/// decides the rounding: `√y·2^24` is never an odd integer exactly (its square `m·2^25` is
/// even), so the discarded remainder cannot make a tie.
#[cfg_attr(
    any(
        not(target_os = "none"),
        all(target_arch = "arm", target_abi = "eabihf")
    ),
    allow(dead_code)
)]
fn integer_sqrt(x: f32) -> f32 {
    let bits = x.to_bits();
    if x == 0.0 || bits == f32::INFINITY.to_bits() || x.is_nan() {
        return x; // ±0, +inf, NaN
    }
    if x < 0.0 {
        return f32::NAN;
    }
    let biased = (bits >> 23) as i32;
    let (mut m, mut e) = if biased == 0 {
        // Subnormal: normalise so the leading bit sits at bit 23.
        let frac = bits & 0x007f_ffff;
        let shift = frac.leading_zeros() as i32 - 8;
        (frac << shift, -126 - shift)
    } else {
        ((bits & 0x007f_ffff) | 0x0080_0000, biased - 127)
    };
    if e & 1 != 0 {
        m <<= 1;
        e -= 1;
    }
    // r < 2q + b at every step, so it stays below 2^27.
    let (mut r, mut q, mut b) = (m << 1, 0u32, 1u32 << 24);
    while b != 0 {
        let t = (q << 1) + b;
        if r >= t {
            r -= t;
            q += b;
        }
        r <<= 1;
        b >>= 1;
    }
    // `q` is in [2^24, 2^25); rounded, the significand lies in `[2^23, 2^24]` (a carry into
    // the exponent at 2^24 is what adding to the exponent field does).
    let significand = (q + 1) >> 1;
    let exponent = (e / 2 + 126) as u32;
    f32::from_bits((exponent << 23) + significand)
}

#[cfg(test)]
mod tests {
    use super::integer_sqrt;

    fn same(x: f32) {
        let (a, b) = (integer_sqrt(x), libm::sqrtf(x));
        assert!(
            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
            "sqrt({x:e}): {a:e} vs {b:e}"
        );
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
}
