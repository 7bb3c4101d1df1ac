//! Bounding volume hierarchy over caller-provided memory.
//!
//! The caller owns every byte: a node slice sized by [`nodes_needed`] and a primitive-id slice
//! with one slot per primitive. [`Bvh::build`] fills them (no allocation, no recursion) and
//! returns a [`Bvh`] that borrows them. Three builders: binned SAH (default), median split
//! (sort along an axis, split in the middle) and midpoint split (partition at the middle of an
//! axis, median when that leaves a side empty). By default a reinsertion pass follows
//! (`optimize.rs`, [`BuildOptions::reinsertion`]): it moves subtrees to where they lower the
//! tree's SAH cost, never past the depth cap.
//!
//! Depth is capped at [`MAX_DEPTH`]: from depth 32 on, every builder splits at the median, which
//! halves the count, so no tree is deeper than 32 + 32 levels. Traversal uses a stack of
//! [`MAX_DEPTH`] entries, so it cannot overflow.

mod build;
mod node;
mod optimize;
mod parts;
mod refit;
mod select;
mod traverse;
mod validate;
mod walk;

pub use node::Node;
pub(crate) use refit::{leaf_bounds, refit_nodes};
pub use refit::{RefitError, TreeShape};
pub(crate) use traverse::{test_leaf, LeafPrims};
pub(crate) use validate::check_permutation;
pub use validate::{InvalidTree, TreeStats};

use crate::accel::BuildError;
use crate::geom::Primitive;
use crate::scalar::Scalar;
use core::marker::PhantomData;

/// Deepest level a leaf may sit at (the root is level 0). Also the traversal stack capacity.
pub const MAX_DEPTH: usize = 64;
/// Depth from which every builder splits at the median, to honour [`MAX_DEPTH`].
pub const MEDIAN_FALLBACK_DEPTH: usize = MAX_DEPTH - 32;
/// Largest accepted `max_leaf_size`.
pub const MAX_LEAF_SIZE: u32 = 64;
/// The default `max_leaf_size`: of the sizes compared by instruction counts on the shared
/// scenes (SAH, binary and 4-wide trees), the one that traverses with the fewest.
pub const DEFAULT_LEAF_SIZE: u32 = 3;

/// Exact node slots [`Bvh::build`] needs for `prim_count` primitives in the worst case:
/// `2n` for `n >= 2` (a binary tree with one primitive per leaf has `2n - 1` nodes, and slot 1
/// stays unused so that sibling pairs start at even slots), 1 for one primitive, 0 for none.
///
/// Sibling pairs are 64 bytes; with the arena aligned to 64 bytes each pair is one cache line.
#[must_use]
pub const fn nodes_needed(prim_count: usize) -> usize {
    match prim_count {
        0 | 1 => prim_count,
        n => n.saturating_mul(2),
    }
}

/// Half the surface area of the box with corners `lo`, `hi` (first three lanes), in `f32`:
/// the SAH's measure for the builder's splits and the reinsertion pass's cost.
#[inline(always)]
pub(crate) fn half_area<S: Scalar>(lo: &[S], hi: &[S]) -> f32 {
    let d: [f32; 3] = core::array::from_fn(|i| {
        let (l, h) = (lo.get(i).copied(), hi.get(i).copied());
        h.unwrap_or(S::ZERO).to_f32() - l.unwrap_or(S::ZERO).to_f32()
    });
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

/// Index of the first child pair: slot 1 is padding so pairs sit at even slots.
pub(crate) const FIRST_PAIR: usize = 2;

/// How to choose splits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuilderKind {
    /// Binned surface area heuristic (32 bins on each axis). Best trees; the default.
    #[default]
    Sah,
    /// Split at the median centroid along the widest axis: balanced, depth `⌈log2(n)⌉`.
    Median,
    /// Split at the middle of the widest centroid extent; median when a side would be empty.
    Midpoint,
}

impl BuilderKind {
    /// Every builder, for tests and benchmarks.
    pub const ALL: [BuilderKind; 3] =
        [BuilderKind::Sah, BuilderKind::Median, BuilderKind::Midpoint];

    /// Lower-case name as used on command lines: `sah`, `median`, `midpoint`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Sah => "sah",
            Self::Median => "median",
            Self::Midpoint => "midpoint",
        }
    }
}

/// Build settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BuildOptions {
    /// Split strategy.
    pub builder: BuilderKind,
    /// No leaf holds more primitives than this (1..=[`MAX_LEAF_SIZE`]).
    pub max_leaf_size: u32,
    /// After the split-based build, move subtrees to wherever that lowers the tree's SAH
    /// cost (Bittner et al. 2013): the same leaves, smaller and less overlapping inner boxes.
    /// On by default. Its bookkeeping lives in the arena slots the tree leaves unused, so it
    /// is skipped when they number fewer than half the tree's nodes (or half the primitives):
    /// trees with about one primitive per leaf. It never makes a leaf deeper than
    /// [`MAX_DEPTH`].
    pub reinsertion: bool,
}

