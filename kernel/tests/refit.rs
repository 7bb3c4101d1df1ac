//! Refit: random meshes (triangle soups and a closed sphere), random motion (small jitter,
//! large displacement, whole-mesh transforms), both modes, every tree kind (binary, 4-wide,
//! 8-wide), with and without leaf order: after `refit` the tree is valid and answers every ray
//! bit for bit as brute force over the moved triangles does.

mod common;

use common::{query, same_hit, TestScalar};
use proptest::prelude::*;
use raykernel::bvh::{nodes_needed, BuildOptions, RefitError};
use raykernel::bvh4::nodes4_needed;
use raykernel::bvh8::{collapse_words_needed, nodes8_needed};
use raykernel::{Bvh, Bvh4, Bvh8, Linear, Node, Node4, Node8, Ray, Triangle, I16F16};
use raykernel_testkit::icosphere::unit_icosphere;
use raykernel_testkit::Rng;

/// `f32` vertices of a mesh.
type Verts = Vec<[[f32; 3]; 3]>;

fn to_mode<S: TestScalar>(v: &Verts) -> Vec<Triangle<S>> {
    v.iter().map(|t| Triangle::from_f32(*t).unwrap()).collect()
}

/// Moves every vertex: `kind` 0 jitters a little, 1 displaces each triangle far, 2 scales
/// and shifts the whole mesh, 3 swaps distant triangles' positions (worst grouping).
fn moved(v: &Verts, kind: u8, rng: &mut Rng) -> Verts {
    let n = v.len();
    let clamp = |x: f32| x.clamp(-90.0, 90.0);
    match kind {
        0 => v
            .iter()
            .map(|t| t.map(|p| p.map(|x| clamp(x + rng.range(-0.05, 0.05)))))
            .collect(),
        1 => v
            .iter()
            .map(|t| {
                let shift = [0; 3].map(|_| rng.range(-30.0, 30.0));
                t.map(|p| [0, 1, 2].map(|k| clamp(p[k] + shift[k])))
            })
            .collect(),
        2 => {
            let s = rng.range(0.3, 3.0);
            let shift = [0; 3].map(|_| rng.range(-10.0, 10.0));
            v.iter()
                .map(|t| t.map(|p| [0, 1, 2].map(|k| clamp(p[k] * s + shift[k]))))
                .collect()
        }
        _ => (0..n).map(|i| v[(i * 7 + n / 2) % n]).collect(),
    }
}

fn rays(rng: &mut Rng, n: usize) -> Vec<([f32; 3], [f32; 3])> {
    (0..n)
        .map(|_| {
            let o = rng.unit_vec().map(|x| x * 120.0);
            let target = [0; 3].map(|_| rng.range(-40.0, 40.0));
            (o, [0, 1, 2].map(|k| target[k] - o[k]))
        })
        .collect()
}

