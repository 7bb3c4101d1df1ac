//! Top-down builders writing into the caller's arena. Iterative: an explicit stack of pending
//! nodes replaces recursion. Split decisions use `f32` keys (centroids, areas) in both modes;
//! `f32` arithmetic is deterministic, so fixed-point trees are identical on every platform too.

use super::select::{select_nth, swap_in};
use super::{
    nodes_needed, BuildSettings, BuilderKind, Node, FIRST_PAIR, MAX_DEPTH, MAX_LEAF_SIZE,
    MEDIAN_FALLBACK_DEPTH,
};
use crate::accel::{check_count, check_each, Arena, BuildError};
use crate::geom::{Aabb, Primitive};
use crate::scalar::lanes::F4;
use crate::scalar::Scalar;

/// Bins per axis for the SAH builder.
const BINS: usize = 32;
/// SAH cost of visiting a node, relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;

/// Builds into `nodes`/`ids`: the top-down split, the optional reinsertion pass, then bounds
/// padded for traversal. Returns (nodes used, depth of the deepest leaf).
pub(super) fn build<S: Scalar, P: Primitive<S>, B: BuildSettings>(
    prims: &[P],
    nodes: &mut [Node<S>],
    ids: &mut [u32],
    options: B,
) -> Result<(usize, u32), BuildError> {
    let (used, mut deepest) = split_top_down(prims, nodes, ids, options)?;
    if options.reinsertion() {
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
fn split_top_down<S: Scalar, P: Primitive<S>, B: BuildSettings>(
    prims: &[P],
    nodes: &mut [Node<S>],
    ids: &mut [u32],
    options: B,
) -> Result<(usize, u32), BuildError> {
    let n = prims.len();
    check_count(n)?;
    let max_leaf_size = options.max_leaf_size();
    if max_leaf_size == 0 || max_leaf_size > MAX_LEAF_SIZE {
        return Err(BuildError::BadLeafSize { max_leaf_size });
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
    check_each(prims)?;
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
        max_leaf: max_leaf_size as usize,
        settings: options,
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
            *root_slot = Node::leaf(root.bounds(), 0, n as u32);
            *pad = Node::EMPTY;
            used = FIRST_PAIR;
        }
        [root_slot, ..] => *root_slot = Node::leaf(root.bounds(), 0, n as u32),
        [] => return Ok((0, 0)),
    }
    let mut deepest = 0u32;
    // Pending nodes with their centroid bounds: at most one sibling per level plus the current.
    let mut stack = [Pending {
        index: 0,
        depth: 0,
        centroids: root.centroids(),
    }; MAX_DEPTH + 2];
    let mut sp = 1usize;
    // Zeroed (in place), then emptied bin by bin: an array of `Bin::empty()` was built in a
    // temporary and copied, 3.5 KB more stack on the M0.
    let zero = Bin {
        lo: [S::ZERO; 4],
        hi: [S::ZERO; 4],
    };
    let mut boxes = [[zero; BINS]; 3];
    for bin in boxes.iter_mut().flatten() {
        *bin = Bin::empty();
    }
    let mut counts = [[0u32; BINS]; 3];
    let mut bins = Bins {
        boxes: &mut boxes,
        counts: &mut counts,
    };
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
        *a = Node::leaf(left.bounds(), first as u32, left.count as u32);
        *b = Node::leaf(
            right.bounds(),
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
                    centroids: side.centroids(),
                };
                sp += 1;
            }
        }
    }
    Ok((used, deepest))
}

/// One SAH bin's box, as four lanes per corner (lane 3 repeats lane 2) so that a union is
/// two vector min/max operations.
#[derive(Clone, Copy)]
struct Bin<S> {
    lo: [S; 4],
    hi: [S; 4],
}

impl<S: Scalar> Bin<S> {
    /// The empty bin: any union replaces it.
    fn empty() -> Self {
        Self {
            lo: [S::FAR; 4],
            hi: [lowest::<S>(); 4],
        }
    }

    /// Grows the bin to hold the box with corners `lo`, `hi` (four lanes each).
    #[inline(always)]
    fn grow(&mut self, lo: &[S; 4], hi: &[S; 4]) {
        for k in 0..4 {
            self.lo[k] = self.lo[k].min_of(lo[k]);
            self.hi[k] = self.hi[k].max_of(hi[k]);
        }
    }

