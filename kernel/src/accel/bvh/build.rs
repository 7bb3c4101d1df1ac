//! Top-down builders writing into the caller's arena. Iterative: an explicit stack of pending
//! nodes replaces recursion. Split decisions use `f32` keys (centroids, areas) in both modes;
//! `f32` arithmetic is deterministic, so fixed-point trees are identical on every platform too.

use super::select::{partition, select_nth};
use super::{
    nodes_needed, BuildOptions, BuilderKind, Node, MAX_DEPTH, MAX_LEAF_SIZE, MEDIAN_FALLBACK_DEPTH,
};
use crate::error::{Arena, BuildError};
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;

/// Bins per axis for the SAH builder.
const BINS: usize = 32;
/// SAH cost of visiting a node, relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;

/// Builds into `nodes`/`ids`; returns (nodes used, depth of the deepest leaf).
pub(super) fn build<S: Scalar, P: Primitive<S>>(
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
    let ids = &mut ids[..n];
    for (slot, id) in ids.iter_mut().zip(0u32..) {
        *slot = id;
    }
    let builder = Builder {
        prims,
        max_leaf: options.max_leaf_size as usize,
        kind: options.builder,
        _scalar: core::marker::PhantomData,
    };
    nodes[0] = Node::leaf(builder.bounds(ids), 0, n as u32);
    let mut used = 1usize;
    let mut deepest = 0u32;
    // Pending nodes: at most one sibling per level plus the current one.
    let mut stack = [(0u32, 0u32); MAX_DEPTH + 2];
    let mut sp = 1usize;
    while sp > 0 {
        sp -= 1;
        let (index, depth) = stack[sp];
        let node = nodes[index as usize];
        let (first, count) = (node.first as usize, node.count as usize);
        deepest = deepest.max(depth);
        let Some(range) = ids.get_mut(first..first + count) else {
            continue;
        };
        let Some(split) = builder.split(range, depth as usize) else {
            continue;
        };
        let (left, right) = range.split_at(split.mid);
        let l = used;
        used += 2;
        nodes[l] = Node::leaf(
            split.left.unwrap_or_else(|| builder.bounds(left)),
            first as u32,
            split.mid as u32,
        );
        nodes[l + 1] = Node::leaf(
            split.right.unwrap_or_else(|| builder.bounds(right)),
            (first + split.mid) as u32,
            (count - split.mid) as u32,
        );
        nodes[index as usize] = Node {
            first: l as u32,
            count: 0,
            ..node
        };
        // Right pushed first so the left subtree is built (and laid out) first.
        for child in [l + 1, l] {
            if let Some(slot) = stack.get_mut(sp) {
                *slot = (child as u32, depth + 1);
                sp += 1;
            }
        }
    }
    for node in &mut nodes[..used] {
        let (lo, hi) = S::pad_bounds(node.lo, node.hi);
        node.lo = lo;
        node.hi = hi;
    }
    Ok((used, deepest))
}

/// A chosen split: ids are already partitioned so `ids[..mid]` go left.
/// Child bounds are filled in when the split search already knows them.
struct Split<S: Scalar> {
    mid: usize,
    left: Option<Aabb<S>>,
    right: Option<Aabb<S>>,
}

