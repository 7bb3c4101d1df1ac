//! Top-down SAH build into the caller's slices (iterative), and the checker.

use super::{
    nodes_needed, refs_needed, InvalidKdTree, KdNode, KdOptions, KdStats, KdTree, MAX_DEPTH,
};
use crate::accel::{Arena, BuildError};
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;

/// Candidate planes per axis (bins of the node's extent).
const BINS: usize = 32;
/// SAH cost of a traversal step, relative to one primitive test.
const TRAVERSAL_COST: f32 = 2.0;
/// SAH cost of a primitive test.
const INTERSECT_COST: f32 = 1.5;
/// Discount on the split cost when one side is empty (cutting off empty space).
const EMPTY_BONUS: f32 = 0.2;
/// Most primitives the tree may hold: node and reference indices must fit 30 bits.
const MAX_PRIMS: usize = 1 << 28;

/// What the build produced.
pub(super) struct Built<S: Scalar> {
    pub(super) nodes: usize,
    pub(super) refs: usize,
    pub(super) depth: u32,
    pub(super) bounds: Aabb<S>,
}

/// A primitive's padded box: the box the slab test is guaranteed to accept for its hits.
#[inline(always)]
pub(super) fn padded<S: Scalar, P: Primitive<S>>(p: &P) -> Aabb<S> {
    let b = p.bounds();
    let (lo, hi) = S::pad_bounds(b.lo, b.hi);
    Aabb::new(lo, hi)
}

/// Which children a padded box goes to: `(below, above)`. A box ending exactly on the plane
/// stays on its side; the children's boxes share the plane, so together they always cover it.
#[inline(always)]
pub(super) fn sides<S: Scalar>(b: &Aabb<S>, axis: usize, plane: S) -> (bool, bool) {
    let a = axis.min(2);
    if b.hi[a] <= plane {
        (true, false)
    } else if b.lo[a] >= plane {
        (false, true)
    } else {
        (true, true)
    }
}

/// The depth limit for `n` primitives.
fn depth_limit(options: KdOptions, n: usize) -> u32 {
    if options.max_depth > 0 {
        return options.max_depth;
    }
    let log2 = (usize::BITS - n.leading_zeros()) as f32;
    ((8.0 + 1.3 * log2) as u32).min(MAX_DEPTH)
}

/// A node waiting to be split or made a leaf; its list is `refs[start..end]`.
#[derive(Clone, Copy)]
struct Pending<S: Scalar> {
    node: u32,
    depth: u32,
    lo: [S; 3],
    hi: [S; 3],
    start: usize,
    end: usize,
    /// References this subtree may add (its share of the reference budget's slack).
    ref_slack: usize,
    /// Nodes this subtree may add below this node.
    node_slack: usize,
}

