//! Refit: after the caller moved the primitives (same primitives, same order), recompute every
//! box of an existing tree in place, bottom-up, instead of rebuilding.
//!
//! Leaves get the padded union of their primitives' boxes (as the builder computes them),
//! inner nodes the union of their children's boxes. The topology is kept, so queries stay
//! exact (the same hits as brute force on the moved primitives); only their cost grows when
//! the motion makes the old grouping a poor one.

use super::{Bvh, Node, FIRST_PAIR};
use crate::error::PointError;
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;
use core::fmt;

/// What a refit needs besides the arrays: the tree's node count, depth and primitive order
/// ([`Bvh::shape`], [`crate::Bvh4::shape`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TreeShape {
    /// Nodes in use.
    pub node_count: usize,
    /// The tree's recorded depth.
    pub depth: u32,
    /// The primitives are in leaf order.
    pub leaf_order: bool,
}

/// Why a refit refused.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum RefitError {
    /// A moved primitive is unusable (non-finite or out of range), as the builder checks.
    BadPrimitive {
        /// Index of the primitive in `prims`.
        index: usize,
        /// The vertex or field.
        vertex: usize,
        /// What is wrong.
        error: PointError,
    },
    /// The arrays do not hold a tree of this shape: too few nodes, ids and primitives of
    /// different counts, a child link not after its node or a leaf range out of bounds.
    /// Nothing was changed beyond the nodes after `node` (in index order).
    ShapeMismatch {
        /// The node where it was found.
        node: usize,
    },
}

impl fmt::Display for RefitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadPrimitive {
                index,
                vertex,
                error,
            } => write!(f, "refit: primitive {index}, vertex {vertex}: {error}"),
            Self::ShapeMismatch { node } => {
                write!(f, "refit: the arrays do not hold this tree (node {node})")
            }
        }
    }
}

impl core::error::Error for RefitError {}

/// Checks every primitive as the builder does.
pub(crate) fn check_prims<S: Scalar, P: Primitive<S>>(prims: &[P]) -> Result<(), RefitError> {
    for (index, p) in prims.iter().enumerate() {
        p.check().map_err(|e| RefitError::BadPrimitive {
            index,
            vertex: e.vertex,
            error: e.error,
        })?;
    }
    Ok(())
}

/// What both trees' refits check first: the primitives, and that `prim_ids` and the shape's
/// node count fit them. Returns the nodes in use.
pub(crate) fn refit_nodes<'n, S: Scalar, P: Primitive<S>, N>(
    prims: &[P],
    nodes: &'n mut [N],
    prim_ids: &[u32],
    shape: TreeShape,
) -> Result<&'n mut [N], RefitError> {
    check_prims(prims)?;
    let count = shape.node_count;
    if prim_ids.len() != prims.len() || (count == 0) != prims.is_empty() {
        return Err(RefitError::ShapeMismatch { node: 0 });
    }
    nodes
        .get_mut(..count)
        .ok_or(RefitError::ShapeMismatch { node: count })
}

/// The padded union of the boxes of the leaf `prim_ids[first..first + count]`'s primitives.
pub(crate) fn leaf_bounds<S: Scalar, P: Primitive<S>>(
    (prim_ids, prims, leaf_order): (&[u32], &[P], bool),
    (first, count): (usize, usize),
) -> Option<Aabb<S>> {
    let ids = prim_ids.get(first..first.checked_add(count)?)?;
    ids.first()?;
    // Grown in place from the empty box: `FAR.min_of(x)` and `LOWEST.max_of(x)` are `x`, so
    // the first union is the first box, bit for bit, and no box is copied.
    let mut lo = [S::FAR; 3];
    let mut hi = [S::LOWEST; 3];
    for (slot, &id) in (first..).zip(ids) {
        let b = prims
            .get(if leaf_order { slot } else { id as usize })?
            .bounds();
        for i in 0..3 {
            lo[i] = lo[i].min_of(b.lo[i]);
            hi[i] = hi[i].max_of(b.hi[i]);
        }
    }
    let (lo, hi) = S::pad_bounds(lo, hi);
    Some(Aabb { lo, hi })
}

impl<'a, S: Scalar, P: Primitive<S>> Bvh<'a, S, P> {
    /// Node count, depth and primitive order: what [`Bvh::refit`] needs to know.
    #[must_use]
    pub fn shape(&self) -> TreeShape {
        TreeShape {
            node_count: self.nodes.len(),
            depth: self.depth,
            leaf_order: self.leaf_order,
        }
    }

    /// Refits the tree in `nodes`/`prim_ids` (as left by a build of `shape`) to `prims`,
    /// which hold the same primitives as at the build (in leaf order if it was one) with
    /// moved vertices, and returns it. `O(n)`, no allocation, no recursion.
    ///
    /// # Errors
    /// [`RefitError::BadPrimitive`] (nothing changed), [`RefitError::ShapeMismatch`].
    pub fn refit(
        prims: &'a [P],
        nodes: &'a mut [Node<S>],
        prim_ids: &'a [u32],
        shape: TreeShape,
    ) -> Result<Self, RefitError> {
        let nodes = refit_nodes(prims, nodes, prim_ids, shape)?;
        let count = nodes.len();
        let mismatch = |node| RefitError::ShapeMismatch { node };
        // Children sit after their parent, so a reverse sweep sees them refitted first.
        for i in (0..count).rev() {
            if i == 1 && count > 1 {
                continue; // the padding slot
            }
            let node = nodes.get(i).copied().ok_or(mismatch(i))?;
            let b = if node.count > 0 {
                let range = (node.first as usize, node.count as usize);
                leaf_bounds((prim_ids, prims, shape.leaf_order), range).ok_or(mismatch(i))?
            } else {
                let l = node.first as usize;
                let pair = nodes.get(l..l + 2).filter(|_| l > i && l >= FIRST_PAIR);
                let [a, b] = pair.ok_or(mismatch(i))? else {
                    return Err(mismatch(i));
                };
                a.bounds().union(&b.bounds())
            };
            if let Some(n) = nodes.get_mut(i) {
                n.lo = b.lo;
                n.hi = b.hi;
            }
        }
        let nodes: &'a [Node<S>] = nodes;
        Ok(Self::from_parts(
            nodes,
            prim_ids,
            prims,
            shape.depth,
            shape.leaf_order,
        ))
    }
}
