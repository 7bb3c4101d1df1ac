//! SplitMix64 (Steele, Lea and Flood, 2014): a tiny seeded generator with the same sequence on
//! every platform, and the few distributions the suites draw from it.

/// A SplitMix64 state. Every derived value uses exact conversions only, so a seed gives the
/// same bits everywhere.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub const fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)` with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in `[lo, hi)` from [`Rng::unit`].
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    /// Uniform in `[0, 1)` with 53 random bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `[lo, hi)` from [`Rng::unit_f64`].
    pub fn range_f64(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit_f64()
    }
    /// A point uniform in the cube `[-r, r)³`, in `f64`.
    pub fn cube_f64(&mut self, r: f64) -> [f64; 3] {
        [
            self.range_f64(-r, r),
            self.range_f64(-r, r),
            self.range_f64(-r, r),
        ]
    }
    /// Uniform in `0..n` (`n > 0`; modulo bias is negligible for test sizes).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    /// A direction (not normalised) uniform in `[-1, 1)³` with squared length above 0.01.
    pub fn dir(&mut self) -> [f32; 3] {
        loop {
            let v = [0; 3].map(|_| self.range(-1.0, 1.0));
            if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 0.01 {
                return v;
            }
        }
    }
    /// A uniformly distributed unit vector (rejection sampling, normalised in `f64`).
    pub fn unit_vec(&mut self) -> [f32; 3] {
        loop {
            let v = [0; 3].map(|_| self.range(-1.0, 1.0) as f64);
            let l2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            if l2 > 1e-4 && l2 <= 1.0 {
                let l = libm::sqrt(l2);
                return v.map(|x| (x / l) as f32);
            }
        }
    }
    /// A point uniformly distributed in the ball of radius `r` around the origin.
    pub fn in_ball(&mut self, r: f32) -> [f32; 3] {
        loop {
            let v = [0; 3].map(|_| self.range(-r, r));
            if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] <= r * r {
                return v;
            }
        }
    }
    /// Uniform on the unit sphere (cylindrical projection, the platform's `f64` sine and
    /// cosine).
    #[cfg(feature = "std")]
    pub fn direction(&mut self) -> [f32; 3] {
        let z = 1.0 - 2.0 * self.unit_f64();
        let phi = 2.0 * core::f64::consts::PI * self.unit_f64();
        let s = (1.0 - z * z).max(0.0).sqrt();
        [(s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32]
    }
}
