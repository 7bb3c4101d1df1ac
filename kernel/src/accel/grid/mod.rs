//! Uniform grid over caller-provided memory (uniform spatial subdivision: Fujimoto, Tanaka and
//! Iwata 1986; traversal after Amanatides and Woo 1987, "A Fast Voxel Traversal Algorithm").
//!
//! **Layout.** The scene box (the union of every primitive's padded box) is cut into
//! `res[0] × res[1] × res[2]` cells by planes `plane(axis, i)`, `i = 0..=res[axis]`, that are
//! monotone in `i` and end exactly on the box. Each cell lists, in compressed-row form, the
//! primitives whose *padded* box (`Numerics::pad_bounds`) overlaps it: `cells[c]..cells[c + 1]`
//! is cell `c`'s range in `refs`, ids ascending. A primitive's cells always cover its whole
//! padded box (its first and last cell on each axis are found by comparing with the planes
//! themselves, not by rounding a division).
//!
//! **Memory.** The caller passes `cells` (`cell_count + 1` offsets) and `refs` (one slot per
//! (cell, primitive) pair). [`Grid::size_for`] runs the counting pass alone and returns the
//! exact sizes; [`Grid::build`] fails with [`BuildError::ArenaTooSmall`] (exact numbers) when a
//! slice is shorter, and with [`BuildError::TooManyRefs`] when the references exceed `u32`.
//!
//! **Resolution heuristic.** About `density · n` cells (`density` = λ, default
//! [`DEFAULT_DENSITY`]), shaped like the box: `res[a] = round(extent[a] · k)` with
//! `k = (λ·n / Π extent)^(1/d)` over the `d` axes of non-zero extent (the cube-root rule; the
//! square-root or linear rule for flat or linear scenes). An axis that would get less than one
//! cell gets exactly one and `k` is recomputed for the others; each axis is capped at
//! [`MAX_RES`].
//!
//! **Traversal** is a 3D-DDA that cannot miss a cell through rounding. Per axis, cell `i`'s
//! interval of `t` comes from `Numerics::slab_axis` on its two planes, the very arithmetic of
//! the conservative slab test; these intervals are monotone along the ray and consecutive ones
//! overlap. The walk keeps, per axis, the range of cells whose interval contains the current
//! `t` and advances `t` to the next interval start on any axis (the classic `tMax` step); a
//! cell is visited when its last axis enters, i.e. exactly at its slab entry, so cells come in
//! nondecreasing entry order and every cell the slab test accepts is visited. Zero direction
//! components need no special case: their intervals are `±inf` (never NaN) and constant.
//!
//! **Why results equal brute force bit for bit.** If primitive `q` is hit at `t`, the slab test
//! accepts `q`'s padded box with entry at most `widen(t)` (the invariant the BVH relies on).
//! Along each axis the intervals of the cells covering that box chain-cover the box's interval,
//! so one of those cells (all of which list `q`) is accepted with entry at most `widen(t)`. The
//! walk stops only when the next cell's entry exceeds `widen(best t)`, so `q` is tested before
//! any termination whenever it could beat the current best. A hit found in a cell beyond that
//! cell's exit therefore never ends the search early; it only tightens `best t`.
//!
//! **Mailboxing.** A primitive spanning several cells is tested once per ray in the common case:
//! a direct-mapped table of the last [`MAILBOX`] ids tested (`id % MAILBOX`), on the call
//! stack. A collision only causes a repeated test, which gives the same bits (`hit_t` is pure),
//! so results never depend on it.

mod build;
mod traverse;

use crate::accel::BuildError;
use crate::geom::Primitive;
use crate::scalar::Scalar;
use core::marker::PhantomData;

/// Default density λ: cells per primitive.
pub const DEFAULT_DENSITY: f32 = 2.0;
/// Largest accepted density.
pub const MAX_DENSITY: f32 = 64.0;
/// Most cells along one axis.
pub const MAX_RES: u32 = 1024;
/// Entries of the per-ray mailbox (a power of two).
pub const MAILBOX: usize = 32;