pub(super) fn build<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    nodes: &mut [KdNode<S>],
    refs: &mut [u32],
    options: KdOptions,
) -> Result<Built<S>, BuildError> {
    let n = prims.len();
    if n > MAX_PRIMS {
        return Err(BuildError::TooManyPrims { count: n });
    }
    if options.max_depth > MAX_DEPTH {
        return Err(BuildError::BadMaxDepth {
            max_depth: options.max_depth,
        });
    }
    let node_budget = nodes_needed(n);
    let ref_budget = refs_needed(n);
    if nodes.len() < node_budget {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Nodes,
            needed: node_budget,
            available: nodes.len(),
        });
    }
    if refs.len() < ref_budget {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Refs,
            needed: ref_budget,
            available: refs.len(),
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
    let empty = Built {
        nodes: 0,
        refs: 0,
        depth: 0,
        bounds: Aabb::new([S::ZERO; 3], [S::ZERO; 3]),
    };
    let Some(first) = prims.first() else {
        return Ok(empty);
    };
    let mut bounds = padded(first);
    for p in prims {
        bounds = bounds.union(&padded(p));
    }
    let max_depth = depth_limit(options, n);
    // The root's list at the back of the budget.
    let (Some(nodes), Some(refs)) = (nodes.get_mut(..node_budget), refs.get_mut(..ref_budget))
    else {
        return Ok(empty);
    };
    let root_start = ref_budget - n;
    for (slot, id) in refs.iter_mut().skip(root_start).zip(0u32..) {
        *slot = id;
    }
    let mut stack = [Pending {
        node: 0,
        depth: 0,
        lo: bounds.lo,
        hi: bounds.hi,
        start: root_start,
        end: ref_budget,
        ref_slack: ref_budget - n,
        node_slack: node_budget - 1,
    }; MAX_DEPTH as usize + 2];
    let mut sp = 1usize;
    let mut used = 1usize;
    let mut front = 0usize;
    let mut deepest = 0u32;
    let builder = Builder { prims };
    while sp > 0 {
        sp -= 1;
        let Some(&job) = stack.get(sp) else {
            break;
        };
        deepest = deepest.max(job.depth);
        let count = job.end - job.start;
        let split =
            if count > 1 && job.depth < max_depth && job.node_slack >= 2 && used + 2 <= node_budget
            {
                refs.get(job.start..job.end)
                    .and_then(|list| builder.sah(list, &job.lo, &job.hi))
            } else {
                None
            };
        // Partition into [below only | both | above only]; split if the straddling
        // references fit between the finished leaves and this list.
        let mut made = None;
        if let (Some((axis, plane)), Some(list)) = (split, refs.get_mut(job.start..job.end)) {
            let (below, both) = builder.partition(list, axis, plane);
            let fits = both <= job.ref_slack && both <= job.start - front;
            if fits && (below + both < count || count - below < count) {
                made = Some((axis, plane, below, both));
            }
        }
        let Some((axis, plane, below, both)) = made else {
            // Leaf: move the list to the front.
            move_within(refs, job.start, job.end, front);
            if let Some(node) = nodes.get_mut(job.node as usize) {
                *node = KdNode::leaf(front as u32, count as u32);
            }
            front += count;
            continue;
        };
        // Duplicate the straddlers: [below | both] moves down by `both`, leaving a copy of
        // `both` in place for the upper child: [below | both] [both | above].
        let start = job.start - both;
        move_within(refs, job.start, job.start + below + both, start);
        let mid = job.start + below;
        let l = used;
        used += 2;
        if let Some(node) = nodes.get_mut(job.node as usize) {
            *node = KdNode::inner(axis, plane, l as u32);
        }
        // The subtree's remaining slack goes to the children in proportion to their lists,
        // so the budget is shared fairly rather than spent by whichever side is built first.
        let share = |slack: usize, part: usize, whole: usize| -> usize {
            if whole == 0 {
                0
            } else {
                (slack as u128 * part as u128 / whole as u128) as usize
            }
        };
        let (n_below, n_above) = (below + both, count - below);
        let refs_left = job.ref_slack - both;
        let nodes_left = job.node_slack - 2;
        let below_refs = share(refs_left, n_below, n_below + n_above);
        let below_nodes = share(nodes_left, n_below, n_below + n_above);
        let a = axis.min(2);
        let mut below_hi = job.hi;
        below_hi[a] = plane;
        let mut above_lo = job.lo;
        above_lo[a] = plane;
        let children = [
            Pending {
                node: l as u32 + 1,
                depth: job.depth + 1,
                lo: above_lo,
                hi: job.hi,
                start: mid,
                end: job.end,
                ref_slack: refs_left - below_refs,
                node_slack: nodes_left - below_nodes,
            },
            Pending {
                node: l as u32,
                depth: job.depth + 1,
                lo: job.lo,
                hi: below_hi,
                start,
                end: mid,
                ref_slack: below_refs,
                node_slack: below_nodes,
            },
        ];
        // Above pushed first: the lower child (whose list is lower in memory) is done next.
        for child in children {
            if let Some(slot) = stack.get_mut(sp) {
                *slot = child;
                sp += 1;
            }
        }
    }
    Ok(Built {
        nodes: used,
        refs: front,
        depth: deepest,
        bounds,
    })
}

/// Copies `v[from..to]` down to `v[dest..]` (`dest <= from`, so a forward copy is right even
/// when the ranges overlap). Element by element through `get`: callers pass proven ranges,
/// and this keeps `copy_within`'s panic path out of the code.
fn move_within(v: &mut [u32], from: usize, to: usize, dest: usize) {
    debug_assert!(dest <= from && from <= to && to <= v.len());
    for k in 0..to.saturating_sub(from) {
        if let Some(&x) = v.get(from + k) {
            if let Some(slot) = v.get_mut(dest + k) {
                *slot = x;
            }
        }
    }
}

