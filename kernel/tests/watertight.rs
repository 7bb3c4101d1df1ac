//! Watertightness: rays from inside a closed mesh always hit it, in both number modes, through
//! the BVH (every builder) and brute force, including rays aimed exactly at vertices and at
//! points on shared edges (computed in the mode's own arithmetic).
//!
//! Meshes share vertices by index, so neighbouring triangles hold bit-identical edges: a
//! subdivided icosphere (also far from the origin), a jittered icosphere and a jittered UV
//! sphere with poles (fans of thin triangles). Also the shared Stanford bunny
//! (`../shared/scenes/bunny.obj` beside the repository): those tests are ignored by default,
//! `--ignored` runs them.
//!
//! Every ray that misses is a leak; the tests count leaks, print the counts and assert zero.
//! All randomness is seeded; a failure prints the seed and the first leaking rays.

mod common;

use common::{all_options, p, with_accel, RaySpec, TestScalar};
use raykernel::bvh::{BuildOptions, BuilderKind};
use raykernel::grid::GridOptions;
use raykernel::kdtree::KdOptions;
use raykernel::{Accel, AccelKind, Linear, Ray, Triangle, I16F16};
use raykernel_testkit::icosphere::unit_icosphere;
use raykernel_testkit::Rng;
use std::collections::HashMap;

const SEED: u64 = 0x0a7e_7715_0001;

/// A triangle mesh over shared vertices.
#[derive(Clone, Debug)]
struct Mesh {
    verts: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
}

impl Mesh {
    fn triangles<S: TestScalar>(&self) -> Vec<Triangle<S>> {
        let verts: Vec<[S; 3]> = self.verts.iter().map(|&v| p::<S>(v)).collect();
        self.faces
            .iter()
            .map(|f| Triangle {
                v: f.map(|i| verts[i as usize]),
            })
            .collect()
    }

    /// Undirected edges with the number of faces using each.
    fn edge_use(&self) -> HashMap<(u32, u32), u32> {
        let mut m = HashMap::new();
        for f in &self.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *m.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        m
    }

    /// Every edge shared by exactly two faces.
    fn is_closed(&self) -> bool {
        self.edge_use().values().all(|&n| n == 2)
    }

    fn edges(&self) -> Vec<(u32, u32)> {
        let mut e: Vec<_> = self.edge_use().into_keys().collect();
        e.sort_unstable();
        e
    }

    fn translated(mut self, by: [f32; 3]) -> Self {
        for v in &mut self.verts {
            *v = [0, 1, 2].map(|i| v[i] + by[i]);
        }
        self
    }
}

/// A unit icosahedron subdivided `level` times (midpoints pushed onto the sphere, shared by
/// index), scaled to `radius`; each vertex's radius is multiplied by `1 + jitter·r`,
/// `r` uniform in [-1, 1).
fn icosphere(level: u32, radius: f64, jitter: f32, rng: &mut Rng) -> Mesh {
    let (verts, faces) = unit_icosphere(level);
    let verts = verts
        .iter()
        .map(|v| {
            let r = radius * (1.0 + (jitter * rng.range(-1.0, 1.0)) as f64);
            v.map(|x| (x * r) as f32)
        })
        .collect();
    Mesh { verts, faces }
}

/// A latitude/longitude sphere with single pole vertices (fans of thin triangles), each
/// vertex's radius jittered as in [`icosphere`].
fn uv_sphere(rings: u32, segments: u32, radius: f64, jitter: f32, rng: &mut Rng) -> Mesh {
    let mut verts = Vec::new();
    let mut at = |theta: f64, phi: f64, rng: &mut Rng| {
        let r = radius * (1.0 + (jitter * rng.range(-1.0, 1.0)) as f64);
        verts.push(
            [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ]
            .map(|x| (x * r) as f32),
        );
    };
    at(0.0, 0.0, rng); // north pole: 0
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            at(
                theta,
                std::f64::consts::TAU * j as f64 / segments as f64,
                rng,
            );
        }
    }
    at(std::f64::consts::PI, 0.0, rng); // south pole: last
    let south = 1 + (rings - 1) * segments;
    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut faces = Vec::new();
    for j in 0..segments {
        faces.push([0, ring(1, j), ring(1, j + 1)]);
        faces.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i + 1, j),
                ring(i + 1, j + 1),
                ring(i, j + 1),
            );
            faces.extend([[a, b, c], [a, c, d]]);
        }
    }
    Mesh { verts, faces }
}