    /// Half the surface area, in `f32`.
    #[inline(always)]
    fn half_area(&self) -> f32 {
        super::half_area(&self.lo, &self.hi)
    }
}

/// SAH bins per axis: boxes and primitive counts. Every bin is empty between splits:
/// [`Builder::sah`] fills bins, [`sweep`] empties the ones it filled.
struct Bins<'a, S> {
    boxes: &'a mut [[Bin<S>; BINS]; 3],
    counts: &'a mut [[u32; BINS]; 3],
}

/// A corner as four lanes, lane 3 repeating lane 2.
#[inline(always)]
fn lanes<S: Scalar>(v: &[S; 3]) -> [S; 4] {
    [v[0], v[1], v[2], v[2]]
}

/// The [`key`]s of a box on every axis, from its corners as four lanes.
#[inline(always)]
fn centroid<S: Scalar>(lo: &[S; 4], hi: &[S; 4]) -> F4 {
    let half = F4::splat(0.5);
    let (lo, hi) = (F4::new(lo.map(S::to_f32)), F4::new(hi.map(S::to_f32)));
    lo.mul(half).add(hi.mul(half))
}

/// A node waiting to be split.
#[derive(Clone, Copy)]
struct Pending {
    index: u32,
    depth: u32,
    centroids: Centroids,
}

/// Per-axis (min, max) of the centroid keys of a set of primitives.
type Centroids = ([f32; 3], [f32; 3]);

/// What a split search knows about one side: its size, box and centroid bounds (as four
/// lanes, lane 3 repeating lane 2).
#[derive(Clone, Copy)]
struct Side<S: Scalar> {
    count: usize,
    bin: Bin<S>,
    centroid_lo: F4,
    centroid_hi: F4,
}

impl<S: Scalar> Side<S> {
    fn empty() -> Self {
        Self {
            count: 0,
            bin: Bin::empty(),
            centroid_lo: F4::splat(f32::INFINITY),
            centroid_hi: F4::splat(f32::NEG_INFINITY),
        }
    }

    /// Adds a box: a union, and the min/max of its [`key`]s, in lanes.
    #[inline(always)]
    fn add(&mut self, b: &Aabb<S>) {
        self.count += 1;
        let (lo, hi) = (lanes(&b.lo), lanes(&b.hi));
        self.bin.grow(&lo, &hi);
        let c = centroid(&lo, &hi);
        self.centroid_lo = self.centroid_lo.min(c);
        self.centroid_hi = self.centroid_hi.max(c);
    }

    fn bounds(&self) -> Aabb<S> {
        let (lo, hi) = (&self.bin.lo, &self.bin.hi);
        Aabb::new([lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]])
    }

    fn centroids(&self) -> Centroids {
        let (lo, hi) = (self.centroid_lo.to_array(), self.centroid_hi.to_array());
        ([lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]])
    }
}

struct Builder<'p, S, P, B> {
    prims: &'p [P],
    max_leaf: usize,
    /// Read for the split rule only: a constant for a [`super::StaticBuild`].
    settings: B,
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
    /// True if the slot keeps a tag (the SAH bins of its primitive).
    const TAGGED: bool;
    /// The tag last set (0 if the slot keeps none).
    fn tag(&self) -> u32;
    /// Sets the tag (a no-op if the slot keeps none).
    fn set_tag(&mut self, tag: u32);
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
    const TAGGED: bool = false;
    #[inline(always)]
    fn tag(&self) -> u32 {
        0
    }
    #[inline(always)]
    fn set_tag(&mut self, _tag: u32) {}
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
    // A cache slot's `count` is otherwise unused.
    const TAGGED: bool = true;
    #[inline(always)]
    fn tag(&self) -> u32 {
        self.count
    }
    #[inline(always)]
    fn set_tag(&mut self, tag: u32) {
        self.count = tag;
    }
}

