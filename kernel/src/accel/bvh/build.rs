//! Top-down builders writing into the caller's arena. Iterative: an explicit stack of pending
//! nodes replaces recursion. Split decisions use `f32` keys (centroids, areas) in both modes;
//! `f32` arithmetic is deterministic, so fixed-point trees are identical on every platform too.
//!
//! Only [`load_boxes`] and the input checks see the primitives: every split reads their boxes
//! from arena slots, so the split code is compiled once per number mode and build settings,
//! not once per primitive type.

use super::select::{select_nth, swap_in};
use super::{
    nodes_needed, BuildSettings, BuilderKind, Node, FIRST_PAIR, MAX_DEPTH, MAX_LEAF_SIZE,
    MEDIAN_FALLBACK_DEPTH,
};
use crate::accel::{check_count, check_each, Arena, BuildError};
use crate::geom::{Aabb, Primitive};
use crate::scalar::lanes::F4;
use crate::scalar::Scalar;
use core::ops::Range;

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
    let n = prims.len();
    check_arena(n, nodes.len(), ids.len(), options.max_leaf_size())?;
    check_each(prims)?;
    let (Some(ids), Some(arena)) = (ids.get_mut(..n), nodes.get_mut(..nodes_needed(n))) else {
        return Ok((0, 0)); // unreachable: `check_arena` checked both sizes
    };
    for (slot, id) in ids.iter_mut().zip(0u32..) {
        *slot = id;
    }
    let mut scratch = Scratch::ZEROED;
    let mut top = TopDown::new(options, n, &mut scratch);
    load_boxes(
        prims,
        ids,
        arena.get_mut(top.first_load()).unwrap_or_default(),
    );
    top.plant_root(arena);
    while let Some(work) = top.next(arena, ids) {
        if work.load {
            let work_ids = ids.get(work.prims.clone()).unwrap_or_default();
            let slots = arena.get_mut(work.slots.clone()).unwrap_or_default();
            load_boxes(prims, work_ids, slots);
        }
        top.split(work, arena, ids);
    }
    Ok(top.finish(arena, ids))
}

/// Writes, for each id in `ids`, the box of `prims[id]` and the id into a slot of `slots` (a
/// one-primitive leaf), in order.
fn load_boxes<S: Scalar, P: Primitive<S>>(prims: &[P], ids: &[u32], slots: &mut [Node<S>]) {
    for (slot, &id) in slots.iter_mut().zip(ids) {
        let bounds = match prims.get(id as usize) {
            Some(p) => p.bounds(),
            None => empty_box(),
        };
        *slot = Node::leaf(bounds, id, 1);
    }
}

/// The size checks of a build over `n` primitives with arenas of `nodes` and `ids` slots.
fn check_arena(n: usize, nodes: usize, ids: usize, max_leaf_size: u32) -> Result<(), BuildError> {
    check_count(n)?;
    if max_leaf_size == 0 || max_leaf_size > MAX_LEAF_SIZE {
        return Err(BuildError::BadLeafSize { max_leaf_size });
    }
    let needed = nodes_needed(n);
    if nodes < needed {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Nodes,
            needed,
            available: nodes,
        });
    }
    if ids < n {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::PrimIds,
            needed: n,
            available: ids,
        });
    }
    Ok(())
}

/// A node to split, as [`TopDown::next`] hands it out.
struct Work {
    /// The node's primitives, as positions in `ids`.
    prims: Range<usize>,
    /// Where its primitives' boxes are: arena slots, one per position.
    slots: Range<usize>,
    /// True if the caller must first fill `slots` with [`load_boxes`].
    load: bool,
    pending: Pending,
}

/// The state of a top-down build over `n` primitives between two splits.
///
/// Bounds cache: while `cached`, slot `n + pos` of the arena holds the box and id of the
/// primitive at position `pos` (a one-primitive leaf), and splits partition these slots
/// instead of ids: sequential reads instead of scattered primitives. Nodes are allocated left
/// to right and every position left of the current node is final, so the cache stays intact
/// while `used + 2 <= n + first`. When a split would break that, the ids of the positions left
/// are written back, and from then on each node's boxes are loaded into the free slots from
/// `used` on before it is split. They fit: with `L` finished leaves (all left of `first`) and
/// `p` pending nodes (the current one, of `c >= 2` primitives, included), `used = 2L + 2p`
/// and the pending nodes share the `n - first >= c + p - 1` positions left, so
/// `2n - used >= 2(n - first) - 2p >= 2c - 2 >= c`.
///
/// Slices are taken with `get`: the arena checks make every range valid, and the fallbacks,
/// never taken, only keep panic paths out of the code.
struct TopDown<'s, S: Scalar, B> {
    builder: Builder<S, B>,
    n: usize,
    used: usize,
    deepest: u32,
    cached: bool,
    /// Entries of `scratch.stack` in use.
    sp: usize,
    scratch: &'s mut Scratch<S>,
}

