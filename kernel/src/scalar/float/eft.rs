//! Error-free transformations in `f32` (Dekker 1971, "A floating-point technique for extending
//! the available precision"; Knuth, TAOCP vol. 2, 4.2.2): a sum or a product returned as an
//! unevaluated pair `hi + lo` equal to the exact result, and double-`f32` arithmetic on such
//! pairs. Only IEEE `+ - *` and `/`, no fused multiply-add, so every platform computes the
//! same bits; no `f64`, so a core with a single-precision FPU needs no soft-float.
//!
//! Exactness conditions, for the magnitudes the triangle test feeds in (coordinates below
//! 2^43): [`two_sum`] is exact whenever `a + b` does not overflow; [`two_prod`] is exact when
//! the error term `a·b - fl(a·b)` is representable, i.e. unless the exponents of `a` and `b`
//! sum below -100 (products under about 2^-100 may lose their lowest bits to underflow).
//!
//! Inlining is forced on hosted targets only (speed); bare-metal targets (`target_os =
//! "none"`) leave it to the optimiser, which keeps one copy of the larger helpers (flash).

use crate::scalar::Scalar;

/// `|x|`.
fn abs(x: f32) -> f32 {
    libm::fabsf(x)
}

/// `(s, e)` with `s = fl(a + b)` and `s + e = a + b` exactly (Knuth's branch-free TwoSum).
#[inline(always)]
pub(crate) fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// As [`two_sum`], valid when `|a| >= |b|` or `a == 0` (Dekker's FastTwoSum).
#[inline(always)]
fn fast_two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    (s, b - (s - a))
}

/// Veltkamp's split: `a = hi + lo` with `hi` holding the upper 12 bits of the 24-bit
/// significand and `lo` the rest (sign included), so products of halves are exact.
#[inline(always)]
fn split(a: f32) -> (f32, f32) {
    const FACTOR: f32 = 4097.0; // 2^12 + 1
    let c = FACTOR * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

/// `(p, e)` with `p = fl(a·b)` and `p + e = a·b` exactly (Dekker's TwoProduct, under the
/// conditions of the module docs).
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline(never))]
pub(crate) fn two_prod(a: f32, b: f32) -> (f32, f32) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// An unevaluated sum `hi + lo`, normalised (`hi = fl(hi + lo)`): about 48 significant bits.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Df {
    pub(crate) hi: f32,
    pub(crate) lo: f32,
}

impl Df {
    /// `a·b - c·d`, with a relative error below 2^-44 however much the products cancel: both
    /// products exactly (four terms), their sum distilled into one pair.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    pub(crate) fn diff_of_products(a: f32, b: f32, c: f32, d: f32) -> Df {
        let (p, pe) = two_prod(a, b);
        let (q, qe) = two_prod(c, d);
        // When the products nearly cancel, `p - q` is exact (Sterbenz) and `se` is zero, and
        // the error terms carry the result; otherwise `p - q` dominates and the rounding of
        // the small terms stays below 2^-46 of it.
        let (s, se) = two_sum(p, -q);
        let (t, te) = two_sum(pe, -qe);
        let (h, l) = two_sum(s, t);
        let (hi, lo) = fast_two_sum(h, l + (se + te));
        Df { hi, lo }
    }

    /// `self + other`, relative error about 2^-46 when both have the same sign (the only use).
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    pub(crate) fn add(self, other: Df) -> Df {
        let (s, e) = two_sum(self.hi, other.hi);
        let (hi, lo) = fast_two_sum(s, e + (self.lo + other.lo));
        Df { hi, lo }
    }

    /// `self·b`, relative error about 2^-46.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    pub(crate) fn mul_f32(self, b: f32) -> Df {
        let (p, e) = two_prod(self.hi, b);
        let (hi, lo) = fast_two_sum(p, e + self.lo * b);
        Df { hi, lo }
    }

    /// `self·2^k` for a power of two `scale` (exact while nothing over- or underflows).
    #[inline(always)]
    pub(crate) fn scaled(self, scale: f32) -> Df {
        Df {
            hi: self.hi * scale,
            lo: self.lo * scale,
        }
    }

    /// `self / d` rounded to `f32`: the quotient of the high parts, corrected by the
    /// remainder `self - q·d` (computed to about 2^-46), so the result is within a hair of
    /// the correctly rounded quotient. `d.hi` must be non-zero.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    #[cfg_attr(target_os = "none", inline(never))]
    pub(crate) fn div(self, d: Df) -> f32 {
        let q = self.hi / d.hi;
        // r = self - q·d, where q·d.hi is taken exactly.
        let (p, pe) = two_prod(q, d.hi);
        let (s, se) = two_sum(self.hi, -p);
        let r = s + (se - pe + self.lo - q * d.lo);
        q + r / d.hi
    }
}