struct Builder<'p, P> {
    prims: &'p [P],
}

/// Half the surface area of a box with these extents.
fn half_area(d: [f32; 3]) -> f32 {
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

impl<P> Builder<'_, P> {
    fn bounds<S: Scalar>(&self, id: u32) -> Aabb<S>
    where
        P: Primitive<S>,
    {
        match self.prims.get(id as usize) {
            Some(p) => padded(p),
            None => Aabb::new([S::ZERO; 3], [S::ZERO; 3]),
        }
    }

    /// Binned SAH over the three axes: the best plane strictly inside the node, if splitting
    /// is cheaper than a leaf.
    fn sah<S: Scalar>(&self, list: &[u32], lo: &[S; 3], hi: &[S; 3]) -> Option<(usize, S)>
    where
        P: Primitive<S>,
    {
        let count = list.len();
        let lo_f = lo.map(S::to_f32);
        let hi_f = hi.map(S::to_f32);
        let ext: [f32; 3] = core::array::from_fn(|a| hi_f[a] - lo_f[a]);
        let area = half_area(ext);
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        let leaf_cost = INTERSECT_COST * count as f32;
        let nb = (2 * count).clamp(4, BINS);
        let scale: [f32; 3] = core::array::from_fn(|a| {
            if ext[a] > 0.0 {
                nb as f32 / ext[a]
            } else {
                0.0
            }
        });
        let bin = |x: f32, a: usize| -> usize {
            let a = a.min(2);
            // Saturating cast (NaN -> 0), then clamped: always a valid bin.
            (((x - lo_f[a]) * scale[a]) as i64)
                .min(nb as i64 - 1)
                .max(0) as usize
        };
        // Per axis: primitives whose clipped box starts / ends in each bin.
        let mut starts = [[0u32; BINS]; 3];
        let mut ends = [[0u32; BINS]; 3];
        for &id in list {
            let b = self.bounds::<S>(id);
            for a in 0..3 {
                let x0 = b.lo[a].max_of(lo[a]).to_f32();
                let x1 = b.hi[a].min_of(hi[a]).to_f32();
                // `% BINS`: a no-op (bins < nb <= BINS) that shows the compiler the bound.
                starts[a][bin(x0, a) % BINS] += 1;
                ends[a][bin(x1, a) % BINS] += 1;
            }
        }
        let mut best: Option<(f32, usize, S)> = None;
        for a in 0..3 {
            if scale[a] == 0.0 {
                continue; // no extent (or NaN) on this axis
            }
            let (mut n_below, mut ended) = (0u32, 0u32);
            for b in 0..nb - 1 {
                n_below += starts[a][b % BINS];
                ended += ends[a][b % BINS];
                let n_above = count as u32 - ended;
                let pos = lo_f[a] + (b + 1) as f32 * (ext[a] / nb as f32);
                let mut d_below = ext;
                d_below[a] = pos - lo_f[a];
                let mut d_above = ext;
                d_above[a] = hi_f[a] - pos;
                let bonus = if n_below == 0 || n_above == 0 {
                    1.0 - EMPTY_BONUS
                } else {
                    1.0
                };
                let cost = TRAVERSAL_COST
                    + INTERSECT_COST
                        * bonus
                        * (half_area(d_below) * n_below as f32
                            + half_area(d_above) * n_above as f32)
                        / area;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    let plane = S::from_f32_saturating(pos);
                    if lo[a] < plane && plane < hi[a] {
                        best = Some((cost, a, plane));
                    }
                }
            }
        }
        let (cost, axis, plane) = best?;
        (cost < leaf_cost).then_some((axis, plane))
    }

    /// Reorders `list` into [below only | both | above only]; returns (below only, both).
    fn partition<S: Scalar>(&self, list: &mut [u32], axis: usize, plane: S) -> (usize, usize)
    where
        P: Primitive<S>,
    {
        // Dutch national flag: [0, lo) below, [lo, i) both, [hi, len) above.
        let (mut lo, mut i, mut hi) = (0usize, 0usize, list.len());
        while i < hi {
            let Some(&id) = list.get(i) else { break };
            match sides(&self.bounds::<S>(id), axis, plane) {
                (true, false) => {
                    if lo < list.len() && i < list.len() {
                        list.swap(lo, i);
                    }
                    lo += 1;
                    i += 1;
                }
                (false, true) => {
                    hi -= 1;
                    if hi < list.len() && i < list.len() {
                        list.swap(i, hi);
                    }
                }
                _ => i += 1,
            }
        }
        (lo, i - lo)
    }
}

