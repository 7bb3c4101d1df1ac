//! Accelerators: one query API over every structure, so results can be compared bit for bit.
//!
//! The lecture's three ways to avoid testing every object: a bounding volume hierarchy
//! ([`bvh`]), a uniform spatial subdivision ([`grid`]) and an axis-aligned binary space
//! partition ([`kdtree`]); and brute force ([`Linear`]), the reference.

pub mod bvh;
pub mod grid;
pub mod kdtree;
mod linear;

pub use linear::Linear;

use crate::geom::{Hit, Ray};
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

/// The query API every accelerator offers.
///
/// `intersect` is the closest hit; ties at equal `t` go to the lowest primitive id, so every
/// accelerator returns the same [`Hit`]. `occluded` is any hit in `[t_min, t_max]` (early exit).
pub trait Accel<S: Scalar> {
    /// Closest hit, counting work in `stats`.
    fn intersect_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Hit<S>>;
    /// Any hit, counting work in `stats`.
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool;

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
