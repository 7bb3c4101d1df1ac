//! The rounding-proof 3D-DDA: a sweep over per-axis slab intervals (see the module docs).

use super::{Grid, Layout, MAILBOX};
use crate::accel::{Accel, Counters, Nearest};
use crate::geom::{closer, Barycentrics, Primitive, Ray};
use crate::scalar::Scalar;

/// One axis of the walk. Cells are numbered `m = 0..n` in the order the ray meets them
/// (`i = m`, or `n - 1 - m` for a negative direction), so entries and exits are nondecreasing
/// in `m`. Invariant: the cells whose interval contains the current `t` are `lo..end`; `next`
/// is the entry of cell `end` (when `end < n`), `lo_exit` the exit of cell `lo` (when
/// `lo < end`).
#[derive(Clone, Copy)]
struct AxisWalk<S> {
    n: u32,
    negative: bool,
    lo: u32,
    end: u32,
    next: S,
    lo_exit: S,
}

impl<S: Scalar> Layout<S> {
    /// `(entry, exit)` of the `m`-th cell the ray meets along `axis`.
    #[inline]
    fn interval(&self, rd: &S::RayData, axis: usize, walk: &AxisWalk<S>, m: u32) -> (S, S) {
        let i = if walk.negative {
            walk.n.saturating_sub(1).saturating_sub(m)
        } else {
            m
        };
        S::slab_axis(rd, axis, self.plane(axis, i), self.plane(axis, i + 1))
    }

    /// The walk state of `axis` at `t`. The search starts from `guess` (a walk position
    /// estimated from the entry point) and steps over the monotone entries and exits, so it
    /// is exact whatever the guess; a good guess makes it a few steps.
    fn start(&self, rd: &S::RayData, axis: usize, t: S, guess: u32) -> AxisWalk<S> {
        let mut w = AxisWalk {
            n: self.res[axis.min(2)],
            negative: S::axis_negative(rd, axis),
            lo: 0,
            end: 0,
            next: t,
            lo_exit: t,
        };
        // end = number of cells entered by t (entries are nondecreasing in m).
        let mut end = guess.min(w.n);
        while end < w.n && self.interval(rd, axis, &w, end).0 <= t {
            end += 1;
        }
        while end > 0 && self.interval(rd, axis, &w, end - 1).0 > t {
            end -= 1;
        }
        // lo = number of cells left before t (exits are nondecreasing; such cells were entered).
        let mut lo = end;
        while lo > 0 && self.interval(rd, axis, &w, lo - 1).1 >= t {
            lo -= 1;
        }
        w.end = end;
        w.lo = lo;
        if w.end < w.n {
            w.next = self.interval(rd, axis, &w, w.end).0;
        }
        if w.lo < w.end {
            w.lo_exit = self.interval(rd, axis, &w, w.lo).1;
        }
        w
    }

    /// A guess of the walk position of the cell holding `origin + t·dir` on `axis` (only the
    /// speed of [`Layout::start`] depends on it).
    fn guess(&self, rd: &S::RayData, axis: usize, t: S, negative: bool) -> u32 {
        let a = axis.min(2);
        let n = self.res[a];
        let (o, d) = (S::ray_origin(rd)[a].to_f32(), S::ray_dir(rd)[a].to_f32());
        let tf = t.to_f32();
        let x = if tf.is_finite() { o + tf * d } else { o };
        let s = self.step[a];
        let i = if s > 0.0 { (x - self.lo_f[a]) / s } else { 0.0 };
        // Saturating cast (NaN -> 0), then clamped to a cell.
        let i = (i as i64).min(n as i64 - 1).max(0) as u32;
        // One past the cell: `start` steps back over cells not yet entered.
        if negative {
            n.saturating_sub(i)
        } else {
            i + 1
        }
    }

    /// Drops the cells of `axis` that end before `t`.
    #[inline]
    fn retire(&self, rd: &S::RayData, axis: usize, w: &mut AxisWalk<S>, t: S) {
        while w.lo < w.end && w.lo_exit < t {
            w.lo += 1;
            if w.lo < w.end {
                w.lo_exit = self.interval(rd, axis, w, w.lo).1;
            }
        }
    }

    /// Cell coordinate of the `m`-th cell along the walk.
    #[inline(always)]
    fn coord(w: &AxisWalk<S>, m: u32) -> u32 {
        if w.negative {
            w.n.saturating_sub(1).saturating_sub(m)
        } else {
            m
        }
    }
}

/// Closest-hit state shared by the cells of one query.
struct Query<'r, S: Scalar> {
    rd: &'r S::RayData,
    t_min: S,
    best_t: S,
    best_prim: u32,
    mailbox: [u32; MAILBOX],
}

