//! A tree view over wide nodes that already exist (baked bytes, a refitted arena).

use super::{WideBvh, WideNode};
use crate::geom::Primitive;
use crate::scalar::Scalar;
use core::marker::PhantomData;

impl<'a, S: Scalar, P: Primitive<S>, const W: usize> WideBvh<'a, S, P, W> {
    /// The tree `nodes` (in use, root first), `prim_ids`, `prims` describe, unchecked: callers
    /// validate before querying (traversal stays memory-safe either way).
    pub(crate) fn from_parts(
        nodes: &'a [WideNode<S, W>],
        prim_ids: &'a [u32],
        prims: &'a [P],
        depth: u32,
        leaf_order: bool,
    ) -> Self {
        Self {
            nodes,
            prim_ids,
            prims,
            depth,
            leaf_order,
            _scalar: PhantomData,
        }
    }
}