/// `1 / 2^e` for the binade `2^e <= |x| < 2^(e+1)` of a finite, non-zero `x`, as a power
/// of two; `2^64` for subnormal `x`. Multiplying by it is exact and brings `x` near 1.
#[inline(always)]
pub(crate) fn recip_binade(x: f32) -> f32 {
    let e = (x.to_bits() >> 23) & 0xff; // biased exponent
    if e == 0 {
        return 18_446_744_073_709_551_616.0; // 2^64
    }
    // 2^(127 - (e - 127)) has biased exponent 254 - e; at least 1 for every finite x we see
    // (e <= 253, |x| < 2^127).
    f32::from_bits((254 - e.min(253)) << 23)
}

/// Two powers of two, both at least 1, whose product brings the binade of `m` (finite,
/// positive) to 2^60; applied one after the other they scale exactly (upwards only, since
/// `m < 2^43` for every input here). Scaled so, the inputs of a product keep their error terms
/// representable unless one is over 2^160 below the largest ([`two_prod`]'s condition).
#[inline(always)]
pub(crate) fn scale_to_2_60(m: f32) -> (f32, f32) {
    const P60: f32 = 1_152_921_504_606_846_976.0; // 2^60
    let r = recip_binade(m);
    if r <= P60 {
        (r * P60, 1.0)
    } else {
        (P60, r)
    }
}

/// `a·b - c·d` for values given as exact pairs (`a = a.0 + a.1`, from [`two_sum`] or a lone
/// `f32` with a zero low part), as a value with its exact sign, zero exactly when it is zero.
///
/// Every part is scaled by one power of two that brings the largest high part up to the binade
/// 2^60 ([`scale_to_2_60`]), so the products of parts keep their error terms (the inputs are
/// below 2^44); the eight products of parts are then taken as exact pairs ([`two_prod`]) and the
/// sign of their sixteen-term sum by [`exact_sum_sign`]. Odd: swapping `(a, b)` with `(c, d)`
/// negates the result exactly. The exact fallback of every sign decision of the triangle test.
#[inline(never)]
pub(crate) fn exact_diff_of_products(
    a: (f32, f32),
    b: (f32, f32),
    c: (f32, f32),
    d: (f32, f32),
) -> f32 {
    let m = abs(a.0).max_of(abs(b.0)).max_of(abs(c.0)).max_of(abs(d.0));
    if m == 0.0 {
        return 0.0;
    }
    let (k1, k2) = scale_to_2_60(m);
    let k = |x: f32| x * k1 * k2;
    // The left factors of a·b and of -(c·d) (negating a factor negates both parts exactly).
    let x = [k(a.0), k(a.1), -k(c.0), -k(c.1)];
    let y = [k(b.0), k(b.1), k(d.0), k(d.1)];
    // Product n: group g = n / 4 (a·b or -(c·d)), high or low part of each factor.
    let products: [(f32, f32); 8] = core::array::from_fn(|n| {
        let g = n / 4 * 2;
        two_prod(x[(g + n / 2 % 2).min(3)], y[(g + n % 2).min(3)])
    });
    let terms: [f32; 16] = core::array::from_fn(|n| {
        let (p, e) = products[(n / 2).min(7)];
        if n % 2 == 0 {
            p
        } else {
            e
        }
    });
    exact_sum_sign(terms)
}

