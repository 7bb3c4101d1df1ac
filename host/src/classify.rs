//! Why two hit files disagree on a ray: could the fixed-point quantization of the inputs
//! (moving each point by at most [`quantization_bound`]) change which triangle the ray hits?
//!
//! Everything is computed in `f64` from the `f32` inputs (ray file, OBJ vertices). For each ray
//! whose prim ids differ (a hit/miss mismatch included):
//! - **edge**: the distance from the ray (half-line `o + s·d`, `d` normalised, `s` in
//!   `[t_min, t_max]`) to the nearest edge (segment) of each reported triangle, minimum over both
//!   (a miss side has no triangle). At most the bound: explained by quantization (the ray can
//!   move to the other side of that edge).
//! - **depth**: otherwise, when both sides hit, [`depth_distance`]: how close the ray comes to
//!   a point near both triangles. At most the bound: the two triangles come that close to each
//!   other where the ray meets them (surfaces crossing or touching, e.g. walls meeting in a
//!   corner), so quantization can swap which is nearer.
//! - **origin**: otherwise, when the nearer of the two hits lies within the bound of the ray's
//!   origin: quantizing the origin can put that surface behind the ray's start (a ray leaving
//!   a surface, as secondary rays do), so the other side sees the next surface instead.
//! - anything else is unexplained: one side missed a triangle that the ray meets well inside,
//!   or picked the farther of two well separated ones.

use crate::obj::Mesh;
use crate::rayfile::{HitRecord, RayRecord};
use serde::Serialize;

/// The bound's formula, as printed in the report.
pub const BOUND_FORMULA: &str = "4*sqrt(3)*2^-17 + t*2^-28";

/// Distance within which fixed point (`I16F16`) and `f32` may legitimately disagree about which
/// side of an edge a ray passes at distance `t`: vertices and origin rounded to 2^-16 (up to
/// `sqrt(3)·2^-17` per point) with a factor 4 of margin (two points move, plus `f32` rounding),
/// and the Q2.30 direction (angular error about 2^-30, with margin 2^-28) times `t`.
#[must_use]
pub fn quantization_bound(t: f64) -> f64 {
    4.0 * 3f64.sqrt() * (-17f64).exp2() + t * (-28f64).exp2()
}

/// How many of the differing rays the quantization bound explains.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Classification {
    /// Rays whose prim ids differ (hit/miss mismatches included).
    pub differing: usize,
    /// Differing rays within [`quantization_bound`] of an edge of a reported triangle.
    pub explained_by_quantization: usize,
    /// Other differing rays where the two reported triangles are within the bound of each other
    /// at the ray (a depth tie that quantization can swap).
    pub explained_by_depth: usize,
    /// Other differing rays whose nearer hit lies within the bound of the ray's origin
    /// (quantizing the origin can put that surface behind the ray's start).
    pub explained_by_origin: usize,
    /// The rest: neither explanation holds.
    pub unexplained: usize,
    /// Largest edge distance (minimum over both triangles) among the differing rays; 0 if none.
    pub max_edge_distance_of_differing: f64,
    /// The bound's formula ([`BOUND_FORMULA`]).
    pub bound: &'static str,
    /// Up to ten unexplained rays, for a closer look.
    pub unexplained_examples: Vec<Unexplained>,
}

/// One unexplained ray, for the report.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Unexplained {
    /// Index in the ray and hit files.
    pub ray: usize,
    /// Prim id in the reference (`u32::MAX`: miss).
    pub prim_ref: u32,
    /// Prim id in the other file.
    pub prim_other: u32,
    /// `t` in the reference (`inf`: miss; JSON `null`).
    pub t_ref: f32,
    /// `t` in the other file.
    pub t_other: f32,
    /// Distance to the nearest edge of either reported triangle.
    pub edge_distance: f64,
    /// Distance between the triangles at the ray (`inf`, JSON `null`, unless both hit).
    pub depth_distance: f64,
    /// The bound for this ray.
    pub bound: f64,
}

/// A ray or hit refers to something the inputs do not hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClassifyError {
    /// The hit files and the ray file hold different numbers of records.
    RayCount {
        /// Records in the hit files.
        hits: usize,
        /// Records in the ray file.
        rays: usize,
    },
    /// A hit names a triangle the scene does not have.
    PrimOutOfRange {
        /// The ray.
        ray: usize,
        /// The prim id.
        prim: u32,
        /// Triangles in the scene.
        triangles: usize,
    },
}

