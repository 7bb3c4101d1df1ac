//! Accuracy of the `f32` triangle test's distance: the kernel's `t` against the exact solve of
//! the same sheared triangle (the watertight test's own frame), and against the former `f64`
//! candidate solve, on random well-conditioned triangles, random slivers (long and thin, or
//! nearly edge-on to the ray), and the triangles of the shared bunny (if `../shared` exists).
//!
//! The error is in ulps of the exact distance. A correctly rounded result is within 0.5 ulp;
//! the test asserts the kernel stays within `0.5 + 2^-8` ulp on every candidate and is never
//! worse than the `f64` solve by more than that hair, and prints both distributions.
//! Deterministic (seeded); a failure prints the seed index and the triangle.

use raykernel::{Ray, Triangle, TriangleHit};
use raykernel_testkit::vec3::{add_scaled, to_f32};
use raykernel_testkit::Rng;

/// Exact-enough double-`f64` arithmetic for the reference (about 106 bits).
#[derive(Clone, Copy, Debug)]
struct Dd(f64, f64);

fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd(s, (a - (s - bb)) + (b - bb))
}

fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd(p, a.mul_add(b, -p))
}

impl Dd {
    fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.0, o.0);
        let t = two_sum(self.1, o.1);
        let s = two_sum(s.0, s.1 + t.0);
        two_sum(s.0, s.1 + t.1)
    }
    fn mul(self, b: f64) -> Dd {
        let p = two_prod(self.0, b);
        two_sum(p.0, p.1 + self.1 * b)
    }
    fn div(self, d: Dd) -> f64 {
        let q = self.0 / d.0;
        let r = self.add(d.mul(-q));
        q + (r.0 + r.1) / d.0
    }
}

/// The kernel's sheared frame for a ray, recomputed as `scalar/float.rs` does.
struct Frame {
    origin: [f32; 3],
    k: [usize; 3],
    shear: [f32; 3],
}

