//! Refit of a wide tree: every slot box recomputed bottom-up after the primitives moved
//! (see the binary tree's refit for the rule).

use super::{ChildSlot, WideBvh, WideNode};
use crate::accel::bvh::{leaf_bounds, refit_nodes};
use crate::accel::bvh::{RefitError, TreeShape};
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;

impl<'a, S: Scalar, P: Primitive<S>, const W: usize> WideBvh<'a, S, P, W> {
    /// Node count, depth and primitive order: what [`WideBvh::refit`] needs to know.
    #[must_use]
    pub fn shape(&self) -> TreeShape {
        TreeShape {
            node_count: self.nodes.len(),
            depth: self.depth,
            leaf_order: self.leaf_order,
        }
    }

    /// Refits the wide tree in `nodes` (over `prim_ids`, as left by a collapse of `shape`) to
    /// `prims`, the same primitives with moved vertices, and returns it. `O(n)`, no allocation,
    /// no recursion.
    ///
    /// # Errors
    /// [`RefitError::BadPrimitive`] (nothing changed), [`RefitError::ShapeMismatch`].
    pub fn refit(
        prims: &'a [P],
        nodes: &'a mut [WideNode<S, W>],
        prim_ids: &'a [u32],
        shape: TreeShape,
    ) -> Result<Self, RefitError> {
        let nodes = refit_nodes(prims, nodes, prim_ids, shape)?;
        let count = nodes.len();
        let mismatch = |node| RefitError::ShapeMismatch { node };
        // Wide nodes are breadth-first, children after parents: refit in reverse.
        for i in (0..count).rev() {
            let node = nodes.get(i).copied().ok_or(mismatch(i))?;
            let mut out = node;
            for slot in 0..node.child_count() {
                let Some(ChildSlot { child, count: k }) = node.slot(slot) else {
                    continue;
                };
                let b = if k == 0 {
                    let c = child as usize;
                    let kid = nodes.get(c).filter(|_| c > i).ok_or(mismatch(i))?;
                    node_bounds(kid).ok_or(mismatch(c))?
                } else {
                    let leaf = (prim_ids, prims, shape.leaf_order);
                    leaf_bounds(leaf, (child as usize, k as usize)).ok_or(mismatch(i))?
                };
                out.set(slot, &b, child, k);
            }
            if let Some(n) = nodes.get_mut(i) {
                *n = out;
            }
        }
        let nodes: &'a [WideNode<S, W>] = nodes;
        Ok(Self::from_parts(
            nodes,
            prim_ids,
            prims,
            shape.depth,
            shape.leaf_order,
        ))
    }
}

/// The union of a node's used slot boxes (`None` for a node without any).
fn node_bounds<S: Scalar, const W: usize>(node: &WideNode<S, W>) -> Option<Aabb<S>> {
    (0..node.child_count())
        .filter_map(|s| node.bounds(s))
        .reduce(|a, b| a.union(&b))
}
