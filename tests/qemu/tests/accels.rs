//! On-target tests (defmt-test under QEMU) of the uniform grid, the kd-tree and the 4-wide and
//! 8-wide BVHs on the 80-triangle icosphere, both modes: arenas sized by the counting pass / the
//! documented budgets, `validate`, every query equal to brute force bit for bit, and typed
//! errors for a slice one slot short. The wide trees use the first 24 triangles on the M0 (see
//! [`WIDE_TRIS`]); the last test fails if less than 512 bytes of RAM stayed free.
//! A binary of its own: with the BVH tests, one would not fit the 256 KB flash.
#![no_std]
#![no_main]

use cortex_m_rt as _; // defmt-test doesn't link it; the vector table and reset handler
use defmt_semihosting as _; // global logger: defmt frames to semihosting stdout
use panic_probe as _; // prints the panic via defmt, then `udf` -> HardFault

use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::bvh8::{collapse_words_needed, wide_nodes_needed};
use raykernel::{
    grid::GridOptions, kdtree, kdtree::KdOptions, Accel, Bvh, Grid, KdNode, KdTree, Linear, Node,
    Scalar, Triangle, WideBvh, WideNode,
};
use raykernel_qemu::cases::{self, Bits, Fail, ICO_TRIS, RAY_COUNT};
use raykernel_qemu::{stack, WideTree, RAM_BYTES};

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

/// Triangles of the icosphere under the wide trees: all [`ICO_TRIS`] where the RAM allows (64 KB
/// on the M3 and the M4F), the first 24 on the M0's 16 KB. Over all 80 the 8-wide tree alone
/// needs 43 nodes of 256 bytes (11 KB) beside the BVH2's 159 nodes of 32 bytes (5 KB), the
/// triangles (2.9 KB) and the build's stack (about 9 KB on the M0); the 4-wide one 53 nodes of
/// 128 bytes (6.8 KB), with the rest also more than 16 KB.
const WIDE_TRIS: usize = if RAM_BYTES >= 64 * 1024 { ICO_TRIS } else { 24 };

/// The first [`WIDE_TRIS`] triangles of the icosphere (`cases::ico_triangle`), in mode `S`.
fn wide_mesh<S: Scalar>() -> [Triangle<S>; WIDE_TRIS] {
    let mut out = [Triangle {
        v: [[S::ZERO; 3]; 3],
    }; WIDE_TRIS];
    for (k, t) in out.iter_mut().enumerate() {
        match Triangle::from_f32(cases::ico_triangle(k)) {
            Ok(tri) => *t = tri,
            Err(_) => defmt::panic!("{} triangle {=usize} rejected", S::NAME, k),
        }
    }
    out
}