impl<S: Scalar, P: Primitive<S>> Grid<'_, S, P> {
    /// Tests the primitives of cell `c`. With `ANY`, returns true at the first hit.
    #[inline(always)]
    fn visit<const ANY: bool, C: Counters>(
        &self,
        q: &mut Query<'_, S>,
        c: usize,
        stats: &mut C,
    ) -> bool {
        stats.node();
        let ids = match (self.cells.get(c), self.cells.get(c + 1)) {
            (Some(&s), Some(&e)) => self.refs.get(s as usize..e as usize).unwrap_or_default(),
            _ => &[],
        };
        for &id in ids {
            // `% MAILBOX` on a power of two: a mask, never out of range.
            let slot = id as usize % MAILBOX;
            if q.mailbox[slot] == id {
                continue;
            }
            q.mailbox[slot] = id;
            let Some(prim) = self.prims.get(id as usize) else {
                continue;
            };
            stats.prim();
            if let Some(t) = prim.hit_t(q.rd, q.t_min, q.best_t) {
                if ANY {
                    q.best_t = t;
                    q.best_prim = id;
                    return true;
                }
                if closer(t, id, q.best_t, q.best_prim) {
                    q.best_t = t;
                    q.best_prim = id;
                }
            }
        }
        false
    }

    /// Visits the cells `xs × ys × zs` (walk positions); true if `ANY` found a hit. Not
    /// inlined: one copy of the primitive test per query type keeps the code small.
    #[inline(never)]
    fn visit_block<const ANY: bool, C: Counters>(
        &self,
        q: &mut Query<'_, S>,
        walks: &[AxisWalk<S>; 3],
        ranges: [(u32, u32); 3],
        stats: &mut C,
    ) -> bool {
        for mz in ranges[2].0..ranges[2].1 {
            for my in ranges[1].0..ranges[1].1 {
                for mx in ranges[0].0..ranges[0].1 {
                    let i = [
                        Layout::coord(&walks[0], mx),
                        Layout::coord(&walks[1], my),
                        Layout::coord(&walks[2], mz),
                    ];
                    if self.visit::<ANY, C>(q, self.layout.cell_index(i), stats) && ANY {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The walk. Returns (t, prim) of the hit; `prim == u32::MAX` for none.
    #[inline(always)]
    fn traverse<const ANY: bool, C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> (S, u32) {
        let rd = ray.data();
        let mut q = Query {
            rd,
            t_min: ray.t_min(),
            best_t: ray.t_max(),
            best_prim: u32::MAX,
            mailbox: [u32::MAX; MAILBOX],
        };
        let l = &self.layout;
        if self.prims.is_empty() || self.cells.is_empty() {
            return (q.best_t, q.best_prim);
        }
        // Every cell lies in the grid box, so none is entered before the box is.
        let Some(t0) = S::slab(rd, &l.lo, &l.hi, q.t_min, q.best_t) else {
            return (q.best_t, q.best_prim);
        };
        let walks: [AxisWalk<S>; 3] = core::array::from_fn(|a| {
            let guess = l.guess(rd, a, t0, S::axis_negative(rd, a));
            l.start(rd, a, t0, guess)
        });
        let mut walks = walks;
        let ranges = walks.map(|w| (w.lo, w.end));
        if self.visit_block::<ANY, C>(&mut q, &walks, ranges, stats) {
            return (q.best_t, q.best_prim);
        }
        loop {
            // The next cell to enter on any axis (lowest axis first on ties).
            let mut axis = 3;
            let mut t = t0;
            for (a, w) in walks.iter().enumerate() {
                if w.end < w.n && (axis == 3 || w.next < t) {
                    axis = a;
                    t = w.next;
                }
            }
            // Every cell left is entered after `t`: stop once that is beyond the best hit.
            if axis == 3 || t > S::widen(q.best_t) {
                break;
            }
            let a = axis.min(2);
            let m = walks[a].end;
            walks[a].end += 1;
            if walks[a].lo == m {
                walks[a].lo_exit = l.interval(rd, a, &walks[a], m).1;
            }
            if walks[a].end < walks[a].n {
                walks[a].next = l.interval(rd, a, &walks[a], walks[a].end).0;
            }
            let mut left_grid = false;
            for (k, w) in walks.iter_mut().enumerate() {
                l.retire(rd, k, w, t);
                left_grid |= w.lo == w.n;
            }
            if left_grid {
                break;
            }
            if m < walks[a].lo {
                continue;
            }
            // The newly entered slice: cell m on `a`, the active cells on the other axes.
            let mut ranges = walks.map(|w| (w.lo, w.end));
            ranges[a] = (m, m + 1);
            if self.visit_block::<ANY, C>(&mut q, &walks, ranges, stats) {
                break;
            }
        }
        (q.best_t, q.best_prim)
    }
}

impl<S: Scalar, P: Primitive<S>> Accel<S> for Grid<'_, S, P> {
    #[inline]
    fn nearest_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> Option<Nearest<S>> {
        let (t, prim) = self.traverse::<false, C>(ray, stats);
        Nearest::found(t, prim, prim as usize)
    }

    fn barycentrics(&self, ray: &Ray<S>, found: &Nearest<S>) -> Barycentrics<S> {
        found.barycentrics_in(self.prims, ray)
    }

    #[inline]
    fn occluded_counted<C: Counters>(&self, ray: &Ray<S>, stats: &mut C) -> bool {
        self.traverse::<true, C>(ray, stats).1 != u32::MAX
    }
}
