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

use super::max_abs;

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
#[cfg_attr(not(target_os = "none"), inline(always))]
#[cfg_attr(target_os = "none", inline(never))]
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

/// `ai·bj - aj·bi + bi·cj - bj·ci + ci·aj - cj·ai` for `f = [ai, aj, bi, bj, ci, cj]` (component
/// `(i, j)` of `a × b + b × c + c × a`) as a value with its exact sign, zero exactly when it is
/// zero (inputs below 2^44 in magnitude; exact unless both factors of one product lie over
/// 2^110 below the largest input, where a product's error term would underflow).
///
/// Every input is scaled by one power of two that brings the largest up to the binade 2^60
/// ([`scale_to_2_60`]), so the products keep their error terms; the six products are taken as
/// exact pairs ([`two_prod`]) and the sign of their twelve-term sum by [`exact_sum_sign`].
/// Swapping the first two points negates the result exactly when `c` is zero (the 2D edge
/// function). The exact fallback of every sign decision of the triangle test.
#[inline(always)]
pub(crate) fn exact_cross_sum(f: [f32; 6]) -> f32 {
    let m = max_abs(&f);
    if m == 0.0 {
        return 0.0;
    }
    let (k1, k2) = scale_to_2_60(m);
    let s = f.map(|v| v * k1 * k2);
    // Product `n` is `±s[n]·s[PARTNER[n]]`, negative for odd `n`: ai·bj, -aj·bi, bi·cj, -bj·ci,
    // ci·aj, -cj·ai. The twelve terms: each product and its error, in order.
    const PARTNER: [usize; 6] = [3, 2, 5, 4, 1, 0];
    let mut terms: [[f32; 2]; 6] = core::array::from_fn(|n| {
        let x = if n % 2 == 0 { s[n] } else { -s[n] };
        let (p, e) = two_prod(x, s[PARTNER[n]]);
        [p, e]
    });
    exact_sum_sign(terms.as_flattened_mut())
}

/// The sign of the exact sum of `terms`, as a value: after distillation (repeated error-free
/// cascades of [`two_sum`], which keep the exact sum, until nothing moves) the last term
/// carries the sign of the sum and is zero exactly when the sum is zero. The cascade is odd:
/// negated terms give the negated result. `0` for no terms; the terms are left distilled.
#[inline(always)]
pub(crate) fn exact_sum_sign(terms: &mut [f32]) -> f32 {
    let n = terms.len();
    // Each pass moves every non-zero remainder up past zeros and merges overlapping terms;
    // a fixed point is a non-overlapping expansion whose largest term is last. The bound only
    // guarantees termination: in practice two or three passes suffice.
    for _ in 0..4 * n + 8 {
        let mut moved = false;
        for i in 1..n {
            let (s, e) = two_sum(terms[i], terms[i - 1]);
            // `s + e` is exactly the old pair's sum, so `s` moved if and only if `e` did.
            moved |= e != terms[i - 1];
            terms[i] = s;
            terms[i - 1] = e;
        }
        if !moved {
            break;
        }
    }
    terms.last().copied().unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::scalar::xorshift as next;

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
            let got = exact_sum_sign(&mut [p, pe, -q, -qe]);
            assert_eq!(got > 0.0, exact > 0.0, "{a:e} {b:e} {c:e} {d:e}");
            assert_eq!(got == 0.0, exact == 0.0, "{a:e} {b:e} {c:e} {d:e}");
            assert_eq!(exact_sum_sign(&mut [-p, -pe, q, qe]), -got);
        }
    }

    #[test]
    fn exact_cross_sum_has_the_exact_sign() {
        let mut st = 0xd1ff_0f9a_0d00_0017;
        // Random values within 2^±16 are multiples of 2^-39 below 2^17, grid values (below)
        // multiples of 2^-10 below 2^21: scaled by 2^40 each, the products are integers below
        // 2^122, summed exactly in i128.
        let scale = libm::exp2(40.0);
        let fixed = |v: f32| (v as f64 * scale) as i128;
        // Small integers times one power of two: sums of a few stay exact in f32.
        let grid =
            |st: &mut u64, e: i32| ((next(st) % 2001) as f32 - 1000.0) * libm::exp2f(e as f32);
        for i in 0..50_000 {
            let mut f: [f32; 6] = core::array::from_fn(|_| value(&mut st, 16));
            let e = (next(&mut st) % 20) as i32 - 10;
            match i % 5 {
                // Collinear points (c - a = 2·(b - a), exactly): an exact zero.
                0 | 1 => {
                    let a = [grid(&mut st, e), grid(&mut st, e)];
                    let d = [grid(&mut st, e), grid(&mut st, e)];
                    let (b, c) = (
                        [a[0] + d[0], a[1] + d[1]],
                        [a[0] + 2.0 * d[0], a[1] + 2.0 * d[1]],
                    );
                    f = [a[0], a[1], b[0], b[1], c[0], c[1]];
                    // Nearly collinear: one coordinate off by one unit in the last place.
                    if i % 5 == 1 && f[5] != 0.0 {
                        f[5] = f32::from_bits(f[5].to_bits() + 1);
                    }
                }
                // A zero third point, as the 2D edge function passes it.
                2 => {
                    f[4] = 0.0;
                    f[5] = 0.0;
                }
                // Nearly collinear full-precision points a, 3a and 5a, rounded: the exact sum
                // is a few units in the last place of the products, which rounded products get
                // wrong; only their error terms carry the sign.
                3 => {
                    let [x, y] = [f[0], f[1]];
                    f = [x, y, 3.0 * x, 3.0 * y, 5.0 * x, 5.0 * y];
                }
                _ => {}
            }
            let [ai, aj, bi, bj, ci, cj] = f.map(fixed);
            let exact = ai * bj - aj * bi + bi * cj - bj * ci + ci * aj - cj * ai;
            let got = exact_cross_sum(f);
            assert_eq!(got > 0.0, exact > 0, "{f:?}");
            assert_eq!(got == 0.0, exact == 0, "{f:?}");
            if i % 5 == 2 {
                assert_eq!(
                    exact_cross_sum([f[2], f[3], f[0], f[1], 0.0, 0.0]),
                    -got,
                    "{f:?}"
                );
            }
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
