//! The on-target suite for cores without defmt-test (RISC-V): known answers, every BVH
//! builder and leaf size and the other accelerators against brute force in both modes, and
//! every golden hash of `tests/golden/kernel_hashes.txt`. Prints one line per test and a
//! closing `N passed, M failed` line; exits 0 only if every test passed.
#![no_std]
#![no_main]

use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::bvh4::nodes4_needed;
use raykernel::bvh8::{collapse_words_needed, nodes8_needed};
use raykernel::grid::GridOptions;
use raykernel::kdtree::KdOptions;
use raykernel::{kdtree, Bvh, Bvh4, Bvh8, Grid, KdNode, KdTree, Linear, Node, Node4, Node8, I16F16};
use raykernel_baremetal::cases::{self, Bits, Fail, ICO_TRIS};
use raykernel_baremetal::{exit, golden, known_answers};
use semihosting::println;

#[cfg_attr(target_arch = "riscv32", riscv_rt::entry)]
#[cfg_attr(target_arch = "arm", cortex_m_rt::entry)]
fn main() -> ! {
    let (mut passed, mut failed) = (0u32, 0u32);
    let mut report_as = |prefix: &str, name: &str, result: Result<(), &str>| match result {
        Ok(()) => {
            println!("test {prefix}{name} ... ok");
            passed += 1;
        }
        Err(why) => {
            println!("test {prefix}{name} ... FAILED: {why}");
            failed += 1;
        }
    };
    let mut report = |name: &str, result: Result<(), &str>| report_as("", name, result);
    report("slab_known_answers_f32", known_answers::slab::<f32>());
    report("slab_known_answers_fixed", known_answers::slab::<I16F16>());
    report(
        "triangle_and_sphere_known_answers_f32",
        known_answers::triangle_and_sphere::<f32>(),
    );
    report(
        "triangle_and_sphere_known_answers_fixed",
        known_answers::triangle_and_sphere::<I16F16>(),
    );
    report(
        "accelerators_match_brute_force_f32",
        accelerators_vs_brute_force::<f32>().map_err(fail_name),
    );
    report(
        "accelerators_match_brute_force_fixed",
        accelerators_vs_brute_force::<I16F16>().map_err(fail_name),
    );
    for name in cases::NAMES {
        let result = match (cases::compute_any(name), golden(name)) {
            (Ok(got), Some(want)) if got == want => Ok(()),
            (Ok(got), Some(want)) => {
                println!("golden {name}: computed {got:#018x}, file {want:#018x}");
                Err("hash differs from kernel_hashes.txt")
            }
            (Ok(_), None) => Err("missing from kernel_hashes.txt"),
            (Err(e), _) => Err(fail_name(e)),
        };
        // The `golden_` prefix is what `cargo xtask determinism` counts as compared hashes.
        report_as("golden_", name, result);
    }
    println!("{passed} passed, {failed} failed");
    exit(i32::from(failed != 0))
}

fn fail_name(f: Fail) -> &'static str {
    match f {
        Fail::UnknownCase => "unknown case",
        Fail::Rejected { .. } => "kernel rejected generated input",
        Fail::Build => "build failed",
        Fail::Invalid => "validate() rejected the structure",
        Fail::Differs { .. } => "accelerator differs from brute force",
        Fail::NotLinked => "needs a kernel feature this build leaves out (path-tracing)",
    }
}

/// Every builder with leaves of 1, 2, 4 and 8, the 4- and 8-wide BVHs, the grid and the kd-tree over
/// the golden icosphere: validated, and every query the same bits as brute force.
#[inline(never)]
fn accelerators_vs_brute_force<S: Bits>() -> Result<(), Fail> {
    let mut tris = cases::empty_mesh::<S>();
    cases::icosphere(&mut tris)?;
    let linear = Linear::new(&tris);
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(ICO_TRIS)];
    let mut ids = [0u32; ICO_TRIS];
    for builder in BuilderKind::ALL {
        for max_leaf_size in [1, 2, 4, 8] {
            let options = BuildOptions {
                builder,
                max_leaf_size,
                reinsertion: true,
            };
            let bvh = Bvh::build(&tris, &mut nodes, &mut ids, options).map_err(|_| Fail::Build)?;
            bvh.validate().map_err(|_| Fail::Invalid)?;
            cases::same_queries(&bvh, &linear)?;
        }
    }
    let bvh = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default())
        .map_err(|_| Fail::Build)?;
    let mut scratch = [0u32; collapse_words_needed(ICO_TRIS, 8)];
    let mut wide = [Node4::<S>::EMPTY; nodes4_needed(ICO_TRIS)];
    let bvh4 = Bvh4::collapse(&bvh, &mut wide, &mut scratch).map_err(|_| Fail::Build)?;
    bvh4.validate().map_err(|_| Fail::Invalid)?;
    cases::same_queries(&bvh4, &linear)?;
    let mut wide8 = [Node8::<S>::EMPTY; nodes8_needed(ICO_TRIS)];
    let bvh8 = Bvh8::collapse(&bvh, &mut wide8, &mut scratch).map_err(|_| Fail::Build)?;
    bvh8.validate().map_err(|_| Fail::Invalid)?;
    cases::same_queries(&bvh8, &linear)?;

    let options = GridOptions::default();
    let size = Grid::size_for(&tris, options).map_err(|_| Fail::Build)?;
    let (mut cells, mut refs) = ([0u32; 4096], [0u32; 4096]);
    let (Some(cells), Some(refs)) = (cells.get_mut(..size.cells), refs.get_mut(..size.refs)) else {
        return Err(Fail::Build);
    };
    let grid = Grid::build(&tris, cells, refs, options).map_err(|_| Fail::Build)?;
    grid.validate().map_err(|_| Fail::Invalid)?;
    cases::same_queries(&grid, &linear)?;

    let mut kd_nodes = [KdNode::<S>::EMPTY; kdtree::nodes_needed(ICO_TRIS)];
    let mut kd_refs = [0u32; kdtree::refs_needed(ICO_TRIS)];
    let kd = KdTree::build(&tris, &mut kd_nodes, &mut kd_refs, KdOptions::default())
        .map_err(|_| Fail::Build)?;
    kd.validate().map_err(|_| Fail::Invalid)?;
    cases::same_queries(&kd, &linear)
}
