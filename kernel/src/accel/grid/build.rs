//! Grid construction: bounds, resolution, counting pass, fill pass; and the checker.

use super::{Grid, GridOptions, GridSize, GridStats, InvalidGrid, Layout, MAX_DENSITY, MAX_RES};
use crate::accel::{Arena, BuildError};
use crate::geom::{Aabb, Primitive};
use crate::scalar::Scalar;

/// A primitive's padded box: the box the slab test is guaranteed to accept for its hits.
#[inline(always)]
pub(super) fn padded<S: Scalar, P: Primitive<S>>(p: &P) -> Aabb<S> {
    let b = p.bounds();
    let (lo, hi) = S::pad_bounds(b.lo, b.hi);
    Aabb::new(lo, hi)
}

/// Checks the input, then computes the box and the resolution.
fn layout<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    options: GridOptions,
) -> Result<Option<Layout<S>>, BuildError> {
    let n = prims.len();
    if n >= u32::MAX as usize {
        return Err(BuildError::TooManyPrims { count: n });
    }
    let density = options.density;
    if !(density > 0.0 && density <= MAX_DENSITY) {
        return Err(BuildError::BadDensity { density });
    }
    for (prim, p) in prims.iter().enumerate() {
        p.check()
            .map_err(|(vertex, error)| BuildError::BadPrimitive {
                prim,
                vertex,
                error,
            })?;
    }
    let Some(first) = prims.first() else {
        return Ok(None);
    };
    let mut bounds = padded(first);
    for p in prims {
        bounds = bounds.union(&padded(p));
    }
    let lo_f = bounds.lo.map(S::to_f32);
    let hi_f = bounds.hi.map(S::to_f32);
    let extent: [f32; 3] = core::array::from_fn(|a| hi_f[a] - lo_f[a]);
    let res = resolution(extent, n, density);
    let step: [f32; 3] = core::array::from_fn(|a| {
        let s = extent[a] / res[a] as f32;
        if s.is_finite() && s > 0.0 {
            s
        } else {
            0.0
        }
    });
    Ok(Some(Layout {
        lo: bounds.lo,
        hi: bounds.hi,
        res,
        lo_f,
        step,
    }))
}

/// Cells per axis for `n` primitives in a box of this extent: about `density · n` cells, in
/// proportion to the extent (cube-root rule over the axes of non-zero extent; an axis that
/// would get less than one cell gets one and the others are recomputed). Computed in `f64`
/// with `libm`, so the same on every platform.
pub(super) fn resolution(extent: [f32; 3], n: usize, density: f32) -> [u32; 3] {
    let target = density as f64 * n as f64;
    let mut active = extent.map(|e| e.is_finite() && e > 0.0);
    let mut res = [1u32; 3];
    for _ in 0..3 {
        let d = active.iter().filter(|&&a| a).count();
        if d == 0 || target <= 1.0 {
            break;
        }
        let mut log_volume = 0.0f64;
        for a in 0..3 {
            if active[a] {
                log_volume += libm::log(extent[a] as f64);
            }
        }
        // Cells per unit length.
        let k = libm::exp((libm::log(target) - log_volume) / d as f64);
        let mut dropped = false;
        for a in 0..3 {
            if active[a] && extent[a] as f64 * k < 1.0 {
                active[a] = false;
                dropped = true;
            }
        }
        if !dropped {
            for a in 0..3 {
                if active[a] {
                    let r = libm::round(extent[a] as f64 * k);
                    // Saturating cast, then capped.
                    res[a] = (r as u32).clamp(1, MAX_RES);
                }
            }
            break;
        }
    }
    res
}

/// Calls `f(cell)` for every cell of `b`'s span.
#[inline(always)]
fn for_each_cell<S: Scalar>(layout: &Layout<S>, b: &Aabb<S>, mut f: impl FnMut(usize)) {
    let (x0, x1) = layout.span(0, b.lo[0], b.hi[0]);
    let (y0, y1) = layout.span(1, b.lo[1], b.hi[1]);
    let (z0, z1) = layout.span(2, b.lo[2], b.hi[2]);
    for z in z0..=z1 {
        for y in y0..=y1 {
            for x in x0..=x1 {
                f(layout.cell_index([x, y, z]));
            }
        }
    }
}

/// Number of cells in `b`'s span.
fn span_cells<S: Scalar>(layout: &Layout<S>, b: &Aabb<S>) -> u64 {
    let mut count = 1u64;
    for a in 0..3 {
        let (first, last) = layout.span(a, b.lo[a], b.hi[a]);
        count = count.saturating_mul(u64::from(last - first) + 1);
    }
    count
}

/// References the layout needs, checked against `u32` offsets.
fn count_refs<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    layout: &Layout<S>,
) -> Result<usize, BuildError> {
    let mut total = 0u64;
    for p in prims {
        total = total.saturating_add(span_cells(layout, &padded(p)));
    }
    if total > u32::MAX as u64 {
        return Err(BuildError::TooManyRefs { needed: total });
    }
    Ok(total as usize)
}

pub(super) fn size_for<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    options: GridOptions,
) -> Result<GridSize, BuildError> {
    let Some(layout) = layout(prims, options)? else {
        return Ok(GridSize::default());
    };
    Ok(GridSize {
        res: layout.res,
        cells: layout.cell_count() + 1,
        refs: count_refs(prims, &layout)?,
    })
}

