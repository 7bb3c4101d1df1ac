//! Loading baked bytes in place: checks, then a [`Bvh`] or [`Bvh4`] borrowing the bytes.

use super::error::BakeError;
use super::format::{checked_header, BakedKind, Header};
use super::plain::{cast_section, Plain};
use super::scalar::BakedScalar;
use crate::accel::bvh::{Bvh, Node};
use crate::accel::wide::{Bvh4, Node4};
use crate::geom::{Primitive, Triangle};

/// Loads a baked binary BVH of mode `S` from `bytes` without copying: the returned tree's
/// nodes, ids and triangles are `bytes` itself. `bytes` must start at a multiple of 32 bytes
/// (see [`BakedKind::align`]).
///
/// Every field is checked (see [`super::read_header`]), every triangle, and the whole tree: links
/// only forward, every node reached once, leaves tiling the ids, ids a permutation, depth as
/// recorded and within [`crate::bvh::MAX_DEPTH`], every leaf box holding its triangles padded by the
/// traversal margin ([`Bvh::validate`]). A tree that loads answers every query exactly as brute force over its
/// triangles does. Time `O(n)` plus the id check's `O(n²/8192)`; stack below 2 KB.
///
/// # Errors
/// The first problem found, as a [`BakeError`].
pub fn load_bvh<S: BakedScalar>(bytes: &[u8]) -> Result<Bvh<'_, S, Triangle<S>>, BakeError> {
    let (header, nodes, ids, prims) = sections::<S, Node<S>>(bytes, BakedKind::Bvh)?;
    let bvh = Bvh::from_parts(nodes, ids, prims, header.depth, header.leaf_order);
    bvh.validate()?;
    Ok(bvh)
}

/// Loads a baked 4-wide BVH of mode `S` from `bytes` without copying, as [`load_bvh`] does;
/// `bytes` must start at a multiple of 128 bytes.
///
/// # Errors
/// The first problem found, as a [`BakeError`].
pub fn load_bvh4<S: BakedScalar>(bytes: &[u8]) -> Result<Bvh4<'_, S, Triangle<S>>, BakeError> {
    let (header, nodes, ids, prims) = sections::<S, Node4<S>>(bytes, BakedKind::Bvh4)?;
    let bvh4 = Bvh4::from_parts(nodes, ids, prims, header.depth, header.leaf_order);
    bvh4.validate()?;
    Ok(bvh4)
}

/// Header checks, then the three sections as slices, then every triangle checked.
#[allow(clippy::type_complexity)]
fn sections<S: BakedScalar, N: Plain>(
    bytes: &[u8],
    kind: BakedKind,
) -> Result<(Header, &[N], &[u32], &[Triangle<S>]), BakeError> {
    let (header, layout) = checked_header(bytes, Some((S::MODE, kind)))?;
    if cfg!(target_endian = "big") {
        return Err(BakeError::BigEndianTarget);
    }
    let misaligned = BakeError::Misaligned {
        required: kind.align(),
    };
    if (bytes.as_ptr() as usize) % kind.align() != 0 {
        return Err(misaligned);
    }
    // Cannot fail: `checked_header` checked the layout against the length, and the alignment
    // is checked above.
    let (nodes, prims) = (header.node_count as usize, header.prim_count as usize);
    let nodes = cast_section::<N>(bytes, layout.nodes, nodes).ok_or(misaligned)?;
    let ids = cast_section::<u32>(bytes, layout.ids, prims).ok_or(misaligned)?;
    let prims = cast_section::<Triangle<S>>(bytes, layout.prims, prims).ok_or(misaligned)?;
    for (index, t) in (0u32..).zip(prims) {
        if t.check().is_err() {
            return Err(BakeError::BadPrimitive { index });
        }
    }
    Ok((header, nodes, ids, prims))
}
