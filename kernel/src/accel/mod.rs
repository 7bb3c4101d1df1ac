//! Accelerators: one query API over every structure, so results can be compared bit for bit.
//!
//! The lecture's three ways to avoid testing every object: a bounding volume hierarchy
//! ([`bvh`], and its 4-wide form [`bvh4`]), a uniform spatial subdivision ([`grid`]) and an axis-aligned binary space
//! partition ([`kdtree`]); and brute force ([`Linear`]), the reference.

mod any;
pub(crate) mod baked;
pub(crate) mod bvh;
mod error;
mod family;
pub(crate) mod grid;
mod input;
pub(crate) mod kdtree;
mod kind;
mod linear;
mod memory;
pub(crate) mod wide;

pub use any::{AccelVisitor, AnyAccel, InvalidAccel};
pub use error::{Arena, BuildError};
pub use family::{
    AccelFamily, AnyFamily, Bvh4Family, Bvh8Family, BvhFamily, GridFamily, KdTreeFamily,
    LinearFamily, TrianglesOnly,
};
pub use input::MAX_PRIMS;
pub(crate) use input::{check_count, check_each};
pub use kind::{AccelKind, UnknownAccel};
pub use linear::Linear;
pub(crate) use memory::take;
pub use memory::{AccelMemory, MemoryNeeded, Shortfall};

use crate::geom::{Barycentrics, Hit, Primitive, Ray};
use crate::scalar::Scalar;

/// Traversal counters, for benchmarks. The [`NoStats`] implementation compiles to nothing.
pub trait Counters {
    /// A node (box) was visited.
    fn node(&mut self);
    /// A primitive was tested.
    fn prim(&mut self);
}

/// Counters that count nothing (the default for [`Accel::intersect`] and [`Accel::occluded`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoStats;

impl Counters for NoStats {
    #[inline(always)]
    fn node(&mut self) {}
    #[inline(always)]
    fn prim(&mut self) {}
}

/// Counts of the work a query did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Nodes whose box was tested or which were entered.
    pub nodes_visited: u64,
    /// Primitive intersection tests.
    pub prims_tested: u64,
}

impl Counters for TraversalStats {
    #[inline(always)]
    fn node(&mut self) {
        self.nodes_visited += 1;
    }
    #[inline(always)]
    fn prim(&mut self) {
        self.prims_tested += 1;
    }
}

/// What a closest-hit traversal found, before barycentrics: distance and primitive id, plus
/// where the primitive sits in the accelerator's storage (for [`Accel::barycentrics`]).
///
/// Callers that need only `t` and the id (hit files, emitters, occlusion-like shading) stop
/// here; [`Accel::intersect`] adds the barycentrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest<S: Scalar> {
    /// Distance along the ray.
    pub t: S,
    /// Id (index in the caller's primitive slice) of the primitive hit.
    pub prim: u32,
    /// Index of that primitive in the accelerator's primitive storage.
    pub(crate) slot: usize,
}

impl<S: Scalar> Nearest<S> {
    /// From a traversal's result, where `prim == u32::MAX` means no hit.
    #[inline]
    pub(crate) fn found(t: S, prim: u32, slot: usize) -> Option<Self> {
        (prim != u32::MAX).then_some(Self { t, prim, slot })
    }

    /// Barycentrics of this hit on `prims[slot]` (zero if the slot is out of range, which a
    /// hit of the accelerator owning `prims` never is).
    #[inline]
    pub(crate) fn barycentrics_in<P: Primitive<S>>(
        &self,
        prims: &[P],
        ray: &Ray<S>,
    ) -> Barycentrics<S> {
        prims
            .get(self.slot)
            .map_or(Barycentrics::ZERO, |p| p.hit_uv(ray.data()))
    }
}

/// The query API every accelerator offers.
///
/// `nearest` is the closest hit; ties at equal `t` go to the lowest primitive id, so every
/// accelerator returns the same [`Nearest`] and the same [`Hit`]. `occluded` is any hit in
/// `[t_min, t_max]` (early exit).
pub trait Accel<S: Scalar> {
    /// Closest hit's distance and primitive, counting work in `stats`.
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>>;
    /// Any hit, counting work in `stats`.
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool;
    /// Barycentrics of a hit `nearest` returned for `ray` (zero for primitives without them).
    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S>;

    /// [`Accel::nearest_counted`] by the walk for coherent rays, where the structure has one
    /// (the 8-wide BVH): the same result, bit for bit. [`Coherent`] calls it.
    #[inline]
    fn nearest_coherent_counted<C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> Option<Nearest<S>> {
        self.nearest_counted(ray, stats)
    }
    /// [`Accel::occluded_counted`] by the walk for coherent rays, as
    /// [`Accel::nearest_coherent_counted`].
    #[inline]
    fn occluded_coherent_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.occluded_counted(ray, stats)
    }

    /// Closest hit with barycentrics, counting work in `stats`.
    #[inline]
    fn intersect_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Hit<S>> {
        let found = self.nearest_counted(ray, stats)?;
        let Barycentrics { u, v } = self.barycentrics(ray, &found);
        Some(Hit {
            t: found.t,
            prim: found.prim,
            u,
            v,
        })
    }
    /// Closest hit's distance and primitive.
    #[inline]
    fn nearest(&self, ray: &Ray<S>) -> Option<Nearest<S>> {
        self.nearest_counted(ray, &mut NoStats)
    }
    /// Closest hit.
    #[inline]
    fn intersect(&self, ray: &Ray<S>) -> Option<Hit<S>> {
        self.intersect_counted(ray, &mut NoStats)
    }
    /// Any hit.
    #[inline]
    fn occluded(&self, ray: &Ray<S>) -> bool {
        self.occluded_counted(ray, &mut NoStats)
    }
}

/// An accelerator queried by its walk for coherent rays: successive queries whose rays are
/// close in origin and direction, as a camera's rays in scanline order are (Embree's
/// `RTC_INTERSECT_CONTEXT_FLAG_COHERENT` is the same kind of hint). Every query returns what
/// the accelerator itself returns, bit for bit; only the speed differs.
///
/// The 8-wide BVH has such a walk: it reaches the nearer of two hit children, and the nearest
/// of more, by a jump over the slots, which the branch predictor gets right when successive
/// rays take the same paths, and wrong, at a cost, when they do not. On incoherent rays it is
/// slower than the default walk. The other structures answer with their one walk.
///
/// ```
/// use raykernel::{Accel, Coherent};
/// # fn camera_rays<A: Accel<f32>>(tree: &A, rays: &[raykernel::Ray<f32>]) {
/// let view = Coherent(tree);
/// for ray in rays {
///     let _hit = view.nearest(ray);
/// }
/// # }
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Coherent<'a, A>(pub &'a A);

impl<S: Scalar, A: Accel<S>> Accel<S> for Coherent<'_, A> {
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        self.0.nearest_coherent_counted(ray, stats)
    }
    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.0.occluded_coherent_counted(ray, stats)
    }
    #[inline]
    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        self.0.barycentrics(ray, found)
    }
}
