//! Counter-based sample generation and the warps that turn unit-square samples into directions
//! and points.
//!
//! Every value is a pure function of `(pixel, sample, dimension, seed)`: no generator state is
//! carried between pixels, so any pixel renders alone, in any order, on any thread, with the
//! same bits. Three samplers share that contract:
//!
//! - [`SamplerKind::Independent`]: a hash per value.
//! - [`SamplerKind::Stratified`]: each 2D dimension pair puts the pixel's samples in
//!   the cells of a `cols × rows` grid (`cols = ⌈√spp⌉`), one sample per cell when `spp` fills
//!   the grid, in a per-pixel, per-dimension shuffled order, jittered inside its cell.
//! - [`SamplerKind::Sobol`] (default): the first two Sobol dimensions with hash-based Owen scrambling and
//!   a scrambled sample order per dimension pair (Burley 2020, "Practical Hash-based Owen
//!   Scrambling"): no tables, low discrepancy at every power-of-two sample count.

use crate::scalar::sqrtf;
use core::num::NonZeroU32;
use glam::Vec3;

/// How sample points are placed within a pixel's sample set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    /// Independent uniform values (a hash per value).
    Independent,
    /// Jittered grid per dimension pair.
    Stratified,
    /// Owen-scrambled Sobol (0,2)-sequence per dimension pair, shuffled per pair (the default:
    /// the fastest to a given image error in the benchmark's convergence renders).
    #[default]
    Sobol,
}

impl SamplerKind {
    /// Every sampler, for tests and benchmarks.
    pub const ALL: [SamplerKind; 3] = [Self::Independent, Self::Stratified, Self::Sobol];

    /// Lower-case name as used on command lines.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Independent => "independent",
            Self::Stratified => "stratified",
            Self::Sobol => "sobol",
        }
    }
}

/// A 32-bit integer hash with good avalanche (the "lowbias32" constants of C. Wellons'
/// hash-prospector search).
#[must_use]
pub const fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Hash of several words, order-sensitive.
#[must_use]
pub const fn hash4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    hash(d ^ hash(c ^ hash(b ^ hash(a))))
}

/// The top 24 bits of `x` as a float in `[0, 1)` (exact: every value is a multiple of 2^-24).
#[must_use]
pub fn unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Nested uniform (Owen) scramble of a 32-bit fraction in base 2: each bit is flipped by a
/// hash of the bits above it. Implemented as Burley's Laine–Karras-style hash on the
/// bit-reversed value (each multiply only carries information towards more significant bits of
/// the reversed word, i.e. towards less significant bits of the fraction).
#[must_use]
pub const fn owen_scramble(x: u32, seed: u32) -> u32 {
    let mut v = x.reverse_bits();
    v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v.reverse_bits()
}

/// First Sobol dimension (the van der Corput sequence): the index's bits reversed.
#[must_use]
pub const fn sobol_0(index: u32) -> u32 {
    index.reverse_bits()
}

/// Second Sobol dimension: direction numbers `v_0 = 2^31`, `v_{k+1} = v_k ^ (v_k >> 1)` (the
/// rows of Pascal's triangle mod 2).
#[must_use]
pub const fn sobol_1(mut index: u32) -> u32 {
    let mut v = 1u32 << 31;
    let mut r = 0;
    while index != 0 {
        if index & 1 != 0 {
            r ^= v;
        }
        index >>= 1;
        v ^= v >> 1;
    }
    r
}

/// A bijection of `0..n` chosen by `seed` (`index < n` required; other inputs are returned
/// unchanged). Cycle-walks a seeded bijection of `0..2^k` (`2^k >= n`), so it takes fewer than
/// `2^k < 2n` steps.
#[must_use]
pub fn permute(index: u32, n: u32, seed: u32) -> u32 {
    if index >= n || n <= 1 {
        return index;
    }
    let mask = u32::MAX >> (n - 1).leading_zeros();
    let mut i = index;
    // Bounded: `i` walks the cycle of a permutation of 0..=mask that contains `index`.
    for _ in 0..=mask {
        // Each step is a bijection on 0..=mask: xor, odd multiply, xor-shift, all masked.
        i ^= seed & mask;
        i = i.wrapping_mul(0x9e37_79b1 | 1) & mask;
        i ^= (i & mask) >> 3;
        i = i.wrapping_mul((seed >> 16) | 1) & mask;
        i ^= (i & mask) >> 5;
        i = i.wrapping_add(seed >> 8) & mask;
        if i < n {
            return i;
        }
    }
    index
}