/// The builder's working memory, borrowed so that it is written in place in the caller's
/// frame ([`Scratch::ZEROED`]): built by a call and returned, its arrays would go through a
/// temporary, twice the stack.
struct Scratch<S: Scalar> {
    /// Pending nodes: at most one sibling per level plus the current.
    stack: [Pending; MAX_DEPTH + 2],
    /// SAH bins, emptied by [`TopDown::plant_root`].
    boxes: [[Bin<S>; BINS]; 3],
    counts: [[u32; BINS]; 3],
}

impl<S: Scalar> Scratch<S> {
    /// All zeros: a zeroed bin is not empty, so [`TopDown::plant_root`] empties them.
    const ZEROED: Self = Self {
        stack: [Pending { index: 0, depth: 0 }; MAX_DEPTH + 2],
        boxes: [[Bin {
            lo: [S::ZERO; 4],
            hi: [S::ZERO; 4],
        }; BINS]; 3],
        counts: [[0; BINS]; 3],
    };
}

impl<'s, S: Scalar, B: BuildSettings> TopDown<'s, S, B> {
    fn new(settings: B, n: usize, scratch: &'s mut Scratch<S>) -> Self {
        Self {
            builder: Builder {
                max_leaf: settings.max_leaf_size() as usize,
                settings,
                _scalar: core::marker::PhantomData,
            },
            n,
            used: 0,
            deepest: 0,
            cached: n >= 2,
            sp: 0,
            scratch,
        }
    }

    /// The arena slots to fill with every primitive's box, in id order ([`load_boxes`]),
    /// before [`TopDown::plant_root`]: the bounds cache, or for a single primitive the root.
    fn first_load(&self) -> Range<usize> {
        match self.n {
            0 | 1 => 0..self.n,
            n => n..2 * n,
        }
    }

    /// Makes the root, a leaf holding every primitive, and queues it to be split.
    fn plant_root(&mut self, nodes: &mut [Node<S>]) {
        let n = self.n;
        self.used = n.min(1);
        if n < 2 {
            return; // a single primitive: the loaded slot is the root
        }
        for bin in self.scratch.boxes.iter_mut().flatten() {
            *bin = Bin::empty();
        }
        let root = summarize(nodes.get(n..2 * n).unwrap_or_default());
        if let [root_slot, pad, ..] = nodes {
            *root_slot = Node::leaf(root.bounds(), 0, n as u32);
            *pad = Node::EMPTY;
        }
        self.used = FIRST_PAIR;
        if let Some(slot) = self.scratch.stack.first_mut() {
            *slot = Pending { index: 0, depth: 0 };
            self.sp = 1;
        }
    }

    /// The next node to split (the root first), `None` when the build is done.
    fn next(&mut self, nodes: &mut [Node<S>], ids: &mut [u32]) -> Option<Work> {
        let n = self.n;
        self.sp = self.sp.checked_sub(1)?;
        let pending = *self.scratch.stack.get(self.sp)?;
        let node = nodes.get(pending.index as usize)?;
        let (first, count) = (node.first as usize, node.count as usize);
        self.deepest = self.deepest.max(pending.depth);
        if self.cached && self.used + 2 > n + first {
            let cache = nodes.get(n + first..2 * n).unwrap_or_default();
            for (id, slot) in ids.iter_mut().skip(first).zip(cache) {
                *id = slot.first;
            }
            self.cached = false;
        }
        let prims = first..first + count;
        let (slots, load) = if self.cached {
            (n + first..n + first + count, false)
        } else if count >= 2 {
            (self.used..self.used + count, true)
        } else {
            (0..0, false) // a leaf, its id already written back
        };
        Some(Work {
            prims,
            slots,
            load,
            pending,
        })
    }

