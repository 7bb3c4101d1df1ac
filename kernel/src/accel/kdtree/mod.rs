//! Kd-tree (axis-aligned binary space partition) over caller-provided memory.
//!
//! Each inner node cuts its box by one axis-aligned plane; a primitive goes to every child its
//! *padded* box (`Numerics::pad_bounds`) reaches past the plane (a box ending exactly on the
//! plane stays on its side), so the leaves listing a primitive always cover its padded box.
//! Splits are chosen by a binned surface area heuristic (32 candidate planes per axis, the
//! primitives' padded boxes clipped to the node; cost `C_trav + C_isect · (1 - bonus) ·
//! (A_l·N_l + A_r·N_r) / A`, with a bonus for cutting off empty space, against `C_isect · N`
//! for a leaf). Build and traversal are iterative (explicit stacks).
//!
//! **Depth.** At most `max_depth` levels below the root ([`KdOptions::max_depth`]; 0 picks
//! `8 + 1.3·log2(n)`, the usual rule), never more than [`MAX_DEPTH`], the traversal stack's
//! capacity, so the stack cannot overflow.
//!
//! **Memory bound (by construction).** The tree never uses more than [`nodes_needed`]`(n)`
//! nodes and [`refs_needed`]`(n)` primitive references: every pending node carries a share of
//! what is left of both budgets (the root gets all of it; a split spends two nodes and one
//! reference per primitive straddling the plane, and divides the rest between the children in
//! proportion to their primitive counts, so one side cannot starve the other), and a node whose
//! split does not fit its share becomes a leaf. The references live in one slice: finished
//! leaves' lists grow from the front, lists still to be split sit at the back in stack order,
//! and a split only moves one list down by the number of straddling primitives; so the peak
//! use equals the final use and no scratch memory is needed. [`KdTree::build`] fails with
//! [`crate::BuildError::ArenaTooSmall`] if a slice is shorter than its budget; what a tree
//! actually uses is [`KdTree::bytes_used`].
//!
//! **Traversal** tests both children's boxes with the conservative slab test, descends into the
//! nearer, stacks the farther with its entry distance, and pops only entries within
//! `widen(best t)`. Because sibling boxes share the split plane exactly, if the slab test
//! accepts a box it accepts one of the two halves (per axis the halves' intervals overlap and
//! cover the whole's), so by induction a hit of primitive `q` at `t` is always in a leaf that
//! is visited with entry at most `widen(t)`: results equal brute force bit for bit. A small
//! mailbox (as in [`crate::grid`]) avoids retesting a primitive listed in several leaves.

mod build;
mod traverse;

use crate::accel::BuildError;
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;
use core::marker::PhantomData;

/// Deepest level a leaf may sit at (root = 0); also the traversal stack's capacity.
pub const MAX_DEPTH: u32 = 40;
/// References reserved per primitive by [`refs_needed`]: the duplication budget.
pub const REFS_PER_PRIM: usize = 6;
/// Nodes reserved per primitive by [`nodes_needed`].
pub const NODES_PER_PRIM: usize = 4;

/// Node slots the builder may use for `prim_count` primitives: `4n + 1` (0 for none).
#[must_use]
pub const fn nodes_needed(prim_count: usize) -> usize {
    if prim_count == 0 {
        0
    } else {
        prim_count.saturating_mul(NODES_PER_PRIM).saturating_add(1)
    }
}

/// Reference slots the builder may use for `prim_count` primitives: `6n`.
#[must_use]
pub const fn refs_needed(prim_count: usize) -> usize {
    prim_count.saturating_mul(REFS_PER_PRIM)
}

/// Build settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct KdOptions {
    /// Depth limit, at most [`MAX_DEPTH`]; 0 means `min(MAX_DEPTH, 8 + 1.3·log2(n))`.
    pub max_depth: u32,
}

impl KdOptions {
    /// The defaults: the automatic depth rule.
    pub const DEFAULT: Self = Self { max_depth: 0 };
}

/// One kd-tree node: 12 bytes in both modes.
///
/// Invariant: the low two bits of `word` are the split axis (0..3) of an inner node, whose
/// children are `word >> 2` (below the plane) and `(word >> 2) + 1` (above), always after the
/// node; or 3 for a leaf covering `refs[word >> 2..][..count]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct KdNode<S: Scalar> {
    split: S,
    word: u32,
    count: u32,
}

const _: () = assert!(core::mem::size_of::<KdNode<f32>>() == 12);
const _: () = assert!(core::mem::size_of::<KdNode<crate::I16F16>>() == 12);

const LEAF: u32 = 3;

impl<S: Scalar> KdNode<S> {
    /// A placeholder to fill arenas with.
    pub const EMPTY: Self = Self {
        split: S::ZERO,
        word: LEAF,
        count: 0,
    };