/// Rays from `origin` (an `f32` point, converted to the mode) towards targets computed in the
/// mode: every vertex, every edge midpoint, `edge_points` random points along each edge, then
/// `random_dirs` random and the six axis directions (±0 components).
fn rays_from<S: TestScalar>(
    mesh: &Mesh,
    origin: [f32; 3],
    edge_points: usize,
    random_dirs: usize,
    rng: &mut Rng,
) -> Vec<RaySpec> {
    let o = p::<S>(origin);
    let verts: Vec<[S; 3]> = mesh.verts.iter().map(|&v| p::<S>(v)).collect();
    let towards = |t: [S; 3]| {
        let d = [0, 1, 2].map(|i| (t[i] - o[i]).to_f32());
        // The direction must reach the kernel exactly as computed in the mode.
        assert!(
            (0..3).all(|i| S::from_f32_saturating(d[i]) == t[i] - o[i]),
            "direction not exact in f32: {d:?}"
        );
        RaySpec::new(origin, d)
    };
    let mut rays: Vec<RaySpec> = verts.iter().map(|&v| towards(v)).collect();
    for (a, b) in mesh.edges() {
        let (a, b) = (verts[a as usize], verts[b as usize]);
        rays.push(towards([0, 1, 2].map(|i| (a[i] + b[i]).half())));
        for _ in 0..edge_points {
            let s = common::c::<S>(rng.unit());
            rays.push(towards([0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * s)));
        }
    }
    for _ in 0..random_dirs {
        rays.push(RaySpec::new(origin, rng.unit_vec()));
    }
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let mut d = [if sign > 0.0 { 0.0 } else { -0.0 }; 3];
            d[axis] = sign;
            rays.push(RaySpec::new(origin, d));
        }
    }
    rays
}

/// Leaks of one accelerator over `rays`, with up to 5 of them described.
fn count_leaks<S: TestScalar>(accel: &impl Accel<S>, rays: &[RaySpec]) -> (usize, Vec<String>) {
    let mut leaks = 0;
    let mut shown = Vec::new();
    for r in rays {
        let ray: Ray<S> = r.ray();
        let hit = accel.intersect(&ray);
        if hit.is_none() || !accel.occluded(&ray) {
            leaks += 1;
            if shown.len() < 5 {
                shown.push(format!("{r} (hit {hit:?})"));
            }
        }
    }
    (leaks, shown)
}

/// Runs `rays` through a BVH from each of `builders`, and every `linear_stride`-th ray through
/// Linear (none for 0; brute force is slow in debug builds); returns the total leak count and
/// a report line per accelerator.
fn leak_report<S: TestScalar>(
    name: &str,
    tris: &[Triangle<S>],
    rays: &[RaySpec],
    builders: &[BuildOptions],
    linear_stride: usize,
) -> (usize, Vec<String>) {
    // Each BVH, then the uniform grid and the kd-tree with default options.
    let kinds = builders.iter().map(|&o| AccelKind::Bvh(o)).chain([
        AccelKind::Grid(GridOptions::DEFAULT),
        AccelKind::KdTree(KdOptions::DEFAULT),
    ]);
    let mut total = 0;
    let mut lines = Vec::new();
    let mut note = |accel: String, count: usize, (leaks, shown): (usize, Vec<String>)| {
        total += leaks;
        lines.push(format!(
            "{name} [{}] {accel}: {leaks} leaks of {count} rays (seed {SEED:#x}){}",
            S::NAME,
            shown
                .iter()
                .map(|s| format!("\n    leak: {s}"))
                .collect::<String>()
        ));
    };
    if linear_stride > 0 {
        let sample: Vec<RaySpec> = rays.iter().step_by(linear_stride).copied().collect();
        let (leaks, shown) = count_leaks(&Linear::new(tris), &sample);
        let accel = format!("linear (every {linear_stride}th ray)");
        note(accel, sample.len(), (leaks, shown));
    }
    for kind in kinds {
        // Built and validated by the helper.
        let leaks = with_accel::<S, _, _>(kind, tris, |accel| count_leaks(accel, rays));
        note(kind.to_string(), rays.len(), leaks);
    }
    (total, lines)
}

