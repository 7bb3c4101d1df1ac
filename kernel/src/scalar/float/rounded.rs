//! Hosted targets' shortcut to a candidate's distance: the `f32` the double-`f32` solve
//! returns, computed in `f64` (hardware there) and certified, else `None` and the caller runs
//! that solve. Bare-metal targets (`target_os = "none"`) do not compile this file: they always
//! run the solve, and link no `f64`.
//!
//! Why the two agree. Let `t = num / det` be the exact distance of the sheared vertices (edge
//! functions `U, V, W`, `det = U + V + W`, `num = U·az + V·bz + W·cz`), `S = |U| + |V| + |W|`
//! and `Z = |U·az| + |V·bz| + |W·cz|`, and `K = 1 + Z / |num| + S / |det|`.
//! - The double-`f32` solve (`FloatRay::scaled`, `Df::div`) keeps each edge function within
//!   `2^-44` of its value, `det` within `2^-45·S`, `num` within `2^-43·Z` (exact power-of-two
//!   scalings aside); its quotient, before the final rounding to `f32`, is within about
//!   `2^-42·K` of `t`, relatively. A rounding to nearest then gives the `f32` nearest to `t`
//!   unless a midpoint between two `f32`s lies within that error of `t`.
//! - Here every product of two `f32` is exact in `f64`, so each edge function rounds once
//!   (`2^-53`), `det` and `num` carry at most `2^-52·S` and `2^-51·Z`, and the quotient is
//!   within `2^-50·K` of `t`.
//! - The result is accepted only if the interval of relative half-width `2^-32·K` around the
//!   `f64` quotient (over `2^9` times both errors) holds no midpoint: then both give the `f32`
//!   nearest to `t`. (Tested multiplied through by `|det|`, which saves two divisions; the
//!   few roundings of that test are far inside the factor `2^9`.) Also refused: `det` within
//!   `2^-20·S` of zero (so neither solve divides by a cancelled value), a zero, subnormal or
//!   non-finite result (signs of zeros, the uneven gaps below the normal range, overflow).

const CONDITION: f64 = 1.0 / 1_048_576.0; // 2^-20
const RELATIVE: f64 = 1.0 / 4_294_967_296.0; // 2^-32

/// The double-`f32` solve's distance for the sheared vertices `a`, `b`, `c`, if the `f64`
/// evaluation can certify it (see the module docs).
#[inline(always)]
pub(super) fn certified_t(a: &[f32; 3], b: &[f32; 3], c: &[f32; 3]) -> Option<f32> {
    let wide = |p: &[f32; 3]| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])];
    let (a, b, c) = (wide(a), wide(b), wide(c));
    let edge = |p: &[f64; 3], q: &[f64; 3]| p[0] * q[1] - p[1] * q[0];
    let (u, v, w) = (edge(&c, &b), edge(&a, &c), edge(&b, &a));
    let det = u + v + w;
    let (nu, nv, nw) = (u * a[2], v * b[2], w * c[2]);
    let num = nu + nv + nw;
    let s = u.abs() + v.abs() + w.abs();
    let z = nu.abs() + nv.abs() + nw.abs();
    if !(det.abs() > s * CONDITION && num != 0.0) {
        return None;
    }
    let t = num / det;
    let t32 = t as f32;
    let half_gap = half_gap(t32)?;
    let at = f64::from(t32);
    // `|t - at| + |t|·RELATIVE·K < half_gap`, multiplied through by `|det|` (using
    // `|t|·|det| = |num|`): one division per candidate instead of three.
    let d = det.abs();
    let bound = RELATIVE * (num.abs() + z + t.abs() * s);
    ((t - at).abs() * d + bound < half_gap * d).then_some(t32)
}

/// The distance from a normal `x` to the nearest midpoint between it and a neighbour: half the
/// smaller gap, `2^(E-24)` for `|x|` in the binade `2^E`, or `2^(E-25)` at a power of two
/// (whose neighbour towards zero is twice as near; at the smallest normal this is half the true
/// distance, which only refuses more). `None` for a zero, subnormal or non-finite `x`.
#[inline(always)]
fn half_gap(x: f32) -> Option<f64> {
    let bits = x.to_bits() & 0x7fff_ffff;
    if !(0x0080_0000..0x7f80_0000).contains(&bits) {
        return None;
    }
    let biased = u64::from(bits >> 23);
    let below = if bits & 0x007f_ffff == 0 { 25 } else { 24 };
    Some(f64::from_bits((biased + 1023 - 127 - below) << 52))
}

#[cfg(test)]
mod tests {
    use super::half_gap;

    /// The half gap from the neighbours' bits, as the definition reads.
    fn from_neighbours(x: f32) -> f64 {
        let (bits, at) = (x.to_bits(), f64::from(x));
        let nearer = (at - f64::from(f32::from_bits(bits - 1))).abs();
        let farther = (f64::from(f32::from_bits(bits + 1)) - at).abs();
        nearer.min(farther) * 0.5
    }

    #[test]
    fn half_gap_is_half_the_distance_to_the_nearer_neighbour() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let random = (0..100_000).flat_map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let x = f32::from_bits((state >> 32) as u32);
            [x, f32::from_bits(x.to_bits() & 0xff80_0000)] // and a power of two
        });
        let fixed = [
            1.0f32,
            1.5,
            3.0e38,
            f32::MAX,
            1.0e-30,
            f32::MIN_POSITIVE,
            -0.75,
        ];
        let mut tested = 0;
        for x in fixed.into_iter().chain(random) {
            let Some(got) = half_gap(x) else {
                assert!(x == 0.0 || !x.is_normal(), "{x:e}");
                continue;
            };
            let want = if x.abs() == f32::MIN_POSITIVE {
                from_neighbours(x) * 0.5
            } else {
                from_neighbours(x)
            };
            assert_eq!(got, want, "{x:e}");
            tested += 1;
        }
        assert!(tested > 150_000, "{tested}");
    }
}
