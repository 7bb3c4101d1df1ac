//! Hit accuracy against an `f64` reference.
//!
//! The reference is the kernel's algorithm at `f64`: the Woop–Benthin–Wald watertight test
//! (translate, permute, shear, edge-function signs, `t = T / det`) on the `f64` values of the
//! scene's `f32` vertices and of the ray records (direction normalised in `f64`, not rounded),
//! closest hit by `(t, lowest id)`, found through an `f32` SAH BVH of the same triangles whose
//! boxes are tested in `f64` with a small outward margin (a box holds its triangles' exact
//! `f32` vertices, so the margin only covers the slab test's own rounding).
//!
//! Per contender, over the traced rays:
//! - hit-distance error: `|t − t*| / t*` with `t*` the distance to the plane of the reported
//!   triangle recomputed in `f64` (so it measures `t` alone, whichever triangle was picked);
//! - primitive disagreement with the reference: `wrong_prim` when both hit different
//!   triangles at distances further apart than `1e-5·t` (a different surface), `ties` when
//!   the distances agree (shared edges, coincident triangles);
//! - `leaks`: the reference hits and the contender misses; `false_hits`: the reverse.

use host::rayfile::{HitRecord, RayRecord};
use raykernel::bvh::{nodes_needed, BuildOptions};
use raykernel::{Bvh, Node, Triangle};
use serde::Serialize;

/// Errors of one contender's closest hits against the reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Accuracy {
    /// Rays compared.
    pub rays: usize,
    /// Largest relative hit-distance error.
    pub t_rel_max: f64,
    /// Mean relative hit-distance error over the contender's hits.
    pub t_rel_mean: f64,
    /// Both hit, different surfaces (distances differ by more than `1e-5·t`).
    pub wrong_prim: usize,
    /// Both hit, different triangles at the same distance (within `1e-5·t`).
    pub ties: usize,
    /// The reference hits, the contender misses.
    pub leaks: usize,
    /// The reference misses, the contender hits.
    pub false_hits: usize,
}

/// Relative tolerance under which two hit distances count as the same surface.
pub const SAME_T_REL: f64 = 1e-5;

/// The `f64` reference for one ray set: rays, triangles and closest hits.
pub struct Reference {
    /// Origin and unit direction (normalised in `f64`) of each traced ray; `None` for a record
    /// the reference cannot use (zero or non-finite direction).
    rays: Vec<Option<RefRay>>,
    tris: Vec<[[f64; 3]; 3]>,
    /// Closest hit `(t, prim)` per traced ray.
    hits: Vec<Option<(f64, u32)>>,
}

#[derive(Clone, Copy, Debug)]
struct RefRay {
    o: [f64; 3],
    d: [f64; 3],
    t_min: f64,
    t_max: f64,
}