impl BuildOptions {
    /// The defaults: SAH, [`DEFAULT_LEAF_SIZE`], reinsertion on.
    pub const DEFAULT: Self = Self {
        builder: BuilderKind::Sah,
        max_leaf_size: DEFAULT_LEAF_SIZE,
        reinsertion: true,
    };
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What a build is told: chosen at run time ([`BuildOptions`]) or named at compile time
/// ([`StaticBuild`]). Every build runs the same generic code; with a [`StaticBuild`] the choice
/// is a constant, so the split rules and passes it does not name are not linked.
pub trait BuildSettings: Copy {
    /// The split rule.
    fn builder(self) -> BuilderKind;
    /// No leaf holds more primitives than this (1..=[`MAX_LEAF_SIZE`]).
    fn max_leaf_size(self) -> u32;
    /// Whether the reinsertion pass runs (see [`BuildOptions::reinsertion`]).
    fn reinsertion(self) -> bool;
}

impl BuildSettings for BuildOptions {
    #[inline(always)]
    fn builder(self) -> BuilderKind {
        self.builder
    }
    #[inline(always)]
    fn max_leaf_size(self) -> u32 {
        self.max_leaf_size
    }
    #[inline(always)]
    fn reinsertion(self) -> bool {
        self.reinsertion
    }
}

/// A split rule named as a type, for [`StaticBuild`].
pub trait SplitRule: Copy {
    /// The rule.
    const KIND: BuilderKind;
}

/// [`BuilderKind::Sah`] as a type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Sah;
/// [`BuilderKind::Median`] as a type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Median;
/// [`BuilderKind::Midpoint`] as a type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Midpoint;

impl SplitRule for Sah {
    const KIND: BuilderKind = BuilderKind::Sah;
}
impl SplitRule for Median {
    const KIND: BuilderKind = BuilderKind::Median;
}
impl SplitRule for Midpoint {
    const KIND: BuilderKind = BuilderKind::Midpoint;
}

/// Build settings fixed at compile time: the split rule `R`, the reinsertion pass if and only
/// if `REINSERT`; only the leaf size is a value. A build with `StaticBuild::<Sah, false>` links
/// the SAH builder and nothing of the other rules or the reinsertion pass. Gives the same tree
/// as the [`BuildOptions`] with the same three choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct StaticBuild<R: SplitRule, const REINSERT: bool> {
    /// As [`BuildOptions::max_leaf_size`].
    pub max_leaf_size: u32,
    rule: PhantomData<R>,
}

impl<R: SplitRule, const REINSERT: bool> StaticBuild<R, REINSERT> {
    /// The settings with leaves of up to `max_leaf_size` primitives.
    #[must_use]
    pub const fn new(max_leaf_size: u32) -> Self {
        Self {
            max_leaf_size,
            rule: PhantomData,
        }
    }
}

impl<R: SplitRule, const REINSERT: bool> Default for StaticBuild<R, REINSERT> {
    /// Leaves of up to [`DEFAULT_LEAF_SIZE`].
    fn default() -> Self {
        Self::new(DEFAULT_LEAF_SIZE)
    }
}

impl<R: SplitRule, const REINSERT: bool> BuildSettings for StaticBuild<R, REINSERT> {
    #[inline(always)]
    fn builder(self) -> BuilderKind {
        R::KIND
    }
    #[inline(always)]
    fn max_leaf_size(self) -> u32 {
        self.max_leaf_size
    }
    #[inline(always)]
    fn reinsertion(self) -> bool {
        REINSERT
    }
}

/// A built BVH, borrowing its nodes, primitive ids and primitives.
#[derive(Clone, Copy, Debug)]
pub struct Bvh<'a, S: Scalar, P: Primitive<S>> {
    nodes: &'a [Node<S>],
    prim_ids: &'a [u32],
    prims: &'a [P],
    depth: u32,
    /// `prims[i]` is the primitive with id `prim_ids[i]` (see [`Bvh::build_in_leaf_order`]);
    /// otherwise `prims` is in id order.
    leaf_order: bool,
    _scalar: PhantomData<S>,
}