/// The per-render part of sampling: kind, sample count, seed, and the stratified grid derived
/// from the sample count once (`cols = ⌈√spp⌉`, `rows = ⌈spp / cols⌉`).
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    spp: u32,
    seed: u32,
    /// Non-zero: the grid divides by it.
    cols: NonZeroU32,
    rows: u32,
}

impl Sampler {
    /// A sampler for `spp` samples per pixel.
    #[must_use]
    pub fn new(kind: SamplerKind, spp: u32, seed: u32) -> Self {
        // At least one column (spp = 0 renders nothing, but must not divide by zero).
        let cols = NonZeroU32::new(ceil_sqrt(spp)).unwrap_or(NonZeroU32::MIN);
        Self {
            kind,
            spp,
            seed,
            cols,
            rows: (spp / cols + u32::from(spp % cols != 0)).max(1),
        }
    }

    /// The stream of sample `sample` of pixel `pixel` (a linear pixel index).
    #[must_use]
    pub const fn stream(&self, pixel: u32, sample: u32) -> SampleStream {
        SampleStream {
            sampler: *self,
            pixel,
            sample,
            pair: 0,
        }
    }
}

/// The sample stream of one pixel sample: hands out dimension pairs in a fixed order.
///
/// Dimension pairs are numbered from 0 in the order the renderer asks for them (pixel position,
/// lens, time, then per bounce the lights' and the lobe's), so a sample's values depend only on
/// `(pixel, sample, pair, seed)`.
#[derive(Clone, Copy, Debug)]
pub struct SampleStream {
    sampler: Sampler,
    pixel: u32,
    sample: u32,
    pair: u32,
}

impl SampleStream {
    /// The stream of sample `sample` (of `spp`) of pixel `pixel`. A renderer makes one
    /// [`Sampler`] and calls [`Sampler::stream`] per sample instead.
    #[must_use]
    pub fn new(kind: SamplerKind, pixel: u32, sample: u32, spp: u32, seed: u32) -> Self {
        Sampler::new(kind, spp, seed).stream(pixel, sample)
    }

    /// The next dimension pair, in `[0, 1)²`.
    pub fn next_2d(&mut self) -> (f32, f32) {
        let Sampler {
            kind,
            spp,
            seed,
            cols,
            rows,
        } = self.sampler;
        let pair = self.pair;
        self.pair = self.pair.wrapping_add(1);
        let key = hash4(self.pixel, pair, seed, 0x5eed_0001);
        match kind {
            SamplerKind::Independent => {
                let h = hash4(self.pixel, self.sample, pair, seed);
                (unit_float(h), unit_float(hash(h ^ 0x68e3_1da4)))
            }
            SamplerKind::Stratified => {
                let cell = permute(self.sample, spp, key);
                let (cx, cy) = (cell % cols, cell / cols);
                let h = hash4(self.pixel, self.sample, pair, seed ^ 0x2545_f491);
                let jx = unit_float(h);
                let jy = unit_float(hash(h ^ 0x68e3_1da4));
                (
                    below_one((cx as f32 + jx) / cols.get() as f32),
                    below_one((cy as f32 + jy) / rows as f32),
                )
            }
            SamplerKind::Sobol => {
                let index = owen_scramble(self.sample, key);
                let x = owen_scramble(sobol_0(index), hash(key ^ 0xa511_e9b3));
                let y = owen_scramble(sobol_1(index), hash(key ^ 0x63d8_3595));
                (unit_float(x), unit_float(y))
            }
        }
    }
}