fn builders_leaf4() -> Vec<BuildOptions> {
    BuilderKind::ALL
        .into_iter()
        .map(|builder| BuildOptions {
            builder,
            max_leaf_size: 4,
            reinsertion: true,
        })
        .collect()
}

/// Rays from the centre and from random interior points (within `inner` of the centre) of a
/// closed mesh: none may leak.
fn closed_mesh_cases<S: TestScalar>(name: &str, mesh: &Mesh, center: [f32; 3], inner: f32) {
    assert!(mesh.is_closed(), "{name} is not closed");
    let mut rng = Rng::new(SEED);
    let mut origins = vec![center];
    for _ in 0..4 {
        let q = rng.in_ball(inner);
        origins.push([0, 1, 2].map(|i| center[i] + q[i]));
    }
    let mut rays = Vec::new();
    for &origin in &origins {
        rays.extend(rays_from::<S>(mesh, origin, 2, 500, &mut rng));
    }
    let name = format!("{name}, {} origins", origins.len());
    let (leaks, lines) = leak_report(&name, &mesh.triangles::<S>(), &rays, &builders_leaf4(), 1);
    for l in &lines {
        println!("{l}");
    }
    assert_eq!(leaks, 0, "{}", lines.join("\n"));
}

fn exact_icosphere_cases<S: TestScalar>() {
    let mesh = icosphere(3, 50.0, 0.0, &mut Rng::new(SEED));
    closed_mesh_cases::<S>("icosphere L3 r50", &mesh, [0.0; 3], 25.0);
}

fn far_icosphere_cases<S: TestScalar>() {
    let c = [1000.5, -2000.25, 500.0];
    let mesh = icosphere(3, 50.0, 0.0, &mut Rng::new(SEED)).translated(c);
    closed_mesh_cases::<S>(
        "icosphere L3 r50 at (1000.5, -2000.25, 500)",
        &mesh,
        c,
        25.0,
    );
}

fn jittered_icosphere_cases<S: TestScalar>() {
    let mesh = icosphere(3, 40.0, 0.15, &mut Rng::new(SEED ^ 1));
    closed_mesh_cases::<S>("jittered icosphere L3 r40±15%", &mesh, [0.0; 3], 20.0);
}

fn jittered_uv_sphere_cases<S: TestScalar>() {
    let mesh = uv_sphere(24, 48, 30.0, 0.1, &mut Rng::new(SEED ^ 2));
    closed_mesh_cases::<S>("jittered UV sphere 24x48 r30±10%", &mesh, [0.0; 3], 15.0);
}

/// A finer, slightly jittered icosphere (level 4, 5120 triangles) through the BVH only, every
/// builder and leaf size: vertices, edge midpoints, one random point per edge and random
/// directions, from the centre and one interior point.
fn fine_icosphere_cases<S: TestScalar>() {
    let mesh = icosphere(4, 60.0, 0.05, &mut Rng::new(SEED ^ 3));
    assert!(mesh.is_closed());
    let tris = mesh.triangles::<S>();
    let mut rng = Rng::new(SEED ^ 4);
    let mut rays = Vec::new();
    for origin in [[0.0; 3], [7.25, -11.5, 3.0]] {
        rays.extend(rays_from::<S>(&mesh, origin, 1, 500, &mut rng));
    }
    let options: Vec<_> = all_options().collect();
    let (leaks, lines) = leak_report("icosphere L4, 2 origins", &tris, &rays, &options, 0);
    for l in &lines {
        println!("{l}");
    }
    assert_eq!(leaks, 0, "{}", lines.join("\n"));
}

