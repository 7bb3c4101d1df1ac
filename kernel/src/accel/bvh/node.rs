use crate::geom::Aabb;
use crate::scalar::Scalar;

/// One BVH node: 32 bytes in both modes.
///
/// Invariant: `count == 0` marks an inner node whose children are `first` and `first + 1`
/// (always after the node itself, `first` even); slot 1 of an arena is unused padding; otherwise a leaf covering `prim_ids[first..first + count]`.
/// Bounds are padded outward by the mode's traversal margin (`Numerics::pad_bounds`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Node<S: Scalar> {
    pub(crate) lo: [S; 3],
    pub(crate) first: u32,
    pub(crate) hi: [S; 3],
    pub(crate) count: u32,
}

const _: () = assert!(core::mem::size_of::<Node<f32>>() == 32);
const _: () = assert!(core::mem::size_of::<Node<crate::I16F16>>() == 32);

impl<S: Scalar> Node<S> {
    /// A placeholder to fill arenas with, e.g. `[Node::EMPTY; nodes_needed(N)]`.
    pub const EMPTY: Self = Self {
        lo: [S::ZERO; 3],
        first: 0,
        hi: [S::ZERO; 3],
        count: 0,
    };

    pub(crate) fn leaf(b: Aabb<S>, first: u32, count: u32) -> Self {
        Self {
            lo: b.lo,
            first,
            hi: b.hi,
            count,
        }
    }
    /// The node's box.
    #[must_use]
    pub fn bounds(&self) -> Aabb<S> {
        Aabb::new(self.lo, self.hi)
    }
    /// True for a leaf.
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
    /// Leaf: index of the first primitive id. Inner: index of the left child.
    #[must_use]
    pub fn first(&self) -> u32 {
        self.first
    }
    /// Leaf: number of primitives. Inner: 0.
    #[must_use]
    pub fn count(&self) -> u32 {
        self.count
    }
}