/// `⌈√n⌉` for `n >= 1` (1 for 0), in integers.
#[must_use]
pub fn ceil_sqrt(n: u32) -> u32 {
    // `⌊√n⌋` digit by digit (two bits of `n` per step), then one more unless `n` is a square.
    // In integers rather than through `crate::scalar::sqrt`: on cores without a double FPU the
    // conversions to and from `f64` cost more flash than this loop.
    let (mut rest, mut root) = (n, 0u32);
    let mut bit = 1u32 << 30;
    while bit > n {
        bit >>= 2;
    }
    while bit != 0 {
        if rest >= root + bit {
            rest -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    (root + u32::from(rest != 0)).max(1)
}

/// Clamps a value that rounding may have pushed to 1 to the largest float below 1.
fn below_one(x: f32) -> f32 {
    if x < 1.0 {
        x
    } else {
        1.0 - f32::EPSILON / 2.0
    }
}

/// A tent-distributed offset in `(-1, 1)` from a uniform `u` in `[0, 1)` (inverse CDF of the
/// triangle filter of radius 1).
#[must_use]
pub fn tent(u: f32) -> f32 {
    let v = 2.0 * u;
    if v < 1.0 {
        sqrtf(v) - 1.0
    } else {
        1.0 - sqrtf(2.0 - v)
    }
}

/// A Gaussian-distributed offset of standard deviation `sigma`, truncated to `(-radius,
/// radius)`, from a uniform `u` in `[0, 1)`: the inverse CDF of the truncated normal,
/// `σ·√2·erf⁻¹(e·(2u − 1))` with `e = erf(radius / (σ·√2))`, with `libm`'s `f32` functions
/// (the same bits everywhere, and no `f64` library code on cores without a double FPU);
/// `erf⁻¹` is Giles' single-precision polynomial refined by two Newton steps. Callers check
/// `sigma > 0` and `radius > 0`, both finite.
#[must_use]
pub fn gaussian(u: f32, sigma: f32, radius: f32) -> f32 {
    let s = sigma * core::f32::consts::SQRT_2;
    let e = libm::erff(radius / s);
    let x = s * erf_inv(e * (2.0 * u - 1.0));
    // Rounding may reach the bound; keep the offset inside it.
    let r = radius * (1.0 - f32::EPSILON);
    if x > r {
        r
    } else if x < -r {
        -r
    } else {
        x
    }
}

/// `erf⁻¹(y)` for `|y| < 1` (M. Giles, "Approximating the erfinv function", 2010, single
/// precision, then two Newton steps on `erf`).
fn erf_inv(y: f32) -> f32 {
    // `erf` rounds to ±1 far from 0: keep the logarithm finite (the caller clamps the result).
    const LIMIT: f32 = 1.0 - f32::EPSILON / 2.0;
    let y = y.clamp(-LIMIT, LIMIT);
    let w = -libm::logf((1.0 - y) * (1.0 + y));
    let mut x = if w < 5.0 {
        let w = w - 2.5;
        let c = [
            2.810_226_4e-8,
            3.432_739_4e-7,
            -3.523_387_7e-6,
            -4.391_506_5e-6,
            2.185_808_7e-4,
            -1.253_725_1e-3,
            -4.177_681_6e-3,
            2.466_407_2e-1,
            1.501_409_4,
        ];
        c.iter().fold(0.0, |p, &k| k + p * w) * y
    } else {
        let w = sqrtf(w) - 3.0;
        let c = [
            -2.002_142_6e-4,
            1.009_505_6e-4,
            1.349_343_2e-3,
            -3.673_428_4e-3,
            5.739_507_7e-3,
            -7.622_461_3e-3,
            9.438_870_5e-3,
            1.001_674,
            2.832_976_8,
        ];
        c.iter().fold(0.0, |p, &k| k + p * w) * y
    };
    // d/dx erf(x) = 2/√π · e^(−x²).
    let two_over_sqrt_pi = core::f32::consts::FRAC_2_SQRT_PI;
    for _ in 0..2 {
        let slope = two_over_sqrt_pi * libm::expf(-x * x);
        if slope > 0.0 {
            x -= (libm::erff(x) - y) / slope;
        }
    }
    x
}

/// A point on the unit disk, area-uniform (Shirley–Chiu concentric map).
#[must_use]
pub fn concentric_disk(u: f32, v: f32) -> (f32, f32) {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    // The angle in turns: `(π/4)·(b/a)` is `(b/a)/8` of a turn.
    let (r, turns) = if abs(a) > abs(b) {
        (a, (b / a) * 0.125)
    } else {
        (b, 0.25 - (a / b) * 0.125)
    };
    let (sin, cos) = sin_cos_turns(turns);
    (r * cos, r * sin)
}

/// A direction around `+z` with density `(n+1)/(2π)·cos^n θ` over the hemisphere (the
/// normalised Phong lobe). `n = 1` is not cosine-weighted sampling (that is
/// [`cosine_hemisphere`]); the lobe is over solid angle.
#[must_use]
pub fn phong_lobe(u: f32, v: f32, exponent: f32) -> Vec3 {
    let cos_t = libm::powf(1.0 - u, 1.0 / (exponent + 1.0));
    let sin_t = sqrtf(max0(1.0 - cos_t * cos_t));
    let (sin, cos) = sin_cos_turns(v);
    Vec3::new(sin_t * cos, sin_t * sin, cos_t)
}

/// A direction around `+z` with density `cos θ / π` (Malley's method on the concentric disk).
#[must_use]
pub fn cosine_hemisphere(u: f32, v: f32) -> Vec3 {
    let (x, y) = concentric_disk(u, v);
    Vec3::new(x, y, sqrtf(max0(1.0 - x * x - y * y)))
}

/// A direction in the cone of half-angle `acos(cos_max)` around `+z`, uniform in solid angle
/// (density `1 / (2π(1 − cos_max))`).
#[must_use]
pub fn uniform_cone(u: f32, v: f32, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u * (1.0 - cos_max);
    let sin_t = sqrtf(max0(1.0 - cos_t * cos_t));
    let (sin, cos) = sin_cos_turns(v);
    Vec3::new(sin_t * cos, sin_t * sin, cos_t)
}

/// The power heuristic (Veach 1997, exponent 2) for one sample of a strategy of density `a`
/// against another of density `b`: `a² / (a² + b²)`, evaluated without overflow (as
/// `1 / (1 + (b/a)²)` or `r² / (1 + r²)` with `r = a/b ≤ 1`). `f(a, b) + f(b, a)` is 1 up to
/// rounding; a density that is not positive (or NaN) gets weight 0, the other then 1; equal
/// densities (also both infinite) split evenly.
#[must_use]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    if a <= 0.0 || a.is_nan() {
        return 0.0;
    }
    if b <= 0.0 || b.is_nan() {
        return 1.0;
    }
    if a == b {
        return 0.5;
    }
    if a > b {
        let r = b / a;
        1.0 / (1.0 + r * r)
    } else {
        let r = a / b;
        let r2 = r * r;
        r2 / (1.0 + r2)
    }
}