impl<S: Scalar, P: Primitive<S>, B: BuildSettings> Builder<'_, S, P, B> {
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
        left: impl Fn(&T, &Aabb<S>) -> bool,
    ) -> [Side<S>; 2] {
        let mut sides = [Side::empty(), Side::empty()];
        let (mut i, mut j) = (0, ids.len());
        while i < j {
            let Some(id) = ids.get(i) else { break };
            let b = id.bounds(self.prims);
            if left(id, &b) {
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
        bins: &mut Bins<'_, S>,
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
        match self.settings.builder() {
            BuilderKind::Median => must_split.then(|| self.median(ids, widest)),
            BuilderKind::Midpoint => must_split.then(|| {
                let mid = clo[widest] * 0.5 + chi[widest] * 0.5;
                let sides = self.partition_by(ids, |_, b| key(b, widest) < mid);
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
        bins: &mut Bins<'_, S>,
    ) -> Option<[Side<S>; 2]> {
        let count = ids.len();
        // Small nodes use fewer bins: the same choices for less set-up work.
        let nb = count.clamp(4, BINS);
        let scale: [f32; 3] = core::array::from_fn(|a| {
            let s = nb as f32 / extent[a];
            if extent[a] > 0.0 && s.is_finite() {
                s
            } else {
                0.0
            }
        });
        if let [p, q] = ids {
            let pair = [p.bounds(self.prims), q.bounds(self.prims)];
            let axis = self.sah_pair(pair, &scale)?.min(2); // `min`: shows the bound
            return Some(self.partition_by(ids, |_, b| key(b, axis) <= clo[axis]));
        }
        // Bin each primitive on all three axes, remembering its bins in the slot's tag (when it
        // keeps one) for the partition below.
        let (origin, scale4) = (F4::new(lanes(clo)), F4::new(lanes(&scale)));
        let top = (nb - 1) as f32;
        for id in ids.iter_mut() {
            let b = id.bounds(self.prims);
            let (lo, hi) = (lanes(&b.lo), lanes(&b.hi));
            let bin = centroid(&lo, &hi)
                .sub(origin)
                .mul(scale4)
                .clamped_trunc(top);
            // Each bin is below `nb <= 32`: five bits per axis.
            id.set_tag(bin[0] | bin[1] << 5 | bin[2] << 10);
            for ((boxes, counts), bin) in bins.boxes.iter_mut().zip(bins.counts.iter_mut()).zip(bin)
            {
                // `% BINS` is a no-op (bins < nb <= BINS) that shows the compiler the bound.
                let bin = bin as usize % BINS;
                boxes[bin].grow(&lo, &hi);
                counts[bin] += 1;
            }
        }
        let (cost, axis, last_left_bin, parent_area) = sweep(bins, nb, &scale)?;
        if count <= self.max_leaf
            && parent_area * count as f32 <= TRAVERSAL_COST * parent_area + cost
        {
            return None;
        }
        let axis = axis.min(2); // a no-op that shows the compiler the bound
        let (shift, origin, scale) = (5 * axis, clo[axis], scale[axis]);
        Some(self.partition_by(ids, |id, b| {
            let bin = if T::TAGGED {
                (id.tag() >> shift) as usize & 31
            } else {
                F4::splat((key(b, axis) - origin) * scale).clamped_trunc(top)[0] as usize
            };
            bin <= last_left_bin
        }))
    }
}

impl<S: Scalar, P: Primitive<S>, B: BuildSettings> Builder<'_, S, P, B> {
    /// [`Builder::sah`] for two primitives with boxes `p`, `q`: the axis to split on, or `None`
    /// for a leaf (or no axis separating the centroids).
    ///
    /// The binned sweep reduces to this: on an axis that separates the two centroids, the lower
    /// one is the minimum (bin 0) and the upper one lies `extent` above it, which scales to
    /// within a few ulps of 4 (bin `nb - 1 = 3`). So each such axis has one candidate,
    /// `{lower} | {upper}`, of cost `half_area(p)·1 + half_area(q)·1` in either order, and the
    /// first such axis wins the tie. The parent's area is that of the union.
    fn sah_pair(&self, [p, q]: [Aabb<S>; 2], scale: &[f32; 3]) -> Option<usize> {
        let axis = (0..3).find(|&a| scale[a] != 0.0)?;
        let (mut p_bin, mut q_bin) = (Bin::<S>::empty(), Bin::<S>::empty());
        p_bin.grow(&lanes(&p.lo), &lanes(&p.hi));
        q_bin.grow(&lanes(&q.lo), &lanes(&q.hi));
        let cost = p_bin.half_area() * 1.0 + q_bin.half_area() * 1.0;
        let mut parent = p_bin;
        parent.grow(&q_bin.lo, &q_bin.hi);
        let parent_area = parent.half_area();
        if 2 <= self.max_leaf && parent_area * 2.0 <= TRAVERSAL_COST * parent_area + cost {
            return None;
        }
        Some(axis)
    }
}

/// Best SAH split over the bins (filled by [`Builder::sah`]): (cost, axis, last bin of the
/// left side, half area of the parent). Leaves every bin empty again.
///
/// Only occupied bins are visited: at an empty bin the left side's box and count and the right
/// side's cost are those of the occupied bin before it, so its cost ties and never wins (ties
/// keep the first), just as in a sweep over every bin.
#[inline(never)]
fn sweep<S: Scalar>(
    bins: &mut Bins<'_, S>,
    nb: usize,
    scale: &[f32; 3],
) -> Option<(f32, usize, usize, f32)> {
    let mut best: Option<(f32, usize, usize)> = None;
    let mut parent_area = 0.0;
    // Written (right to left) at each occupied bin but the first before it is read.
    let mut right_cost = [0.0f32; BINS];
    for (a, (boxes, counts)) in bins
        .boxes
        .iter_mut()
        .zip(bins.counts.iter_mut())
        .enumerate()
    {
        let mut occupied = 0u32;
        for (k, &n) in counts.iter().enumerate().take(nb) {
            occupied |= u32::from(n != 0) << k;
        }
        if scale[a] != 0.0 {
            // Right to left: cost of the right side starting at each occupied bin but the
            // first.
            let (mut right, mut right_count) = (Bin::<S>::empty(), 0u32);
            let mut rest = occupied & !1;
            while rest != 0 {
                let k = (31 - rest.leading_zeros()) as usize % BINS;
                rest &= !(1 << k);
                right.grow(&boxes[k].lo, &boxes[k].hi);
                right_count += counts[k];
                right_cost[k] = right.half_area() * right_count as f32;
            }
            // Left to right: split after each occupied bin but the last (whose left side holds
            // everything); the right side starts at the next occupied bin.
            let (mut left, mut left_count) = (Bin::<S>::empty(), 0u32);
            let mut rest = occupied;
            while rest != 0 {
                let i = rest.trailing_zeros() as usize % BINS;
                rest &= rest - 1;
                left.grow(&boxes[i].lo, &boxes[i].hi);
                left_count += counts[i];
                if rest != 0 {
                    let next = rest.trailing_zeros() as usize % BINS;
                    let cost = left.half_area() * left_count as f32 + right_cost[next];
                    if best.is_none_or(|b| cost < b.0) {
                        best = Some((cost, a, i));
                    }
                }
            }
            // `left` now holds every bin: the parent's box, whose area (the order of a union's
            // operands does not change it) goes with the best split found so far.
            if best.is_some_and(|b| b.1 == a) {
                parent_area = left.half_area();
            }
        }
        let mut rest = occupied;
        while rest != 0 {
            let k = rest.trailing_zeros() as usize % BINS;
            rest &= rest - 1;
            boxes[k] = Bin::empty();
            counts[k] = 0;
        }
    }
    best.map(|(cost, axis, bin)| (cost, axis, bin, parent_area))
}

#[cfg(test)]
mod tests {
    use crate::scalar::lanes::F4;

    /// The bin of `f` as the builder first computed it.
    fn bin_reference(f: f32, top: i32) -> u32 {
        (f as i32).clamp(0, top) as u32
    }

    #[test]
    fn bins_are_the_saturating_cast_clamped() {
        let special = [
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            f32::MAX,
            f32::MIN,
            2_147_483_648.0,
            -2_147_483_904.0,
            12_582_912.0,
            4_194_304.5,
        ];
        let near_whole = (0..=40).flat_map(|i| {
            let x = i as f32;
            let (up, down) = (f32::from_bits(x.to_bits() + 1), x - x * f32::EPSILON);
            [x, -x, x - 0.5, x + 0.5, up, down, -up, x - 1e-7, x + 1e-7]
        });
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let random = core::iter::repeat_with(move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            f32::from_bits((seed >> 32) as u32)
        })
        .take(100_000);
        let small = (0..20_000).map(|i| i as f32 * 0.0017 - 3.0);
        for f in special
            .into_iter()
            .chain(near_whole)
            .chain(random)
            .chain(small)
        {
            for top in 3..32 {
                let want = bin_reference(f, top);
                let got = F4::new([f, 0.0, f, -f]).clamped_trunc(top as f32);
                assert_eq!(got[0], want, "f = {f:e} ({:#x}), top = {top}", f.to_bits());
                assert_eq!(got[2], want, "f = {f:e}, top = {top}");
                assert_eq!(got[3], bin_reference(-f, top), "f = {:e}, top = {top}", -f);
            }
        }
    }
}