pub(super) fn validate<S: Scalar, P: Primitive<S>>(
    tree: &KdTree<'_, S, P>,
) -> Result<KdStats, InvalidKdTree> {
    let mut stats = KdStats {
        node_count: tree.nodes.len(),
        ref_count: tree.refs.len(),
        ..KdStats::default()
    };
    if tree.nodes.is_empty() {
        return if tree.prims.is_empty() && tree.refs.is_empty() {
            Ok(stats)
        } else {
            Err(InvalidKdTree::BadLeaf { node: 0 })
        };
    }
    // Structure: children after parents and in range, leaves in range, depth.
    let mut stack = [(0usize, 0usize); MAX_DEPTH as usize + 2];
    let mut sp = 1usize;
    while sp > 0 {
        sp -= 1;
        let Some(&(index, depth)) = stack.get(sp) else {
            return Err(InvalidKdTree::TooDeep { depth: sp });
        };
        if depth > MAX_DEPTH as usize {
            return Err(InvalidKdTree::TooDeep { depth });
        }
        stats.depth = stats.depth.max(depth);
        let Some(node) = tree.nodes.get(index) else {
            return Err(InvalidKdTree::BadChild { node: index });
        };
        if node.is_leaf() {
            let (first, count) = (node.first() as usize, node.count as usize);
            let Some(list) = tree.refs.get(first..first + count) else {
                return Err(InvalidKdTree::BadLeaf { node: index });
            };
            if list.iter().any(|&id| id as usize >= tree.prims.len()) {
                return Err(InvalidKdTree::BadLeaf { node: index });
            }
            stats.leaf_count += 1;
            stats.empty_leaves += usize::from(count == 0);
            stats.max_leaf_size = stats.max_leaf_size.max(node.count);
            continue;
        }
        let l = node.first() as usize;
        if l <= index || l + 1 >= tree.nodes.len() {
            return Err(InvalidKdTree::BadChild { node: index });
        }
        for child in [l + 1, l] {
            let Some(slot) = stack.get_mut(sp) else {
                return Err(InvalidKdTree::TooDeep { depth: depth + 1 });
            };
            *slot = (child, depth + 1);
            sp += 1;
        }
    }
    if stats.depth != tree.depth as usize {
        return Err(InvalidKdTree::TooDeep { depth: stats.depth });
    }
    // Coverage: every primitive is listed in every leaf the side rule sends its padded box to.
    for (id, p) in (0u32..).zip(tree.prims) {
        let b = padded(p);
        if !tree.bounds.contains(&b) {
            return Err(InvalidKdTree::MissingPrim { prim: id, node: 0 });
        }
        let mut sp = 1usize;
        stack[0] = (0, 0);
        while sp > 0 {
            sp -= 1;
            let Some(&(index, _)) = stack.get(sp) else {
                break;
            };
            let Some(node) = tree.nodes.get(index) else {
                return Err(InvalidKdTree::BadChild { node: index });
            };
            if node.is_leaf() {
                let (first, count) = (node.first() as usize, node.count as usize);
                let list = tree.refs.get(first..first + count).unwrap_or_default();
                if !list.contains(&id) {
                    return Err(InvalidKdTree::MissingPrim {
                        prim: id,
                        node: index,
                    });
                }
                continue;
            }
            let l = node.first() as usize;
            let (below, above) = sides(&b, node.axis(), node.split);
            for (go, child) in [(above, l + 1), (below, l)] {
                if go {
                    let Some(slot) = stack.get_mut(sp) else {
                        return Err(InvalidKdTree::TooDeep { depth: sp });
                    };
                    *slot = (child, 0);
                    sp += 1;
                }
            }
        }
    }
    Ok(stats)
}
