//! Any built accelerator, chosen at run time by an [`AccelKind`]: the one place that
//! dispatches over the structures.

use super::bvh::{Bvh, InvalidTree};
use super::family::{
    AccelFamily, Bvh4Family, Bvh8Family, BvhFamily, GridFamily, KdTreeFamily, LinearFamily,
};
use super::grid::{Grid, InvalidGrid};
use super::kdtree::{InvalidKdTree, KdTree};
use super::memory::take;
use super::wide::{collapse_words_needed, Bvh4, Bvh8};
use super::{Accel, AccelKind, AccelMemory, BuildError, Counters, Linear, MemoryNeeded, Nearest};
use crate::geom::{Barycentrics, Primitive, Ray};
use crate::scalar::Scalar;

/// A built accelerator of any kind. Its queries return what the structure inside returns.
#[derive(Clone, Copy, Debug)]
pub enum AnyAccel<'a, S: Scalar, P: Primitive<S>> {
    /// Brute force.
    Linear(Linear<'a, S, P>),
    /// A binary BVH.
    Bvh(Bvh<'a, S, P>),
    /// A 4-wide BVH.
    Bvh4(Bvh4<'a, S, P>),
    /// An 8-wide BVH.
    Bvh8(Bvh8<'a, S, P>),
    /// A uniform grid.
    Grid(Grid<'a, S, P>),
    /// A kd-tree.
    KdTree(KdTree<'a, S, P>),
}

impl<'a, S: Scalar, P: Primitive<S>> AnyAccel<'a, S, P> {
    /// Builds `kind` over `prims`, taking [`AccelKind::memory_needed`] from the front of
    /// `memory`'s buffers (shorter buffers give the structure's
    /// [`BuildError::ArenaTooSmall`]).
    ///
    /// # Errors
    /// What the structure's builder reports; brute force checks the primitives as every
    /// builder does ([`BuildError::TooManyPrims`], [`BuildError::BadPrimitive`]).
    pub fn build(
        kind: AccelKind,
        prims: &'a [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Self, BuildError> {
        match kind {
            AccelKind::Linear => LinearFamily::build(&(), prims, memory).map(Self::Linear),
            AccelKind::Bvh(o) => BvhFamily::build(&o, prims, memory).map(Self::Bvh),
            AccelKind::Bvh4(o) => Bvh4Family::build(&o, prims, memory).map(Self::Bvh4),
            AccelKind::Bvh8(o) => Bvh8Family::build(&o, prims, memory).map(Self::Bvh8),
            AccelKind::Grid(o) => GridFamily::build(&o, prims, memory).map(Self::Grid),
            AccelKind::KdTree(o) => KdTreeFamily::build(&o, prims, memory).map(Self::KdTree),
        }
    }

    /// As [`AnyAccel::build`], but the BVHs permute `prims` into leaf order
    /// ([`Bvh::build_in_leaf_order`]); the other structures leave them as they are.
    ///
    /// # Errors
    /// As [`AnyAccel::build`].
    pub fn build_in_leaf_order(
        kind: AccelKind,
        prims: &'a mut [P],
        memory: &mut AccelMemory<'a, S>,
    ) -> Result<Self, BuildError>
    where
        P: Copy,
    {
        let need = MemoryNeeded::bvh(prims.len());
        match kind {
            AccelKind::Bvh(options) => {
                let nodes = take(&mut memory.nodes, need.nodes);
                let ids = take(&mut memory.words, need.words);
                let tree = Bvh::build_in_leaf_order(prims, nodes, ids, options)?;
                Ok(Self::Bvh(tree))
            }
            AccelKind::Bvh4(options) => {
                let nodes = take(&mut memory.nodes, need.nodes);
                let ids = take(&mut memory.words, need.words);
                let nodes4 = take(&mut memory.nodes4, MemoryNeeded::bvh4(prims.len()).nodes4);
                let scratch = take(&mut memory.words, collapse_words_needed(prims.len(), 4));
                let binary = Bvh::build_in_leaf_order(prims, nodes, ids, options)?;
                Ok(Self::Bvh4(Bvh4::collapse(&binary, nodes4, scratch)?))
            }
            AccelKind::Bvh8(options) => {
                let nodes = take(&mut memory.nodes, need.nodes);
                let ids = take(&mut memory.words, need.words);
                let nodes8 = take(&mut memory.nodes8, MemoryNeeded::bvh8(prims.len()).nodes8);
                let scratch = take(&mut memory.words, collapse_words_needed(prims.len(), 8));
                let binary = Bvh::build_in_leaf_order(prims, nodes, ids, options)?;
                Ok(Self::Bvh8(Bvh8::collapse(&binary, nodes8, scratch)?))
            }
            AccelKind::Linear | AccelKind::Grid(_) | AccelKind::KdTree(_) => {
                Self::build(kind, prims, memory)
            }
        }
    }

    /// The structure's name, as [`AccelKind::name`] gives it.
    #[must_use]
    pub const fn name(&self) -> &'static str {
        match self {
            Self::Linear(_) => "linear",
            Self::Bvh(_) => "bvh",
            Self::Bvh4(_) => "bvh4",
            Self::Bvh8(_) => "bvh8",
            Self::Grid(_) => "grid",
            Self::KdTree(_) => "kdtree",
        }
    }

    /// Nodes in use: tree nodes, or the grid's cells (0 for brute force).
    #[must_use]
    pub fn node_count(&self) -> usize {
        match self {
            Self::Linear(_) => 0,
            Self::Bvh(a) => a.nodes().len(),
            Self::Bvh4(a) => a.nodes().len(),
            Self::Bvh8(a) => a.nodes().len(),
            Self::Grid(a) => a.cells().len().saturating_sub(1),
            Self::KdTree(a) => a.nodes().len(),
        }
    }

    /// Bytes a query reads besides the primitives (0 for brute force; the wide BVHs' build
    /// scratch is not counted).
    #[must_use]
    pub fn bytes_used(&self) -> usize {
        match self {
            Self::Linear(_) => 0,
            Self::Bvh(a) => a.bytes_used(),
            Self::Bvh4(a) => a.bytes_used(),
            Self::Bvh8(a) => a.bytes_used(),
            Self::Grid(a) => a.bytes_used(),
            Self::KdTree(a) => a.bytes_used(),
        }
    }

    /// Depth of the deepest leaf (0 for brute force and the grid).
    #[must_use]
    pub fn depth(&self) -> u32 {
        match self {
            Self::Linear(_) | Self::Grid(_) => 0,
            Self::Bvh(a) => a.depth(),
            Self::Bvh4(a) => a.depth(),
            Self::Bvh8(a) => a.depth(),
            Self::KdTree(a) => a.depth(),
        }
    }
}

impl<S: Scalar, P: Primitive<S>> AnyAccel<'_, S, P> {
    /// Checks every invariant of the structure inside (its own `validate`; brute force has
    /// none to break).
    ///
    /// # Errors
    /// The first violated invariant, as the structure reports it.
    pub fn validate(&self) -> Result<(), InvalidAccel> {
        match self {
            Self::Linear(_) => Ok(()),
            Self::Bvh(a) => a.validate().map(drop).map_err(InvalidAccel::Tree),
            Self::Bvh4(a) => a.validate().map(drop).map_err(InvalidAccel::Tree),
            Self::Bvh8(a) => a.validate().map(drop).map_err(InvalidAccel::Tree),
            Self::Grid(a) => a.validate().map(drop).map_err(InvalidAccel::Grid),
            Self::KdTree(a) => a.validate().map(drop).map_err(InvalidAccel::KdTree),
        }
    }
}

/// The first violated invariant found by [`AnyAccel::validate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum InvalidAccel {
    /// From [`Bvh::validate`], [`Bvh4::validate`] or [`Bvh8::validate`].
    Tree(InvalidTree),
    /// From [`Grid::validate`].
    Grid(InvalidGrid),
    /// From [`KdTree::validate`].
    KdTree(InvalidKdTree),
}

impl core::fmt::Display for InvalidAccel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Tree(e) => core::fmt::Display::fmt(e, f),
            Self::Grid(e) => core::fmt::Display::fmt(e, f),
            Self::KdTree(e) => core::fmt::Display::fmt(e, f),
        }
    }
}