/// The sign of the exact sum of `terms`, as a value: after distillation (repeated error-free
/// cascades of [`two_sum`], which keep the exact sum, until nothing moves) the last term
/// carries the sign of the sum and is zero exactly when the sum is zero. The cascade is odd:
/// negated terms give the negated result.
#[inline(never)]
pub(crate) fn exact_sum_sign<const N: usize>(mut terms: [f32; N]) -> f32 {
    // Each pass moves every non-zero remainder up past zeros and merges overlapping terms;
    // a fixed point is a non-overlapping expansion whose largest term is last. The bound only
    // guarantees termination: in practice two or three passes suffice.
    for _ in 0..4 * N + 8 {
        let mut moved = false;
        for i in 1..N {
            let (s, e) = two_sum(terms[i], terms[i - 1]);
            moved |= s != terms[i] || e != terms[i - 1];
            terms[i] = s;
            terms[i - 1] = e;
        }
        if !moved {
            break;
        }
    }
    terms[N - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn next(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    /// A random f32 of random sign with exponent in `[-exp, exp]`.
    fn value(state: &mut u64, exp: i32) -> f32 {
        let r = next(state);
        let e = (r % (2 * exp as u64 + 1)) as i32 - exp;
        let m = 1.0 + ((r >> 20) & 0x7f_ffff) as f32 / 8_388_608.0;
        let s = if r & 1 == 0 { 1.0 } else { -1.0 };
        s * m * libm::exp2f(e as f32)
    }

    #[test]
    fn two_sum_and_two_prod_are_exact() {
        let mut st = 0x1234_5678_9abc_def1;
        for _ in 0..100_000 {
            let (a, b) = (value(&mut st, 40), value(&mut st, 40));
            let (s, e) = two_sum(a, b);
            assert_eq!(s as f64 + e as f64, a as f64 + b as f64, "{a:e} + {b:e}");
            let (p, e) = two_prod(a, b);
            assert_eq!(p as f64 + e as f64, a as f64 * b as f64, "{a:e} * {b:e}");
        }
    }

    #[test]
    fn diff_of_products_keeps_44_bits_under_cancellation() {
        let mut st = 0x0bad_cafe_f00d_0001;
        for i in 0..100_000 {
            let (a, b, c) = (value(&mut st, 20), value(&mut st, 20), value(&mut st, 20));
            // Every other case nearly cancels: d close to a·b / c.
            let d = if i % 2 == 0 {
                ((a as f64 * b as f64) / c as f64) as f32
            } else {
                value(&mut st, 20)
            };
            let exact = a as f64 * b as f64 - c as f64 * d as f64; // exact in f64 here
            let got = Df::diff_of_products(a, b, c, d);
            let err = (got.hi as f64 + got.lo as f64 - exact).abs();
            assert!(
                err <= exact.abs() * libm::exp2(-44.0),
                "{a:e} {b:e} {c:e} {d:e}"
            );
        }
    }

    #[test]
    fn exact_sum_sign_matches_the_exact_sum() {
        let mut st = 0x5eed_0000_0000_0042;
        for i in 0..50_000 {
            let (a, b, c, d) = (
                value(&mut st, 30),
                value(&mut st, 30),
                value(&mut st, 30),
                value(&mut st, 30),
            );
            let (p, pe) = two_prod(a, b);
            let (q, qe) = two_prod(c, d);
            // Every third case is an exact zero (c·d = a·b).
            let (q, qe) = if i % 3 == 0 { (p, pe) } else { (q, qe) };
            let exact = (p as f64 + pe as f64) - (q as f64 + qe as f64); // exact: 48-bit terms
            let got = exact_sum_sign([p, pe, -q, -qe]);
            assert_eq!(got > 0.0, exact > 0.0, "{a:e} {b:e} {c:e} {d:e}");
            assert_eq!(got == 0.0, exact == 0.0, "{a:e} {b:e} {c:e} {d:e}");
            assert_eq!(exact_sum_sign([-p, -pe, q, qe]), -got);
        }
    }

    /// `hi + lo` times 2^37 as an integer (exact for the pairs the test below builds).
    fn fixed(p: (f32, f32)) -> i128 {
        let scale = libm::exp2(37.0);
        (p.0 as f64 * scale) as i128 + (p.1 as f64 * scale) as i128
    }

    #[test]
    fn exact_diff_of_products_has_the_exact_sign() {
        let mut st = 0xd1ff_0f9a_0d00_0017;
        // Pairs from two_sum of values within 2^±12: multiples of 2^-35 below 2^14 (halved:
        // 2^-36), so the products are exact in i128 once scaled by 2^37 each.
        let pair = |st: &mut u64| two_sum(value(st, 12), value(st, 12));
        for i in 0..50_000 {
            let (a, b) = (pair(&mut st), pair(&mut st));
            let (c, d) = match i % 4 {
                0 => (b, a),                                           // exactly a·b
                1 => ((b.0 * 2.0, b.1 * 2.0), (a.0 * 0.5, a.1 * 0.5)), // exactly a·b too
                // Nearly a·b: b with about 2^-35 more (rounded, still a multiple of it).
                2 => (a, two_sum(b.0, b.1 + libm::exp2f(-35.0))),
                _ => (pair(&mut st), pair(&mut st)),
            };
            let exact = fixed(a) * fixed(b) - fixed(c) * fixed(d);
            let got = exact_diff_of_products(a, b, c, d);
            assert_eq!(got > 0.0, exact > 0, "{a:?} {b:?} {c:?} {d:?}");
            assert_eq!(got == 0.0, exact == 0, "{a:?} {b:?} {c:?} {d:?}");
            assert_eq!(exact_diff_of_products(c, d, a, b), -got);
        }
    }

    #[test]
    fn recip_binade_brings_values_into_one_two() {
        for x in [
            1.0f32,
            1.5,
            3.0,
            -7.9,
            1e-30,
            1e30,
            1.7e38,
            f32::MIN_POSITIVE,
        ] {
            let y = x.abs() * recip_binade(x);
            assert!((1.0..2.0).contains(&y), "{x:e} -> {y:e}");
        }
        let tiny = f32::from_bits(5);
        assert_eq!(recip_binade(tiny), libm::exp2f(64.0));
    }
}