#[test]
fn ray_from_inside_icosphere_always_hits_f32() {
    exact_icosphere_cases::<f32>();
}
#[test]
fn ray_from_inside_icosphere_always_hits_fixed() {
    exact_icosphere_cases::<I16F16>();
}
#[test]
fn ray_from_inside_far_icosphere_always_hits_f32() {
    far_icosphere_cases::<f32>();
}
#[test]
fn ray_from_inside_far_icosphere_always_hits_fixed() {
    far_icosphere_cases::<I16F16>();
}
#[test]
fn ray_from_inside_jittered_icosphere_always_hits_f32() {
    jittered_icosphere_cases::<f32>();
}
#[test]
fn ray_from_inside_jittered_icosphere_always_hits_fixed() {
    jittered_icosphere_cases::<I16F16>();
}
#[test]
fn ray_from_inside_jittered_uv_sphere_always_hits_f32() {
    jittered_uv_sphere_cases::<f32>();
}
#[test]
fn ray_from_inside_jittered_uv_sphere_always_hits_fixed() {
    jittered_uv_sphere_cases::<I16F16>();
}
#[test]
fn ray_from_inside_fine_icosphere_always_hits_every_builder_f32() {
    fine_icosphere_cases::<f32>();
}
#[test]
fn ray_from_inside_fine_icosphere_always_hits_every_builder_fixed() {
    fine_icosphere_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// Rays aimed at vertices from outside, along the vertex normal: they cross the vertex's fan,
// so they hit (something, possibly nearer) unless the vertex lies on an open boundary.

/// Area-weighted vertex normals (in f64), and which vertices have a closed fan.
fn normals_and_interior(mesh: &Mesh) -> (Vec<[f64; 3]>, Vec<bool>) {
    let mut n = vec![[0.0f64; 3]; mesh.verts.len()];
    for f in &mesh.faces {
        let v = f.map(|i| mesh.verts[i as usize].map(f64::from));
        let (a, b) = (
            [0, 1, 2].map(|i| v[1][i] - v[0][i]),
            [0, 1, 2].map(|i| v[2][i] - v[0][i]),
        );
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        for &i in f {
            for k in 0..3 {
                n[i as usize][k] += c[k];
            }
        }
    }
    let mut interior = vec![true; mesh.verts.len()];
    for ((a, b), uses) in mesh.edge_use() {
        if uses != 2 {
            interior[a as usize] = false;
            interior[b as usize] = false;
        }
    }
    (n, interior)
}

/// For every vertex with a closed fan and a usable normal: a ray from `dist` outside along the
/// normal, aimed (in the mode) exactly at the vertex.
fn rays_along_normals<S: TestScalar>(mesh: &Mesh, dist: f64) -> Vec<RaySpec> {
    let (normals, interior) = normals_and_interior(mesh);
    let mut rays = Vec::new();
    for (i, &v) in mesh.verts.iter().enumerate() {
        let nl = normals[i].iter().map(|x| x * x).sum::<f64>().sqrt();
        if !interior[i] || nl.is_nan() || nl <= 0.0 {
            continue;
        }
        let o: [f32; 3] = [0, 1, 2].map(|k| (v[k] as f64 + normals[i][k] / nl * dist) as f32);
        let (os, vs) = (p::<S>(o), p::<S>(v));
        let d = [0, 1, 2].map(|k| (vs[k] - os[k]).to_f32());
        if d != [0.0; 3] {
            rays.push(RaySpec::new(o, d));
        }
    }
    rays
}

fn outside_normal_cases<S: TestScalar>() {
    let mesh = icosphere(3, 50.0, 0.1, &mut Rng::new(SEED ^ 5));
    let rays = rays_along_normals::<S>(&mesh, 10.0);
    let (leaks, lines) = leak_report(
        "icosphere vertices from outside",
        &mesh.triangles::<S>(),
        &rays,
        &builders_leaf4(),
        1,
    );
    for l in &lines {
        println!("{l}");
    }
    assert_eq!(leaks, 0, "{}", lines.join("\n"));
}

#[test]
fn ray_at_vertex_from_outside_along_normal_hits_f32() {
    outside_normal_cases::<f32>();
}
#[test]
fn ray_at_vertex_from_outside_along_normal_hits_fixed() {
    outside_normal_cases::<I16F16>();
}

// ---------------------------------------------------------------------------------------------
// The shared Stanford bunny.

/// Parses the `v` and `f` lines of a canonical OBJ (1-based, triangles only).
fn parse_obj(text: &str) -> Mesh {
    let mut mesh = Mesh {
        verts: Vec::new(),
        faces: Vec::new(),
    };
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let v: Vec<f32> = it.map(|x| x.parse().expect("vertex coordinate")).collect();
                mesh.verts.push([v[0], v[1], v[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = it
                    .map(|x| {
                        x.split('/')
                            .next()
                            .unwrap()
                            .parse::<u32>()
                            .expect("face index")
                            - 1
                    })
                    .collect();
                assert_eq!(f.len(), 3, "non-triangle face: {line}");
                mesh.faces.push([f[0], f[1], f[2]]);
            }
            _ => {}
        }
    }
    mesh
}

/// The shared bunny; the tests using it are `#[ignore]`d by default and fail here when
/// `../shared` is missing, so `--ignored` never passes without it.
fn load_bunny() -> Mesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/scenes/bunny.obj");
    match std::fs::read_to_string(path) {
        Ok(text) => parse_obj(&text),
        Err(e) => panic!("../shared not found ({path}): {e}"),
    }
}

