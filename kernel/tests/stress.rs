//! Numerical stability stress suite: counts leaks, false hits (self-hits of spawned
//! rays, hits on zero-area triangles) and mismatches (BVH builders vs each other and vs brute
//! force, `occluded` vs `intersect`, wrong or missing typed errors, panics) per ray class, in
//! both number modes, with a Möller–Trumbore contrast column (test-only code, not the kernel).
//!
//! One test per ray class and mode (`watertight_f32`, `spawned_fixed`, ...), each failing unless
//! the kernel's counts of its classes are zero. `cargo xtask stress` runs the ignored `table`
//! test over the full matrix and writes the Markdown table of docs/STRESS.md.
//! `STRESS_FULL=1` selects the full matrix, `STRESS_SPAWN=N` the spawned rays per mode.
// MT keeps its textbook comparisons (NaN-safe as written).
#![allow(clippy::manual_range_contains, clippy::type_complexity)]

mod common;

use common::{hit_bits, TestScalar};
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::spawn::{offset_origin, spawn_ray, spawn_shadow_ray};
use raykernel::{
    grid::GridOptions, kdtree::KdOptions, Aabb, Accel, AccelKind, AccelVisitor, AnyAccel, Arena,
    Barycentrics, BuildError, Bvh, Hit, Linear, Node, PointError, Primitive, Ray, RayData,
    RayError, Scalar, Triangle, Vec3x, VertexError, I16F16,
};
use raykernel_testkit::icosphere::unit_icosphere;
use raykernel_testkit::memory::OwnedMemory;
use raykernel_testkit::vec3::{cross, dot, normalize, sub};
use raykernel_testkit::Rng;
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::OnceLock;

const SEED: u64 = 0x5757_2e55_0006;

// ---------------------------------------------------------------------------------------------
// Counters and the table.

/// Counts for one ray class in one column (a mode, or Möller–Trumbore).
#[derive(Clone, Copy, Debug, Default)]
struct Count {
    rays: u64,
    leaks: u64,
    false_hits: u64,
    mismatches: u64,
}

impl Count {
    fn add(&mut self, o: Count) {
        self.rays += o.rays;
        self.leaks += o.leaks;
        self.false_hits += o.false_hits;
        self.mismatches += o.mismatches;
    }
}

/// Column names.
const F32: &str = "f32";
const FIXED: &str = "fixed";
const MT: &str = "mt";

/// (class, column) -> counts, plus the first few failures per class for the assertion message.
#[derive(Default)]
struct Table {
    rows: BTreeMap<(usize, String), BTreeMap<&'static str, Count>>,
    failures: Vec<String>,
    /// Classes reported only (not asserted), e.g. spawning without the offset rule.
    informational: Vec<String>,
}

impl Table {
    /// Adds `other`'s counts, failures and informational classes to this table's.
    fn merge(&mut self, other: Table) {
        for (key, cols) in other.rows {
            let row = self.rows.entry(key).or_default();
            for (col, c) in cols {
                row.entry(col).or_default().add(c);
            }
        }
        self.failures.extend(other.failures);
        for class in other.informational {
            if !self.informational.contains(&class) {
                self.informational.push(class);
            }
        }
    }
}

thread_local! {
    /// The counts of the classes run on this thread: each test runs on its own thread, so each
    /// test sees only what it ran.
    static TABLE: RefCell<Table> = RefCell::new(Table::default());
}

/// Ordered row names (the number sorts the table).
fn class_order(class: &str) -> usize {
    const ORDER: [&str; 12] = [
        "watertight: at vertices",
        "watertight: at shared edges",
        "watertight: at interior points",
        "axis-parallel (±0 components) at grid vertices/edges",
        "rays in a triangle's plane",
        "box faces, edges, corners (slab)",
        "spawned: reflection and hemisphere",
        "spawned: shadow rays",
        "spawned without offset (informational)",
        "degenerate input",
        "bad input",
        "",
    ];
    ORDER
        .iter()
        .position(|c| *c == class)
        .unwrap_or(ORDER.len())
}

fn record(class: &str, column: &'static str, c: Count, failures: Vec<String>) {
    TABLE.with_borrow_mut(|t| record_in(t, class, column, c, failures));
}

fn record_in(t: &mut Table, class: &str, column: &'static str, c: Count, failures: Vec<String>) {
    t.rows
        .entry((class_order(class), class.to_string()))
        .or_default()
        .entry(column)
        .or_default()
        .add(c);
    if column != MT && !class.contains("informational") {
        for f in failures.into_iter().take(3) {
            if t.failures.len() < 30 {
                t.failures.push(format!("{class} [{column}]: {f}"));
            }
        }
    } else if class.contains("informational") && !t.informational.contains(&class.to_string()) {
        t.informational.push(class.to_string());
    }
}

fn table_markdown(t: &Table) -> String {
    let mut s = String::new();
    s.push_str(
        "| ray class | rays f32 / fixed / MT | leaks f32 | leaks fixed | leaks MT | false or self-hits f32 | fixed | MT | mismatches f32 | fixed |\n",
    );
    s.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    for ((_, class), cols) in &t.rows {
        let g = |c: &str| cols.get(c).copied();
        let n =
            |c: &str, f: fn(&Count) -> u64| g(c).map_or("–".to_string(), |x| f(&x).to_string());
        s.push_str(&format!(
            "| {class} | {} / {} / {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            n(F32, |c| c.rays),
            n(FIXED, |c| c.rays),
            n(MT, |c| c.rays),
            n(F32, |c| c.leaks),
            n(FIXED, |c| c.leaks),
            n(MT, |c| c.leaks),
            n(F32, |c| c.false_hits),
            n(FIXED, |c| c.false_hits),
            n(MT, |c| c.false_hits),
            n(F32, |c| c.mismatches),
            n(FIXED, |c| c.mismatches),
        ));
    }
    s
}

// ---------------------------------------------------------------------------------------------
// Number modes.

/// What the suite needs from a mode on top of the shared test helpers.
trait Mode: TestScalar {
    const COLUMN: &'static str;
    /// Rounds a coordinate to the mode (the caller keeps it in range).
    fn from_f64(x: f64) -> Self;
    /// A ray from `o` aimed at `target`, the direction computed as exactly as the mode allows
    /// (exact integer difference in fixed point, `f64` difference rounded once in `f32`).
    fn ray_to(o: [Self; 3], target: [Self; 3]) -> Result<Ray<Self>, RayError>;
    /// A ray from `o` along an `f64` direction.
    fn ray_along(o: [Self; 3], d: [f64; 3]) -> Result<Ray<Self>, RayError>;
}

impl Mode for f32 {
    const COLUMN: &'static str = F32;
    fn from_f64(x: f64) -> f32 {
        x as f32
    }
    fn ray_to(o: [f32; 3], t: [f32; 3]) -> Result<Ray<f32>, RayError> {
        let d = [0, 1, 2].map(|k| (f64::from(t[k]) - f64::from(o[k])) as f32);
        Ray::from_f32(o, d, 0.0, f32::INFINITY)
    }
    fn ray_along(o: [f32; 3], d: [f64; 3]) -> Result<Ray<f32>, RayError> {
        Ray::from_f32(o, d.map(|x| x as f32), 0.0, f32::INFINITY)
    }
}

impl Mode for I16F16 {
    const COLUMN: &'static str = FIXED;
    fn from_f64(x: f64) -> I16F16 {
        I16F16::from_raw((x * 65536.0).round() as i32)
    }
    fn ray_to(o: [I16F16; 3], t: [I16F16; 3]) -> Result<Ray<I16F16>, RayError> {
        let d = [0, 1, 2].map(|k| {
            let r = i64::from(t[k].raw()) - i64::from(o[k].raw());
            I16F16::from_raw(r.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32)
        });
        Ray::new(Vec3x::new(o[0], o[1], o[2]), Vec3x::new(d[0], d[1], d[2]))
    }
    fn ray_along(o: [I16F16; 3], d: [f64; 3]) -> Result<Ray<I16F16>, RayError> {
        // Scale the direction up so Q16.16 keeps plenty of its bits.
        let m = d.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let q = d.map(|x| I16F16::from_raw((x / m * 65536.0 * 4096.0).round() as i32));
        Ray::new(Vec3x::new(o[0], o[1], o[2]), Vec3x::new(q[0], q[1], q[2]))
    }
}

