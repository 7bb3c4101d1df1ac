//! The two number modes: `f32` and the fixed-point [`I16F16`].
//!
//! Every algorithm above this module (builders, traversal, queries) is written once, generic over
//! [`Scalar`]. What must differ between the modes lives here: the public trait holds what a caller
//! needs (constants, conversions, checks); its sealed supertrait `Numerics` holds how a ray is
//! prepared, the conservative slab test and the exact-as-possible primitive tests, which the
//! kernel reaches through `S: Scalar` and callers never name. Each mode's numerics sit in its own
//! file (`float.rs`, `fixed.rs`). A second sealed supertrait, `Spawn`, holds the per-mode steps
//! of [`crate::spawn`]'s rule and is implemented there, next to the rule and its constants.

mod error;
mod fixed;
mod float;
pub(crate) mod lanes;
mod wide;

/// The unit tests' xorshift generator: advances `state` and returns it.
#[cfg(test)]
pub(crate) fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

pub use error::{PointError, RayError};
pub use fixed::{Vec3x, FIXED_COORD_LIMIT, I16F16};
pub use float::F32_COORD_LIMIT;
pub(crate) use float::{sqrt, sqrtf};

use core::fmt::Debug;

/// The per-mode numerics behind [`Scalar`]: ray preparation, the conservative slab test, the
/// primitive tests. Sealed (implemented for the two modes only) and not part of the public API.
pub(crate) mod sealed {
    use super::RayError;
    use core::fmt::Debug;

    /// Ray preparation, slab tests and primitive tests of one mode; a supertrait of [`Scalar`],
    /// so everything generic over `S: Scalar` calls them as `S::slab(..)`.
    ///
    /// [`Scalar`]: super::Scalar
    pub trait Numerics: Copy + PartialEq + PartialOrd + Debug + Send + Sync + 'static {
        /// Per-ray data precomputed once by [`crate::Ray`]'s constructors for the box and
        /// primitive tests (public as [`crate::RayData`]).
        type RayData: Copy + Debug + Send + Sync;
        /// The lowest value: `-inf` for `f32`, the most negative one for fixed point. Below or
        /// equal to every value, so `LOWEST.max_of(x)` is `x`, bit for bit.
        const LOWEST: Self;

        /// Prepares a ray from an origin and a direction given in this mode.
        fn ray_data(origin: [Self; 3], dir: [Self; 3]) -> Result<Self::RayData, RayError>;
        /// Prepares a ray from an `f32` origin and direction (for fixed point, the direction keeps
        /// more precision than a Q16.16 vector could carry).
        fn ray_data_from_f32(origin: [f32; 3], dir: [f32; 3]) -> Result<Self::RayData, RayError>;
        /// [`Numerics::ray_data_from_f32`] written into `data`, which is unchanged on error. The
        /// default moves the prepared data in; `f32` writes it field by field.
        #[inline(always)]
        fn set_ray_data_from_f32(
            data: &mut Self::RayData,
            origin: [f32; 3],
            dir: [f32; 3],
        ) -> Result<(), RayError> {
            *data = Self::ray_data_from_f32(origin, dir)?;
            Ok(())
        }
        /// The same ray (direction bits unchanged) from another origin: motion blur moves rays
        /// into a moving object's frame this way.
        ///
        /// # Errors
        /// [`RayError::Origin`] for an unusable origin.
        fn ray_moved(ray: &Self::RayData, origin: [Self; 3]) -> Result<Self::RayData, RayError>;
        /// The ray from the same origin along another direction given in `f32`: the same bits as
        /// `Numerics::ray_data_from_f32` with this ray's origin, without checking and preparing the
        /// origin again.
        ///
        /// # Errors
        /// [`RayError::ZeroDirection`] and [`RayError::NonFiniteDirection`].
        fn ray_redirected_f32(
            ray: &Self::RayData,
            dir: [f32; 3],
        ) -> Result<Self::RayData, RayError>;