impl Reference {
    /// Computes the reference for every record, on `threads` threads (this part is not timed).
    ///
    /// # Errors
    /// The kernel's build error if the triangles cannot be built into a BVH.
    pub fn compute(
        tris: &[[[f32; 3]; 3]],
        records: &[RayRecord],
        threads: usize,
    ) -> Result<Self, raykernel::BuildError> {
        let kernel_tris: Vec<Triangle<f32>> = tris.iter().map(|t| Triangle { v: *t }).collect();
        let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(tris.len())];
        let mut ids = vec![0u32; tris.len()];
        let bvh = Bvh::build(&kernel_tris, &mut nodes, &mut ids, BuildOptions::default())?;
        let tris64: Vec<[[f64; 3]; 3]> = tris.iter().map(|t| t.map(|p| p.map(f64::from))).collect();
        let rays: Vec<Option<RefRay>> = records.iter().map(RefRay::from_record).collect();
        let mut hits = vec![None; rays.len()];
        let chunk = rays.len().div_ceil(threads.max(1)).max(1);
        let (tree_nodes, tree_ids) = (bvh.nodes(), bvh.prim_ids());
        std::thread::scope(|s| {
            for (out, rays) in hits.chunks_mut(chunk).zip(rays.chunks(chunk)) {
                let tris64 = &tris64;
                s.spawn(move || {
                    let mut stack = Vec::with_capacity(128);
                    for (slot, ray) in out.iter_mut().zip(rays) {
                        *slot = ray
                            .as_ref()
                            .and_then(|r| closest(tree_nodes, tree_ids, tris64, r, &mut stack));
                    }
                });
            }
        });
        Ok(Self {
            rays,
            tris: tris64,
            hits,
        })
    }

    /// Rays in the reference.
    #[must_use]
    pub fn len(&self) -> usize {
        self.hits.len()
    }

    /// True if no ray was traced.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.hits.is_empty()
    }

    /// Rays the reference hits.
    #[must_use]
    pub fn hit_count(&self) -> usize {
        self.hits.iter().filter(|h| h.is_some()).count()
    }

    /// Errors of `hits` (one per traced ray, in order) against the reference.
    #[must_use]
    pub fn accuracy(&self, hits: &[HitRecord]) -> Accuracy {
        let mut a = Accuracy {
            rays: hits.len().min(self.hits.len()),
            ..Accuracy::default()
        };
        let (mut sum, mut counted) = (0.0f64, 0usize);
        for ((h, reference), ray) in hits.iter().zip(&self.hits).zip(&self.rays) {
            match (h.is_hit(), reference) {
                (false, Some(_)) => a.leaks += 1,
                (true, None) => a.false_hits += 1,
                _ => {}
            }
            let Some(ray) = ray else { continue };
            if !h.is_hit() {
                continue;
            }
            if let Some(exact) = self
                .tris
                .get(h.prim as usize)
                .and_then(|tri| plane_t(tri, ray))
            {
                let rel = (f64::from(h.t) - exact).abs() / exact;
                sum += rel;
                counted += 1;
                a.t_rel_max = a.t_rel_max.max(rel);
            }
            if let Some((t_ref, prim_ref)) = *reference {
                if prim_ref != h.prim {
                    if (f64::from(h.t) - t_ref).abs() <= SAME_T_REL * t_ref.abs() {
                        a.ties += 1;
                    } else {
                        a.wrong_prim += 1;
                    }
                }
            }
        }
        a.t_rel_mean = if counted > 0 {
            sum / counted as f64
        } else {
            0.0
        };
        a
    }
}