/// Builds over `before`, refits to `after` (binary, 4-wide and 8-wide), checks each against
/// brute force on `after`.
fn check_refit<S: TestScalar>(
    before: &Verts,
    after: &Verts,
    leaf: u32,
    leaf_order: bool,
    rays: &[([f32; 3], [f32; 3])],
) -> Result<(), String> {
    let n = before.len();
    let options = BuildOptions {
        max_leaf_size: leaf,
        ..BuildOptions::default()
    };
    let mut tris = to_mode::<S>(before);
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
    let mut ids = vec![0u32; n];
    let mut nodes4 = vec![Node4::<S>::EMPTY; nodes4_needed(n)];
    let mut nodes8 = vec![Node8::<S>::EMPTY; nodes8_needed(n)];
    let (shape, shape4, shape8) = {
        let bvh = if leaf_order {
            Bvh::build_in_leaf_order(&mut tris, &mut nodes, &mut ids, options)
        } else {
            Bvh::build(&tris, &mut nodes, &mut ids, options)
        }
        .map_err(|e| e.to_string())?;
        let mut scratch = vec![0u32; collapse_words_needed(n, 8)];
        let wide4 = Bvh4::collapse(&bvh, &mut nodes4, &mut scratch).map_err(|e| e.to_string())?;
        let wide8 = Bvh8::collapse(&bvh, &mut nodes8, &mut scratch).map_err(|e| e.to_string())?;
        (bvh.shape(), wide4.shape(), wide8.shape())
    };
    // Move: triangle with id `id` takes `after[id]`, wherever it sits.
    let moved_by_id = to_mode::<S>(after);
    let moved: Vec<Triangle<S>> = if leaf_order {
        ids.iter().map(|&id| moved_by_id[id as usize]).collect()
    } else {
        moved_by_id.clone()
    };
    let linear = Linear::new(&moved_by_id);
    let refit = Bvh::refit(&moved, &mut nodes, &ids, shape).map_err(|e| e.to_string())?;
    refit.validate().map_err(|e| format!("refit bvh: {e}"))?;
    let refit4 = Bvh4::refit(&moved, &mut nodes4, &ids, shape4).map_err(|e| e.to_string())?;
    refit4.validate().map_err(|e| format!("refit bvh4: {e}"))?;
    let refit8 = Bvh8::refit(&moved, &mut nodes8, &ids, shape8).map_err(|e| e.to_string())?;
    refit8.validate().map_err(|e| format!("refit bvh8: {e}"))?;
    for (o, d) in rays {
        let Ok(ray) = Ray::<S>::from_f32(*o, *d, 0.0, f32::INFINITY) else {
            continue;
        };
        let want = query(&linear, &ray)?;
        let ctx = |e: String| format!("{} ray {o:?} {d:?}: {e}", S::NAME);
        same_hit(&query(&refit, &ray)?, &want).map_err(|e| ctx(format!("bvh {e}")))?;
        same_hit(&query(&refit4, &ray)?, &want).map_err(|e| ctx(format!("bvh4 {e}")))?;
        same_hit(&query(&refit8, &ray)?, &want).map_err(|e| ctx(format!("bvh8 {e}")))?;
    }
    Ok(())
}

fn soup(rng: &mut Rng, n: usize) -> Verts {
    (0..n)
        .map(|_| {
            let a = [0; 3].map(|_| rng.range(-40.0, 40.0));
            let mut t = [a; 3];
            for p in &mut t[1..] {
                *p = [0, 1, 2].map(|k| a[k] + rng.range(-4.0, 4.0));
            }
            t
        })
        .collect()
}

fn sphere(radius: f32) -> Verts {
    let (verts, faces) = unit_icosphere(3);
    faces
        .iter()
        .map(|f| f.map(|i| verts[i as usize].map(|x| (x as f32) * radius)))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn refitted_trees_answer_like_brute_force(
        seed in any::<u64>(),
        n in 1usize..200,
        motion in 0u8..4,
        leaf in prop_oneof![Just(1u32), Just(3), Just(8)],
        leaf_order in any::<bool>(),
        closed in any::<bool>(),
    ) {
        let mut rng = Rng::new(seed);
        let before = if closed { sphere(20.0) } else { soup(&mut rng, n) };
        let after = moved(&before, motion, &mut rng);
        let rays = rays(&mut rng, 150);
        check_refit::<f32>(&before, &after, leaf, leaf_order, &rays)
            .map_err(|e| TestCaseError::fail(format!("seed {seed}: {e}")))?;
        check_refit::<I16F16>(&before, &after, leaf, leaf_order, &rays)
            .map_err(|e| TestCaseError::fail(format!("seed {seed}: {e}")))?;
    }
}

#[test]
fn refit_rejects_bad_vertices_and_foreign_arrays() {
    let mut rng = Rng::new(3);
    let before = soup(&mut rng, 20);
    let tris = to_mode::<f32>(&before);
    let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(20)];
    let mut ids = vec![0u32; 20];
    let shape = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default())
        .unwrap()
        .shape();
    let mut bad = tris.clone();
    bad[7].v[1][2] = f32::NAN;
    assert!(matches!(
        Bvh::refit(&bad, &mut nodes, &ids, shape),
        Err(RefitError::BadPrimitive {
            index: 7,
            vertex: 1,
            ..
        })
    ));
    assert!(matches!(
        Bvh::refit(&tris[..19], &mut nodes, &ids, shape),
        Err(RefitError::ShapeMismatch { .. })
    ));
    let mut empty = vec![Node::<f32>::EMPTY; nodes_needed(20)];
    assert!(matches!(
        Bvh::refit(&tris, &mut empty, &ids, shape),
        Err(RefitError::ShapeMismatch { .. })
    ));
}
