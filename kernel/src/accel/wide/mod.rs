//! Wide BVHs, 4-wide ([`Bvh4`]) and 8-wide ([`Bvh8`]), collapsed from a built binary [`Bvh`],
//! over caller-provided memory.
//!
//! Each [`WideNode`] holds the boxes of up to four (eight) children side by side, so traversal
//! tests them at once (one vector lane per child, `Numerics::slab4`, twice for eight children
//! or once in 256-bit lanes where the CPU has AVX) and visits the hit children nearest first
//! (any hit: in slot order, see the walks).
//!
//! The collapse chooses which BVH2 nodes become wide nodes and which small subtrees become
//! leaves (of at most as many primitives as the BVH2's largest leaf) by minimising the surface
//! area heuristic over every such choice, by dynamic programming (Ylitie, Karras and Laine
//! 2017); its cost table takes `W - 1` scratch words per BVH2 node slot
//! ([`collapse_words_needed`]). Should that tree not fit the node arena, whose bound
//! ([`wide_nodes_needed`]) is proved for the greedy collapse, the greedy one is made instead: a
//! wide node starts from a BVH2 inner node's two children and repeatedly opens the inner child
//! with the largest surface area until it has four (eight) children or none is inner (Wald et
//! al. 2008, "Getting rid of packets"). Leaves reference `prim_ids` ranges of the BVH2 (a
//! subtree's leaves cover one range), so a wide tree borrows the primitive ids and primitives
//! of the [`Bvh`] it came from (leaf order included). The BVH2 node arena and the scratch
//! words are only build scratch: once collapsed, queries read the wide node arena, the ids and
//! the primitives.
//!
//! [`WideBvh::collapse`] is iterative: wide nodes are laid out breadth-first and the arena
//! itself is the work queue (a node still to fill holds its BVH2 source). Every box is a BVH2
//! node's box bit for bit, and every query returns exactly what [`Bvh`] and
//! [`crate::Linear`] return.

mod collapse;
mod node;
#[cfg(target_arch = "x86_64")]
mod order;
mod parts;
mod refit;
mod traverse;
mod traverse8;
mod validate;

pub use node::{ChildSlot, Node4, Node8, WideNode};

use crate::accel::bvh::{nodes_needed, Bvh};
use crate::accel::BuildError;
use crate::geom::Primitive;
use crate::scalar::Scalar;
use core::marker::PhantomData;

/// Node slots [`WideBvh::collapse`] needs in the worst case for a `width`-wide tree over
/// `prim_count` primitives: 0 for none, 1 for up to `width`, otherwise
/// `max(width·a + 1, n - c - (c - 1)·a)` with `c = width - 1` and `a = ⌊(n - 2) / 2c⌋`: about
/// `width·n / 2c`, `2n/3` for width 4 and `4n/7` for width 8 (leaves of one primitive).
///
/// Proof. Each wide node stems from a distinct BVH2 inner node, and a wide node with fewer
/// than `width` children has only leaf children (opening stops early only when no inner child
/// is left). Let `F` nodes be full and `M` not (two or more leaves each), `N = F + M`, with
/// `L <= n` leaves. Children that are nodes number `N - 1`, all in the `F` full nodes, so
/// `N - 1 <= width·F`, i.e. `M <= c·F + 1`; and `L >= 2M + (width·F - (N - 1)) = M + c·F + 1`.
/// Maximising `F + M` under `M <= c·F + 1` and `M <= L - 1 - c·F` gives the formula (the
/// optimum is at `F = a` or `F = a + 1`), which grows with `L`, so `L = n` bounds it. The bound
/// is reached, e.g. for width 4 by a perfect binary tree of 8 leaves (5 wide nodes).
#[must_use]
pub const fn wide_nodes_needed(prim_count: usize, width: usize) -> usize {
    let c = width.saturating_sub(1);
    match prim_count {
        0 => 0,
        n if n <= width || c < 2 => 1,
        n => {
            let a = (n - 2) / (2 * c);
            let full_first = width * a + 1;
            let small_first = n - c - (c - 1) * a;
            if full_first > small_first {
                full_first
            } else {
                small_first
            }
        }
    }
}