impl<'a, S: Scalar, P: Primitive<S>> Bvh<'a, S, P> {
    /// Builds a BVH over `prims` into `nodes` (at least [`nodes_needed`]`(prims.len())` slots)
    /// and `prim_ids` (at least `prims.len()` slots). Single-threaded, allocation-free,
    /// deterministic: the same input gives the same tree on every platform.
    ///
    /// # Errors
    /// [`BuildError::ArenaTooSmall`] with exact sizes, [`BuildError::TooManyPrims`],
    /// [`BuildError::BadPrimitive`] for the first non-finite or out-of-range vertex, and
    /// [`BuildError::BadLeafSize`].
    pub fn build<B: BuildSettings>(
        prims: &'a [P],
        nodes: &'a mut [Node<S>],
        prim_ids: &'a mut [u32],
        options: B,
    ) -> Result<Self, BuildError> {
        let (node_count, depth) = build::build(prims, nodes, prim_ids, options)?;
        let nodes: &'a [Node<S>] = nodes;
        let prim_ids: &'a [u32] = prim_ids;
        Ok(Self {
            nodes: nodes.get(..node_count).unwrap_or_default(),
            prim_ids: prim_ids.get(..prims.len()).unwrap_or_default(),
            prims,
            depth,
            leaf_order: false,
            _scalar: PhantomData,
        })
    }

    /// As [`Bvh::build`], then permutes `prims` in place into leaf order, so each leaf's
    /// primitives are contiguous in memory: faster traversal, one indirection fewer.
    /// Afterwards `prims[i]` is the primitive whose original index is `prim_ids[i]`; hits still
    /// report original indices, and ties still go to the lowest original index.
    ///
    /// # Errors
    /// As [`Bvh::build`].
    pub fn build_in_leaf_order<B: BuildSettings>(
        prims: &'a mut [P],
        nodes: &'a mut [Node<S>],
        prim_ids: &'a mut [u32],
        options: B,
    ) -> Result<Self, BuildError>
    where
        P: Copy,
    {
        // Marks visited ids; free, as ids stay below `MAX_PRIMS`.
        const MARK: u32 = 1 << 31;
        const _: () = assert!(crate::accel::MAX_PRIMS < MARK as usize);
        let (node_count, depth) = build::build(prims, nodes, prim_ids, options)?;
        let available = prim_ids.len();
        let Some(ids) = prim_ids.get_mut(..prims.len()) else {
            // Unreachable: `build` checked the size.
            return Err(BuildError::ArenaTooSmall {
                arena: crate::accel::Arena::PrimIds,
                needed: prims.len(),
                available,
            });
        };
        // Apply the permutation cycle by cycle: slot j receives the primitive ids[j].
        // (`ids` is a permutation of `0..n` from the builder, so every `get` succeeds.)
        for start in 0..ids.len() {
            let (Some(&id), Some(&first)) = (ids.get(start), prims.get(start)) else {
                break;
            };
            if id & MARK != 0 {
                continue;
            }
            let mut j = start;
            while let Some(id) = ids.get_mut(j) {
                let k = *id as usize;
                *id |= MARK;
                let next = if k == start {
                    Some(first)
                } else {
                    prims.get(k).copied()
                };
                if let (Some(p), Some(slot)) = (next, prims.get_mut(j)) {
                    *slot = p;
                }
                if k == start {
                    break;
                }
                j = k;
            }
        }
        for id in ids.iter_mut() {
            *id &= !MARK;
        }
        let nodes: &'a [Node<S>] = nodes;
        let prim_ids: &'a [u32] = prim_ids;
        let prims: &'a [P] = prims;
        Ok(Self {
            nodes: nodes.get(..node_count).unwrap_or_default(),
            prim_ids: prim_ids.get(..prims.len()).unwrap_or_default(),
            prims,
            depth,
            leaf_order: true,
            _scalar: PhantomData,
        })
    }

    /// The primitive with original index `id`, if `prims` are still in id order (`None` after
    /// [`Bvh::build_in_leaf_order`]: look it up through [`Bvh::prim_ids`] instead).
    #[must_use]
    pub fn prim(&self, id: u32) -> Option<&'a P> {
        if self.leaf_order {
            None
        } else {
            self.prims.get(id as usize)
        }
    }

    /// True if the primitives were permuted into leaf order.
    #[must_use]
    pub fn is_leaf_order(&self) -> bool {
        self.leaf_order
    }

    /// The nodes in use (root first).
    #[must_use]
    pub fn nodes(&self) -> &'a [Node<S>] {
        self.nodes
    }
    /// Primitive ids in leaf order.
    #[must_use]
    pub fn prim_ids(&self) -> &'a [u32] {
        self.prim_ids
    }
    /// The primitives (in leaf order after [`Bvh::build_in_leaf_order`]).
    #[must_use]
    pub fn prims(&self) -> &'a [P] {
        self.prims
    }
    /// Depth of the deepest leaf (root = 0).
    #[must_use]
    pub fn depth(&self) -> u32 {
        self.depth
    }
    /// Bytes of nodes and primitive ids in use (excluding the primitives themselves).
    #[must_use]
    pub fn bytes_used(&self) -> usize {
        core::mem::size_of_val(self.nodes) + core::mem::size_of_val(self.prim_ids)
    }
}