        /// Pads a node box outward by this mode's traversal error margin. Identity for fixed point.
        fn pad_bounds(lo: [Self; 3], hi: [Self; 3]) -> ([Self; 3], [Self; 3]);
        /// Conservative slab test. Returns the entry distance if the ray's interval `[t_min, t_max]`
        /// overlaps the box, never culling a box that holds a primitive hit in that interval.
        fn slab(
            ray: &Self::RayData,
            lo: &[Self; 3],
            hi: &[Self; 3],
            t_min: Self,
            t_max: Self,
        ) -> Option<Self>;
        /// `Numerics::slab` of two boxes `(lo, hi)` at once (a BVH node's children), with the same
        /// results: bit for bit the same entry distances.
        #[inline(always)]
        fn slab_pair(
            ray: &Self::RayData,
            a: (&[Self; 3], &[Self; 3]),
            b: (&[Self; 3], &[Self; 3]),
            t_min: Self,
            t_max: Self,
        ) -> [Option<Self>; 2] {
            [
                Self::slab(ray, a.0, a.1, t_min, t_max),
                Self::slab(ray, b.0, b.1, t_min, t_max),
            ]
        }
        /// `Numerics::slab` of four boxes at once (a 4-wide BVH node's children), given as
        /// structure of arrays: `lo[axis][box]`, `hi[axis][box]`. Returns a mask (bit `i` set if box
        /// `i` is accepted) and the entry distances. Entries of rejected boxes are unspecified.
        ///
        /// The default runs `slab` per box. `f32` computes the four boxes in the lanes of one
        /// vector (`scalar/wide.rs`), with each lane doing `slab`'s operations in its order:
        /// decisions and entries are `slab`'s, bit for bit. Fixed point where `F4` has vector
        /// lanes runs a conservative `f32` version of its test in them (`wide::slab4_fixed`):
        /// every box the ray meets within `[t_min, t_max + 1]` is accepted with an entry no later
        /// than the exact one, so the hits are the same, but decisions and entries may differ
        /// from `slab`'s.
        #[inline(always)]
        fn slab4(
            ray: &Self::RayData,
            lo: &[[Self; 4]; 3],
            hi: &[[Self; 4]; 3],
            t_min: Self,
            t_max: Self,
        ) -> (u32, [Self; 4]) {
            let mut mask = 0u32;
            let mut t = [t_min; 4];
            for (i, slot) in t.iter_mut().enumerate() {
                let i = i.min(3); // a no-op that shows the compiler the bound
                let l = [lo[0][i], lo[1][i], lo[2][i]];
                let h = [hi[0][i], hi[1][i], hi[2][i]];
                if let Some(near) = Self::slab(ray, &l, &h, t_min, t_max) {
                    *slot = near;
                    mask |= 1 << i;
                }
            }
            (mask, t)
        }
        /// [`Numerics::slab4`] of eight boxes (an 8-wide BVH node's children): on lanes 0..4,
        /// then on lanes 4..8, so each box gets exactly its `slab4` decision and entry.
        #[inline(always)]
        fn slab8(
            ray: &Self::RayData,
            lo: &[[Self; 8]; 3],
            hi: &[[Self; 8]; 3],
            t_min: Self,
            t_max: Self,
        ) -> (u32, [Self; 8]) {
            let half = |planes: &[[Self; 8]; 3], h: usize| {
                planes.map(|axis| core::array::from_fn::<Self, 4, _>(|i| axis[(4 * h + i) % 8]))
            };
            let (low, t_low) = Self::slab4(ray, &half(lo, 0), &half(hi, 0), t_min, t_max);
            let (high, t_high) = Self::slab4(ray, &half(lo, 1), &half(hi, 1), t_min, t_max);
            let t = core::array::from_fn(|i| if i < 4 { t_low[i % 4] } else { t_high[i % 4] });
            (low | high << 4, t)
        }
        /// [`Numerics::slab8`], bit for bit, for code that runs on a CPU with AVX2: the eight
        /// boxes in the 256-bit lanes of one vector (`wide::slab8_avx2` for `f32`,
        /// `wide::slab8_avx2_fixed` for fixed point), each lane doing the operations of a
        /// `slab4` lane in their order; the default is `slab8`.
        ///
        /// # Safety
        /// The CPU must have AVX2.
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        #[inline(always)]
        unsafe fn slab8_avx2(
            ray: &Self::RayData,
            lo: &[[Self; 8]; 3],
            hi: &[[Self; 8]; 3],
            t_min: Self,
            t_max: Self,
        ) -> (u32, [Self; 8]) {
            Self::slab8(ray, lo, hi, t_min, t_max)
        }
        /// `t >= 0` widened by the slab test's margin: the test accepts boxes entered up to
        /// `widen(t)`.
        #[must_use]
        fn widen(t: Self) -> Self;
        /// Bits that order entry distances `t >= +0` as the distances are ordered (`f32`: the
        /// IEEE bits; fixed point: the raw integer): `a < b` gives
        /// `order_bits(a) <= order_bits(b)`. The 8-wide walk's sort keys: visit order only.
        #[must_use]
        fn order_bits(t: Self) -> u32;
        /// The per-axis part of `Numerics::slab`, for traversals that walk cells plane by plane
        /// (the uniform grid): `(entry, exit)` of the ray between the planes `lo <= hi` of `axis`,
        /// the exit already widened.
        ///
        /// Contract (tested against `slab`): `slab(ray, lo, hi, t_min, t_max)` returns `Some(e)`
        /// exactly when `e = max(t_min, entry_0, entry_1, entry_2) <= min(widen(t_max), exit_0,
        /// exit_1, exit_2)`; in fixed point values beyond the range are clamped to it, which can
        /// only add acceptances at the range end. An axis that constrains nothing (`f32`: a zero
        /// direction component whose shifted origin lies on the `hi` plane) gives `(-inf, +inf)`.
        /// Both ends are nondecreasing in `lo` and `hi` when `Numerics::axis_negative` is false and
        /// nonincreasing when it is true (including zero direction components).
        fn slab_axis(ray: &Self::RayData, axis: usize, lo: Self, hi: Self) -> (Self, Self);
        /// True if the ray runs towards decreasing coordinates on `axis` as the slab test sees it
        /// (in `f32` a `-0` component counts as negative: its reciprocal is `-inf`).
        fn axis_negative(ray: &Self::RayData, axis: usize) -> bool;