/// Build settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridOptions {
    /// Target cells per primitive (λ), in `(0, MAX_DENSITY]`.
    pub density: f32,
}

impl GridOptions {
    /// The defaults: density [`DEFAULT_DENSITY`].
    pub const DEFAULT: Self = Self {
        density: DEFAULT_DENSITY,
    };
}

impl Default for GridOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Exact memory a grid needs, from [`Grid::size_for`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GridSize {
    /// Cells per axis (all zero for an empty scene).
    pub res: [u32; 3],
    /// Length of the `cells` slice: cell count plus one (0 for an empty scene).
    pub cells: usize,
    /// Length of the `refs` slice: (cell, primitive) pairs.
    pub refs: usize,
}

/// Where the planes are: the box and the resolution. Planes are computed, not stored.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout<S: Scalar> {
    lo: [S; 3],
    hi: [S; 3],
    res: [u32; 3],
    /// `lo` in `f32` and the plane spacing, for [`Layout::plane`] and cell estimates.
    lo_f: [f32; 3],
    step: [f32; 3],
}

impl<S: Scalar> Layout<S> {
    /// Plane `i` of `axis` (`0..=res`): `lo` at 0, `hi` at `res`, in between
    /// `lo + i·step` rounded to `S` and clamped into `[lo, hi]`. Nondecreasing in `i`
    /// (every step is a monotone function of `i`).
    #[inline(always)]
    fn plane(&self, axis: usize, i: u32) -> S {
        let a = axis.min(2);
        if i == 0 {
            self.lo[a]
        } else if i >= self.res[a] {
            self.hi[a]
        } else {
            let x = S::from_f32_saturating(self.lo_f[a] + i as f32 * self.step[a]);
            x.max_of(self.lo[a]).min_of(self.hi[a])
        }
    }

    /// Cells `first..=last` on `axis` whose union covers `[x_lo, x_hi]` (which must lie in
    /// `[lo, hi]`): `first` is the last cell whose lower plane is `<= x_lo`, `last` the first
    /// (from `first` on) whose upper plane is `>= x_hi`. Found from an `f32` estimate corrected
    /// against the planes themselves, so rounding cannot drop a cell.
    fn span(&self, axis: usize, x_lo: S, x_hi: S) -> (u32, u32) {
        let a = axis.min(2);
        let n = self.res[a];
        if n <= 1 {
            return (0, 0);
        }
        let estimate = |x: S| -> u32 {
            let s = self.step[a];
            let e = if s > 0.0 {
                (x.to_f32() - self.lo_f[a]) / s
            } else {
                0.0
            };
            // Saturating cast (NaN -> 0), then clamped to a cell.
            (e as i64).max(0).min(n as i64 - 1) as u32
        };
        let mut first = estimate(x_lo);
        while first > 0 && self.plane(a, first) > x_lo {
            first -= 1;
        }
        while first + 1 < n && self.plane(a, first + 1) <= x_lo {
            first += 1;
        }
        let mut last = estimate(x_hi).max(first);
        while last > first && self.plane(a, last) >= x_hi {
            last -= 1;
        }
        while last + 1 < n && self.plane(a, last + 1) < x_hi {
            last += 1;
        }
        (first, last)
    }

    fn cell_count(&self) -> usize {
        self.res[0] as usize * self.res[1] as usize * self.res[2] as usize
    }

    #[inline(always)]
    fn cell_index(&self, i: [u32; 3]) -> usize {
        (i[2] as usize * self.res[1] as usize + i[1] as usize) * self.res[0] as usize
            + i[0] as usize
    }
}

/// A built uniform grid, borrowing its cell offsets, references and primitives.
#[derive(Clone, Copy, Debug)]
pub struct Grid<'a, S: Scalar, P: Primitive<S>> {
    prims: &'a [P],
    cells: &'a [u32],
    refs: &'a [u32],
    layout: Layout<S>,
    _scalar: PhantomData<S>,
}

