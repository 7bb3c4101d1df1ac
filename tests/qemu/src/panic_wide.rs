//! The body of the wide BVHs' panic-freedom images (`panic_never_bvh4`, `panic_never_bvh8`),
//! included by each with `#[path]`, as `panic_never.rs` does for the BVH: builds a BVH and
//! collapses it ([`raykernel::WideBvh::collapse`], into an arena of opaque length) and calls
//! every query, the checker and the accessors, for triangles and spheres, on inputs the
//! optimiser cannot see (`black_box`). Each image calls it in both modes.

use core::hint::black_box;
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::bvh8::{collapse_words_needed, wide_nodes_needed};
use raykernel::{
    Accel, Bvh, Node, Primitive, Ray, Scalar, Sphere, TraversalStats, Triangle, WideBvh, WideNode,
};
use raykernel_qemu::WideTree;

/// Primitives per scene.
pub const N: usize = 8;

/// BVH build, collapse into `wide` (at most [`wide_nodes_needed`] of it, an opaque length),
/// every query, the checker, accessors.
pub fn exercise<const W: usize, S: Scalar, P: Primitive<S>>(
    prims: &[P],
    wide: &mut [WideNode<S, W>],
) where
    for<'a> WideBvh<'a, S, P, W>: WideTree<S>,
{
    let (o, d, t0, t1) = black_box(([0.0f32; 3], [0.0f32, 0.0, 1.0], 0.0f32, 100.0f32));
    let Ok(ray) = Ray::<S>::from_f32(o, d, t0, t1) else {
        return;
    };
    let mut stats = TraversalStats::default();
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(N)];
    let mut ids = [0u32; N];
    let used = black_box(wide_nodes_needed(N, W)).min(wide.len());
    let options = black_box(BuildOptions::default());
    let Ok(bvh) = Bvh::build(prims, &mut nodes, &mut ids, options) else {
        return;
    };
    let mut scratch = [0u32; collapse_words_needed(N, 8)];
    if let Ok(tree) = WideBvh::collapse(&bvh, &mut wide[..used], &mut scratch) {
        black_box(tree.intersect(&ray));
        black_box(tree.occluded(&ray));
        black_box(tree.intersect_counted(&ray, &mut stats));
        black_box(tree.occluded_counted(&ray, &mut stats));
        black_box(tree.check().ok());
        black_box((tree.bytes_used(), tree.depth(), tree.is_leaf_order()));
        black_box((
            tree.nodes().len(),
            tree.prim_ids().len(),
            tree.prims().len(),
        ));
        if let Some(n) = tree.nodes().first() {
            let i = black_box(0usize);
            black_box((n.child_count(), n.bounds(i), n.slot(i)));
        }
    }
    black_box(stats);
}

/// [`N`] triangles from opaque vertices.
pub fn triangles<S: Scalar>() -> [Triangle<S>; N] {
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

/// [`N`] spheres from opaque centres and radii.
pub fn spheres<S: Scalar>() -> [Sphere<S>; N] {
    let c: [([f32; 3], f32); N] = black_box([([0.0; 3], 1.0); N]);
    c.map(|(c, r)| Sphere {
        center: c.map(S::from_f32_saturating),
        radius: S::from_f32_saturating(r),
    })
}