/// An orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017, branch on
/// the sign of `n.z`; `copysign` written as an explicit comparison).
#[must_use]
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z < 0.0 { -1.0 } else { 1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// `local` (around `+z`) expressed in the frame whose `z` axis is the unit vector `n`.
#[must_use]
pub fn to_world(local: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    t * local.x + b * local.y + n * local.z
}

/// `(sin 2πt, cos 2πt)`: the sine and cosine of `t` turns, within 2·10⁻⁷ of the exact values
/// for `|t| < 2^20` (NaN for NaN; no meaning beyond 2^20).
///
/// `4t` is exact, and so is its distance `r ∈ [-½, ½]` to the nearest integer `k`, the
/// quadrant; `x = r·π/2 ∈ [-π/4, π/4]` goes through the Taylor series of `sin` and `cos` to
/// degree 9 and 10 (truncation below 3·10⁻⁸ there). Plain `f32` products and sums, so the bits
/// are the same on every platform; no `libm` trigonometry (whose argument reduction for any
/// angle is larger than the rest of the sampling code).
#[must_use]
pub fn sin_cos_turns(t: f32) -> (f32, f32) {
    let q = 4.0 * t;
    let k = (q + if q < 0.0 { -0.5 } else { 0.5 }) as i32;
    let x = (q - k as f32) * core::f32::consts::FRAC_PI_2;
    let x2 = x * x;
    let sin = x + x
        * x2
        * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0))));
    let cos = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0)))));
    match k & 3 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

fn abs(x: f32) -> f32 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

fn max0(x: f32) -> f32 {
    if x > 0.0 {
        x
    } else {
        0.0
    }
}