/// Distances of every crossing of the ray with the mesh, sorted (brute force over the
/// triangles; cheaper in debug builds than building a tree).
fn all_hits(tris: &[Triangle<f32>], r: RaySpec) -> Vec<f32> {
    let ray = r.ray::<f32>();
    let mut out: Vec<f32> = tris
        .iter()
        .filter_map(|t| t.intersect(&ray))
        .map(|h| h.t)
        .collect();
    out.sort_by(f32::total_cmp);
    out
}

/// A point inside a closed mesh: the middle of the longest inside segment of an axis ray
/// through the bounding-box centre, confirmed by odd crossing counts along the other axes.
fn point_inside(mesh: &Mesh, tris: &[Triangle<f32>]) -> [f32; 3] {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for v in &mesh.verts {
        for i in 0..3 {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
        }
    }
    let center = [0, 1, 2].map(|i| (lo[i] + hi[i]) * 0.5);
    for axis in 0..3 {
        let mut o = center;
        o[axis] = lo[axis] - 1.0;
        let mut d = [0.0; 3];
        d[axis] = 1.0;
        let hits = all_hits(tris, RaySpec::new(o, d));
        // Entering at even indices, leaving at odd ones.
        let Some((a, b)) = hits
            .chunks_exact(2)
            .map(|w| (w[0], w[1]))
            .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        else {
            continue;
        };
        let mut q = o;
        q[axis] += (a + b) * 0.5;
        let odd = (0..3).filter(|&k| k != axis).all(|k| {
            let mut d = [0.0; 3];
            d[k] = 1.0;
            all_hits(tris, RaySpec::new(q, d)).len() % 2 == 1
        });
        if odd {
            return q;
        }
    }
    panic!("no interior point found");
}

fn bunny_cases<S: TestScalar>() {
    let mesh = load_bunny();
    // Rays along the vertex normals from outside, aimed at every vertex with a closed fan.
    let mut rays = rays_along_normals::<S>(&mesh, 0.5);
    let mut name = String::from("bunny: vertices along normals from outside");
    if mesh.is_closed() {
        // Closed: also rays from a point inside, aimed at every vertex.
        let inside = point_inside(&mesh, &mesh.triangles::<f32>());
        println!("bunny: inside point {inside:?}");
        let o = p::<S>(inside);
        rays.extend(mesh.verts.iter().map(|&v| {
            let v = p::<S>(v);
            RaySpec::new(inside, [0, 1, 2].map(|i| (v[i] - o[i]).to_f32()))
        }));
        name.push_str(" and from inside");
    } else {
        println!("bunny is open: checking rays at vertices from outside only");
    }
    let stride = rays.len() / 300 + 1;
    let sah = [BuildOptions::default()];
    let (leaks, lines) = leak_report(&name, &mesh.triangles::<S>(), &rays, &sah, stride);
    for l in &lines {
        println!("{l}");
    }
    assert_eq!(leaks, 0, "{}", lines.join("\n"));
}

#[test]
#[ignore = "needs ../shared"]
fn ray_at_bunny_vertex_always_hits_f32() {
    bunny_cases::<f32>();
}

#[test]
#[ignore = "needs ../shared"]
fn ray_at_bunny_vertex_always_hits_fixed() {
    bunny_cases::<I16F16>();
}