        /// Distance to a two-sided triangle if it is hit within `[t_min, t_max]`.
        /// Degenerate triangles are never hit.
        fn triangle_t(
            ray: &Self::RayData,
            v: &[[Self; 3]; 3],
            t_min: Self,
            t_max: Self,
        ) -> Option<Self>;
        /// Barycentrics `(u, v)` of the hit (weights of the second and third vertex). Only meaningful
        /// for a triangle that `Numerics::triangle_t` reports as hit; zero otherwise.
        fn triangle_uv(ray: &Self::RayData, v: &[[Self; 3]; 3]) -> (Self, Self);
        /// Distance to a sphere surface if it is hit within `[t_min, t_max]` (nearest root first).
        fn sphere_t(
            ray: &Self::RayData,
            center: &[Self; 3],
            radius: Self,
            t_min: Self,
            t_max: Self,
        ) -> Option<Self>;
        /// `center - r` and `center + r` per axis, rounded outward.
        fn sphere_bounds(center: &[Self; 3], radius: Self) -> ([Self; 3], [Self; 3]);
    }

    /// The per-mode steps of the spawn rule ([`crate::spawn`]): rounding to the mode, the exact
    /// side test and unit steps. Implemented next to the rule, in `geom/spawn.rs`; a supertrait
    /// of [`Scalar`] as [`Numerics`] is.
    ///
    /// [`Scalar`]: super::Scalar
    pub trait Spawn: Sized {
        /// A point rounded to the nearest representable one (saturating at the mode's range).
        fn point_from_f64(p: [f64; 3]) -> [Self; 3];
        /// The distance [`crate::spawn`] moves a ray origin off a triangle's plane, for a triangle
        /// and hit point of largest coordinate magnitude `m`.
        fn spawn_offset(m: f64) -> f64;
        /// Sign of `n·(p − v0)` with `n = (v1−v0)×(v2−v0)`: exact in fixed point, `f64` for `f32`.
        fn side(v: &[[Self; 3]; 3], p: &[Self; 3]) -> i32;
        /// `x` moved one unit (ulp or raw) up or down; non-finite `f32` values stay unchanged.
        fn step(x: Self, up: bool) -> Self;
        /// A distance rounded toward zero to this mode, with `extra` further units taken off
        /// (never below zero).
        fn t_down(t: f64, extra: u32) -> Self;
    }
}