impl<S: Scalar> Split<S> {
    fn at(mid: usize) -> Self {
        Self {
            mid,
            left: None,
            right: None,
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

impl<S: Scalar, P: Primitive<S>> Builder<'_, S, P> {
    fn prim(&self, id: u32) -> Aabb<S> {
        match self.prims.get(id as usize) {
            Some(p) => p.bounds(),
            None => empty_box(),
        }
    }

    fn bounds(&self, ids: &[u32]) -> Aabb<S> {
        ids.iter()
            .fold(empty_box(), |acc, &id| acc.union(&self.prim(id)))
    }

    /// Centroid-key bounds of `ids`: (min, max) per axis.
    fn centroid_bounds(&self, ids: &[u32]) -> ([f32; 3], [f32; 3]) {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for &id in ids {
            let b = self.prim(id);
            for axis in 0..3 {
                let c = key(&b, axis);
                lo[axis] = lo[axis].min_of(c);
                hi[axis] = hi[axis].max_of(c);
            }
        }
        (lo, hi)
    }

    /// Decides whether and where to split `ids`; `None` makes a leaf.
    fn split(&self, ids: &mut [u32], depth: usize) -> Option<Split<S>> {
        let count = ids.len();
        if count <= 1 {
            return None;
        }
        let (clo, chi) = self.centroid_bounds(ids);
        let extent: [f32; 3] = core::array::from_fn(|i| chi[i] - clo[i]);
        let widest = if extent[0] >= extent[1] && extent[0] >= extent[2] {
            0
        } else if extent[1] >= extent[2] {
            1
        } else {
            2
        };
        if depth >= MEDIAN_FALLBACK_DEPTH {
            return (count > self.max_leaf).then(|| self.median(ids, widest));
        }
        match self.kind {
            BuilderKind::Median => (count > self.max_leaf).then(|| self.median(ids, widest)),
            BuilderKind::Midpoint => (count > self.max_leaf).then(|| {
                let mid = clo[widest] * 0.5 + chi[widest] * 0.5;
                let k = partition(ids, |id| key(&self.prim(id), widest) < mid);
                if k == 0 || k == count {
                    self.median(ids, widest)
                } else {
                    Split::at(k)
                }
            }),
            BuilderKind::Sah => match self.sah(ids, &clo, &extent) {
                Some(s) => Some(s),
                None => (count > self.max_leaf).then(|| self.median(ids, widest)),
            },
        }
    }

    fn median(&self, ids: &mut [u32], axis: usize) -> Split<S> {
        let mid = ids.len() / 2;
        select_nth(ids, mid, |id| key(&self.prim(id), axis));
        Split::at(mid)
    }

    /// Binned SAH over all three axes. `None` when a leaf is cheaper (and allowed) or no axis
    /// separates the centroids.
    fn sah(&self, ids: &mut [u32], clo: &[f32; 3], extent: &[f32; 3]) -> Option<Split<S>> {
        let count = ids.len();
        let mut bins = [[(empty_box::<S>(), 0u32); BINS]; 3];
        let scale: [f32; 3] = core::array::from_fn(|a| {
            let s = BINS as f32 / extent[a];
            if extent[a] > 0.0 && s.is_finite() {
                s
            } else {
                0.0
            }
        });
        let bin_of = |c: f32, a: usize| -> usize {
            let b = ((c - clo[a]) * scale[a]) as usize; // saturating cast, NaN -> 0
            if b < BINS {
                b
            } else {
                BINS - 1
            }
        };
        for &id in ids.iter() {
            let b = self.prim(id);
            for (a, axis_bins) in bins.iter_mut().enumerate() {
                let bin = &mut axis_bins[bin_of(key(&b, a), a)];
                bin.0 = bin.0.union(&b);
                bin.1 += 1;
            }
        }
        // Sweep each axis: cost(split after bin i) = A_left·N_left + A_right·N_right.
        let mut best: Option<(f32, usize, usize, Aabb<S>, Aabb<S>)> = None;
        for a in 0..3 {
            if scale[a] == 0.0 {
                continue;
            }
            let mut right_area = [0.0f32; BINS];
            let mut right_box = [empty_box::<S>(); BINS];
            let mut acc = (empty_box::<S>(), 0u32);
            for i in (1..BINS).rev() {
                acc.0 = acc.0.union(&bins[a][i].0);
                acc.1 += bins[a][i].1;
                right_area[i] = if acc.1 > 0 {
                    half_area(&acc.0) * acc.1 as f32
                } else {
                    0.0
                };
                right_box[i] = acc.0;
            }
            let mut left = (empty_box::<S>(), 0u32);
            for i in 0..BINS - 1 {
                left.0 = left.0.union(&bins[a][i].0);
                left.1 += bins[a][i].1;
                if left.1 == 0 || left.1 as usize == count {
                    continue;
                }
                let cost = half_area(&left.0) * left.1 as f32 + right_area[i + 1];
                if best.map_or(true, |b| cost < b.0) {
                    best = Some((cost, a, i, left.0, right_box[i + 1]));
                }
            }
        }
        let (cost, axis, last_left_bin, lbox, rbox) = best?;
        let parent_area = half_area(&lbox.union(&rbox));
        let split_cost = TRAVERSAL_COST * parent_area + cost;
        let leaf_cost = parent_area * count as f32;
        if count <= self.max_leaf && leaf_cost <= split_cost {
            return None;
        }
        let mid = partition(ids, |id| {
            bin_of(key(&self.prim(id), axis), axis) <= last_left_bin
        });
        Some(Split {
            mid,
            left: Some(lbox),
            right: Some(rbox),
        })
    }
}
