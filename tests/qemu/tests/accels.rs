//! On-target tests (defmt-test under QEMU) of the uniform grid and the kd-tree on the 80-triangle
//! icosphere, both modes: arenas sized by the counting pass / the documented budgets, `validate`,
//! every query equal to brute force bit for bit, and typed errors for a slice one slot short.
//! A binary of its own: with the BVH tests, one would not fit the 256 KB flash.
#![no_std]
#![no_main]

use cortex_m_rt as _; // defmt-test doesn't link it; the vector table and reset handler
use defmt_semihosting as _; // global logger: defmt frames to semihosting stdout
use panic_probe as _; // prints the panic via defmt, then `udf` -> HardFault

use raykernel::{grid::GridOptions, kdtree, kdtree::KdOptions, Grid, KdNode, KdTree, Linear};
use raykernel_qemu::cases::{self, Bits, Fail, ICO_TRIS};

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    panic_probe::hard_fault()
}

/// The default handler spins, so QEMU would hang until the runner's timeout: exit instead.
#[cortex_m_rt::exception]
unsafe fn HardFault(_: &cortex_m_rt::ExceptionFrame) -> ! {
    semihosting::process::exit(101)
}

fn fail_name(f: Fail) -> &'static str {
    match f {
        Fail::UnknownCase => "unknown case",
        Fail::Rejected { .. } => "kernel rejected generated input",
        Fail::Build => "build failed",
        Fail::Invalid => "validate() rejected the structure",
        Fail::Differs { .. } => "differs from brute force",
        Fail::NotLinked => "needs a kernel feature this build leaves out (path-tracing)",
    }
}

/// Uniform grid (three densities) on the icosphere: the counting pass's sizes fit the arenas,
/// the grid validates, and every query equals brute force bit for bit. Arenas are local to a
/// non-inlined function, so their stack frame is gone before the kd-tree test.
#[inline(never)]
fn grid_vs_linear<S: Bits>() {
    let mut tris = cases::empty_mesh::<S>();
    if let Err(e) = cases::icosphere(&mut tris) {
        defmt::panic!("{}", fail_name(e));
    }
    let mut cells = [0u32; 512];
    let mut refs = [0u32; 1536];
    for density in [0.5, 2.0, 4.0] {
        let options = GridOptions { density };
        let size = Grid::<S, _>::size_for(&tris, options);
        defmt::assert!(
            size.is_ok_and(|s| s.cells <= cells.len() && s.refs <= refs.len()),
            "{} grid size",
            S::NAME
        );
        let grid = Grid::build(&tris, &mut cells, &mut refs, options);
        defmt::assert!(grid.is_ok(), "{} grid build", S::NAME);
        let Ok(grid) = grid else { return };
        defmt::assert!(grid.validate().is_ok(), "{} grid validate", S::NAME);
        if let Err(e) = cases::same_queries(&grid, &Linear::new(&tris)) {
            defmt::panic!("{} grid: {}", S::NAME, fail_name(e));
        }
    }
    // One slot short: a typed error with the exact need.
    let need = Grid::<S, _>::size_for(&tris, GridOptions::default()).map_or(0, |s| s.refs);
    let e = Grid::build(
        &tris,
        &mut cells,
        &mut refs[..need - 1],
        GridOptions::default(),
    )
    .err();
    defmt::assert!(
        e == Some(raykernel::BuildError::ArenaTooSmall {
            arena: raykernel::Arena::Refs,
            needed: need,
            available: need - 1,
        }),
        "{} grid short refs",
        S::NAME
    );
}

/// Kd-tree (automatic depth, depth 3) on the icosphere, in arenas of the documented budgets:
/// validates, and every query equals brute force bit for bit.
#[inline(never)]
fn kdtree_vs_linear<S: Bits>() {
    let mut tris = cases::empty_mesh::<S>();
    if let Err(e) = cases::icosphere(&mut tris) {
        defmt::panic!("{}", fail_name(e));
    }
    let mut nodes = [KdNode::<S>::EMPTY; kdtree::nodes_needed(ICO_TRIS)];
    let mut refs = [0u32; kdtree::refs_needed(ICO_TRIS)];
    for max_depth in [0, 3] {
        let tree = KdTree::build(&tris, &mut nodes, &mut refs, KdOptions { max_depth });
        defmt::assert!(tree.is_ok(), "{} kd-tree build", S::NAME);
        let Ok(tree) = tree else { return };
        defmt::assert!(tree.validate().is_ok(), "{} kd-tree validate", S::NAME);
        if let Err(e) = cases::same_queries(&tree, &Linear::new(&tris)) {
            defmt::panic!("{} kd-tree: {}", S::NAME, fail_name(e));
        }
    }
    let short = kdtree::nodes_needed(ICO_TRIS) - 1;
    let e = KdTree::build(&tris, &mut nodes[..short], &mut refs, KdOptions::default()).err();
    defmt::assert!(
        e == Some(raykernel::BuildError::ArenaTooSmall {
            arena: raykernel::Arena::Nodes,
            needed: short + 1,
            available: short,
        }),
        "{} kd-tree short nodes",
        S::NAME
    );
}

#[defmt_test::tests]
mod tests {
    use raykernel::I16F16;

    use super::{grid_vs_linear, kdtree_vs_linear};

    #[test]
    fn grid_matches_brute_force_f32() {
        grid_vs_linear::<f32>()
    }
    #[test]
    fn grid_matches_brute_force_fixed() {
        grid_vs_linear::<I16F16>()
    }
    #[test]
    fn kdtree_matches_brute_force_f32() {
        kdtree_vs_linear::<f32>()
    }
    #[test]
    fn kdtree_matches_brute_force_fixed() {
        kdtree_vs_linear::<I16F16>()
    }
}