    /// Splits the node `work` names (its boxes in place), or makes it a leaf.
    fn split(&mut self, work: Work, nodes: &mut [Node<S>], ids: &mut [u32]) {
        let Work {
            prims,
            slots,
            pending: Pending { index, depth },
            ..
        } = work;
        let Some(slots) = nodes.get_mut(slots) else {
            return;
        };
        let mut bins = Bins {
            boxes: &mut self.scratch.boxes,
            counts: &mut self.scratch.counts,
        };
        let split = self.builder.split(slots, depth as usize, &mut bins);
        // Cache slots stay partitioned in place until the node is a leaf; loaded slots are
        // overwritten by the next nodes.
        if split.is_none() || !self.cached {
            let node_ids = ids.get_mut(prims.clone()).unwrap_or_default();
            for (id, slot) in node_ids.iter_mut().zip(slots.iter()) {
                *id = slot.first;
            }
        }
        let Some([left, right]) = split else {
            return;
        };
        let (first, l) = (prims.start, self.used);
        let Some([a, b]) = nodes.get_mut(l..l + 2) else {
            return;
        };
        *a = Node::leaf(left.bounds(), first as u32, left.count as u32);
        *b = Node::leaf(
            right.bounds(),
            (first + left.count) as u32,
            right.count as u32,
        );
        self.used += 2;
        if let Some(parent) = nodes.get_mut(index as usize) {
            parent.first = l as u32;
            parent.count = 0;
        }
        // Right pushed first so the left subtree is built (and laid out) first.
        for child in [l + 1, l] {
            if let Some(slot) = self.scratch.stack.get_mut(self.sp) {
                *slot = Pending {
                    index: child as u32,
                    depth: depth + 1,
                };
                self.sp += 1;
            }
        }
    }

    /// Ends the build: the optional reinsertion pass, then bounds padded for traversal.
    /// Returns (nodes used, depth of the deepest leaf).
    fn finish(&self, nodes: &mut [Node<S>], ids: &mut [u32]) -> (usize, u32) {
        let (used, mut deepest) = (self.used, self.deepest);
        if self.builder.settings.reinsertion() {
            if let Some(depth) = super::optimize::reinsert(nodes, used, ids) {
                deepest = depth;
            }
        }
        for node in nodes.iter_mut().take(used) {
            let (lo, hi) = S::pad_bounds(node.lo, node.hi);
            node.lo = lo;
            node.hi = hi;
        }
        (used, deepest)
    }
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

/// A node waiting to be split. Its centroid bounds are not kept, which would make the
/// stack (one entry per level) four times larger, but found again when it is split
/// ([`centroid_bounds`]), in a pass over the boxes the split reads next.
#[derive(Clone, Copy)]
struct Pending {
    index: u32,
    depth: u32,
}

/// What a split search knows about one side: its size and box (as four lanes, lane 3
/// repeating lane 2).
#[derive(Clone, Copy)]
struct Side<S: Scalar> {
    count: usize,
    bin: Bin<S>,
}

impl<S: Scalar> Side<S> {
    fn empty() -> Self {
        Self {
            count: 0,
            bin: Bin::empty(),
        }
    }

    /// Adds a box.
    #[inline(always)]
    fn add(&mut self, b: &Aabb<S>) {
        self.count += 1;
        self.bin.grow(&lanes(&b.lo), &lanes(&b.hi));
    }

    /// A copy built field by field: returned whole, a side is copied out with a `memcpy`
    /// call on thumb targets, which links `memcpy`.
    #[inline(always)]
    fn copied(&self) -> Self {
        Self {
            count: self.count,
            bin: self.bin,
        }
    }

    fn bounds(&self) -> Aabb<S> {
        let (lo, hi) = (&self.bin.lo, &self.bin.hi);
        Aabb::new([lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]])
    }
}

/// Per-axis (min, max) of the [`key`]s of the boxes in `slots`.
fn centroid_bounds<S: Scalar>(slots: &[Node<S>]) -> ([f32; 3], [f32; 3]) {
    let (mut lo, mut hi) = (F4::splat(f32::INFINITY), F4::splat(f32::NEG_INFINITY));
    for slot in slots {
        let c = centroid(&lanes(&slot.lo), &lanes(&slot.hi));
        lo = lo.min(c);
        hi = hi.max(c);
    }
    let (lo, hi) = (lo.to_array(), hi.to_array());
    ([lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]])
}