/// Scratch words [`WideBvh::collapse`] needs for a `width`-wide tree from a BVH over
/// `prim_count` primitives: `width - 1` per BVH node slot ([`crate::bvh::nodes_needed`]).
#[must_use]
pub const fn collapse_words_needed(prim_count: usize, width: usize) -> usize {
    width.saturating_sub(1) * nodes_needed(prim_count)
}

/// [`wide_nodes_needed`] for the 4-wide BVH.
#[must_use]
pub const fn nodes4_needed(prim_count: usize) -> usize {
    wide_nodes_needed(prim_count, 4)
}

/// [`wide_nodes_needed`] for the 8-wide BVH.
#[must_use]
pub const fn nodes8_needed(prim_count: usize) -> usize {
    wide_nodes_needed(prim_count, 8)
}

/// A `W`-wide BVH, borrowing its nodes and the primitive ids and primitives of the [`Bvh`] it
/// was collapsed from.
#[derive(Clone, Copy, Debug)]
pub struct WideBvh<'a, S: Scalar, P: Primitive<S>, const W: usize> {
    nodes: &'a [WideNode<S, W>],
    prim_ids: &'a [u32],
    prims: &'a [P],
    /// Depth of the deepest wide node (root = 0); at most that of the BVH2's deepest inner
    /// node, so below [`crate::bvh::MAX_DEPTH`].
    depth: u32,
    /// As [`Bvh::is_leaf_order`]: `prims[i]` is the primitive with id `prim_ids[i]`.
    leaf_order: bool,
    _scalar: PhantomData<S>,
}

/// The 4-wide BVH.
pub type Bvh4<'a, S, P> = WideBvh<'a, S, P, 4>;
/// The 8-wide BVH.
pub type Bvh8<'a, S, P> = WideBvh<'a, S, P, 8>;

impl<'a, S: Scalar, P: Primitive<S>, const W: usize> WideBvh<'a, S, P, W> {
    /// Collapses `bvh` into `nodes` (at least [`wide_nodes_needed`]`(bvh.prims().len(), W)`
    /// slots), with `scratch` for the cost table (at least `W - 1` words per slot of
    /// [`Bvh::nodes`], which [`collapse_words_needed`] bounds; its contents are overwritten).
    /// Allocation-free, no recursion, deterministic.
    ///
    /// # Errors
    /// [`BuildError::ArenaTooSmall`] with the exact bound: arena [`crate::Arena::Nodes`] or
    /// [`crate::Arena::Scratch`].
    pub fn collapse(
        bvh: &Bvh<'a, S, P>,
        nodes: &'a mut [WideNode<S, W>],
        scratch: &mut [u32],
    ) -> Result<Self, BuildError> {
        let (count, depth) = collapse::collapse(bvh.nodes(), nodes, scratch, bvh.prims().len())?;
        let nodes: &'a [WideNode<S, W>] = nodes;
        Ok(Self {
            nodes: nodes.get(..count).unwrap_or_default(),
            prim_ids: bvh.prim_ids(),
            prims: bvh.prims(),
            depth,
            leaf_order: bvh.is_leaf_order(),
            _scalar: PhantomData,
        })
    }

    /// The nodes in use (root first, breadth-first order).
    #[must_use]
    pub fn nodes(&self) -> &'a [WideNode<S, W>] {
        self.nodes
    }
    /// Primitive ids in leaf order (the source BVH's).
    #[must_use]
    pub fn prim_ids(&self) -> &'a [u32] {
        self.prim_ids
    }
    /// The primitives (in leaf order if the source BVH was built in leaf order).
    #[must_use]
    pub fn prims(&self) -> &'a [P] {
        self.prims
    }
    /// True if the primitives are in leaf order.
    #[must_use]
    pub fn is_leaf_order(&self) -> bool {
        self.leaf_order
    }
    /// Depth of the deepest wide node (root = 0).
    #[must_use]
    pub fn depth(&self) -> u32 {
        self.depth
    }
    /// Bytes a query reads besides the primitives: the wide nodes in use and the primitive
    /// ids (the BVH2 node arena it was collapsed from is not needed after the collapse).
    #[must_use]
    pub fn bytes_used(&self) -> usize {
        core::mem::size_of_val(self.nodes) + core::mem::size_of_val(self.prim_ids)
    }
}