/// The per-ray data of mode `S` that [`Primitive`](crate::Primitive) tests receive: read its
/// origin and direction with [`Scalar::ray_origin`] and [`Scalar::ray_dir`].
pub type RayData<S> = <S as sealed::Numerics>::RayData;

/// The number type the kernel computes in. Implemented for `f32` and [`I16F16`] only.
///
/// Determinism contract for both implementations: the same inputs give the same bits on every
/// platform. Only correctly rounded IEEE operations and `libm` are used in `f32` mode, min/max are
/// explicit comparisons, and no NaN is ever returned.
pub trait Scalar:
    sealed::Numerics
    + sealed::Spawn
    + Copy
    + PartialEq
    + PartialOrd
    + Debug
    + Default
    + Send
    + Sync
    + 'static
{
    /// The vector type of the public API: `glam::Vec3` for `f32`, [`crate::Vec3x`] for fixed point.
    type Vec3: Copy + Debug;

    /// Zero.
    const ZERO: Self;
    /// The far end of an unbounded ray: `+inf` for `f32`, the largest value for fixed point.
    const FAR: Self;
    /// Short name of the mode, as used on command lines and in reports: `f32` or `fixed`.
    const NAME: &'static str;

    /// Converts to `f32` (exact for `f32`; rounds to nearest for fixed point).
    fn to_f32(self) -> f32;
    /// Converts to `f64` (exact in both modes).
    fn to_f64(self) -> f64;
    /// Converts from `f32`, saturating at the representable range (NaN gives zero).
    fn from_f32_saturating(x: f32) -> Self;
    /// Converts one coordinate from `f32`, failing on NaN, infinity or values outside the mode's
    /// coordinate range.
    fn coord_from_f32(x: f32) -> Result<Self, PointError>;
    /// The public vector type as an array.
    fn vec_to_array(v: Self::Vec3) -> [Self; 3];
    /// An array as the public vector type.
    fn array_to_vec(a: [Self; 3]) -> Self::Vec3;
    /// Checks that a point is usable as a vertex, sphere centre or ray origin.
    fn check_point(p: [Self; 3]) -> Result<(), PointError>;
    /// Checks that a sphere radius is usable (finite / in range, and not negative).
    fn check_radius(r: Self) -> Result<(), PointError>;

    /// `self` if `self < other`, else `other` (explicit comparison, deterministic for ±0).
    #[must_use]
    fn min_of(self, other: Self) -> Self {
        if self < other {
            self
        } else {
            other
        }
    }
    /// `self` if `self > other`, else `other` (explicit comparison, deterministic for ±0).
    #[must_use]
    fn max_of(self, other: Self) -> Self {
        if self > other {
            self
        } else {
            other
        }
    }

    /// The ray origin.
    fn ray_origin(ray: &Self::RayData) -> [Self; 3];
    /// The (unit-length) ray direction, rounded to this mode.
    fn ray_dir(ray: &Self::RayData) -> [Self; 3];
}