impl<'a, S: Scalar, P: Primitive<S>> Grid<'a, S, P> {
    /// The counting pass alone: the exact slice sizes [`Grid::build`] needs for `prims`.
    ///
    /// # Errors
    /// As [`Grid::build`], except [`BuildError::ArenaTooSmall`].
    pub fn size_for(prims: &[P], options: GridOptions) -> Result<GridSize, BuildError> {
        build::size_for(prims, options)
    }

    /// Builds a grid over `prims` into `cells` and `refs` (sizes from [`Grid::size_for`]; longer
    /// slices are fine). Single-threaded, allocation-free, deterministic.
    ///
    /// # Errors
    /// [`BuildError::ArenaTooSmall`] (`Cells` or `Refs`, exact sizes),
    /// [`BuildError::TooManyRefs`], [`BuildError::TooManyPrims`], [`BuildError::BadPrimitive`]
    /// and [`BuildError::BadDensity`].
    pub fn build(
        prims: &'a [P],
        cells: &'a mut [u32],
        refs: &'a mut [u32],
        options: GridOptions,
    ) -> Result<Self, BuildError> {
        let (layout, size) = build::build(prims, cells, refs, options)?;
        let cells: &'a [u32] = cells;
        let refs: &'a [u32] = refs;
        Ok(Self {
            prims,
            cells: cells.get(..size.cells).unwrap_or_default(),
            refs: refs.get(..size.refs).unwrap_or_default(),
            layout,
            _scalar: PhantomData,
        })
    }

    /// Cells per axis.
    #[must_use]
    pub fn resolution(&self) -> [u32; 3] {
        self.layout.res
    }
    /// The grid's box (the union of the primitives' padded boxes).
    #[must_use]
    pub fn bounds(&self) -> crate::Aabb<S> {
        crate::Aabb::new(self.layout.lo, self.layout.hi)
    }
    /// Cell offsets in use (cell count plus one).
    #[must_use]
    pub fn cells(&self) -> &'a [u32] {
        self.cells
    }
    /// Primitive references in use.
    #[must_use]
    pub fn refs(&self) -> &'a [u32] {
        self.refs
    }
    /// The primitives.
    #[must_use]
    pub fn prims(&self) -> &'a [P] {
        self.prims
    }
    /// Bytes of cell offsets and references in use (excluding the primitives).
    #[must_use]
    pub fn bytes_used(&self) -> usize {
        core::mem::size_of_val(self.cells) + core::mem::size_of_val(self.refs)
    }

    /// Checks the invariants: offsets nondecreasing and ending at the reference count, every
    /// reference in range, and every primitive listed in every cell of its span, a block of
    /// cells whose planes enclose its padded box.
    ///
    /// # Errors
    /// The first violation found.
    pub fn validate(&self) -> Result<GridStats, InvalidGrid> {
        build::validate(self)
    }
}

/// Shape of a valid grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GridStats {
    /// Cells.
    pub cell_count: usize,
    /// Cells listing no primitive.
    pub empty_cells: usize,
    /// References (sum of the cells' list lengths).
    pub ref_count: usize,
    /// Longest cell list.
    pub max_cell_refs: usize,
}

/// The first violated invariant found by [`Grid::validate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum InvalidGrid {
    /// The offsets are not nondecreasing, do not start at 0 or do not end at the reference
    /// count.
    BadOffsets {
        /// The cell.
        cell: usize,
    },
    /// A reference is out of range.
    BadRef {
        /// The reference's position.
        at: usize,
    },
    /// A primitive is missing from a cell of its span, or its span does not enclose its padded
    /// box.
    MissingPrim {
        /// The primitive.
        prim: u32,
        /// The cell.
        cell: usize,
    },
}

impl core::fmt::Display for InvalidGrid {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "invalid grid: {self:?}")
    }
}

impl core::error::Error for InvalidGrid {}
