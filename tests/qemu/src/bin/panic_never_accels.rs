//! Panic-freedom check for the uniform grid and the kd-tree, as `panic_never.rs` does for the
//! BVH: calls every public build and query entry point of [`raykernel::Grid`] and
//! [`raykernel::KdTree`], in both modes, for triangles and spheres, on inputs the optimiser
//! cannot see (`black_box`), and links with a panic handler that calls a function nobody
//! defines. Build: `cargo build --release --bin panic_never_accels --features panic-check` in
//! tests/qemu (`cargo xtask panic-check`). Never run: it only has to link.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use raykernel::{
    grid::GridOptions, kdtree, kdtree::KdOptions, Accel, Grid, KdNode, KdTree, Primitive, Ray,
    Scalar, Sphere, TraversalStats, Triangle, I16F16,
};

const N: usize = 8;

/// Sizing, builds into arenas of opaque length, every query, the checks and accessors.
fn exercise<S: Scalar, P: Primitive<S>>(prims: &[P]) {
    let (o, d, t0, t1) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0], 0.0f32, 100.0f32));
    let Ok(ray) = Ray::<S>::from_f32(o, d, t0, t1) else {
        return;
    };
    let mut stats = TraversalStats::default();
    let density = black_box(GridOptions::default());
    black_box(Grid::<S, P>::size_for(prims, density).ok());
    let mut cells = [0u32; 64];
    let mut refs = [0u32; 256];
    let (nc, nr) = black_box((64usize, 256usize));
    let (nc, nr) = (nc.min(cells.len()), nr.min(refs.len()));
    if let Ok(grid) = Grid::build(prims, &mut cells[..nc], &mut refs[..nr], density) {
        black_box(grid.intersect(&ray));
        black_box(grid.occluded(&ray));
        black_box(grid.intersect_counted(&ray, &mut stats));
        black_box(grid.occluded_counted(&ray, &mut stats));
        black_box(grid.validate().ok());
        black_box((grid.resolution(), grid.bounds(), grid.bytes_used()));
        black_box((grid.cells().len(), grid.refs().len(), grid.prims().len()));
    }
    let mut nodes = [KdNode::<S>::EMPTY; kdtree::nodes_needed(N)];
    let mut krefs = [0u32; kdtree::refs_needed(N)];
    let used = black_box(kdtree::nodes_needed(N)).min(nodes.len());
    let options = black_box(KdOptions::default());
    if let Ok(tree) = KdTree::build(prims, &mut nodes[..used], &mut krefs, options) {
        black_box(tree.intersect(&ray));
        black_box(tree.occluded(&ray));
        black_box(tree.intersect_counted(&ray, &mut stats));
        black_box(tree.occluded_counted(&ray, &mut stats));
        black_box(tree.validate().ok());
        black_box((tree.bounds(), tree.bytes_used(), tree.depth()));
        black_box((tree.nodes().len(), tree.refs().len(), tree.prims().len()));
        if let Some(n) = tree.nodes().first() {
            black_box((n.is_leaf(), n.axis(), n.split(), n.first(), n.count()));
        }
    }
    black_box(stats);
}

fn triangles<S: Scalar>() -> [Triangle<S>; N] {
    let v: [[[f32; 3]; 3]; N] = black_box([[[0.0; 3]; 3]; N]);
    let mut out = [Triangle {
        v: [[S::ZERO; 3]; 3],
    }; N];
    for (o, v) in out.iter_mut().zip(v) {
        if let Ok(t) = Triangle::from_f32(v) {
            *o = t;
        }
    }
    out
}

fn spheres<S: Scalar>() -> [Sphere<S>; N] {
    let c: [([f32; 3], f32); N] = black_box([([0.0; 3], 1.0); N]);
    c.map(|(c, r)| Sphere {
        center: c.map(S::from_f32_saturating),
        radius: S::from_f32_saturating(r),
    })
}

#[entry]
fn main() -> ! {
    exercise::<f32, _>(&triangles::<f32>());
    exercise::<I16F16, _>(&triangles::<I16F16>());
    exercise::<f32, _>(&spheres::<f32>());
    exercise::<I16F16, _>(&spheres::<I16F16>());
    loop {
        cortex_m::asm::nop();
    }
}

#[path = "../panic_check.rs"]
mod panic_check;
