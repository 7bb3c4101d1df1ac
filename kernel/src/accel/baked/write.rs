//! Writing a built tree and its triangles as baked bytes (the host's `bake` command, tests).

use super::error::BakeError;
use super::format::{checksum, field, BakedKind, Layout, FLAG_LEAF_ORDER, MAGIC, VERSION};
use super::scalar::BakedScalar;
use crate::accel::bvh::Bvh;
use crate::accel::wide::Bvh4;
use crate::geom::Triangle;

/// Bytes of the baked file of a tree of `kind` with `node_count` nodes over `prim_count`
/// triangles; `None` beyond the format's `u32::MAX` bytes.
#[must_use]
pub fn baked_len(kind: BakedKind, node_count: usize, prim_count: usize) -> Option<usize> {
    let nodes = u32::try_from(node_count).ok()?;
    let prims = u32::try_from(prim_count).ok()?;
    Layout::of(kind, nodes, prims).map(|l| l.total)
}

/// Writes `bvh` (nodes, ids, triangles, leaf order included) into `out`; returns the bytes
/// written ([`baked_len`]).
///
/// # Errors
/// [`BakeError::Truncated`] if `out` is too small, [`BakeError::TooLarge`].
pub fn bake_bvh<S: BakedScalar>(
    bvh: &Bvh<'_, S, Triangle<S>>,
    out: &mut [u8],
) -> Result<usize, BakeError> {
    let nodes = bvh.nodes();
    let tree = Tree {
        kind: BakedKind::Bvh,
        node_count: nodes.len(),
        depth: bvh.depth(),
        leaf_order: bvh.is_leaf_order(),
        prim_ids: bvh.prim_ids(),
        prims: bvh.prims(),
    };
    write(&tree, out, |i, w| {
        let Some(n) = nodes.get(i) else { return };
        let lo = n.lo.map(S::to_word);
        let hi = n.hi.map(S::to_word);
        for (k, v) in lo
            .into_iter()
            .chain([n.first])
            .chain(hi)
            .chain([n.count])
            .enumerate()
        {
            w(k, v);
        }
    })
}

/// Writes `bvh4` (wide nodes, ids, triangles, leaf order included) into `out`; returns the
/// bytes written ([`baked_len`]).
///
/// # Errors
/// [`BakeError::Truncated`] if `out` is too small, [`BakeError::TooLarge`].
pub fn bake_bvh4<S: BakedScalar>(
    bvh4: &Bvh4<'_, S, Triangle<S>>,
    out: &mut [u8],
) -> Result<usize, BakeError> {
    let nodes = bvh4.nodes();
    let tree = Tree {
        kind: BakedKind::Bvh4,
        node_count: nodes.len(),
        depth: bvh4.depth(),
        leaf_order: bvh4.is_leaf_order(),
        prim_ids: bvh4.prim_ids(),
        prims: bvh4.prims(),
    };
    write(&tree, out, |i, w| {
        let Some(n) = nodes.get(i) else { return };
        let boxes =
            n.lo.iter()
                .chain(n.hi.iter())
                .flatten()
                .map(|&x| x.to_word());
        for (k, v) in boxes.chain(n.child).chain(n.count).enumerate() {
            w(k, v);
        }
    })
}

/// What both writers share: the header fields and the id and triangle sections.
struct Tree<'a, S: BakedScalar> {
    kind: BakedKind,
    node_count: usize,
    depth: u32,
    leaf_order: bool,
    prim_ids: &'a [u32],
    prims: &'a [Triangle<S>],
}

/// Writes the file: header, nodes (node `i`'s `k`-th word through `node_words(i, put)`),
/// ids, triangles, then the checksum.
fn write<S: BakedScalar>(
    tree: &Tree<'_, S>,
    out: &mut [u8],
    node_words: impl Fn(usize, &mut dyn FnMut(usize, u32)),
) -> Result<usize, BakeError> {
    let node_count = u32::try_from(tree.node_count).map_err(|_| BakeError::TooLarge)?;
    let prim_count = u32::try_from(tree.prims.len()).map_err(|_| BakeError::TooLarge)?;
    let layout = Layout::of(tree.kind, node_count, prim_count).ok_or(BakeError::TooLarge)?;
    let available = out.len();
    let Some(out) = out.get_mut(..layout.total) else {
        return Err(BakeError::Truncated {
            needed: layout.total,
            available,
        });
    };
    out.fill(0);
    let mut put = |at: usize, v: u32| {
        if let Some(dst) = out.get_mut(at..at + 4) {
            dst.copy_from_slice(&v.to_le_bytes());
        }
    };
    let flags = if tree.leaf_order { FLAG_LEAF_ORDER } else { 0 };
    let fields = [
        (field::VERSION, VERSION),
        (field::MODE, S::MODE as u32),
        (field::KIND, tree.kind as u32),
        (field::FLAGS, flags),
        (field::PRIM_COUNT, prim_count),
        (field::NODE_COUNT, node_count),
        (field::DEPTH, tree.depth),
        (field::NODES_OFFSET, layout.nodes as u32),
        (field::IDS_OFFSET, layout.ids as u32),
        (field::PRIMS_OFFSET, layout.prims as u32),
        (field::TOTAL_LEN, layout.total as u32),
    ];
    for (at, v) in fields {
        put(at, v);
    }
    let node_len = tree.kind.node_len();
    for i in 0..tree.node_count {
        let base = layout.nodes + i * node_len;
        node_words(i, &mut |k, v| put(base + 4 * k, v));
    }
    for (i, &id) in tree.prim_ids.iter().enumerate() {
        put(layout.ids + 4 * i, id);
    }
    for (i, t) in tree.prims.iter().enumerate() {
        let words = t.v.iter().flatten().map(|&x| x.to_word());
        for (k, v) in words.enumerate() {
            put(layout.prims + 36 * i + 4 * k, v);
        }
    }
    if let Some(magic) = out.get_mut(field::MAGIC..field::MAGIC + 8) {
        magic.copy_from_slice(&MAGIC);
    }
    let sum = checksum(out);
    if let Some(dst) = out.get_mut(field::CHECKSUM..field::CHECKSUM + 4) {
        dst.copy_from_slice(&sum.to_le_bytes());
    }
    Ok(layout.total)
}