/// The split rules, over arena slots each holding one primitive's box and id (`first`), with
/// `count` free for a tag (the SAH bins of the primitive).
struct Builder<S, B> {
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

/// Count and box of the boxes in `slots`.
fn summarize<S: Scalar>(slots: &[Node<S>]) -> Side<S> {
    let mut side = Side::empty();
    for slot in slots {
        side.add(&slot.bounds());
    }
    side.copied()
}

/// Partitions `slots` into those whose tag's field `(tag >> shift) & 31` (an SAH bin, or 0/1
/// as [`tag_halves`] sets) is at most `last` and the rest, summarizing both sides on the way.
/// One loop for every split rule, so a firmware links it once.
fn partition_by<S: Scalar>(slots: &mut [Node<S>], shift: u32, last: u32) -> [Side<S>; 2] {
    let mut sides = [Side::empty(), Side::empty()];
    let (mut i, mut j) = (0, slots.len());
    while i < j {
        let Some(slot) = slots.get(i) else { break };
        let b = slot.bounds();
        if (slot.count >> shift) & 31 <= last {
            sides[0].add(&b);
            i += 1;
        } else {
            sides[1].add(&b);
            j -= 1;
            swap_in(slots, i, j);
        }
    }
    [sides[0].copied(), sides[1].copied()]
}

/// Tags each slot 0 if its [`key`] on `axis` is below `bound` (`inclusive`: at most `bound`),
/// else 1, for [`partition_by`] with `shift` 0 and `last` 0.
fn tag_halves<S: Scalar>(slots: &mut [Node<S>], axis: usize, bound: f32, inclusive: bool) {
    for slot in slots.iter_mut() {
        let k = key(&slot.bounds(), axis);
        let left = k < bound || (inclusive && k == bound);
        slot.count = u32::from(!left);
    }
}

impl<S: Scalar, B: BuildSettings> Builder<S, B> {
    /// Decides whether and where to split `slots` (partitioning them); `None` makes a leaf.
    fn split(
        &self,
        slots: &mut [Node<S>],
        depth: usize,
        bins: &mut Bins<'_, S>,
    ) -> Option<[Side<S>; 2]> {
        let count = slots.len();
        if count <= 1 {
            return None;
        }
        let (clo, chi) = &centroid_bounds(slots);
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
            return must_split.then(|| median(slots, widest));
        }
        match self.settings.builder() {
            BuilderKind::Median => must_split.then(|| median(slots, widest)),
            BuilderKind::Midpoint => must_split.then(|| {
                let mid = clo[widest] * 0.5 + chi[widest] * 0.5;
                tag_halves(slots, widest, mid, false);
                let sides = partition_by(slots, 0, 0);
                if sides[0].count == 0 || sides[1].count == 0 {
                    median(slots, widest)
                } else {
                    sides
                }
            }),
            BuilderKind::Sah => match self.sah(slots, clo, &extent, bins) {
                Some(sides) => Some(sides),
                None => must_split.then(|| median(slots, widest)),
            },
        }
    }

    /// Binned SAH over all three axes. `None` when a leaf is cheaper (and allowed) or no axis
    /// separates the centroids.
    fn sah(
        &self,
        slots: &mut [Node<S>],
        clo: &[f32; 3],
        extent: &[f32; 3],
        bins: &mut Bins<'_, S>,
    ) -> Option<[Side<S>; 2]> {
        let count = slots.len();
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
        if let [p, q] = slots {
            let pair = [p.bounds(), q.bounds()];
            let axis = self.sah_pair(pair, &scale)?.min(2); // `min`: shows the bound
            tag_halves(slots, axis, clo[axis], true);
            return Some(partition_by(slots, 0, 0));
        }
        // Bin each primitive on all three axes, remembering its bins in the slot's tag for the
        // partition below.
        let (origin, scale4) = (F4::new(lanes(clo)), F4::new(lanes(&scale)));
        let top = (nb - 1) as f32;
        for slot in slots.iter_mut() {
            let b = slot.bounds();
            let (lo, hi) = (lanes(&b.lo), lanes(&b.hi));
            let bin = centroid(&lo, &hi)
                .sub(origin)
                .mul(scale4)
                .clamped_trunc(top);
            // Each bin is below `nb <= 32`: five bits per axis.
            slot.count = bin[0] | bin[1] << 5 | bin[2] << 10;
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
        let shift = 5 * axis.min(2) as u32; // `min`: a no-op that shows the bound
        Some(partition_by(slots, shift, last_left_bin as u32))
    }

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

/// Splits `slots` at the median of their [`key`]s on `axis` (ties by id).
fn median<S: Scalar>(slots: &mut [Node<S>], axis: usize) -> [Side<S>; 2] {
    let axis = axis.min(2);
    let mid = slots.len() / 2;
    select_nth(slots, mid, |slot| (key(&slot.bounds(), axis), slot.first));
    let (left, right) = slots.split_at(mid);
    [summarize(left), summarize(right)]
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
            // Quiet NaNs only: on aarch64 the compiler may turn the lanes' `max` with 0 into
            // `fmaxnm`, which returns a NaN for a signaling one (the builder sees no NaN at
            // all: its centroids come from checked, finite triangles).
            let x = f32::from_bits((seed >> 32) as u32);
            if x.is_nan() {
                f32::from_bits(x.to_bits() | 0x0040_0000)
            } else {
                x
            }
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