/// The `W`-wide BVH collapsed from every builder's tree (leaves of up to 4) over
/// [`wide_mesh`], and from a leaf-order build: validates, and every query equals brute force
/// bit for bit (over a scene most rays hit). `arena` has exactly `wide_nodes_needed` slots;
/// one slot less is a typed error with the exact bound. Not inlined, so its buffers are off the
/// stack before the next test.
#[inline(never)]
fn wide_vs_linear<const W: usize, S: Bits>(arena: &mut [WideNode<S, W>])
where
    for<'a> WideBvh<'a, S, Triangle<S>, W>: WideTree<S>,
{
    let tris = wide_mesh::<S>();
    let linear = Linear::new(&tris);
    let hits = (0..RAY_COUNT)
        .filter(|&i| cases::ray::<S>(i).is_ok_and(|r| linear.occluded(&r)))
        .count();
    defmt::info!(
        "{=usize}-wide, {}: {=usize} triangles, {=usize} of {=usize} rays hit",
        W,
        S::NAME,
        WIDE_TRIS,
        hits,
        RAY_COUNT
    );
    defmt::assert!(hits >= RAY_COUNT / 4, "too few rays hit the scene");
    let needed = wide_nodes_needed(WIDE_TRIS, W);
    defmt::assert_eq!(arena.len(), needed);
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(WIDE_TRIS)];
    let mut ids = [0u32; WIDE_TRIS];
    let mut scratch = [0u32; collapse_words_needed(WIDE_TRIS, 8)];
    for builder in BuilderKind::ALL {
        let options = BuildOptions {
            builder,
            max_leaf_size: 4,
            reinsertion: true,
        };
        let bvh = Bvh::build(&tris, &mut nodes, &mut ids, options);
        let Ok(bvh) = bvh else {
            defmt::panic!("{} build", S::NAME)
        };
        let tree = WideBvh::collapse(&bvh, &mut *arena, &mut scratch);
        let Ok(tree) = tree else {
            defmt::panic!("{=usize}-wide {} collapse", W, S::NAME)
        };
        defmt::assert!(
            tree.check().is_ok(),
            "{=usize}-wide {} validate",
            W,
            S::NAME
        );
        if let Err(e) = cases::same_queries(&tree, &linear) {
            defmt::panic!("{=usize}-wide {}: {}", W, S::NAME, fail_name(e));
        }
    }
    // Leaf order: the primitives permuted, the same answers.
    let mut own = tris;
    let bvh = Bvh::build_in_leaf_order(&mut own, &mut nodes, &mut ids, BuildOptions::default());
    let Ok(bvh) = bvh else {
        defmt::panic!("{} leaf-order build", S::NAME)
    };
    match WideBvh::collapse(&bvh, &mut *arena, &mut scratch) {
        Ok(tree) => {
            defmt::assert!(tree.check().is_ok() && tree.is_leaf_order());
            if let Err(e) = cases::same_queries(&tree, &linear) {
                defmt::panic!("{=usize}-wide {} leaf order: {}", W, S::NAME, fail_name(e));
            }
        }
        Err(_) => defmt::panic!("{=usize}-wide {} leaf-order collapse", W, S::NAME),
    }
    let e = WideBvh::collapse(&bvh, &mut arena[..needed - 1], &mut scratch).err();
    defmt::assert!(
        e == Some(raykernel::BuildError::ArenaTooSmall {
            arena: raykernel::Arena::Nodes,
            needed,
            available: needed - 1,
        }),
        "{=usize}-wide {} short nodes",
        W,
        S::NAME
    );
}

#[defmt_test::tests]
mod tests {
    use raykernel::bvh4::nodes4_needed;
    use raykernel::bvh8::nodes8_needed;
    use raykernel::{Node4, Node8, I16F16};

    use super::{grid_vs_linear, kdtree_vs_linear, stack, wide_vs_linear, WIDE_TRIS};

    /// Paints the free stack, so the last test can report the peak of the run.
    #[init]
    fn init() {
        stack::paint(cortex_m::register::msp::read() as usize - 256);
    }

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
    #[test]
    fn bvh4_matches_brute_force_f32() {
        wide_vs_linear::<4, f32>(&mut [Node4::EMPTY; nodes4_needed(WIDE_TRIS)])
    }
    #[test]
    fn bvh4_matches_brute_force_fixed() {
        wide_vs_linear::<4, I16F16>(&mut [Node4::EMPTY; nodes4_needed(WIDE_TRIS)])
    }
    #[test]
    fn bvh8_matches_brute_force_f32() {
        wide_vs_linear::<8, f32>(&mut [Node8::EMPTY; nodes8_needed(WIDE_TRIS)])
    }
    #[test]
    fn bvh8_matches_brute_force_fixed() {
        wide_vs_linear::<8, I16F16>(&mut [Node8::EMPTY; nodes8_needed(WIDE_TRIS)])
    }
    /// Last test: how much of the stack the whole run used. Fails when less than 512 bytes of
    /// the target's RAM stay free, before an overflow would.
    #[test]
    fn stack_headroom_of_the_whole_run() {
        stack::assert_headroom();
    }
}
