//! Top-down builders writing into the caller's arena. Iterative: an explicit stack of pending
//! nodes replaces recursion. Split decisions use `f32` keys (centroids, areas) in both modes;
//! `f32` arithmetic is deterministic, so fixed-point trees are identical on every platform too.

use super::select::{select_nth, swap_in};
use super::{
    nodes_needed, BuildOptions, BuilderKind, Node, FIRST_PAIR, MAX_DEPTH, MAX_LEAF_SIZE,
    MEDIAN_FALLBACK_DEPTH,
};
use crate::error::{Arena, BuildError};
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;

/// Bins per axis for the SAH builder.
const BINS: usize = 32;
/// SAH cost of visiting a node, relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;

/// Builds into `nodes`/`ids`: the top-down split, the optional reinsertion pass, then bounds
/// padded for traversal. Returns (nodes used, depth of the deepest leaf).
pub(super) fn build<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    nodes: &mut [Node<S>],
    ids: &mut [u32],
    options: BuildOptions,
) -> Result<(usize, u32), BuildError> {
    let (used, mut deepest) = split_top_down(prims, nodes, ids, options)?;
    if options.reinsertion {
        let arena = nodes.get_mut(..nodes_needed(prims.len()));
        if let (Some(arena), Some(ids)) = (arena, ids.get_mut(..prims.len())) {
            if let Some(depth) = super::optimize::reinsert(arena, used, ids) {
                deepest = depth;
            }
        }
    }
    for node in nodes.iter_mut().take(used) {
        let (lo, hi) = S::pad_bounds(node.lo, node.hi);
        node.lo = lo;
        node.hi = hi;
    }
    Ok((used, deepest))
}

