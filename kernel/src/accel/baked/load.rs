//! Loading baked bytes in place: checks, then a [`Bvh`] or [`Bvh4`] borrowing the bytes.

use super::error::BakeError;
use super::format::{read_header, BakedKind, Header, Layout};
use super::plain::{cast_slice, Plain};
use super::scalar::BakedScalar;
use crate::accel::bvh::{leaf_bounds, Bvh, Node, MAX_DEPTH};
use crate::accel::bvh4::{Bvh4, Node4};
use crate::geom::{Aabb, Primitive, Triangle};
use crate::scalar::Scalar;

/// Loads a baked binary BVH of mode `S` from `bytes` without copying: the returned tree's
/// nodes, ids and triangles are `bytes` itself. `bytes` must start at a multiple of 32 bytes
/// (see [`BakedKind::align`]).
///
/// Every field is checked (see [`read_header`]), every triangle, and the whole tree: links
/// only forward, every node reached once, leaves tiling the ids, ids a permutation, depth as
/// recorded and within [`MAX_DEPTH`], every leaf box holding its triangles padded by the
/// traversal margin. A tree that loads answers every query exactly as brute force over its
/// triangles does. Time `O(n)` plus the id check's `O(n²/8192)`; stack below 2 KB.
///
/// # Errors
/// The first problem found, as a [`BakeError`].
pub fn load_bvh<S: BakedScalar>(bytes: &[u8]) -> Result<Bvh<'_, S, Triangle<S>>, BakeError> {
    let (header, nodes, ids, prims) = sections::<S, Node<S>>(bytes, BakedKind::Bvh)?;
    let bvh = Bvh::from_parts(nodes, ids, prims, header.depth, header.leaf_order);
    bvh.validate()?;
    check_bvh_leaves(&bvh)?;
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
    check_bvh4_leaves(&bvh4)?;
    Ok(bvh4)
}

/// Header checks, then the three sections as slices, then every triangle checked.
#[allow(clippy::type_complexity)]
fn sections<S: BakedScalar, N: Plain>(
    bytes: &[u8],
    kind: BakedKind,
) -> Result<(Header, &[N], &[u32], &[Triangle<S>]), BakeError> {
    let header = read_header(bytes)?;
    if header.mode != S::MODE || header.kind != kind {
        return Err(BakeError::WrongStructure);
    }
    if cfg!(target_endian = "big") {
        return Err(BakeError::BigEndianTarget);
    }
    if (bytes.as_ptr() as usize) % kind.align() != 0 {
        return Err(BakeError::Misaligned {
            required: kind.align(),
        });
    }
    let layout = Layout::of(kind, header.node_count, header.prim_count);
    let (nodes, ids, prims) = layout
        .and_then(|l| {
            let nodes = cast_slice::<N>(bytes.get(l.nodes..l.ids)?)?;
            let ids = cast_slice::<u32>(bytes.get(l.ids..l.prims)?)?;
            let prims = cast_slice::<Triangle<S>>(bytes.get(l.prims..l.total)?)?;
            Some((nodes, ids, prims))
        })
        // Unreachable: `read_header` checked the layout, and the alignment is checked above.
        .ok_or(BakeError::Misaligned {
            required: kind.align(),
        })?;
    if let Some(index) = prims.iter().position(|t| t.check().is_err()) {
        return Err(BakeError::BadPrimitive {
            index: index as u32,
        });
    }
    Ok((header, nodes, ids, prims))
}

/// True if the box `lo`, `hi` holds the padded union of the boxes of the triangles of the
/// leaf `prim_ids[first..first + count]` (false if the range or an id is out of bounds).
fn leaf_holds<S: Scalar>(
    (lo, hi): ([S; 3], [S; 3]),
    leaf: (&[u32], &[Triangle<S>], bool),
    range: (usize, usize),
) -> bool {
    leaf_bounds(leaf, range).is_some_and(|b| Aabb::new(lo, hi).contains(&b))
}

/// Every reachable leaf of a validated binary tree holds its padded triangles.
fn check_bvh_leaves<S: Scalar>(bvh: &Bvh<'_, S, Triangle<S>>) -> Result<(), BakeError> {
    let nodes = bvh.nodes();
    let leaf = (bvh.prim_ids(), bvh.prims(), bvh.is_leaf_order());
    // Depth-first; `validate` bounded the depth, so two entries per level suffice.
    let mut stack = [0u32; MAX_DEPTH + 2];
    let mut sp = usize::from(!nodes.is_empty());
    while sp > 0 {
        sp -= 1;
        let index = stack.get(sp).copied().unwrap_or(0);
        let Some(node) = nodes.get(index as usize) else {
            return Err(BakeError::LeafTooSmall { node: index });
        };
        if node.is_leaf() {
            let range = (node.first as usize, node.count as usize);
            if !leaf_holds((node.lo, node.hi), leaf, range) {
                return Err(BakeError::LeafTooSmall { node: index });
            }
            continue;
        }
        for child in [node.first, node.first.saturating_add(1)] {
            let Some(top) = stack.get_mut(sp) else {
                return Err(BakeError::LeafTooSmall { node: index });
            };
            *top = child;
            sp += 1;
        }
    }
    Ok(())
}

/// Every leaf slot of a validated 4-wide tree (every node is reachable) holds its padded
/// triangles.
fn check_bvh4_leaves<S: Scalar>(bvh4: &Bvh4<'_, S, Triangle<S>>) -> Result<(), BakeError> {
    let leaf = (bvh4.prim_ids(), bvh4.prims(), bvh4.is_leaf_order());
    for (index, node) in bvh4.nodes().iter().enumerate() {
        for slot in 0..node.child_count() {
            let (Some(b), Some((first, count))) = (node.bounds(slot), node.slot(slot)) else {
                continue;
            };
            if count > 0 && !leaf_holds((b.lo, b.hi), leaf, (first as usize, count as usize)) {
                return Err(BakeError::LeafTooSmall { node: index as u32 });
            }
        }
    }
    Ok(())
}