fn to_f64<S: Mode>(p: [S; 3]) -> [f64; 3] {
    p.map(Scalar::to_f64)
}

fn tri_normal<S: Mode>(t: &Triangle<S>) -> [f64; 3] {
    let v = t.v.map(to_f64::<S>);
    normalize(cross(sub(v[1], v[0]), sub(v[2], v[0])))
}

// ---------------------------------------------------------------------------------------------
// Möller–Trumbore, the contrast column (f32, as usually written: `det == 0` rejected exactly,
// NaN-safe comparisons). It implements the kernel's `Primitive` trait, so it runs under the
// kernel's BVH, whose conservative traversal does not lose hits: every leak is the test's.

#[derive(Clone, Copy, Debug)]
struct MtTri(Triangle<f32>);

fn mt_t(o: [f32; 3], d: [f32; 3], v: &[[f32; 3]; 3], t_min: f32, t_max: f32) -> Option<f32> {
    let s3 = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let c3 = |a: [f32; 3], b: [f32; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let d3 = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let e1 = s3(v[1], v[0]);
    let e2 = s3(v[2], v[0]);
    let p = c3(d, e2);
    let det = d3(e1, p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = s3(o, v[0]);
    let u = d3(s, p) * inv;
    if !(u >= 0.0 && u <= 1.0) {
        return None;
    }
    let q = c3(s, e1);
    let w = d3(d, q) * inv;
    if !(w >= 0.0 && u + w <= 1.0) {
        return None;
    }
    let t = d3(e2, q) * inv;
    (t >= t_min && t <= t_max).then_some(t)
}

impl Primitive<f32> for MtTri {
    fn bounds(&self) -> Aabb<f32> {
        self.0.bounds()
    }
    fn check(&self) -> Result<(), VertexError> {
        self.0.check()
    }
    fn hit_t(&self, ray: &RayData<f32>, t_min: f32, t_max: f32) -> Option<f32> {
        let o = <f32 as Scalar>::ray_origin(ray);
        let d = <f32 as Scalar>::ray_dir(ray);
        mt_t(o, d, &self.0.v, t_min, t_max)
    }
    fn hit_uv(&self, _ray: &RayData<f32>) -> Barycentrics<f32> {
        Barycentrics::ZERO
    }
}

// ---------------------------------------------------------------------------------------------
// Meshes, in f64 until placed and rounded into a mode.

#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    /// Convex: every point strictly inside the unit ball's 0.5 radius is inside.
    Sphere,
    /// Torus around z, radii `R = 1`, `r = 0.35`: inside the tube around the core circle.
    Torus,
    /// Closed, non-convex; `inside` is a checked interior point.
    Bunny([f64; 3]),
}

#[derive(Clone, Debug)]
struct Mesh {
    name: String,
    shape: Shape,
    verts: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    /// Largest coordinate magnitude before placement.
    extent: f64,
}

impl Mesh {
    fn edges(&self) -> Vec<(u32, u32)> {
        let mut m: HashMap<(u32, u32), u32> = HashMap::new();
        for f in &self.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *m.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(m.values().all(|&n| n == 2), "{} is not closed", self.name);
        let mut e: Vec<_> = m.into_keys().collect();
        e.sort_unstable();
        e
    }
}

fn icosphere(level: u32) -> Mesh {
    let (verts, faces) = unit_icosphere(level);
    Mesh {
        name: format!("icosphere{level}"),
        shape: Shape::Sphere,
        verts,
        faces,
        extent: 1.0,
    }
}

fn torus(major: u32, minor: u32) -> Mesh {
    let (rr, r) = (1.0f64, 0.35f64);
    let mut verts = Vec::new();
    for i in 0..major {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(major);
        for j in 0..minor {
            let b = std::f64::consts::TAU * f64::from(j) / f64::from(minor);
            let w = rr + r * b.cos();
            verts.push([w * a.cos(), w * a.sin(), r * b.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % major) * minor + (j % minor);
    let mut faces = Vec::new();
    for i in 0..major {
        for j in 0..minor {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    Mesh {
        name: format!("torus{major}x{minor}"),
        shape: Shape::Torus,
        verts,
        faces,
        extent: rr + r,
    }
}

/// The shared bunny, centred at its bounding-box centre, with an interior point found by
/// crossing parity (brute force in f64-safe f32 geometry).
fn bunny() -> Option<Mesh> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/scenes/bunny.obj");
    let Ok(text) = std::fs::read_to_string(path) else {
        println!("skipped bunny: ../shared not found ({path})");
        return None;
    };
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let mut faces = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let v: Vec<f64> = it.map(|x| x.parse().expect("coordinate")).collect();
                verts.push([v[0], v[1], v[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = it
                    .map(|x| x.split('/').next().unwrap().parse::<u32>().expect("index") - 1)
                    .collect();
                faces.push([f[0], f[1], f[2]]);
            }
            _ => {}
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in &verts {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let c = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0);
    for v in &mut verts {
        *v = sub(*v, c);
    }
    let extent = verts
        .iter()
        .flat_map(|v| v.iter())
        .fold(0.0f64, |a, x| a.max(x.abs()));
    // Interior point: the middle of the longest inside segment of a z ray through the centre
    // column, confirmed by odd crossing counts along x and y.
    let tris: Vec<Triangle<f32>> = faces
        .iter()
        .map(|f: &[u32; 3]| Triangle {
            v: f.map(|i| verts[i as usize].map(|x| x as f32)),
        })
        .collect();
    let crossings = |o: [f32; 3], d: [f32; 3]| {
        let ray = Ray::<f32>::from_f32(o, d, 0.0, f32::INFINITY).unwrap();
        let mut h: Vec<f32> = tris
            .iter()
            .filter_map(|t| t.intersect(&ray).map(|x| x.t))
            .collect();
        h.sort_by(f32::total_cmp);
        h
    };
    let mut inside = None;
    'search: for dx in [0.0f32, 0.5, -0.5, 1.0, -1.0] {
        for dy in [0.0f32, 0.5, -0.5, 1.0, -1.0] {
            let o = [dx, dy, -(extent as f32) - 1.0];
            let h = crossings(o, [0.0, 0.0, 1.0]);
            let Some((a, b)) = h
                .chunks_exact(2)
                .map(|w| (w[0], w[1]))
                .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
            else {
                continue;
            };
            let q = [o[0], o[1], o[2] + (a + b) / 2.0];
            if crossings(q, [1.0, 0.0, 0.0]).len() % 2 == 1
                && crossings(q, [0.0, 1.0, 0.0]).len() % 2 == 1
            {
                inside = Some(q.map(f64::from));
                break 'search;
            }
        }
    }
    let inside = inside.expect("bunny: no interior point");
    Some(Mesh {
        name: "bunny".into(),
        shape: Shape::Bunny(inside),
        verts,
        faces,
        extent,
    })
}

/// A mesh placed (scaled, translated) and rounded into mode `S`.
struct Placed<S: Mode> {
    tris: Vec<Triangle<S>>,
    verts: Vec<[S; 3]>,
    scale: f64,
    shift: [f64; 3],
}

fn place<S: Mode>(mesh: &Mesh, scale: f64, shift: [f64; 3]) -> Placed<S> {
    let verts: Vec<[S; 3]> = mesh
        .verts
        .iter()
        .map(|v| [0, 1, 2].map(|k| S::from_f64(v[k] * scale + shift[k])))
        .collect();
    let tris = mesh
        .faces
        .iter()
        .map(|f| Triangle {
            v: f.map(|i| verts[i as usize]),
        })
        .collect();
    Placed {
        tris,
        verts,
        scale,
        shift,
    }
}

impl<S: Mode> Placed<S> {
    fn world(&self, p: [f64; 3]) -> [S; 3] {
        [0, 1, 2].map(|k| S::from_f64(p[k] * self.scale + self.shift[k]))
    }
}

/// An interior point of the mesh (in mesh coordinates) near which to start a ray aimed at
/// `target` (mesh coordinates).
fn interior(mesh: &Mesh, target: [f64; 3], rng: &mut Rng) -> [f64; 3] {
    match mesh.shape {
        Shape::Sphere => {
            let j = rng.in_ball(0.5);
            [0, 1, 2].map(|k| f64::from(j[k]))
        }
        Shape::Torus => {
            let a = target[1].atan2(target[0]);
            let j = rng.in_ball(0.15);
            [
                a.cos() + f64::from(j[0]),
                a.sin() + f64::from(j[1]),
                f64::from(j[2]),
            ]
        }
        Shape::Bunny(p) => p,
    }
}

// ---------------------------------------------------------------------------------------------
// Accelerators and per-ray checks.

/// The structures every ray goes through, each checked against the first (SAH/4, the answer):
/// median/1, midpoint/8, the 4-wide and the 8-wide BVH (SAH/4), the uniform grid and the
/// kd-tree (default options), and brute force on every `linear_stride`-th ray.
fn kinds() -> [AccelKind; 7] {
    let bvh = |builder, max_leaf_size| BuildOptions {
        builder,
        max_leaf_size,
        reinsertion: true,
    };
    [
        AccelKind::Bvh(bvh(BuilderKind::Sah, 4)),
        AccelKind::Bvh(bvh(BuilderKind::Median, 1)),
        AccelKind::Bvh(bvh(BuilderKind::Midpoint, 8)),
        AccelKind::Bvh4(bvh(BuilderKind::Sah, 4)),
        AccelKind::Bvh8(bvh(BuilderKind::Sah, 4)),
        AccelKind::Grid(GridOptions::DEFAULT),
        AccelKind::KdTree(KdOptions::DEFAULT),
    ]
}

struct Accels<'a, S: Mode> {
    /// Built [`kinds`], in order; the first gives the answer.
    built: Vec<(AccelKind, AnyAccel<'a, S, Triangle<S>>)>,
    linear: Linear<'a, S, Triangle<S>>,
    linear_stride: usize,
}

/// One buffer set per structure, reused (resized) from one mesh placement to the next.
struct Arenas<S: Scalar>(Vec<OwnedMemory<S>>);

impl<S: Mode> Arenas<S> {
    fn new() -> Self {
        Self(kinds().map(|_| OwnedMemory::default()).into())
    }
}

/// Builds every structure of [`kinds`] over `tris` into exactly the memory it needs and checks
/// its invariants.
fn accels<'a, S: Mode>(tris: &'a [Triangle<S>], arenas: &'a mut Arenas<S>) -> Accels<'a, S> {
    let built = kinds()
        .into_iter()
        .zip(arenas.0.iter_mut())
        .map(|(kind, arena)| {
            arena.resize(OwnedMemory::<S>::needed(kind, tris));
            let accel = AnyAccel::build(kind, tris, &mut arena.memory())
                .unwrap_or_else(|e| panic!("build {kind}: {e}"));
            accel.validate().unwrap_or_else(|e| panic!("{kind}: {e}"));
            (kind, accel)
        })
        .collect();
    Accels {
        built,
        linear: Linear::new(tris),
        linear_stride: if tris.len() <= 2048 { 1 } else { 97 },
    }
}

impl<'a, S: Mode> Accels<'a, S> {
    /// The structure that gives the answer (SAH/4).
    fn answer(&self) -> &AnyAccel<'a, S, Triangle<S>> {
        &self.built[0].1
    }
}

/// The closest hit and the any-hit answer of one ray, through whichever structure it visits.
struct Query<'r, S: Scalar>(&'r Ray<S>);

impl<S: Scalar> AccelVisitor<S> for Query<'_, S> {
    type Output = (Option<Hit<S>>, bool);
    fn visit<A: Accel<S>>(self, accel: &A) -> Self::Output {
        (accel.intersect(self.0), accel.occluded(self.0))
    }
}

/// Closest hit of the first structure (SAH/4); `mismatch` is set if any other structure (or
/// `occluded`) disagrees.
fn trace<S: Mode>(a: &Accels<S>, ray: &Ray<S>, index: usize) -> (Option<Hit<S>>, Option<String>) {
    let (first, answer) = &a.built[0];
    let (h, occluded) = answer.visit(Query(ray));
    let mut bad = None;
    let want = hit_bits(&h);
    let mut check = |name: &dyn std::fmt::Display, (got, occ): (Option<Hit<S>>, bool)| {
        if hit_bits(&got) != want || occ != got.is_some() {
            bad.get_or_insert_with(|| {
                format!("{name}: {got:?} (occluded {occ}) vs {first} {h:?}, ray {ray:?}")
            });
        }
    };
    check(first, (h, occluded));
    for (kind, accel) in &a.built[1..] {
        check(kind, accel.visit(Query(ray)));
    }
    if index % a.linear_stride == 0 {
        check(&"linear", Query(ray).visit(&a.linear));
    }
    (h, bad)
}

// ---------------------------------------------------------------------------------------------
// Placements.

/// (scale, shift) pairs for a mesh of extent `e` in mode `S`; `f32` skips placements where the
/// mesh would be smaller than about 2^-16 of the shift, a few hundred ulps (it
/// collapses onto a coarse grid).
fn placements_for<S: Mode>(mesh: &Mesh) -> (Vec<(f64, [f64; 3])>, usize) {
    let (all, skipped) = placements::<S>(mesh.extent);
    if mesh.faces.len() > 10_000 && !full() {
        // Large meshes: the first, the largest and one in the middle.
        let n = all.len();
        let picked = [0, n / 2, n - 1].iter().map(|&i| all[i]).collect();
        return (picked, skipped);
    }
    (all, skipped)
}

fn placements<S: Mode>(e: f64) -> (Vec<(f64, [f64; 3])>, usize) {
    let dir = [1.0, -0.75, 0.5];
    let mut out = Vec::new();
    let mut skipped = 0;
    if S::COLUMN == F32 {
        for s in [1e-4, 1e-2, 1.0, 1e2, 1e4] {
            for t in [0.0, 1e2, 1e4, 1e5] {
                if t > 0.0 && s * e < t * 2f64.powi(-16) {
                    skipped += 1;
                    continue;
                }
                out.push((s / e, dir.map(|d| d * t)));
            }
        }
    } else {
        // Fixed point: mesh sizes from 2^-6 to the whole range, up to the ±8192 limit.
        for size in [0.02, 1.0, 100.0, 4000.0] {
            for t in [0.0, 100.0, 4000.0, 8191.0 - size] {
                if size + t > 8191.0 || (t == 8191.0 - size && t <= 4000.0) {
                    continue;
                }
                out.push((size / e, [t, -t, t]));
            }
        }
        out.push((8191.0 / e, [0.0; 3]));
    }
    (out, skipped)
}

fn meshes() -> Vec<Mesh> {
    let mut m = vec![icosphere(1), icosphere(3), torus(12, 8), torus(48, 24)];
    m.extend(bunny());
    m
}

// ---------------------------------------------------------------------------------------------
// Watertightness: rays from inside at vertices, shared edges and interior points.

fn watertight<S: Mode>(meshes: &[Mesh]) {
    let mut rng = Rng::new(SEED ^ 1);
    let classes = [
        "watertight: at vertices",
        "watertight: at shared edges",
        "watertight: at interior points",
    ];
    let mut counts = [Count::default(); 3];
    let mut mt_counts = [Count::default(); 3];
    let mut fails: [Vec<String>; 3] = Default::default();
    let mut skipped_total = 0;
    for mesh in meshes {
        let edges = mesh.edges();
        let (places, skipped) = placements_for::<S>(mesh);
        skipped_total += skipped;
        // The bunny is large: every run covers a rotating 1/stride of its vertices, edges, faces.
        let stride = if mesh.faces.len() > 10_000 && full() {
            16
        } else if mesh.faces.len() > 10_000 {
            64
        } else {
            1
        };
        for (pi, &(scale, shift)) in places.iter().enumerate() {
            let placed = place::<S>(mesh, scale, shift);
            let mut arenas = Arenas::new();
            let acc = accels(&placed.tris, &mut arenas);
            let mt_tris: Vec<MtTri> = if S::COLUMN == F32 {
                placed
                    .tris
                    .iter()
                    .map(|t| {
                        MtTri(Triangle {
                            v: t.v.map(|p| p.map(|x| x.to_f32())),
                        })
                    })
                    .collect()
            } else {
                Vec::new()
            };
            let mut mt_nodes = vec![Node::<f32>::EMPTY; nodes_needed(mt_tris.len())];
            let mut mt_ids = vec![0u32; mt_tris.len()];
            let mt_bvh = Bvh::build(
                &mt_tris,
                &mut mt_nodes,
                &mut mt_ids,
                BuildOptions::default(),
            )
            .expect("MT build");

            // Targets in mesh coordinates (for origins) and in the mode (exact aim points).
            let mut targets: [Vec<([f64; 3], [S; 3])>; 3] = Default::default();
            let off = pi % stride;
            for (i, v) in mesh.verts.iter().enumerate().skip(off).step_by(stride) {
                targets[0].push((*v, placed.verts[i]));
            }
            for &(a, b) in edges.iter().skip(off).step_by(stride) {
                let (va, vb) = (placed.verts[a as usize], placed.verts[b as usize]);
                let (ma, mb) = (mesh.verts[a as usize], mesh.verts[b as usize]);
                for s in [0.5, f64::from(rng.unit())] {
                    // A point on the rounded edge, rounded again: as close to it as the mode
                    // can aim.
                    let p = [0, 1, 2].map(|k| {
                        let (x, y) = (Scalar::to_f64(va[k]), Scalar::to_f64(vb[k]));
                        S::from_f64(x + (y - x) * s)
                    });
                    targets[1].push(([0, 1, 2].map(|k| ma[k] + (mb[k] - ma[k]) * s), p));
                }
            }
            for f in mesh.faces.iter().skip(off).step_by(stride) {
                let (u, v) = (f64::from(rng.unit()), f64::from(rng.unit()));
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let m = f.map(|i| mesh.verts[i as usize]);
                let p =
                    [0, 1, 2].map(|k| m[0][k] + u * (m[1][k] - m[0][k]) + v * (m[2][k] - m[0][k]));
                targets[2].push((p, placed.world(p)));
            }
            for (ci, list) in targets.iter().enumerate() {
                for (ri, &(mp, target)) in list.iter().enumerate() {
                    let o = placed.world(interior(mesh, mp, &mut rng));
                    let Ok(ray) = S::ray_to(o, target) else {
                        continue;
                    };
                    counts[ci].rays += 1;
                    let (h, bad) = trace(&acc, &ray, ri);
                    if let Some(b) = bad {
                        counts[ci].mismatches += 1;
                        fails[ci].push(format!("{} s={scale:e} t={shift:?}: {b}", mesh.name));
                    }
                    if h.is_none() {
                        counts[ci].leaks += 1;
                        fails[ci].push(format!(
                            "{} scale {scale:e} shift {shift:?}: leak {ray:?}",
                            mesh.name
                        ));
                    }
                    if S::COLUMN == F32 {
                        let o32 = o.map(|x| x.to_f32());
                        let t32 = target.map(|x| x.to_f32());
                        let d = [0, 1, 2].map(|k| (f64::from(t32[k]) - f64::from(o32[k])) as f32);
                        if let Ok(r) = Ray::<f32>::from_f32(o32, d, 0.0, f32::INFINITY) {
                            mt_counts[ci].rays += 1;
                            if mt_bvh.intersect(&r).is_none() {
                                mt_counts[ci].leaks += 1;
                            }
                        }
                    }
                }
            }
        }
    }
    if skipped_total > 0 {
        println!(
            "[{}] skipped {skipped_total} (mesh, scale, shift) placements whose mesh is smaller than 2^-16 of the shift",
            S::COLUMN
        );
    }
    for ci in 0..3 {
        record(
            classes[ci],
            S::COLUMN,
            counts[ci],
            std::mem::take(&mut fails[ci]),
        );
        if S::COLUMN == F32 {
            record(classes[ci], MT, mt_counts[ci], Vec::new());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Axis-parallel and grazing rays on an axis-aligned grid box.

/// A closed axis-aligned cube `[-h, h]^3` with each face split into an `n × n` grid.
fn grid_cube(n: u32, h: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut faces = Vec::new();
    let g = |i: u32| -1.0 + 2.0 * f64::from(i) / f64::from(n);
    for axis in 0..3 {
        for side in [-1.0f64, 1.0] {
            let mut id = |a: u32, b: u32| {
                let mut p = [0.0; 3];
                p[axis] = side;
                p[(axis + 1) % 3] = g(a);
                p[(axis + 2) % 3] = g(b);
                let key = p.map(|x| (x * 1e6).round() as i64);
                *index.entry(key).or_insert_with(|| {
                    verts.push(p.map(|x| x * h));
                    verts.len() as u32 - 1
                })
            };
            for a in 0..n {
                for b in 0..n {
                    let (p, q, r, s) = (id(a, b), id(a + 1, b), id(a + 1, b + 1), id(a, b + 1));
                    faces.push([p, q, r]);
                    faces.push([p, r, s]);
                }
            }
        }
    }
    (verts, faces)
}

fn axis_parallel<S: Mode>() {
    let class = "axis-parallel (±0 components) at grid vertices/edges";
    let plane_class = "rays in a triangle's plane";
    let (mut c, mut pc, mut mt, mut pmt) = Default::default();
    let (c, pc, mt, pmt): (&mut Count, &mut Count, &mut Count, &mut Count) =
        (&mut c, &mut pc, &mut mt, &mut pmt);
    let mut fails = Vec::new();
    let n = 8u32;
    for h in [1.0f64, 64.0, 4096.0] {
        let (verts, faces) = grid_cube(n, h);
        let tris: Vec<Triangle<S>> = faces
            .iter()
            .map(|f| Triangle {
                v: f.map(|i| verts[i as usize].map(S::from_f64)),
            })
            .collect();
        let mt_tris: Vec<MtTri> = faces
            .iter()
            .map(|f| {
                MtTri(Triangle {
                    v: f.map(|i| verts[i as usize].map(|x| x as f32)),
                })
            })
            .collect();
        let mut arenas = Arenas::new();
        let acc = accels(&tris, &mut arenas);
        let mt_lin = Linear::new(&mt_tris);
        let g = |i: u32| h * (-1.0 + 2.0 * f64::from(i) / f64::from(n));
        let mut idx = 0;
        // Origins on interior grid lines (coordinates equal to vertex coordinates), directions
        // along ±axes with ±0 elsewhere: every ray runs exactly through vertices or edges of
        // the face it leaves through.
        for a in 1..n {
            for b in 1..n {
                for axis in 0..3 {
                    for (sign, zero) in [(1.0f32, 0.0f32), (-1.0, -0.0), (1.0, -0.0), (-1.0, 0.0)] {
                        let mut o = [0.0f64; 3];
                        o[(axis + 1) % 3] = g(a);
                        o[(axis + 2) % 3] = g(b);
                        o[axis] = g(a.min(b)) * 0.5;
                        let mut d = [zero; 3];
                        d[axis] = sign;
                        let os = o.map(S::from_f64);
                        let o32 = o.map(|x| x as f32);
                        let Ok(ray) = Ray::<S>::from_f32(o32, d, 0.0, f32::INFINITY) else {
                            continue;
                        };
                        assert_eq!(os.map(|x| x.to_f32()), o32);
                        c.rays += 1;
                        idx += 1;
                        let (hit, bad) = trace(&acc, &ray, idx);
                        if let Some(b) = bad {
                            c.mismatches += 1;
                            fails.push(b);
                        }
                        if hit.is_none() {
                            c.leaks += 1;
                            fails.push(format!("leak: cube {h}, {ray:?}"));
                        }
                        let r32 = Ray::<f32>::from_f32(o32, d, 0.0, f32::INFINITY).unwrap();
                        mt.rays += 1;
                        if mt_lin.intersect(&r32).is_none() {
                            mt.leaks += 1;
                        }
                    }
                }
            }
        }
        // Rays lying in a face's plane, from outside the cube, along grid lines and diagonals:
        // no required answer (the kernel's rule: a ray in a triangle's plane does not hit it),
        // but every accelerator must agree. A hit on a triangle in whose plane the ray lies
        // counts as a false hit.
        for a in 0..=n {
            for axis in 0..3 {
                for dd in [[1.0f32, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, -0.0]] {
                    let mut o = [0.0f64; 3];
                    o[axis] = h;
                    o[(axis + 1) % 3] = -2.0 * h;
                    o[(axis + 2) % 3] = g(a);
                    let mut d = [0.0f32; 3];
                    d[(axis + 1) % 3] = dd[0] + 0.0;
                    d[(axis + 2) % 3] = dd[1];
                    if dd == [1.0, 1.0] {
                        o[(axis + 2) % 3] = -2.0 * h + g(a) + h;
                    }
                    let o32 = o.map(|x| x as f32);
                    let Ok(ray) = Ray::<S>::from_f32(o32, d, 0.0, f32::INFINITY) else {
                        continue;
                    };
                    pc.rays += 1;
                    idx += 1;
                    let (hit, bad) = trace(&acc, &ray, idx);
                    if let Some(b) = bad {
                        pc.mismatches += 1;
                        fails.push(b);
                    }
                    let in_plane =
                        |t: &Triangle<S>| t.v.iter().all(|p| p[axis].to_f32() as f64 == h);
                    if let Some(hh) = hit {
                        if in_plane(&tris[hh.prim as usize]) {
                            pc.false_hits += 1;
                            fails.push(format!("in-plane hit {hh:?} {ray:?}"));
                        }
                    }
                    let r32 = Ray::<f32>::from_f32(o32, d, 0.0, f32::INFINITY).unwrap();
                    pmt.rays += 1;
                    if let Some(hh) = mt_lin.intersect(&r32) {
                        if mt_tris[hh.prim as usize]
                            .0
                            .v
                            .iter()
                            .all(|p| f64::from(p[axis]) == h)
                        {
                            pmt.false_hits += 1;
                        }
                    }
                }
            }
        }
    }
    record(class, S::COLUMN, *c, fails.clone());
    record(plane_class, S::COLUMN, *pc, fails);
    if S::COLUMN == F32 {
        record(class, MT, *mt, Vec::new());
        record(plane_class, MT, *pmt, Vec::new());
    }
}

/// Slab test on boxes: rays lying in a face, along an edge, through a corner, starting on the
/// box, with ±0 components. All must hit (inclusive boundaries).
fn box_rays<S: Mode>() {
    let class = "box faces, edges, corners (slab)";
    let mut c = Count::default();
    let mut fails = Vec::new();
    let mut rng = Rng::new(SEED ^ 3);
    for h in [1.0f32, 0.25, 1000.0, 4096.0] {
        for shift in [0.0f32, 100.0, -3000.0] {
            let lo = [-h + shift, -h, -h];
            let hi = [h + shift, h, h];
            let bx = Aabb::new(
                lo.map(|x| S::from_f64(f64::from(x))),
                hi.map(|x| S::from_f64(f64::from(x))),
            );
            let corner = |m: u32| [0, 1, 2].map(|k| if m >> k & 1 == 1 { hi[k] } else { lo[k] });
            let mut rays: Vec<([f32; 3], [f32; 3])> = Vec::new();
            for m in 0..8u32 {
                let p = corner(m);
                // Along each edge from this corner, and diagonally through the corner.
                for k in 0..3 {
                    let mut d = [0.0f32, -0.0, 0.0];
                    d[k] = if m >> k & 1 == 1 { -1.0 } else { 1.0 };
                    let mut o = p;
                    o[k] -= d[k] * 2.0 * h;
                    rays.push((o, d));
                }
                let d = [0, 1, 2].map(|k| if m >> k & 1 == 1 { -1.0f32 } else { 1.0 });
                rays.push(([0, 1, 2].map(|k| p[k] - d[k] * h), d));
                rays.push((p, rng.unit_vec()));
            }
            for k in 0..3 {
                for side in [lo[k], hi[k]] {
                    for _ in 0..8 {
                        // In the face's plane, crossing it.
                        let mut o = [0, 1, 2].map(|j| rng.range(lo[j] - h, hi[j] + h));
                        o[k] = side;
                        let mut t = [0, 1, 2].map(|j| rng.range(lo[j], hi[j]));
                        t[k] = side;
                        let mut d = [0, 1, 2].map(|j| t[j] - o[j]);
                        d[k] = if rng.unit() < 0.5 { 0.0 } else { -0.0 };
                        if d.iter().all(|&x| x == 0.0) {
                            continue;
                        }
                        rays.push((o, d));
                    }
                }
            }
            for (o, d) in rays {
                let Ok(ray) = Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY) else {
                    continue;
                };
                c.rays += 1;
                if bx.slab(&ray).is_none() {
                    c.leaks += 1;
                    fails.push(format!("box {lo:?}..{hi:?} missed by {o:?} {d:?}"));
                }
            }
        }
    }
    record(class, S::COLUMN, c, fails);
}

// ---------------------------------------------------------------------------------------------
// Spawned rays: reflection, hemisphere and shadow rays from hits must not re-hit their own
// surface.

fn spawn_total() -> u64 {
    std::env::var("STRESS_SPAWN")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(if full() { 1_000_000 } else { 200_000 })
}

fn spawned<S: Mode>(meshes: &[Mesh]) {
    let mut rng = Rng::new(SEED ^ 4);
    let (mut refl, mut shadow, mut naive) = (Count::default(), Count::default(), Count::default());
    let (mut mrefl, mut mshadow, mut mnaive) =
        (Count::default(), Count::default(), Count::default());
    let mut fails = Vec::new();
    let mut jobs = Vec::new();
    for mesh in meshes {
        for p in placements_for::<S>(mesh).0 {
            jobs.push((mesh, p));
        }
    }
    // Four spawned rays per primary hit.
    let per_job = (spawn_total() / 4).div_ceil(jobs.len() as u64);
    for (mesh, (scale, shift)) in jobs {
        let placed = place::<S>(mesh, scale, shift);
        let mut arenas = Arenas::new();
        let acc = accels(&placed.tris, &mut arenas);
        let mt_tris: Vec<MtTri> = placed
            .tris
            .iter()
            .map(|t| {
                MtTri(Triangle {
                    v: t.v.map(|p| p.map(|x| x.to_f32())),
                })
            })
            .collect();
        let mut mt_nodes = vec![Node::<f32>::EMPTY; nodes_needed(mt_tris.len())];
        let mut mt_ids = vec![0u32; mt_tris.len()];
        let mt_bvh = Bvh::build(
            &mt_tris,
            &mut mt_nodes,
            &mut mt_ids,
            BuildOptions::default(),
        )
        .expect("MT build");
        let convex = mesh.shape == Shape::Sphere;
        let mut done = 0;
        let mut guard = 0;
        while done < per_job && guard < per_job * 4 {
            guard += 1;
            let f = rng.below(mesh.faces.len());
            let (u, v) = (f64::from(rng.unit()), f64::from(rng.unit()));
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let m = mesh.faces[f].map(|i| mesh.verts[i as usize]);
            let mp = [0, 1, 2].map(|k| m[0][k] + u * (m[1][k] - m[0][k]) + v * (m[2][k] - m[0][k]));
            let o = placed.world(interior(mesh, mp, &mut rng));
            let Ok(ray) = S::ray_to(o, placed.world(mp)) else {
                continue;
            };
            let Some(hit) = acc.answer().intersect(&ray) else {
                continue; // a leak: counted by the watertight classes
            };
            done += 1;
            let own = hit.prim;
            let tri = placed.tris[own as usize];
            let n = tri_normal(&tri);
            let d = to_f64(S::vec_to_array(ray.dir()));
            // Reflection (back to the side the ray came from), and random directions into both
            // half-spaces.
            let r = sub(d, n.map(|x| 2.0 * dot(d, n) * x));
            let mut dirs = vec![(r, false)];
            for side in [1.0, -1.0] {
                let w = loop {
                    let w = rng.unit_vec().map(f64::from);
                    if dot(w, n).abs() > 1e-3 {
                        break w;
                    }
                };
                let w = if dot(w, n) * side < 0.0 {
                    w.map(|x| -x)
                } else {
                    w
                };
                // Outward from a convex mesh: nothing may be hit at all.
                let outward = convex && dot(w, n) * dot(d, n) > 0.0;
                dirs.push((w, outward));
            }
            for (w, outward) in dirs {
                let wv = S::array_to_vec(w.map(S::from_f64_dir));
                let Ok(sr) = spawn_ray(&ray, &hit, &tri, wv) else {
                    continue;
                };
                refl.rays += 1;
                let h2 = acc.answer().intersect(&sr);
                if h2.is_some_and(|h| h.prim == own) || (outward && h2.is_some()) {
                    refl.false_hits += 1;
                    fails.push(format!(
                        "{} self-hit {h2:?} from {hit:?} spawned {sr:?}",
                        mesh.name
                    ));
                }
                if S::COLUMN == F32 {
                    let o32 = S::vec_to_array(sr.origin()).map(|x| x.to_f32());
                    let d32 = S::vec_to_array(sr.dir()).map(|x| x.to_f32());
                    if let Ok(mr) = Ray::<f32>::from_f32(o32, d32, 0.0, f32::INFINITY) {
                        mrefl.rays += 1;
                        let h3 = mt_bvh.intersect(&mr);
                        if h3.is_some_and(|h| h.prim == own) || (outward && h3.is_some()) {
                            mrefl.false_hits += 1;
                        }
                    }
                }
            }
            // Shadow ray to a point on another face, offset toward the shading point.
            let g = rng.below(mesh.faces.len());
            if g != f {
                let (a, b) = (rng.unit(), rng.unit());
                let (a, b) = if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                };
                let gt = placed.tris[g];
                let (ga, gb) = (S::from_f64(f64::from(a)), S::from_f64(f64::from(b)));
                let ht = to_f64(S::vec_to_array(ray.origin()));
                let hp = [0, 1, 2].map(|k| ht[k] + Scalar::to_f64(hit.t) * d[k]);
                let gv = gt.v.map(to_f64::<S>);
                let (af, bf) = (Scalar::to_f64(ga), Scalar::to_f64(gb));
                let gq = [0, 1, 2]
                    .map(|k| gv[0][k] + af * (gv[1][k] - gv[0][k]) + bf * (gv[2][k] - gv[0][k]));
                // Offset the target toward the shading point's *offset* origin: the raw hit
                // point may lie on an edge shared with the target's triangle, i.e. on its plane.
                let to_target = S::array_to_vec(normalize(sub(gq, hp)).map(S::from_f64_dir));
                let o_ref = to_f64(offset_origin(&tri, hit.u, hit.v, to_target));
                let toward = S::array_to_vec(normalize(sub(o_ref, gq)).map(S::from_f64_dir));
                let target = offset_origin(&gt, ga, gb, toward);
                if let Ok(sr) = spawn_shadow_ray(&ray, &hit, &tri, target) {
                    shadow.rays += 1;
                    let h2 = acc.answer().intersect(&sr);
                    let occluded = acc.answer().occluded(&sr);
                    if occluded != h2.is_some() {
                        shadow.mismatches += 1;
                    }
                    // The target's own triangle counts near the end of the ray; elsewhere a
                    // non-convex mesh may put it (or anything) in the way.
                    let end = |h: &Hit<S>| h.t.to_f32() >= 0.99 * sr.t_max().to_f32();
                    if h2.is_some_and(|h| h.prim == own || (h.prim == g as u32 && end(&h)))
                        || (convex && h2.is_some())
                    {
                        shadow.false_hits += 1;
                        fails.push(format!(
                            "{} shadow false hit {h2:?} from {hit:?} on {tri:?} to prim {g} {gt:?} at {target:?} (bary {ga:?} {gb:?}): {sr:?}",
                            mesh.name
                        ));
                    }
                    if S::COLUMN == F32 {
                        let o32 = S::vec_to_array(sr.origin()).map(|x| x.to_f32());
                        let d32 = S::vec_to_array(sr.dir()).map(|x| x.to_f32());
                        if let Ok(mr) = Ray::<f32>::from_f32(o32, d32, 0.0, sr.t_max().to_f32()) {
                            mshadow.rays += 1;
                            let h3 = mt_bvh.intersect(&mr);
                            let end = |h: &Hit<f32>| h.t >= 0.99 * mr.t_max();
                            if h3.is_some_and(|h| h.prim == own || (h.prim == g as u32 && end(&h)))
                                || (convex && h3.is_some())
                            {
                                mshadow.false_hits += 1;
                            }
                        }
                    }
                }
            }
            // Informational: the reflection ray from the unmodified hit point o + t·d.
            let hp = [0, 1, 2].map(|k| {
                Scalar::to_f64(S::vec_to_array(ray.origin())[k]) + Scalar::to_f64(hit.t) * d[k]
            });
            let ho = hp.map(S::from_f64);
            if let Ok(nr) = S::ray_along(ho, r) {
                naive.rays += 1;
                if acc.answer().intersect(&nr).is_some_and(|h| h.prim == own) {
                    naive.false_hits += 1;
                }
                if S::COLUMN == F32 {
                    let o32 = ho.map(|x| x.to_f32());
                    if let Ok(mr) =
                        Ray::<f32>::from_f32(o32, r.map(|x| x as f32), 0.0, f32::INFINITY)
                    {
                        mnaive.rays += 1;
                        if mt_bvh.intersect(&mr).is_some_and(|h| h.prim == own) {
                            mnaive.false_hits += 1;
                        }
                    }
                }
            }
        }
    }
    record(
        "spawned: reflection and hemisphere",
        S::COLUMN,
        refl,
        fails.clone(),
    );
    record("spawned: shadow rays", S::COLUMN, shadow, fails);
    record(
        "spawned without offset (informational)",
        S::COLUMN,
        naive,
        Vec::new(),
    );
    if S::COLUMN == F32 {
        record("spawned: reflection and hemisphere", MT, mrefl, Vec::new());
        record("spawned: shadow rays", MT, mshadow, Vec::new());
        record(
            "spawned without offset (informational)",
            MT,
            mnaive,
            Vec::new(),
        );
    }
}

/// Directions in the mode: `f32` as is; fixed point scaled up (any length is fine).
trait DirConv: Mode {
    fn from_f64_dir(x: f64) -> Self;
}
impl<S: Mode> DirConv for S {
    fn from_f64_dir(x: f64) -> S {
        if S::COLUMN == F32 {
            S::from_f64(x)
        } else {
            S::from_f64(x * 4096.0)
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate and bad input.

fn degenerate<S: Mode>() {
    let class = "degenerate input";
    let mut c = Count::default();
    let mut mt = Count::default();
    let mut fails = Vec::new();
    let mut rng = Rng::new(SEED ^ 5);
    let base = [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]];
    // (name, triangles, must_hit_index: a triangle a ray at its centroid must hit, or none)
    let mut scenes: Vec<(&str, Vec<[[f64; 3]; 3]>, bool)> = vec![
        (
            "all-identical vertices",
            vec![[[0.25, 0.25, 5.0]; 3]],
            false,
        ),
        (
            "collinear",
            vec![[[0.0, 0.0, 5.0], [0.5, 0.5, 5.0], [1.0, 1.0, 5.0]]],
            false,
        ),
        (
            "two equal vertices",
            vec![[[0.0, 0.0, 5.0], [1.0, 1.0, 5.0], [1.0, 1.0, 5.0]]],
            false,
        ),
        ("single triangle", vec![base], true),
        ("duplicate triangles", vec![base; 5], true),
        (
            "coincident, permuted",
            vec![
                base,
                [base[1], base[2], base[0]],
                [base[2], base[1], base[0]],
            ],
            true,
        ),
        (
            "sliver 1e-3",
            vec![[[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.5, 1e-3, 5.0]]],
            true,
        ),
        (
            "sliver 1e-2 long",
            vec![[[-8.0, 0.0, 5.0], [8.0, 0.0, 5.0], [0.0, 1e-2, 5.0]]],
            true,
        ),
        ("empty scene", vec![], false),
    ];
    // Mixed: degenerate ones among many copies.
    let mut mixed = vec![[[0.25, 0.25, 4.0]; 3]; 20];
    mixed.push(base);
    scenes.push(("degenerate crowd", mixed, true));
    for (name, tris64, must_hit) in scenes {
        let tris: Vec<Triangle<S>> = tris64
            .iter()
            .map(|t| Triangle {
                v: t.map(|p| p.map(S::from_f64)),
            })
            .collect();
        let mt_tris: Vec<MtTri> = tris64
            .iter()
            .map(|t| {
                MtTri(Triangle {
                    v: t.map(|p| p.map(|x| x as f32)),
                })
            })
            .collect();
        let zero_area = |v: &[[f64; 3]; 3]| {
            let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
            n == [0.0; 3]
        };
        let mut arenas = Arenas::new();
        let acc = accels(&tris, &mut arenas);
        let mut idx = 0;
        for k in 0..64 {
            // Centroid of the first non-degenerate triangle (or of the first one), from several
            // origins, and a few intervals: [0, inf), t_min == t_max at the hit, huge t_max.
            let t0 = tris64
                .iter()
                .find(|t| !zero_area(t))
                .or(tris64.first())
                .copied();
            let target = t0.map_or([0.3, 0.3, 5.0], |t| {
                [0, 1, 2].map(|j| (t[0][j] + t[1][j] + t[2][j]) / 3.0)
            });
            let o = if k == 0 {
                [target[0], target[1], 0.0]
            } else {
                let j = rng.in_ball(2.0);
                [
                    target[0] + f64::from(j[0]),
                    target[1] + f64::from(j[1]),
                    0.0,
                ]
            };
            let os = o.map(S::from_f64);
            let ts = target.map(S::from_f64);
            let Ok(base_ray) = S::ray_to(os, ts) else {
                continue;
            };
            let exact_t = acc.linear.intersect(&base_ray).map(|h| h.t);
            let intervals: Vec<(S, S)> = {
                let mut v = vec![
                    (S::ZERO, S::FAR),
                    (S::ZERO, S::from_f64(1e30f64.min(8000.0))),
                ];
                if let Some(t) = exact_t {
                    v.push((t, t));
                }
                v
            };
            for (lo, hi) in intervals {
                let Ok(ray) = base_ray.with_interval(lo, hi) else {
                    c.mismatches += 1;
                    fails.push(format!("{name}: with_interval({lo:?}, {hi:?}) refused"));
                    continue;
                };
                c.rays += 1;
                idx += 1;
                let (h, bad) = trace(&acc, &ray, idx);
                if let Some(b) = bad {
                    c.mismatches += 1;
                    fails.push(format!("{name}: {b}"));
                }
                if must_hit && h.is_none() {
                    c.leaks += 1;
                    fails.push(format!("{name}: leak {ray:?}"));
                }
                if let Some(h) = h {
                    if zero_area(&tris64[h.prim as usize]) {
                        c.false_hits += 1;
                        fails.push(format!("{name}: hit on a zero-area triangle {h:?}"));
                    }
                }
                let o32 = os.map(|x| x.to_f32());
                let d32 = S::vec_to_array(ray.dir()).map(|x| x.to_f32());
                if S::COLUMN == F32 {
                    if let Ok(mr) = Ray::<f32>::from_f32(o32, d32, lo.to_f32(), hi.to_f32()) {
                        mt.rays += 1;
                        let mh = Linear::new(&mt_tris).intersect(&mr);
                        if must_hit && mh.is_none() {
                            mt.leaks += 1;
                        }
                        if mh.is_some_and(|h| zero_area(&tris64[h.prim as usize])) {
                            mt.false_hits += 1;
                        }
                    }
                }
            }
        }
    }
    record(class, S::COLUMN, c, fails);
    if S::COLUMN == F32 {
        record(class, MT, mt, Vec::new());
    }
}

/// Bad input: each case must give its typed error; nothing may panic. A wrong or missing error
/// or a panic counts as a mismatch.
fn bad_input<S: Mode>() {
    let class = "bad input";
    let mut c = Count::default();
    let mut fails = Vec::new();
    let mut check = |what: String, f: &dyn Fn() -> bool| {
        c.rays += 1;
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(true) => {}
            Ok(false) => {
                c.mismatches += 1;
                fails.push(format!("{what}: wrong result"));
            }
            Err(_) => {
                c.mismatches += 1;
                fails.push(format!("{what}: panicked"));
            }
        }
    };
    let nonfinite = [f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let out_of_range: Vec<f32> = if S::COLUMN == F32 {
        vec![raykernel::F32_COORD_LIMIT * 2.0, f32::MAX, -f32::MAX]
    } else {
        vec![8192.001, -8192.001, 1e6, -3e9]
    };
    let good = [[0.0f32, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]];
    for k in 0..3 {
        for j in 0..3 {
            for &x in nonfinite.iter().chain(&out_of_range) {
                let mut v = good;
                v[k][j] = x;
                let expect = if x.is_finite() {
                    PointError::OutOfRange {
                        limit: if S::COLUMN == F32 {
                            raykernel::F32_COORD_LIMIT
                        } else {
                            raykernel::FIXED_COORD_LIMIT
                        },
                    }
                } else {
                    PointError::NonFinite
                };
                check(format!("vertex {k} axis {j} = {x}"), &|| {
                    Triangle::<S>::from_f32(v) == Err(VertexError::new(k, expect))
                });
                // The builder must name the same vertex when handed unchecked data (f32 only:
                // fixed point cannot hold such values).
                if S::COLUMN == F32 {
                    check(format!("build with vertex {k} axis {j} = {x}"), &|| {
                        let tris = [Triangle::<f32>::from_f32(good).unwrap(), Triangle { v }];
                        let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(2)];
                        let mut ids = vec![0u32; 2];
                        Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()).err()
                            == Some(BuildError::BadPrimitive {
                                prim: 1,
                                vertex: k,
                                error: expect,
                            })
                    });
                }
                let mut o = [0.0f32; 3];
                o[j] = x;
                check(format!("origin axis {j} = {x}"), &|| {
                    Ray::<S>::from_f32(o, [0.0, 0.0, 1.0], 0.0, f32::INFINITY).err()
                        == Some(RayError::Origin(expect))
                });
            }
            for &x in &nonfinite {
                let mut d = [0.0f32, 0.0, 1.0];
                d[j] = x;
                check(format!("direction axis {j} = {x}"), &|| {
                    Ray::<S>::from_f32([0.0; 3], d, 0.0, f32::INFINITY).err()
                        == Some(RayError::NonFiniteDirection)
                });
            }
        }
    }
    for d in [[0.0f32; 3], [-0.0, 0.0, -0.0]] {
        check(format!("direction {d:?}"), &|| {
            Ray::<S>::from_f32([0.0; 3], d, 0.0, f32::INFINITY).err()
                == Some(RayError::ZeroDirection)
        });
    }
    for (lo, hi) in [
        (f32::NAN, 1.0),
        (0.0, f32::NAN),
        (-1.0, 1.0),
        (2.0, 1.0),
        (f32::INFINITY, f32::INFINITY),
    ] {
        check(format!("interval [{lo}, {hi}]"), &|| {
            Ray::<S>::from_f32([0.0; 3], [0.0, 0.0, 1.0], lo, hi).err()
                == Some(RayError::InvalidInterval)
        });
    }
    // Arenas too small by one, for 1..=9 primitives and every builder.
    for n in 1..=9usize {
        let tris: Vec<Triangle<S>> = (0..n)
            .map(|i| {
                let z = i as f32;
                Triangle::from_f32([[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]]).unwrap()
            })
            .collect();
        for builder in BuilderKind::ALL {
            let o = BuildOptions {
                builder,
                max_leaf_size: 1,
                reinsertion: true,
            };
            check(
                format!("{n} prims, nodes short by one ({builder:?})"),
                &|| {
                    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n) - 1];
                    let mut ids = vec![0u32; n];
                    Bvh::build(&tris, &mut nodes, &mut ids, o).err()
                        == Some(BuildError::ArenaTooSmall {
                            arena: Arena::Nodes,
                            needed: nodes_needed(n),
                            available: nodes_needed(n) - 1,
                        })
                },
            );
            check(
                format!("{n} prims, ids short by one ({builder:?})"),
                &|| {
                    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
                    let mut ids = vec![0u32; n - 1];
                    Bvh::build(&tris, &mut nodes, &mut ids, o).err()
                        == Some(BuildError::ArenaTooSmall {
                            arena: Arena::PrimIds,
                            needed: n,
                            available: n - 1,
                        })
                },
            );
        }
        for leaf in [0u32, 65] {
            check(format!("{n} prims, leaf size {leaf}"), &|| {
                let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
                let mut ids = vec![0u32; n];
                let o = BuildOptions {
                    builder: BuilderKind::Sah,
                    max_leaf_size: leaf,
                    reinsertion: true,
                };
                Bvh::build(&tris, &mut nodes, &mut ids, o).err()
                    == Some(BuildError::BadLeafSize {
                        max_leaf_size: leaf,
                    })
            });
        }
    }
    record(class, S::COLUMN, c, fails);
}

// ---------------------------------------------------------------------------------------------

/// Runs every class in mode `S` (the `table` test).
fn run_mode<S: Mode>(meshes: &[Mesh]) {
    let t = std::time::Instant::now();
    let lap = |what: &str| println!("[{}] {what}: {:.1} s", S::COLUMN, t.elapsed().as_secs_f64());
    watertight::<S>(meshes);
    lap("watertight");
    axis_parallel::<S>();
    box_rays::<S>();
    lap("axis-parallel, boxes");
    spawned::<S>(meshes);
    lap("spawned");
    degenerate::<S>();
    bad_input::<S>();
    lap("degenerate, bad input");
}

/// `STRESS_FULL=1`: the whole matrix (every placement of the bunny, 1M spawned rays per mode).
/// Otherwise (the `cargo test` default) the bunny at a few placements and 200k spawned rays.
fn full() -> bool {
    std::env::var("STRESS_FULL").is_ok_and(|v| v == "1")
}

/// The meshes of the mesh-based classes, built (and the bunny read) once for every test.
fn shared_meshes() -> &'static [Mesh] {
    static MESHES: OnceLock<Vec<Mesh>> = OnceLock::new();
    MESHES.get_or_init(meshes)
}

/// Runs `classes` on this thread's table, emptied first, and returns what they recorded.
fn counted(classes: impl FnOnce()) -> Table {
    TABLE.with_borrow_mut(|t| *t = Table::default());
    classes();
    TABLE.take()
}

/// Why `t` fails: in each of `columns`, an asserted class that did not run or has non-zero
/// kernel counts. Empty if it passes.
fn problems(t: &Table, columns: &[&str]) -> Vec<String> {
    let mut bad = Vec::new();
    for ((_, class), cols) in &t.rows {
        for &col in columns {
            let Some(c) = cols.get(col) else {
                bad.push(format!("{class}: no {col} results"));
                continue;
            };
            if t.informational.contains(class) {
                continue;
            }
            if c.rays == 0 {
                bad.push(format!("{class} [{col}]: no rays"));
            }
            if c.leaks + c.false_hits + c.mismatches > 0 {
                bad.push(format!("{class} [{col}]: {c:?}"));
            }
        }
    }
    bad
}

/// Runs `classes` in mode `S` and fails unless every class it recorded is clean in `S`'s column.
fn check<S: Mode>(classes: impl FnOnce()) -> Table {
    let t = counted(classes);
    assert!(!t.rows.is_empty(), "no class recorded anything");
    let bad = problems(&t, &[S::COLUMN]);
    assert!(
        bad.is_empty(),
        "{}\nfirst failures:\n{}",
        bad.join("\n"),
        t.failures.join("\n")
    );
    t
}

/// Fails unless about [`spawn_total`] rays were spawned in `column` (reflection and shadow).
fn assert_spawned_all(t: &Table, column: &str) {
    let spawned: u64 = t
        .rows
        .iter()
        .filter(|((_, class), _)| class.starts_with("spawned: "))
        .map(|(_, cols)| cols.get(column).map_or(0, |c| c.rays))
        .sum();
    assert!(
        spawned >= spawn_total() * 9 / 10,
        "only {spawned} spawned rays in {column}, want about {}",
        spawn_total()
    );
}

#[test]
fn watertight_f32() {
    check::<f32>(|| watertight::<f32>(shared_meshes()));
}

#[test]
fn watertight_fixed() {
    check::<I16F16>(|| watertight::<I16F16>(shared_meshes()));
}

#[test]
fn axis_parallel_f32() {
    check::<f32>(axis_parallel::<f32>);
}

#[test]
fn axis_parallel_fixed() {
    check::<I16F16>(axis_parallel::<I16F16>);
}

#[test]
fn box_rays_f32() {
    check::<f32>(box_rays::<f32>);
}

#[test]
fn box_rays_fixed() {
    check::<I16F16>(box_rays::<I16F16>);
}

#[test]
fn spawned_f32() {
    let t = check::<f32>(|| spawned::<f32>(shared_meshes()));
    assert_spawned_all(&t, F32);
}

#[test]
fn spawned_fixed() {
    let t = check::<I16F16>(|| spawned::<I16F16>(shared_meshes()));
    assert_spawned_all(&t, FIXED);
}

#[test]
fn degenerate_f32() {
    check::<f32>(degenerate::<f32>);
}

#[test]
fn degenerate_fixed() {
    check::<I16F16>(degenerate::<I16F16>);
}

#[test]
fn bad_input_f32() {
    check::<f32>(bad_input::<f32>);
}

#[test]
fn bad_input_fixed() {
    check::<I16F16>(bad_input::<I16F16>);
}

/// Every class in both modes, printed as the Markdown table of docs/STRESS.md between marker
/// lines (`cargo xtask stress` runs it with `STRESS_FULL=1` and writes the table).
#[test]
#[ignore = "the docs table: `cargo xtask stress`"]
fn table() {
    let start = std::time::Instant::now();
    let meshes = shared_meshes();
    let (f, x) = std::thread::scope(|s| {
        let f = s.spawn(|| counted(|| run_mode::<f32>(meshes)));
        let x = s.spawn(|| counted(|| run_mode::<I16F16>(meshes)));
        (f.join(), x.join())
    });
    let (mut t, x) = match (f, x) {
        (Ok(f), Ok(x)) => (f, x),
        (Err(e), _) | (_, Err(e)) => std::panic::resume_unwind(e),
    };
    t.merge(x);
    println!(
        "{STRESS_TABLE_BEGIN}\n{}{STRESS_TABLE_END}",
        table_markdown(&t)
    );
    println!(
        "meshes: {}; stress suite took {:.1} s",
        meshes
            .iter()
            .map(|m| format!("{} ({} tris)", m.name, m.faces.len()))
            .collect::<Vec<_>>()
            .join(", "),
        start.elapsed().as_secs_f64()
    );
    let bad = problems(&t, &[F32, FIXED]);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    assert_spawned_all(&t, F32);
    assert_spawned_all(&t, FIXED);
}

/// The lines around the table the `table` test prints (`cargo xtask stress` looks for them).
const STRESS_TABLE_BEGIN: &str = "--- stress table ---";
const STRESS_TABLE_END: &str = "--- end stress table ---";