/// The top-down build into `nodes`/`ids`, bounds unpadded.
fn split_top_down<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    nodes: &mut [Node<S>],
    ids: &mut [u32],
    options: BuildOptions,
) -> Result<(usize, u32), BuildError> {
    let n = prims.len();
    if n >= u32::MAX as usize {
        return Err(BuildError::TooManyPrims { count: n });
    }
    if options.max_leaf_size == 0 || options.max_leaf_size > MAX_LEAF_SIZE {
        return Err(BuildError::BadLeafSize {
            max_leaf_size: options.max_leaf_size,
        });
    }
    let needed = nodes_needed(n);
    if nodes.len() < needed {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Nodes,
            needed,
            available: nodes.len(),
        });
    }
    if ids.len() < n {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::PrimIds,
            needed: n,
            available: ids.len(),
        });
    }
    for (prim, p) in prims.iter().enumerate() {
        p.check()
            .map_err(|(vertex, error)| BuildError::BadPrimitive {
                prim,
                vertex,
                error,
            })?;
    }
    if n == 0 {
        return Ok((0, 0));
    }
    let Some(ids) = ids.get_mut(..n) else {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::PrimIds,
            needed: n,
            available: ids.len(),
        });
    };
    for (slot, id) in ids.iter_mut().zip(0u32..) {
        *slot = id;
    }
    let builder = Builder {
        prims,
        max_leaf: options.max_leaf_size as usize,
        kind: options.builder,
        _scalar: core::marker::PhantomData,
    };
    // Bounds cache: while it is valid, slot `n + pos` of the arena holds the bounds and id of
    // the primitive at position `pos` (a one-primitive leaf), and the builder partitions these
    // slots instead of ids: sequential reads instead of recomputing scattered primitives.
    // Nodes are allocated left to right and every position left of the current node is
    // final, so the cache stays intact while `used + 2 <= n + first`; when a split would break
    // that, the ids are written back and the build goes on from the primitives themselves.
    // (Slices below are taken with `get`: the arena checks above make every range valid, and
    // the fallbacks, never taken, only keep panic paths out of the code.)
    let mut cached = false;
    if let (true, Some(cache)) = (n >= 2, nodes.get_mut(n..2 * n)) {
        for (pos, slot) in cache.iter_mut().enumerate() {
            let bounds = builder.prim(pos as u32);
            *slot = Node::leaf(bounds, pos as u32, 1);
        }
        cached = true;
    }
    let root = match (cached, nodes.get(n..2 * n)) {
        (true, Some(cache)) => builder.summarize(cache),
        _ => builder.summarize(ids),
    };
    let mut used = 1usize;
    match nodes {
        [root_slot, pad, ..] if n > 1 => {
            *root_slot = Node::leaf(root.bounds, 0, n as u32);
            *pad = Node::EMPTY;
            used = FIRST_PAIR;
        }
        [root_slot, ..] => *root_slot = Node::leaf(root.bounds, 0, n as u32),
        [] => return Ok((0, 0)),
    }
    let mut deepest = 0u32;
    // Pending nodes with their centroid bounds: at most one sibling per level plus the current.
    let mut stack = [Pending {
        index: 0,
        depth: 0,
        centroids: root.centroids,
    }; MAX_DEPTH + 2];
    let mut sp = 1usize;
    let mut bins = [[(empty_box::<S>(), 0u32); BINS]; 3];
    while sp > 0 {
        sp -= 1;
        let Some(&Pending {
            index,
            depth,
            centroids,
        }) = stack.get(sp)
        else {
            break;
        };
        let Some(&node) = nodes.get(index as usize) else {
            continue;
        };
        let (first, count) = (node.first as usize, node.count as usize);
        deepest = deepest.max(depth);
        if cached && used + 2 > n + first {
            let cache = nodes.get(n + first..2 * n).unwrap_or_default();
            for (id, slot) in ids.iter_mut().skip(first).zip(cache) {
                *id = slot.first;
            }
            cached = false;
        }
        let range = first..first + count;
        let split = match (cached, nodes.get_mut(n + first..n + first + count)) {
            (true, Some(slots)) => {
                let split = builder.split(slots, depth as usize, &centroids, &mut bins);
                if split.is_none() {
                    let leaf_ids = ids.get_mut(range).unwrap_or_default();
                    for (id, slot) in leaf_ids.iter_mut().zip(slots.iter()) {
                        *id = slot.first;
                    }
                }
                split
            }
            _ => match ids.get_mut(range) {
                Some(leaf_ids) => builder.split(leaf_ids, depth as usize, &centroids, &mut bins),
                None => None,
            },
        };
        let Some([left, right]) = split else {
            continue;
        };
        let l = used;
        let Some([a, b]) = nodes.get_mut(l..l + 2) else {
            continue;
        };
        *a = Node::leaf(left.bounds, first as u32, left.count as u32);
        *b = Node::leaf(
            right.bounds,
            (first + left.count) as u32,
            right.count as u32,
        );
        used += 2;
        if let Some(parent) = nodes.get_mut(index as usize) {
            *parent = Node {
                first: l as u32,
                count: 0,
                ..node
            };
        }
        // Right pushed first so the left subtree is built (and laid out) first.
        for (child, side) in [(l + 1, right), (l, left)] {
            if let Some(slot) = stack.get_mut(sp) {
                *slot = Pending {
                    index: child as u32,
                    depth: depth + 1,
                    centroids: side.centroids,
                };
                sp += 1;
            }
        }
    }
    Ok((used, deepest))
}

/// SAH bins per axis: box and primitive count.
type Bins<S> = [[(Aabb<S>, u32); BINS]; 3];

/// A node waiting to be split.
#[derive(Clone, Copy)]
struct Pending {
    index: u32,
    depth: u32,
    centroids: Centroids,
}

/// Per-axis (min, max) of the centroid keys of a set of primitives.
type Centroids = ([f32; 3], [f32; 3]);

/// What a split search knows about one side: its size, box and centroid bounds.
#[derive(Clone, Copy)]
struct Side<S: Scalar> {
    count: usize,
    bounds: Aabb<S>,
    centroids: Centroids,
}

impl<S: Scalar> Side<S> {
    fn empty() -> Self {
        Self {
            count: 0,
            bounds: empty_box(),
            centroids: ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        }
    }

    fn add(&mut self, b: &Aabb<S>) {
        self.count += 1;
        self.bounds = self.bounds.union(b);
        for axis in 0..3 {
            let c = key(b, axis);
            self.centroids.0[axis] = self.centroids.0[axis].min_of(c);
            self.centroids.1[axis] = self.centroids.1[axis].max_of(c);
        }
    }
}

struct Builder<'p, S, P> {
    prims: &'p [P],
    max_leaf: usize,
    kind: BuilderKind,
    _scalar: core::marker::PhantomData<S>,
}