impl core::error::Error for InvalidAccel {}

/// Something to do with a built accelerator, generic over its type, so that
/// [`AnyAccel::visit`] runs it on the structure itself (monomorphised per structure, no
/// dispatch per query).
pub trait AccelVisitor<S: Scalar> {
    /// What the visit returns.
    type Output;
    /// Called once with the accelerator.
    fn visit<A: Accel<S>>(self, accel: &A) -> Self::Output;
}

impl<S: Scalar, P: Primitive<S>> AnyAccel<'_, S, P> {
    /// Runs `visitor` on the structure inside.
    pub fn visit<V: AccelVisitor<S>>(&self, visitor: V) -> V::Output {
        match self {
            Self::Linear(a) => visitor.visit(a),
            Self::Bvh(a) => visitor.visit(a),
            Self::Bvh4(a) => visitor.visit(a),
            Self::Bvh8(a) => visitor.visit(a),
            Self::Grid(a) => visitor.visit(a),
            Self::KdTree(a) => visitor.visit(a),
        }
    }
}

impl<S: Scalar, P: Primitive<S>> Accel<S> for AnyAccel<'_, S, P> {
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        match self {
            Self::Linear(a) => a.nearest_counted(ray, stats),
            Self::Bvh(a) => a.nearest_counted(ray, stats),
            Self::Bvh4(a) => a.nearest_counted(ray, stats),
            Self::Bvh8(a) => a.nearest_counted(ray, stats),
            Self::Grid(a) => a.nearest_counted(ray, stats),
            Self::KdTree(a) => a.nearest_counted(ray, stats),
        }
    }

    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        match self {
            Self::Linear(a) => a.occluded_counted(ray, stats),
            Self::Bvh(a) => a.occluded_counted(ray, stats),
            Self::Bvh4(a) => a.occluded_counted(ray, stats),
            Self::Bvh8(a) => a.occluded_counted(ray, stats),
            Self::Grid(a) => a.occluded_counted(ray, stats),
            Self::KdTree(a) => a.occluded_counted(ray, stats),
        }
    }

    #[inline]
    fn nearest_coherent_counted<C: Counters>(
        &self,
        ray: &Ray<S>,
        stats: &mut C,
    ) -> Option<Nearest<S>> {
        match self {
            Self::Linear(a) => a.nearest_coherent_counted(ray, stats),
            Self::Bvh(a) => a.nearest_coherent_counted(ray, stats),
            Self::Bvh4(a) => a.nearest_coherent_counted(ray, stats),
            Self::Bvh8(a) => a.nearest_coherent_counted(ray, stats),
            Self::Grid(a) => a.nearest_coherent_counted(ray, stats),
            Self::KdTree(a) => a.nearest_coherent_counted(ray, stats),
        }
    }

    #[inline]
    fn occluded_coherent_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        match self {
            Self::Linear(a) => a.occluded_coherent_counted(ray, stats),
            Self::Bvh(a) => a.occluded_coherent_counted(ray, stats),
            Self::Bvh4(a) => a.occluded_coherent_counted(ray, stats),
            Self::Bvh8(a) => a.occluded_coherent_counted(ray, stats),
            Self::Grid(a) => a.occluded_coherent_counted(ray, stats),
            Self::KdTree(a) => a.occluded_coherent_counted(ray, stats),
        }
    }

    #[inline]
    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        match self {
            Self::Linear(a) => a.barycentrics(ray, found),
            Self::Bvh(a) => a.barycentrics(ray, found),
            Self::Bvh4(a) => a.barycentrics(ray, found),
            Self::Bvh8(a) => a.barycentrics(ray, found),
            Self::Grid(a) => a.barycentrics(ray, found),
            Self::KdTree(a) => a.barycentrics(ray, found),
        }
    }
}