/// Builds into `cells`/`refs`; returns the layout and the sizes used.
pub(super) fn build<S: Scalar, P: Primitive<S>>(
    prims: &[P],
    cells: &mut [u32],
    refs: &mut [u32],
    options: GridOptions,
) -> Result<(Layout<S>, GridSize), BuildError> {
    let Some(layout) = layout(prims, options)? else {
        let empty = Layout {
            lo: [S::ZERO; 3],
            hi: [S::ZERO; 3],
            res: [0; 3],
            lo_f: [0.0; 3],
            step: [0.0; 3],
        };
        return Ok((empty, GridSize::default()));
    };
    let cell_count = layout.cell_count();
    let available = cells.len();
    let Some(cells) = cells.get_mut(..cell_count + 1) else {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Cells,
            needed: cell_count + 1,
            available,
        });
    };
    // Counting pass, straight into the offsets: cells[c] = primitives listed in cell c.
    cells.fill(0);
    let mut total = 0u64;
    for p in prims {
        let b = padded(p);
        for_each_cell(&layout, &b, |c| {
            if let Some(slot) = cells.get_mut(c) {
                *slot = slot.saturating_add(1);
            }
        });
        total = total.saturating_add(span_cells(&layout, &b));
    }
    if total > u32::MAX as u64 {
        return Err(BuildError::TooManyRefs { needed: total });
    }
    let ref_count = total as usize;
    let available = refs.len();
    let Some(refs) = refs.get_mut(..ref_count) else {
        return Err(BuildError::ArenaTooSmall {
            arena: Arena::Refs,
            needed: ref_count,
            available,
        });
    };
    // Running sums: cells[c] = end of cell c's list; cells[cell_count] = total.
    let mut sum = 0u32;
    for slot in cells.iter_mut() {
        sum = sum.saturating_add(*slot);
        *slot = sum;
    }
    if let Some(last) = cells.last_mut() {
        *last = total as u32;
    }
    // Fill pass, last primitive first, each cell's list from its end: afterwards cells[c] is
    // the start of cell c's list and the ids in each list ascend.
    for (id, p) in (0..prims.len() as u32).zip(prims).rev() {
        for_each_cell(&layout, &padded(p), |c| {
            if let Some(end) = cells.get_mut(c) {
                *end = end.saturating_sub(1);
                if let Some(slot) = refs.get_mut(*end as usize) {
                    *slot = id;
                }
            }
        });
    }
    let size = GridSize {
        res: layout.res,
        cells: cell_count + 1,
        refs: ref_count,
    };
    Ok((layout, size))
}

pub(super) fn validate<S: Scalar, P: Primitive<S>>(
    grid: &Grid<'_, S, P>,
) -> Result<GridStats, InvalidGrid> {
    let layout = &grid.layout;
    let cell_count = if grid.prims.is_empty() {
        0
    } else {
        layout.cell_count()
    };
    let mut stats = GridStats {
        cell_count,
        ref_count: grid.refs.len(),
        ..GridStats::default()
    };
    if cell_count == 0 {
        return if grid.cells.is_empty() && grid.refs.is_empty() {
            Ok(stats)
        } else {
            Err(InvalidGrid::BadOffsets { cell: 0 })
        };
    }
    if grid.cells.len() != cell_count + 1 || grid.cells.first() != Some(&0) {
        return Err(InvalidGrid::BadOffsets { cell: 0 });
    }
    for (c, w) in grid.cells.windows(2).enumerate() {
        let &[start, end] = w else {
            return Err(InvalidGrid::BadOffsets { cell: c });
        };
        let (start, end) = (start as usize, end as usize);
        if start > end || end > grid.refs.len() {
            return Err(InvalidGrid::BadOffsets { cell: c });
        }
        stats.empty_cells += usize::from(start == end);
        stats.max_cell_refs = stats.max_cell_refs.max(end - start);
    }
    if grid.cells.last().map(|&e| e as usize) != Some(grid.refs.len()) {
        return Err(InvalidGrid::BadOffsets { cell: cell_count });
    }
    if let Some(at) = grid
        .refs
        .iter()
        .position(|&id| id as usize >= grid.prims.len())
    {
        return Err(InvalidGrid::BadRef { at });
    }
    for (id, p) in (0u32..).zip(grid.prims) {
        let b = padded(p);
        for a in 0..3 {
            let (first, last) = layout.span(a, b.lo[a], b.hi[a]);
            if layout.plane(a, first) > b.lo[a] || layout.plane(a, last + 1) < b.hi[a] {
                return Err(InvalidGrid::MissingPrim { prim: id, cell: 0 });
            }
        }
        let mut missing = None;
        for_each_cell(layout, &b, |c| {
            let list = match (grid.cells.get(c), grid.cells.get(c + 1)) {
                (Some(&s), Some(&e)) => grid.refs.get(s as usize..e as usize).unwrap_or_default(),
                _ => &[],
            };
            if missing.is_none() && list.binary_search(&id).is_err() {
                missing = Some(c);
            }
        });
        if let Some(cell) = missing {
            return Err(InvalidGrid::MissingPrim { prim: id, cell });
        }
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_follows_the_cube_root_rule_and_flattens() {
        // A cube: λn = 8000 cells -> 20 per axis.
        assert_eq!(resolution([1.0, 1.0, 1.0], 4000, 2.0), [20, 20, 20]);
        // Flat: the square-root rule on the two extended axes.
        assert_eq!(resolution([4.0, 1.0, 0.0], 100, 1.0), [20, 5, 1]);
        // Nearly flat: the thin axis drops out instead of inflating the count.
        let r = resolution([100.0, 100.0, 0.001], 1000, 4.0);
        assert_eq!(r, [63, 63, 1]);
        // A point, or no primitives: one cell.
        assert_eq!(resolution([0.0; 3], 50, 2.0), [1, 1, 1]);
        assert_eq!(resolution([1.0; 3], 0, 2.0), [1, 1, 1]);
        // Capped per axis.
        assert_eq!(resolution([1.0, 0.0, 0.0], 1 << 20, 64.0), [MAX_RES, 1, 1]);
    }
}