impl std::fmt::Display for ClassifyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::RayCount { hits, rays } => write!(
                f,
                "the hit files have {hits} records but the ray file has {rays} rays"
            ),
            Self::PrimOutOfRange {
                ray,
                prim,
                triangles,
            } => write!(
                f,
                "ray {ray} hits triangle {prim}, but the scene has {triangles} triangles"
            ),
        }
    }
}

impl std::error::Error for ClassifyError {}

/// Classifies every ray on which `reference` and `other` report different prim ids.
///
/// # Errors
/// [`ClassifyError`] if the record counts differ or a prim id is out of range.
pub fn classify(
    reference: &[HitRecord],
    other: &[HitRecord],
    rays: &[RayRecord],
    mesh: &Mesh,
) -> Result<Classification, ClassifyError> {
    let n = reference.len();
    if other.len() != n || rays.len() != n {
        return Err(ClassifyError::RayCount {
            hits: n,
            rays: rays.len(),
        });
    }
    let mut c = Classification {
        differing: 0,
        explained_by_quantization: 0,
        explained_by_depth: 0,
        explained_by_origin: 0,
        unexplained: 0,
        max_edge_distance_of_differing: 0.0,
        bound: BOUND_FORMULA,
        unexplained_examples: Vec::new(),
    };
    for (i, ((a, b), ray)) in reference.iter().zip(other).zip(rays).enumerate() {
        if a.prim == b.prim {
            continue;
        }
        c.differing += 1;
        let mut tris = [None, None];
        let mut t = 0.0f64;
        let mut nearest = f64::INFINITY;
        for (slot, h) in tris.iter_mut().zip([a, b]) {
            if !h.is_hit() {
                continue;
            }
            let tri = mesh
                .triangles
                .get(h.prim as usize)
                .ok_or(ClassifyError::PrimOutOfRange {
                    ray: i,
                    prim: h.prim,
                    triangles: mesh.triangle_count(),
                })?;
            *slot = Some(tri.map(|k| mesh.positions[k as usize].map(f64::from)));
            t = t.max(f64::from(h.t));
            nearest = nearest.min(f64::from(h.t));
        }
        let bound = quantization_bound(t);
        let edge = tris
            .iter()
            .flatten()
            .map(|v| ray_triangle_edge_distance(ray, v))
            .fold(f64::INFINITY, f64::min);
        c.max_edge_distance_of_differing = c.max_edge_distance_of_differing.max(edge);
        if edge <= bound {
            c.explained_by_quantization += 1;
            continue;
        }
        let depth = match tris {
            [Some(ta), Some(tb)] => depth_distance(ray, &ta, &tb),
            _ => f64::INFINITY,
        };
        if depth <= bound {
            c.explained_by_depth += 1;
            continue;
        }
        if nearest <= bound {
            c.explained_by_origin += 1;
            continue;
        }
        c.unexplained += 1;
        if c.unexplained_examples.len() < 10 {
            c.unexplained_examples.push(Unexplained {
                ray: i,
                prim_ref: a.prim,
                prim_other: b.prim,
                t_ref: a.t,
                t_other: b.t,
                edge_distance: edge,
                depth_distance: depth,
                bound,
            });
        }
    }
    Ok(c)
}

/// Distance from the ray (its `f32` fields, direction normalised in `f64`) to the nearest of
/// the three edges of triangle `v`. Infinite for a ray with a zero or non-finite direction.
#[must_use]
pub fn ray_triangle_edge_distance(ray: &RayRecord, v: &[[f64; 3]; 3]) -> f64 {
    let o = ray.origin.map(f64::from);
    let d = ray.dir.map(f64::from);
    let len = dot(d, d).sqrt();
    if len == 0.0 || !len.is_finite() {
        return f64::INFINITY;
    }
    let d = d.map(|x| x / len);
    let (s0, s1) = (f64::from(ray.t_min), f64::from(ray.t_max));
    (0..3)
        .map(|k| ray_segment_distance(o, d, s0, s1, v[k], v[(k + 1) % 3]))
        .fold(f64::INFINITY, f64::min)
}