    fn leaf(first: u32, count: u32) -> Self {
        Self {
            split: S::ZERO,
            word: (first << 2) | LEAF,
            count,
        }
    }
    fn inner(axis: usize, split: S, first_child: u32) -> Self {
        Self {
            split,
            word: (first_child << 2) | (axis.min(2) as u32),
            count: 0,
        }
    }
    /// True for a leaf.
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.word & 3 == LEAF
    }
    /// Inner: split axis (0..3). Leaf: 3.
    #[must_use]
    pub fn axis(&self) -> usize {
        (self.word & 3) as usize
    }
    /// Inner: the split plane's coordinate.
    #[must_use]
    pub fn split(&self) -> S {
        self.split
    }
    /// Inner: index of the lower child (the upper one follows it). Leaf: first reference.
    #[must_use]
    pub fn first(&self) -> u32 {
        self.word >> 2
    }
    /// Leaf: number of references. Inner: 0.
    #[must_use]
    pub fn count(&self) -> u32 {
        self.count
    }
}

/// A built kd-tree, borrowing its nodes, references and primitives.
#[derive(Clone, Copy, Debug)]
pub struct KdTree<'a, S: Scalar, P: Primitive<S>> {
    nodes: &'a [KdNode<S>],
    refs: &'a [u32],
    prims: &'a [P],
    bounds: Aabb<S>,
    depth: u32,
    _scalar: PhantomData<S>,
}

impl<'a, S: Scalar, P: Primitive<S>> KdTree<'a, S, P> {
    /// Builds a kd-tree over `prims` into `nodes` (at least [`nodes_needed`]`(n)` slots) and
    /// `refs` (at least [`refs_needed`]`(n)`). Single-threaded, allocation-free, deterministic.
    ///
    /// # Errors
    /// [`BuildError::ArenaTooSmall`] with the exact budgets, [`BuildError::TooManyPrims`]
    /// (above [`crate::MAX_PRIMS`]), [`BuildError::BadPrimitive`]
    /// and [`BuildError::BadMaxDepth`].
    pub fn build(
        prims: &'a [P],
        nodes: &'a mut [KdNode<S>],
        refs: &'a mut [u32],
        options: KdOptions,
    ) -> Result<Self, BuildError> {
        let built = build::build(prims, nodes, refs, options)?;
        let nodes: &'a [KdNode<S>] = nodes;
        let refs: &'a [u32] = refs;
        Ok(Self {
            nodes: nodes.get(..built.nodes).unwrap_or_default(),
            refs: refs.get(..built.refs).unwrap_or_default(),
            prims,
            bounds: built.bounds,
            depth: built.depth,
            _scalar: PhantomData,
        })
    }

    /// The nodes in use (root first).
    #[must_use]
    pub fn nodes(&self) -> &'a [KdNode<S>] {
        self.nodes
    }
    /// The references in use, leaf by leaf.
    #[must_use]
    pub fn refs(&self) -> &'a [u32] {
        self.refs
    }
    /// The primitives.
    #[must_use]
    pub fn prims(&self) -> &'a [P] {
        self.prims
    }
    /// The root's box (the union of the primitives' padded boxes).
    #[must_use]
    pub fn bounds(&self) -> Aabb<S> {
        self.bounds
    }
    /// Depth of the deepest leaf (root = 0).
    #[must_use]
    pub fn depth(&self) -> u32 {
        self.depth
    }
    /// Bytes of nodes and references in use (excluding the primitives).
    #[must_use]
    pub fn bytes_used(&self) -> usize {
        core::mem::size_of_val(self.nodes) + core::mem::size_of_val(self.refs)
    }

    /// Checks every invariant: children after their parent and in range, leaves' ranges in
    /// the reference slice, ids in range, depth within the cap, and every primitive listed in
    /// every leaf its padded box reaches (following the builder's side rule), so the leaves
    /// listing it cover that box.
    ///
    /// # Errors
    /// The first violation found.
    pub fn validate(&self) -> Result<KdStats, InvalidKdTree> {
        build::validate(self)
    }
}

/// Shape of a valid kd-tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KdStats {
    /// Nodes in use.
    pub node_count: usize,
    /// Leaves.
    pub leaf_count: usize,
    /// Leaves listing nothing.
    pub empty_leaves: usize,
    /// References (sum of the leaves' list lengths).
    pub ref_count: usize,
    /// Depth of the deepest leaf (root = 0).
    pub depth: usize,
    /// Largest leaf.
    pub max_leaf_size: u32,
}

/// The first violated invariant found by [`KdTree::validate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum InvalidKdTree {
    /// An inner node's children are out of range or not after it.
    BadChild {
        /// The node.
        node: usize,
    },
    /// A leaf's range is outside the reference slice, or lists an id out of range.
    BadLeaf {
        /// The leaf.
        node: usize,
    },
    /// A primitive is missing from a leaf its padded box reaches.
    MissingPrim {
        /// The primitive.
        prim: u32,
        /// The leaf.
        node: usize,
    },
    /// A leaf is deeper than the cap, or the recorded depth is wrong.
    TooDeep {
        /// The depth found.
        depth: usize,
    },
}

impl core::fmt::Display for InvalidKdTree {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "invalid kd-tree: {self:?}")
    }
}

impl core::error::Error for InvalidKdTree {}