impl RefRay {
    fn from_record(r: &RayRecord) -> Option<Self> {
        let d = r.dir.map(f64::from);
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let o = r.origin.map(f64::from);
        if !(n > 0.0 && n.is_finite()) || o.iter().any(|x| !x.is_finite()) {
            return None;
        }
        Some(Self {
            o,
            d: d.map(|x| x / n),
            t_min: f64::from(r.t_min),
            t_max: f64::from(r.t_max),
        })
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Distance along the ray to the plane of `tri` (`None` if parallel, degenerate or behind).
fn plane_t(tri: &[[f64; 3]; 3], ray: &RefRay) -> Option<f64> {
    let e1 = sub(tri[1], tri[0]);
    let e2 = sub(tri[2], tri[0]);
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let nd = dot(n, ray.d);
    let t = dot(n, sub(tri[0], ray.o)) / nd;
    (nd != 0.0 && t.is_finite() && t > 0.0).then_some(t)
}

/// Slab test in `f64` against an `f32` box grown by a relative 1e-9: entry distance if the
/// ray's `[t_min, t_max]` meets it.
fn slab(node: &Node<f32>, ray: &RefRay, t_max: f64) -> Option<f64> {
    let b = node.bounds();
    let (mut t0, mut t1) = (ray.t_min, t_max);
    for k in 0..3 {
        let (lo, hi) = (f64::from(b.lo[k]), f64::from(b.hi[k]));
        let pad = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
        let (lo, hi) = (lo - pad, hi + pad);
        if ray.d[k] == 0.0 {
            if ray.o[k] < lo || ray.o[k] > hi {
                return None;
            }
            continue;
        }
        let inv = 1.0 / ray.d[k];
        let (a, c) = ((lo - ray.o[k]) * inv, (hi - ray.o[k]) * inv);
        let (near, far) = if a < c { (a, c) } else { (c, a) };
        t0 = t0.max(near);
        t1 = t1.min(far * (1.0 + 1e-12));
        if t0 > t1 {
            return None;
        }
    }
    Some(t0)
}

/// Closest hit by `(t, lowest id)` over the tree.
fn closest(
    nodes: &[Node<f32>],
    ids: &[u32],
    tris: &[[[f64; 3]; 3]],
    ray: &RefRay,
    stack: &mut Vec<usize>,
) -> Option<(f64, u32)> {
    let mut best: Option<(f64, u32)> = None;
    let wbw = Wbw::new(ray);
    stack.clear();
    if !nodes.is_empty() {
        stack.push(0);
    }
    while let Some(i) = stack.pop() {
        let Some(node) = nodes.get(i) else { continue };
        let t_max = best.map_or(ray.t_max, |b| b.0);
        if slab(node, ray, t_max).is_none() {
            continue;
        }
        let first = node.first() as usize;
        if node.is_leaf() {
            for &id in ids
                .get(first..first + node.count() as usize)
                .unwrap_or_default()
            {
                let Some(tri) = tris.get(id as usize) else {
                    continue;
                };
                if let Some(t) = wbw.hit(tri, ray.t_min, t_max) {
                    let better = match best {
                        None => true,
                        Some((bt, bid)) => t < bt || (t == bt && id < bid),
                    };
                    if better {
                        best = Some((t, id));
                    }
                }
            }
        } else {
            stack.push(first);
            stack.push(first + 1);
        }
    }
    best
}

/// Woop–Benthin–Wald in `f64`: the per-ray permutation and shear.
struct Wbw {
    o: [f64; 3],
    k: [usize; 3],
    s: [f64; 3],
}

impl Wbw {
    fn new(ray: &RefRay) -> Self {
        // Permute so that |d[kz]| is largest; swap kx, ky if d[kz] < 0 to keep the winding.
        let d = ray.d;
        let mut kz = 0;
        for k in 1..3 {
            if d[k].abs() > d[kz].abs() {
                kz = k;
            }
        }
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            o: ray.o,
            k: [kx, ky, kz],
            s: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
        }
    }

    fn hit(&self, tri: &[[f64; 3]; 3], t_min: f64, t_max: f64) -> Option<f64> {
        let [kx, ky, kz] = self.k;
        // Translate to the ray origin, then shear so the ray is the +z axis.
        let p = tri.map(|v| {
            let a = sub(v, self.o);
            [
                a[kx] - self.s[0] * a[kz],
                a[ky] - self.s[1] * a[kz],
                self.s[2] * a[kz],
            ]
        });
        let [a, b, c] = p;
        // Edge functions; reject if their signs differ (two-sided, edges inclusive).
        let u = c[0] * b[1] - c[1] * b[0];
        let v = a[0] * c[1] - a[1] * c[0];
        let w = b[0] * a[1] - b[1] * a[0];
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t = (u * a[2] + v * b[2] + w * c[2]) / det;
        (t >= t_min && t <= t_max && t.is_finite()).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Vec<[[f32; 3]; 3]> {
        vec![
            [[-1.0, -1.0, 5.0], [1.0, -1.0, 5.0], [1.0, 1.0, 5.0]],
            [[-1.0, -1.0, 5.0], [1.0, 1.0, 5.0], [-1.0, 1.0, 5.0]],
            [[-1.0, -1.0, 9.0], [1.0, -1.0, 9.0], [0.0, 1.0, 9.0]],
        ]
    }

    #[test]
    fn reference_finds_the_nearest_and_ties_to_the_lower_id() {
        let rays = [
            RayRecord::new([0.5, -0.5, 0.0], [0.0, 0.0, 1.0]),
            RayRecord::new([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), // on the shared diagonal
            RayRecord::new([5.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            RayRecord::new([0.0, 0.0, 20.0], [0.0, 0.0, -1.0]),
        ];
        let r = Reference::compute(&quad(), &rays, 2).unwrap();
        assert_eq!(
            r.hits,
            vec![Some((5.0, 0)), Some((5.0, 0)), None, Some((11.0, 2))]
        );
        let hit = |t, prim| HitRecord { t, prim };
        let a = r.accuracy(&[hit(5.0, 0), hit(5.0, 1), hit(6.0, 0), HitRecord::MISS]);
        assert_eq!((a.ties, a.false_hits, a.leaks, a.wrong_prim), (1, 1, 1, 0));
        // t = 6 against the plane of triangle 0 at 5: relative error 0.2.
        assert!((a.t_rel_max - 0.2).abs() < 1e-12);
        // Triangle 0 (z = 5) behind triangle 2 (z = 9) seen from z = 20: a different surface.
        let b = r.accuracy(&[hit(5.0, 0), hit(5.0, 0), HitRecord::MISS, hit(15.0, 0)]);
        assert_eq!((b.wrong_prim, b.ties), (1, 0));
        assert!(b.t_rel_max < 1e-12);
    }
}
