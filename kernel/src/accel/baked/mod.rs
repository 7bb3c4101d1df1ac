//! Baked trees: a BVH or 4-wide BVH built on the host, stored with its triangles as bytes
//! (`docs/BAKED_FORMAT.md`), and loaded on the device in place, without building.
//!
//! [`bake_bvh`] / [`bake_bvh4`] write a built tree; [`load_bvh`] / [`load_bvh4`] (or
//! [`Baked::load`] for either kind) check untrusted bytes completely and return the same
//! [`Bvh`] / [`Bvh4`] a build returns, borrowing the bytes: the same traversal, the same hits,
//! bit for bit, no RAM for the structure. The bytes must be aligned to the node alignment
//! ([`BakedKind::align`]: 32 for the binary tree, 128 for the 4-wide one; [`MAX_ALIGN`] fits
//! both), e.g. by `#[repr(align(128))]` around an `include_bytes!` array.

mod error;
mod format;
mod load;
mod plain;
mod scalar;
mod write;

pub use error::BakeError;
pub use format::{
    checksum, read_header, BakedKind, BakedMode, Header, FLAG_LEAF_ORDER, HEADER_LEN, MAGIC,
    MAX_ALIGN, TRIANGLE_LEN, VERSION,
};
pub use load::{load_bvh, load_bvh4};
pub use scalar::BakedScalar;
pub use write::{bake_bvh, bake_bvh4, baked_len};

use crate::accel::bvh::{Bvh, Node, RefitError, TreeShape};
use crate::accel::wide::{Bvh4, Node4};
use crate::accel::{Accel, AnyAccel, Counters, Nearest};
use crate::geom::{Barycentrics, Ray, Triangle};

/// A loaded baked tree of either kind.
#[derive(Clone, Copy, Debug)]
pub enum Baked<'a, S: BakedScalar> {
    /// A binary BVH.
    Bvh(Bvh<'a, S, Triangle<S>>),
    /// A 4-wide BVH.
    Bvh4(Bvh4<'a, S, Triangle<S>>),
}

impl<'a, S: BakedScalar> Baked<'a, S> {
    /// Loads whichever kind `bytes` holds ([`load_bvh`], [`load_bvh4`]).
    ///
    /// # Errors
    /// As the loaders; [`BakeError::WrongStructure`] for a file of the other mode.
    pub fn load(bytes: &'a [u8]) -> Result<Self, BakeError> {
        match read_header(bytes)?.kind {
            BakedKind::Bvh => load_bvh(bytes).map(Self::Bvh),
            BakedKind::Bvh4 => load_bvh4(bytes).map(Self::Bvh4),
        }
    }

    /// The tree inside `accel`, if it is one of the two kinds a baked file holds.
    #[must_use]
    pub fn from_any(accel: AnyAccel<'a, S, Triangle<S>>) -> Option<Self> {
        match accel {
            AnyAccel::Bvh(t) => Some(Self::Bvh(t)),
            AnyAccel::Bvh4(t) => Some(Self::Bvh4(t)),
            AnyAccel::Linear(_) | AnyAccel::Bvh8(_) | AnyAccel::Grid(_) | AnyAccel::KdTree(_) => {
                None
            }
        }
    }

    /// The length of this tree's baked file ([`baked_len`]); `None` if the format cannot
    /// hold it.
    #[must_use]
    pub fn baked_len(&self) -> Option<usize> {
        let nodes = match self {
            Self::Bvh(t) => t.nodes().len(),
            Self::Bvh4(t) => t.nodes().len(),
        };
        baked_len(self.kind(), nodes, self.prims().len())
    }

    /// Writes this tree into `out` ([`bake_bvh`], [`bake_bvh4`]); returns the bytes written.
    ///
    /// # Errors
    /// As the writers.
    pub fn bake(&self, out: &mut [u8]) -> Result<usize, BakeError> {
        match self {
            Self::Bvh(t) => bake_bvh(t, out),
            Self::Bvh4(t) => bake_bvh4(t, out),
        }
    }

    /// Which tree this is.
    #[must_use]
    pub const fn kind(&self) -> BakedKind {
        match self {
            Self::Bvh(_) => BakedKind::Bvh,
            Self::Bvh4(_) => BakedKind::Bvh4,
        }
    }

    /// The triangles, in the order the tree stores them (see [`Baked::is_leaf_order`]).
    #[must_use]
    pub fn prims(&self) -> &'a [Triangle<S>] {
        match self {
            Self::Bvh(t) => t.prims(),
            Self::Bvh4(t) => t.prims(),
        }
    }

    /// The caller-visible id of each stored triangle, slot by slot.
    #[must_use]
    pub fn prim_ids(&self) -> &'a [u32] {
        match self {
            Self::Bvh(t) => t.prim_ids(),
            Self::Bvh4(t) => t.prim_ids(),
        }
    }

    /// True if the triangles are stored in leaf order (slot `i` holds id `prim_ids()[i]`),
    /// false if they are in id order.
    #[must_use]
    pub fn is_leaf_order(&self) -> bool {
        match self {
            Self::Bvh(t) => t.is_leaf_order(),
            Self::Bvh4(t) => t.is_leaf_order(),
        }
    }

    /// What [`Baked::refit`] needs to know of the tree besides its memory.
    #[must_use]
    pub fn shape(&self) -> TreeShape {
        match self {
            Self::Bvh(t) => t.shape(),
            Self::Bvh4(t) => t.shape(),
        }
    }

    /// A tree of `kind` and `shape` refitted in place over moved `prims` ([`Bvh::refit`],
    /// [`Bvh4::refit`]): the binary tree's nodes are `nodes`, the 4-wide tree's `nodes4`; the
    /// arena of the other kind is not touched.
    ///
    /// # Errors
    /// As the tree's `refit`.
    pub fn refit(
        kind: BakedKind,
        prims: &'a [Triangle<S>],
        nodes: &'a mut [Node<S>],
        nodes4: &'a mut [Node4<S>],
        prim_ids: &'a [u32],
        shape: TreeShape,
    ) -> Result<Self, RefitError> {
        match kind {
            BakedKind::Bvh => Bvh::refit(prims, nodes, prim_ids, shape).map(Self::Bvh),
            BakedKind::Bvh4 => Bvh4::refit(prims, nodes4, prim_ids, shape).map(Self::Bvh4),
        }
    }
}

impl<S: BakedScalar> Accel<S> for Baked<'_, S> {
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        match self {
            Self::Bvh(t) => t.nearest_counted(ray, stats),
            Self::Bvh4(t) => t.nearest_counted(ray, stats),
        }
    }
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        match self {
            Self::Bvh(t) => t.occluded_counted(ray, stats),
            Self::Bvh4(t) => t.occluded_counted(ray, stats),
        }
    }
    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        match self {
            Self::Bvh(t) => t.barycentrics(ray, found),
            Self::Bvh4(t) => t.barycentrics(ray, found),
        }
    }
}