/// How close triangles `a` and `b` come to each other where the ray meets them: at the ray's
/// point on the plane of each triangle, the larger of its distances to the two triangles; the
/// minimum over both points. Small only where the ray passes close to both triangles at one
/// point (where they cross or touch). Infinite when the ray is parallel to both planes (or has
/// no usable direction).
#[must_use]
pub fn depth_distance(ray: &RayRecord, a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> f64 {
    let o = ray.origin.map(f64::from);
    let d = ray.dir.map(f64::from);
    let len = norm(d);
    if len == 0.0 || !len.is_finite() {
        return f64::INFINITY;
    }
    let d = d.map(|x| x / len);
    let on_plane = |v: &[[f64; 3]; 3]| {
        let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
        let dn = dot(d, n);
        (dn != 0.0).then(|| add(o, scale(d, dot(sub(v[0], o), n) / dn)))
    };
    [on_plane(a), on_plane(b)]
        .into_iter()
        .flatten()
        .map(|p| point_triangle_distance(p, a).max(point_triangle_distance(p, b)))
        .fold(f64::INFINITY, f64::min)
}

/// Distance from point `p` to the (closed, solid) triangle `v`; a degenerate triangle is the
/// segment or point it collapses to.
#[must_use]
pub fn point_triangle_distance(p: [f64; 3], v: &[[f64; 3]; 3]) -> f64 {
    let [a, b, c] = *v;
    let (ab, ac) = (sub(b, a), sub(c, a));
    let n = cross(ab, ac);
    let nn = dot(n, n);
    let edges = || {
        [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(x, y)| point_segment_distance(p, x, y))
            .fold(f64::INFINITY, f64::min)
    };
    if nn == 0.0 {
        return edges();
    }
    // Barycentrics of p's projection on the plane.
    let ap = sub(p, a);
    let w1 = dot(cross(ap, ac), n) / nn;
    let w2 = dot(cross(ab, ap), n) / nn;
    if w1 >= 0.0 && w2 >= 0.0 && w1 + w2 <= 1.0 {
        dot(ap, n).abs() / nn.sqrt()
    } else {
        edges()
    }
}

fn point_segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let e = sub(b, a);
    let ee = dot(e, e);
    let u = if ee > 0.0 {
        (dot(sub(p, a), e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, add(a, scale(e, u))))
}

/// Distance between the ray part `{o + s·d : s0 <= s <= s1}` (`s1` may be `+inf`, `s0 <= s1`)
/// and the segment `[a, b]` (which may be a point).
///
/// The squared distance is a convex quadratic in `(s, u)` over the box `[s0, s1] × [0, 1]`, so
/// its minimum is the unconstrained one when that lies in the box, and otherwise on one of the
/// box's sides, each a clamped one-dimensional projection.
#[must_use]
pub fn ray_segment_distance(
    o: [f64; 3],
    d: [f64; 3],
    s0: f64,
    s1: f64,
    a: [f64; 3],
    b: [f64; 3],
) -> f64 {
    let e = sub(b, a);
    let (dd, ee, de) = (dot(d, d), dot(e, e), dot(d, e));
    let ray_at = |s: f64| add(o, scale(d, s));
    let seg_at = |u: f64| add(a, scale(e, u));
    // Closest point of the segment to p (a degenerate segment is its first point).
    let on_segment = |p: [f64; 3]| {
        if ee > 0.0 {
            seg_at((dot(sub(p, a), e) / ee).clamp(0.0, 1.0))
        } else {
            a
        }
    };
    // Closest point of the ray part to p.
    let on_ray = |p: [f64; 3]| {
        if dd > 0.0 {
            ray_at((dot(sub(p, o), d) / dd).clamp(s0, s1))
        } else {
            ray_at(s0)
        }
    };
    let mut best = f64::INFINITY;
    let mut consider = |p: [f64; 3], q: [f64; 3]| best = best.min(norm(sub(p, q)));

    // Sides u = 0 and u = 1: the segment's ends against the ray.
    consider(on_ray(a), a);
    consider(on_ray(b), b);
    // Side s = s0 (and s = s1 when finite): the ray's ends against the segment.
    let start = ray_at(s0);
    consider(start, on_segment(start));
    if s1.is_finite() {
        let end = ray_at(s1);
        consider(end, on_segment(end));
    }
    // Interior: both partial derivatives zero, when the lines are not parallel.
    let det = dd * ee - de * de;
    if det > 1e-12 * dd * ee {
        let w = sub(o, a);
        let (wd, we) = (dot(w, d), dot(w, e));
        // With w = o − a: d/ds = 0 gives dd·s − de·u = −wd, d/du = 0 gives de·s − ee·u = −we.
        let s = (de * we - ee * wd) / det;
        let u = (dd * we - de * wd) / det;
        if (s0..=s1).contains(&s) && (0.0..=1.0).contains(&u) {
            consider(ray_at(s), seg_at(u));
        }
    }
    best
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    a.map(|x| x * k)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const INF: f64 = f64::INFINITY;
    const X: [f64; 3] = [1.0, 0.0, 0.0];
    const Y: [f64; 3] = [0.0, 1.0, 0.0];
    const Z: [f64; 3] = [0.0, 0.0, 1.0];
    const O: [f64; 3] = [0.0, 0.0, 0.0];

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} != {b}");
    }

    /// Brute force: the minimum over a grid of (s, u) (the inputs lie in [-2, 2]³, so s <= s0 + 8 is enough).
    fn sampled(o: [f64; 3], d: [f64; 3], s0: f64, s1: f64, a: [f64; 3], b: [f64; 3]) -> f64 {
        let s1 = s1.min(s0 + 8.0);
        let n = 600;
        let mut best = INF;
        for i in 0..=n {
            let s = s0 + (s1 - s0) * f64::from(i) / f64::from(n);
            for j in 0..=n {
                let u = f64::from(j) / f64::from(n);
                best = best.min(norm(sub(add(o, scale(d, s)), add(a, scale(sub(b, a), u)))));
            }
        }
        best
    }

    #[test]
    fn skew_lines_closest_in_the_interior() {
        // Ray along x at height z = 2; segment along y through x = 3: distance 2.
        close(
            ray_segment_distance(
                [0.0, 0.0, 2.0],
                X,
                0.0,
                INF,
                [3.0, -1.0, 0.0],
                [3.0, 1.0, 0.0],
            ),
            2.0,
        );
    }

    #[test]
    fn segment_behind_the_origin_uses_the_ray_start() {
        // Segment along y at x = -3: the ray (x >= 0) is closest at its origin, distance 3.
        close(
            ray_segment_distance(O, X, 0.0, INF, [-3.0, -1.0, 0.0], [-3.0, 1.0, 0.0]),
            3.0,
        );
        // With the whole line it would be 0; a t_min moves the start forward.
        close(
            ray_segment_distance(O, X, 1.0, INF, [-3.0, -1.0, 0.0], [-3.0, 1.0, 0.0]),
            4.0,
        );
    }

    #[test]
    fn segment_end_beyond_the_clamp() {
        // Segment from (3, 1, 0) to (3, 5, 0): nearest point is the end (3, 1, 0), distance 1.
        close(
            ray_segment_distance(O, X, 0.0, INF, [3.0, 1.0, 0.0], [3.0, 5.0, 0.0]),
            1.0,
        );
        // A finite t_max stops the ray at x = 1: distance from (1,0,0) to (3,1,0).
        close(
            ray_segment_distance(O, X, 0.0, 1.0, [3.0, 1.0, 0.0], [3.0, 5.0, 0.0]),
            5f64.sqrt(),
        );
    }

    #[test]
    fn parallel_and_degenerate_segments() {
        // Parallel to the ray, offset by 0.5 in y and z.
        close(
            ray_segment_distance(O, X, 0.0, INF, [2.0, 0.5, 0.5], [7.0, 0.5, 0.5]),
            0.5f64.sqrt(),
        );
        // Parallel, entirely behind: distance to the nearer end (-2, 0, 1).
        close(
            ray_segment_distance(O, X, 0.0, INF, [-7.0, 0.0, 1.0], [-2.0, 0.0, 1.0]),
            5f64.sqrt(),
        );
        // A point.
        close(
            ray_segment_distance(O, Z, 0.0, INF, [0.0, 3.0, 4.0], [0.0, 3.0, 4.0]),
            3.0,
        );
        // Crossing exactly.
        close(
            ray_segment_distance(O, Y, 0.0, INF, [-1.0, 2.0, 0.0], [1.0, 2.0, 0.0]),
            0.0,
        );
    }

    #[test]
    fn agrees_with_sampling_on_random_configurations() {
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..200 {
            let o = [unit(), unit(), unit()];
            let d = [unit(), unit(), unit()];
            let d = scale(d, 1.0 / norm(d));
            let (a, b) = ([unit(), unit(), unit()], [unit(), unit(), unit()]);
            let s1 = if unit() > 0.0 { INF } else { 3.0 };
            let exact = ray_segment_distance(o, d, 0.0, s1, a, b);
            let grid = sampled(o, d, 0.0, s1, a, b);
            // The grid minimum is never below the true one, and close above it.
            assert!(exact <= grid + 1e-12, "{exact} > {grid}");
            assert!(grid - exact < 0.02, "{exact} vs {grid}");
        }
    }

    #[test]
    fn triangle_edge_distance_and_bound() {
        let tri = [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]];
        // Through the interior point (0.25, 0.25): nearest edges at 0.25.
        let ray = RayRecord::new([0.25, 0.25, 0.0], [0.0, 0.0, 2.0]);
        close(ray_triangle_edge_distance(&ray, &tri), 0.25);
        // Through the hypotenuse's midpoint: 0.
        let ray = RayRecord::new([0.5, 0.5, 0.0], [0.0, 0.0, 1.0]);
        close(ray_triangle_edge_distance(&ray, &tri), 0.0);
        let zero = RayRecord::new([0.5, 0.5, 0.0], [0.0; 3]);
        assert_eq!(ray_triangle_edge_distance(&zero, &tri), INF);
        close(quantization_bound(0.0), 4.0 * 3f64.sqrt() / 131_072.0);
        close(
            quantization_bound(8.0) - quantization_bound(0.0),
            8.0 / 268_435_456.0,
        );
    }

    #[test]
    fn point_triangle_distance_regions() {
        let tri = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        // Above the interior: the height.
        close(point_triangle_distance([0.5, 0.5, 3.0], &tri), 3.0);
        close(point_triangle_distance([0.5, 0.5, 0.0], &tri), 0.0);
        // Beside an edge, beyond a vertex.
        close(point_triangle_distance([1.0, -1.0, 0.0], &tri), 1.0);
        close(point_triangle_distance([2.0, 2.0, 0.0], &tri), 2f64.sqrt());
        close(point_triangle_distance([-3.0, -4.0, 0.0], &tri), 5.0);
        close(point_triangle_distance([3.0, 0.0, 4.0], &tri), 17f64.sqrt());
        // Degenerate: a segment from (0,0,0) to (2,0,0), and a point.
        let seg = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        close(point_triangle_distance([1.5, 3.0, 4.0], &seg), 5.0);
        let pt = [[1.0, 1.0, 1.0]; 3];
        close(point_triangle_distance([1.0, 1.0, 3.0], &pt), 2.0);
    }

    #[test]
    fn depth_distance_of_crossing_and_separate_triangles() {
        // Floor z = 0 and a wall x = 1 meeting it; a ray down through the corner region.
        let floor = [[-5.0, -5.0, 0.0], [15.0, -5.0, 0.0], [-5.0, 15.0, 0.0]];
        let wall = [[1.0, -5.0, -1.0], [1.0, 5.0, -1.0], [1.0, 0.0, 5.0]];
        let ray = |x: f32| RayRecord::new([x, 0.0, 2.0], [-1.0, 0.0, -1.0]);
        // From x = 3 the ray meets floor and wall at the same point (1, 0, 0): distance 0.
        close(depth_distance(&ray(3.0), &floor, &wall), 0.0);
        // From x = 3.5 it meets the wall 0.5 above the floor and the floor 0.5 off the wall.
        close(depth_distance(&ray(3.5), &floor, &wall), 0.5);
        // Coplanar, side by side: the ray meets the plane 0.3 from the other triangle.
        let beside = [[0.3, -5.0, 0.0], [5.0, -5.0, 0.0], [0.3, 5.0, 0.0]];
        let down = RayRecord::new([0.0, 0.0, 3.0], [0.0, 0.0, -1.0]);
        close(depth_distance(&down, &floor, &beside), 0.3);
        // Parallel floors one apart, ray straight down: 1.
        let up = floor.map(|p| [p[0], p[1], 1.0]);
        close(depth_distance(&down, &floor, &up), 1.0);
        // A ray parallel to both planes.
        let flat = RayRecord::new([0.0, 0.0, 3.0], [1.0, 0.0, 0.0]);
        assert_eq!(depth_distance(&flat, &floor, &up), INF);
    }

    #[test]
    fn classify_counts_and_examples() {
        let mesh = Mesh {
            positions: vec![
                [0.0, 0.0, 5.0],
                [1.0, 0.0, 5.0],
                [0.0, 1.0, 5.0],
                [1.0, 1.0, 5.0],
            ],
            position_lines: vec![1, 2, 3, 4],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
            triangle_lines: vec![5, 6],
            ..Mesh::default()
        };
        let down = [0.0, 0.0, 1.0];
        let eps = 1e-6f32;
        let rays = [
            RayRecord::new([0.2, 0.2, 0.0], down),       // agree
            RayRecord::new([0.5 + eps, 0.5, 0.0], down), // on the shared diagonal
            RayRecord::new([0.3, 0.3, 0.0], down),       // far from every edge
            RayRecord::new([1.0 + eps, 0.5, 0.0], down), // silhouette: hit vs miss
        ];
        let h = |t, prim| HitRecord { t, prim };
        let a = [h(5.0, 0), h(5.0, 0), h(5.0, 0), h(5.0, 1)];
        let b = [h(5.0, 0), h(5.0, 1), h(5.0, 1), HitRecord::MISS];
        let c = classify(&a, &b, &rays, &mesh).unwrap();
        assert_eq!(
            (
                c.differing,
                c.explained_by_quantization,
                c.explained_by_depth,
                c.unexplained
            ),
            (3, 2, 0, 1)
        );
        assert_eq!(c.unexplained_examples.len(), 1);
        let u = c.unexplained_examples[0];
        assert_eq!((u.ray, u.prim_ref, u.prim_other), (2, 0, 1));
        // Coplanar triangles: the ray meets triangle 0's plane 0.28 from triangle 1.
        close(u.depth_distance, u.edge_distance);
        // Ray 2's nearest edge is the shared diagonal x + y = 1.
        let x = f64::from(0.3f32);
        close(
            c.max_edge_distance_of_differing,
            (1.0 - 2.0 * x) / 2f64.sqrt(),
        );
        assert_eq!(c.bound, BOUND_FORMULA);

        // A third triangle, slanted, crossing the plane z = 5 along x = 0.3: ray 2 meets both at
        // (0.3, 0.3, 5), far from their edges, so which is nearer is a depth tie.
        let mut walled = mesh.clone();
        walled
            .positions
            .extend([[-0.7, -1.0, 4.0], [-0.7, 2.0, 4.0], [1.3, 0.5, 6.0]]);
        walled.triangles.push([4, 5, 6]);
        let b = [h(5.0, 0), h(5.0, 1), h(5.0, 2), HitRecord::MISS];
        let c = classify(&a, &b, &rays, &walled).unwrap();
        assert_eq!((c.explained_by_depth, c.unexplained), (1, 0));

        // A ray leaving triangle 0 (origin a hair above its plane): one side hits it at once,
        // the other (origin quantized behind it) reports another surface, far from its edges.
        let mut leaving = rays;
        leaving[2] = RayRecord::new([0.3, 0.3, 5.0 - eps], down);
        let near = [h(5.0, 0), h(5.0, 0), h(eps, 0), h(5.0, 1)];
        let far = [h(5.0, 0), h(5.0, 1), h(3.0, 1), HitRecord::MISS];
        let c = classify(&near, &far, &leaving, &mesh).unwrap();
        assert_eq!((c.explained_by_origin, c.unexplained), (1, 0));

        let bad = [h(5.0, 0), h(5.0, 0), h(5.0, 7), h(5.0, 1)];
        assert_eq!(
            classify(&a, &bad, &rays, &mesh),
            Err(ClassifyError::PrimOutOfRange {
                ray: 2,
                prim: 7,
                triangles: 2
            })
        );
        assert_eq!(
            classify(&a, &b, &rays[..2], &mesh),
            Err(ClassifyError::RayCount { hits: 4, rays: 2 })
        );
    }
}