/// Twice the centroid of a box along `axis`, as the `f32` key every split decision uses.
#[inline(always)]
fn key<S: Scalar>(b: &Aabb<S>, axis: usize) -> f32 {
    // `min(2)`: a no-op for the axes callers pass (folded away for constants) that shows the
    // compiler the bound where the axis comes through a closure.
    let axis = axis.min(2);
    b.lo[axis].to_f32() * 0.5 + b.hi[axis].to_f32() * 0.5
}

/// Half the surface area, in `f32`.
fn half_area<S: Scalar>(b: &Aabb<S>) -> f32 {
    let d: [f32; 3] = core::array::from_fn(|i| b.hi[i].to_f32() - b.lo[i].to_f32());
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

/// A box that any union replaces: `lo = FAR`, `hi = lowest`.
fn empty_box<S: Scalar>() -> Aabb<S> {
    Aabb::new([S::FAR; 3], [lowest::<S>(); 3])
}

/// The most negative value of the mode (`-inf` / `I16F16::MIN`).
fn lowest<S: Scalar>() -> S {
    S::from_f32_saturating(f32::NEG_INFINITY)
}

/// What the builder partitions: primitive ids, or cached (bounds, id) slots.
trait Slot<S: Scalar>: Copy {
    /// The primitive's id.
    fn id(&self) -> u32;
    /// The primitive's box, from the cache or recomputed.
    fn bounds<P: Primitive<S>>(&self, prims: &[P]) -> Aabb<S>;
}

impl<S: Scalar> Slot<S> for u32 {
    #[inline(always)]
    fn id(&self) -> u32 {
        *self
    }
    #[inline(always)]
    fn bounds<P: Primitive<S>>(&self, prims: &[P]) -> Aabb<S> {
        match prims.get(*self as usize) {
            Some(p) => p.bounds(),
            None => empty_box(),
        }
    }
}

impl<S: Scalar> Slot<S> for Node<S> {
    #[inline(always)]
    fn id(&self) -> u32 {
        self.first
    }
    #[inline(always)]
    fn bounds<P: Primitive<S>>(&self, _prims: &[P]) -> Aabb<S> {
        Aabb::new(self.lo, self.hi)
    }
}

impl<S: Scalar, P: Primitive<S>> Builder<'_, S, P> {
    fn prim(&self, id: u32) -> Aabb<S> {
        match self.prims.get(id as usize) {
            Some(p) => p.bounds(),
            None => empty_box(),
        }
    }

    /// Count, box and centroid bounds of `ids`.
    fn summarize<T: Slot<S>>(&self, ids: &[T]) -> Side<S> {
        let mut side = Side::empty();
        for id in ids {
            side.add(&id.bounds(self.prims));
        }
        side
    }

    /// Partitions `ids` by `left`, summarizing both sides on the way.
    fn partition_by<T: Slot<S>>(
        &self,
        ids: &mut [T],
        left: impl Fn(&Aabb<S>) -> bool,
    ) -> [Side<S>; 2] {
        let mut sides = [Side::empty(), Side::empty()];
        let (mut i, mut j) = (0, ids.len());
        while i < j {
            let Some(id) = ids.get(i) else { break };
            let b = id.bounds(self.prims);
            if left(&b) {
                sides[0].add(&b);
                i += 1;
            } else {
                sides[1].add(&b);
                j -= 1;
                swap_in(ids, i, j);
            }
        }
        sides
    }

    /// Decides whether and where to split `ids` (partitioning them); `None` makes a leaf.
    fn split<T: Slot<S>>(
        &self,
        ids: &mut [T],
        depth: usize,
        centroids: &Centroids,
        bins: &mut Bins<S>,
    ) -> Option<[Side<S>; 2]> {
        let count = ids.len();
        if count <= 1 {
            return None;
        }
        let (clo, chi) = centroids;
        let extent: [f32; 3] = core::array::from_fn(|i| chi[i] - clo[i]);
        let widest = if extent[0] >= extent[1] && extent[0] >= extent[2] {
            0
        } else if extent[1] >= extent[2] {
            1
        } else {
            2
        };
        let must_split = count > self.max_leaf;
        if depth >= MEDIAN_FALLBACK_DEPTH {
            return must_split.then(|| self.median(ids, widest));
        }
        match self.kind {
            BuilderKind::Median => must_split.then(|| self.median(ids, widest)),
            BuilderKind::Midpoint => must_split.then(|| {
                let mid = clo[widest] * 0.5 + chi[widest] * 0.5;
                let sides = self.partition_by(ids, |b| key(b, widest) < mid);
                if sides[0].count == 0 || sides[1].count == 0 {
                    self.median(ids, widest)
                } else {
                    sides
                }
            }),
            BuilderKind::Sah => match self.sah(ids, clo, &extent, bins) {
                Some(sides) => Some(sides),
                None => must_split.then(|| self.median(ids, widest)),
            },
        }
    }

    fn median<T: Slot<S>>(&self, ids: &mut [T], axis: usize) -> [Side<S>; 2] {
        let axis = axis.min(2);
        let mid = ids.len() / 2;
        select_nth(ids, mid, |id| (key(&id.bounds(self.prims), axis), id.id()));
        let (left, right) = ids.split_at(mid);
        [self.summarize(left), self.summarize(right)]
    }

    /// Binned SAH over all three axes. `None` when a leaf is cheaper (and allowed) or no axis
    /// separates the centroids.
    fn sah<T: Slot<S>>(
        &self,
        ids: &mut [T],
        clo: &[f32; 3],
        extent: &[f32; 3],
        bins: &mut Bins<S>,
    ) -> Option<[Side<S>; 2]> {
        let count = ids.len();
        // Small nodes use fewer bins: the same choices for less set-up work.
        let nb = count.clamp(4, BINS);
        for axis_bins in bins.iter_mut() {
            for bin in axis_bins.iter_mut().take(nb) {
                *bin = (empty_box(), 0);
            }
        }
        let scale: [f32; 3] = core::array::from_fn(|a| {
            let s = nb as f32 / extent[a];
            if extent[a] > 0.0 && s.is_finite() {
                s
            } else {
                0.0
            }
        });
        let bin_of = |c: f32, a: usize| -> usize {
            // Saturating cast (NaN -> 0), then clamped: always a valid bin.
            let b = ((c - clo[a]) * scale[a]) as i32;
            b.clamp(0, nb as i32 - 1) as usize
        };
        for id in ids.iter() {
            let b = id.bounds(self.prims);
            for (a, axis_bins) in bins.iter_mut().enumerate() {
                // `% BINS` is a no-op (bins < nb <= BINS) that shows the compiler the bound.
                let bin = &mut axis_bins[bin_of(key(&b, a), a) % BINS];
                bin.0 = bin.0.union(&b);
                bin.1 += 1;
            }
        }
        // Sweep each axis: cost(split after bin i) = A_left·N_left + A_right·N_right.
        let mut best: Option<(f32, usize, usize, Aabb<S>)> = None;
        for a in 0..3 {
            if scale[a] == 0.0 {
                continue;
            }
            let axis_bins = bins[a].get(..nb).unwrap_or_default();
            let mut right_cost = [0.0f32; BINS];
            let mut right = (empty_box::<S>(), 0u32);
            for (bin, rc) in axis_bins.iter().zip(right_cost.iter_mut()).skip(1).rev() {
                right.0 = right.0.union(&bin.0);
                right.1 += bin.1;
                *rc = if right.1 > 0 {
                    half_area(&right.0) * right.1 as f32
                } else {
                    0.0
                };
            }
            let mut left = (empty_box::<S>(), 0u32);
            let sweep = axis_bins.iter().zip(right_cost.iter().skip(1));
            for (i, (bin, rc)) in sweep.take(nb - 1).enumerate() {
                left.0 = left.0.union(&bin.0);
                left.1 += bin.1;
                if left.1 == 0 || left.1 as usize == count {
                    continue;
                }
                let cost = half_area(&left.0) * left.1 as f32 + rc;
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, a, i, left.0.union(&right.0)));
                }
            }
        }
        let (cost, axis, last_left_bin, parent) = best?;
        let axis = axis.min(2); // a no-op that shows the compiler the bound
        let parent_area = half_area(&parent);
        if count <= self.max_leaf
            && parent_area * count as f32 <= TRAVERSAL_COST * parent_area + cost
        {
            return None;
        }
        Some(self.partition_by(ids, |b| bin_of(key(b, axis), axis) <= last_left_bin))
    }
}