impl Frame {
    fn new(ray: &Ray<f32>) -> Frame {
        let dir = ray.dir().to_array();
        let a = dir.map(f32::abs);
        let kz = if a[0] >= a[1] && a[0] >= a[2] {
            0
        } else if a[1] >= a[2] {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / dir[kz];
        Frame {
            origin: ray.origin().to_array(),
            k: [kx, ky, kz],
            shear: [dir[kx] * sz, dir[ky] * sz, sz],
        }
    }

    fn shear(&self, v: &[f32; 3]) -> [f32; 3] {
        let p = self.k.map(|k| v[k] - self.origin[k]);
        let [sx, sy, sz] = self.shear;
        [p[0] - sx * p[2], p[1] - sy * p[2], sz * p[2]]
    }
}

/// Edge functions of sheared vertices, exactly (the f32 products are exact in f64; their
/// difference as an exact pair).
fn edge(p: &[f32; 3], q: &[f32; 3]) -> Dd {
    two_sum(p[0] as f64 * q[1] as f64, -(p[1] as f64 * q[0] as f64))
}

/// The exact distance of the sheared triangle (to about 2^-100), if its determinant is not 0.
fn exact_t(s: &[[f32; 3]; 3]) -> Option<f64> {
    let [a, b, c] = s;
    let (u, v, w) = (edge(c, b), edge(a, c), edge(b, a));
    let det = u.add(v).add(w);
    if det.0 == 0.0 {
        return None;
    }
    let num = u
        .mul(a[2] as f64)
        .add(v.mul(b[2] as f64))
        .add(w.mul(c[2] as f64));
    Some(num.div(det))
}

/// The former candidate solve: edge functions and `num` in `f64`, one rounding each.
fn f64_solve_t(s: &[[f32; 3]; 3]) -> Option<f32> {
    let [a, b, c] = s;
    let e = |p: &[f32; 3], q: &[f32; 3]| p[0] as f64 * q[1] as f64 - p[1] as f64 * q[0] as f64;
    let (u, v, w) = (e(c, b), e(a, c), e(b, a));
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let num = u * a[2] as f64 + v * b[2] as f64 + w * c[2] as f64;
    Some((num / det) as f32)
}

/// |t - exact| in ulps of the `f32` nearest to `exact`.
fn ulps(t: f32, exact: f64) -> f64 {
    let r = exact as f32;
    let ulp = (f32::from_bits(r.abs().to_bits() + 1) - r.abs()) as f64;
    (t as f64 - exact).abs() / ulp
}

#[derive(Default)]
struct Stats {
    count: usize,
    max_new: f64,
    max_old: f64,
    sum_new: f64,
    sum_old: f64,
    /// Candidates where the new `t` is farther from the exact one than the `f64` solve's.
    new_worse: usize,
    /// Candidates where the new `t` is nearer.
    new_better: usize,
}

impl Stats {
    fn add(&mut self, new: f64, old: f64) {
        self.count += 1;
        self.max_new = self.max_new.max(new);
        self.max_old = self.max_old.max(old);
        self.sum_new += new;
        self.sum_old += old;
        self.new_worse += (new > old) as usize;
        self.new_better += (new < old) as usize;
    }
    fn print(&self, what: &str) {
        let n = self.count.max(1) as f64;
        println!(
            "{what}: {} candidates; t error in ulps: double-f32 max {:.6} mean {:.6}, f64 max {:.6} mean {:.6}; double-f32 farther on {}, nearer on {}",
            self.count,
            self.max_new,
            self.sum_new / n,
            self.max_old,
            self.sum_old / n,
            self.new_worse,
            self.new_better
        );
    }
}

/// Worst accepted error, in ulps: correctly rounded plus a hair.
const BOUND: f64 = 0.5 + 1.0 / 256.0;

/// Measures one ray/triangle pair if the kernel reports a hit there.
fn measure(stats: &mut Stats, ray: &Ray<f32>, v: [[f32; 3]; 3], case: &str) {
    let Some(TriangleHit { t, .. }) = Triangle { v }.intersect(ray) else {
        return;
    };
    let frame = Frame::new(ray);
    let s = v.map(|p| frame.shear(&p));
    let (Some(exact), Some(old)) = (exact_t(&s), f64_solve_t(&s)) else {
        panic!("{case}: a hit with a zero determinant: {v:?}");
    };
    let (new, old) = (ulps(t, exact), ulps(old, exact));
    assert!(
        new <= BOUND && new <= old.max(0.5) + 1.0 / 256.0,
        "{case}: t = {t:e}, exact {exact:e} ({new} ulps; f64 solve {old} ulps): {v:?}, ray {:?} {:?}",
        ray.origin(),
        ray.dir()
    );
    stats.add(new, old);
}

/// A ray from a random origin through a random point `p` of a random triangle, which is
/// well-conditioned, a long thin sliver, or nearly edge-on to the ray.
fn random_case(rng: &mut Rng, kind: usize) -> (Ray<f32>, [[f32; 3]; 3]) {
    let scale = [1e-3, 1.0, 1e3, 1e6][(rng.next_u64() % 4) as usize];
    let origin = rng.cube_f64(scale);
    let p = rng.cube_f64(scale);
    let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
    let size = scale * rng.range_f64(0.01, 1.0);
    let v = match kind {
        // Well-conditioned: three vertices around p.
        0 => [0, 1, 2].map(|_| to_f32(add_scaled(p, rng.cube_f64(size), 1.0))),
        // Long and thin: two vertices far apart on a line through p, the third just off it.
        1 => {
            let axis = rng.cube_f64(1.0);
            let thin = size * libm::exp2(-rng.range_f64(8.0, 24.0));
            let off = rng.cube_f64(thin);
            let a = add_scaled(p, axis, size * rng.range_f64(0.2, 1.0));
            let b = add_scaled(p, axis, -size * rng.range_f64(0.2, 1.0));
            let c = add_scaled(
                add_scaled(p, axis, size * rng.range_f64(-0.1, 0.1)),
                off,
                1.0,
            );
            [to_f32(a), to_f32(b), to_f32(c)]
        }
        // Nearly edge-on: the triangle's plane almost contains the ray direction.
        _ => {
            let tilt = libm::exp2(-rng.range_f64(6.0, 20.0));
            let side = rng.cube_f64(1.0);
            let a = add_scaled(add_scaled(p, d, tilt), side, size);
            let b = add_scaled(add_scaled(p, d, -tilt), side, -size);
            let c = add_scaled(p, rng.cube_f64(size), tilt);
            [to_f32(a), to_f32(b), to_f32(c)]
        }
    };
    let ray = Ray::from_f32(to_f32(origin), to_f32(d), 0.0, f32::INFINITY).expect("valid ray");
    (ray, v)
}

#[test]
fn triangle_t_is_as_accurate_as_the_f64_solve_on_random_triangles() {
    let mut rng = Rng::new(0x7a11_d157_0001);
    for (kind, what) in ["well-conditioned", "long thin slivers", "nearly edge-on"]
        .iter()
        .enumerate()
    {
        let mut stats = Stats::default();
        for i in 0..60_000 {
            let (ray, v) = random_case(&mut rng, kind);
            measure(&mut stats, &ray, v, &format!("{what} #{i}"));
        }
        stats.print(what);
        assert!(stats.count > 1000, "{what}: only {} hits", stats.count);
    }
}

/// Vertices and triangles of a triangulated OBJ (`v x y z`, `f a b c ...` with fans).
fn read_obj(path: &std::path::Path) -> Option<Vec<[[f32; 3]; 3]>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut verts: Vec<[f32; 3]> = Vec::new();
    let mut tris = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.take(3).filter_map(|x| x.parse().ok()).collect();
                verts.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let idx: Vec<usize> = it
                    .filter_map(|x| x.split('/').next()?.parse::<i64>().ok())
                    .map(|i| if i < 0 { verts.len() as i64 + i } else { i - 1 } as usize)
                    .collect();
                for k in 1..idx.len().saturating_sub(1) {
                    tris.push([verts[idx[0]], verts[idx[k]], verts[idx[k + 1]]]);
                }
            }
            _ => {}
        }
    }
    Some(tris)
}

#[test]
fn triangle_t_is_as_accurate_as_the_f64_solve_on_the_bunny() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes/bunny.obj");
    let Some(tris) = read_obj(&path) else {
        println!("skipped: {} not found", path.display());
        return;
    };
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for p in tris.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let mut rng = Rng::new(0xb0_0001);
    let mut stats = Stats::default();
    // Rays from random points of the scene's box through a random interior point of each
    // triangle (every eighth).
    for (i, v) in tris.iter().enumerate().step_by(8) {
        let o: [f32; 3] = std::array::from_fn(|k| rng.range_f64(lo[k] as f64, hi[k] as f64) as f32);
        let (a, b) = (rng.unit_f64(), rng.unit_f64());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let p: [f64; 3] = std::array::from_fn(|k| {
            v[0][k] as f64
                + a * (v[1][k] as f64 - v[0][k] as f64)
                + b * (v[2][k] as f64 - v[0][k] as f64)
        });
        let d = to_f32([p[0] - o[0] as f64, p[1] - o[1] as f64, p[2] - o[2] as f64]);
        let Ok(ray) = Ray::from_f32(o, d, 0.0, f32::INFINITY) else {
            continue;
        };
        measure(&mut stats, &ray, *v, &format!("bunny triangle {i}"));
    }
    stats.print("bunny");
    assert!(stats.count > 1000, "only {} hits", stats.count);
}
