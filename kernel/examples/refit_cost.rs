//! Refit against rebuild: wall time of each, and the traversal work (nodes visited and
//! triangles tested per ray) of the refitted tree against a tree rebuilt over the moved mesh,
//! for small and large motion. `cargo run --release -p raykernel --example refit_cost
//! [MESH.obj]` (default: a generated icosphere of 81,920 triangles). Figures go to stdout;
//! nothing is asserted (timings are not tests).

use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Accel, Bvh, Node, Ray, TraversalStats, Triangle};
use std::time::Instant;

type Verts = Vec<[[f32; 3]; 3]>;

/// `v x y z` and triangle-fan `f` lines of an OBJ (positions only).
fn read_obj(path: &str) -> Verts {
    let text = std::fs::read_to_string(path).expect("readable OBJ");
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let p: Vec<f32> = it.take(3).map(|x| x.parse().expect("number")).collect();
                pos.push([p[0], p[1], p[2]]);
            }
            Some("f") => {
                let ids: Vec<usize> = it
                    .map(|w| {
                        w.split('/')
                            .next()
                            .unwrap()
                            .parse::<usize>()
                            .expect("index")
                            - 1
                    })
                    .collect();
                for k in 1..ids.len() - 1 {
                    tris.push([pos[ids[0]], pos[ids[k]], pos[ids[k + 1]]]);
                }
            }
            _ => {}
        }
    }
    tris
}

/// A UV sphere of `2·n·n` triangles, radius 1.
fn sphere(n: usize) -> Verts {
    let p = |i: usize, j: usize| {
        let (th, ph) = (
            std::f32::consts::PI * i as f32 / n as f32,
            2.0 * std::f32::consts::PI * j as f32 / n as f32,
        );
        [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]
    };
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            out.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            out.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    out
}

fn tris(v: &Verts) -> Vec<Triangle<f32>> {
    v.iter()
        .map(|t| Triangle::from_f32(*t).expect("usable vertex"))
        .collect()
}

/// Median of `runs` timings of `f`, in milliseconds.
fn time_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[runs / 2]
}

/// Mean nodes visited and triangles tested per closest-hit ray.
fn cost<A: Accel<f32>>(a: &A, rays: &[Ray<f32>]) -> (f64, f64) {
    let mut s = TraversalStats::default();
    for r in rays {
        a.nearest_counted(r, &mut s);
    }
    let n = rays.len() as f64;
    (s.nodes_visited as f64 / n, s.prims_tested as f64 / n)
}

fn main() {
    let before = match std::env::args().nth(1) {
        Some(path) => read_obj(&path),
        None => sphere(202),
    };
    let n = before.len();
    let (lo, hi) = before
        .iter()
        .flatten()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(l, h), p| {
            (
                [0, 1, 2].map(|k| l[k].min(p[k])),
                [0, 1, 2].map(|k| h[k].max(p[k])),
            )
        });
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f32::max);
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    // Primary-like rays from outside towards the middle, 10,000 of them.
    let rays: Vec<Ray<f32>> = (0..10_000)
        .map(|i| {
            let (a, b) = (
                (i % 100) as f32 / 100.0 - 0.5,
                (i / 100) as f32 / 100.0 - 0.5,
            );
            let o = [centre[0], centre[1], centre[2] - 3.0 * size];
            let d = [a * size, b * size, 3.0 * size];
            Ray::from_f32(o, d, 0.0, f32::INFINITY).expect("ray")
        })
        .collect();
    println!("{n} triangles, {} rays", rays.len());
    let options = BuildOptions::default();
    let base = tris(&before);
    let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(n)];
    let mut ids = vec![0u32; n];
    let build_ms = time_ms(5, || {
        Bvh::build(&base, &mut nodes, &mut ids, options).expect("build");
    });
    let shape = Bvh::build(&base, &mut nodes, &mut ids, options)
        .expect("build")
        .shape();
    println!("SAH build (with reinsertion): {build_ms:.2} ms");
    // Small motion: a wave of 1% of the size; large: each triangle moved by up to half the size
    // along a direction that depends on its position (the mesh tears apart).
    let wave = |t: &[[f32; 3]; 3], amp: f32| {
        t.map(|p| {
            let s = (p[0] * 7.0 / size).sin() * (p[1] * 5.0 / size).cos();
            [p[0], p[1], p[2] + amp * size * s]
        })
    };
    let motions: [(&str, Verts); 2] = [
        (
            "small (1% wave)",
            before.iter().map(|t| wave(t, 0.01)).collect(),
        ),
        (
            "large (50% wave)",
            before.iter().map(|t| wave(t, 0.5)).collect(),
        ),
    ];
    for (name, after) in motions {
        let moved = tris(&after);
        let refit_ms = time_ms(5, || {
            Bvh::refit(&moved, &mut nodes, &ids, shape).expect("refit");
        });
        let refit = Bvh::refit(&moved, &mut nodes, &ids, shape).expect("refit");
        let (rn, rp) = cost(&refit, &rays);
        let mut nodes2 = vec![Node::<f32>::EMPTY; nodes_needed(n)];
        let mut ids2 = vec![0u32; n];
        let rebuilt = Bvh::build(&moved, &mut nodes2, &mut ids2, options).expect("build");
        let (bn, bp) = cost(&rebuilt, &rays);
        println!(
            "{name}: refit {refit_ms:.2} ms ({:.1}x faster than the build); per ray: refitted \
             {rn:.1} nodes / {rp:.1} tris, rebuilt {bn:.1} nodes / {bp:.1} tris",
            build_ms / refit_ms
        );
    }
}
