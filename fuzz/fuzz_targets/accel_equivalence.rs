//! Arbitrary bytes -> a triangle scene and a few rays, in both number modes.
//!
//! Checks, for every structure of [`kinds`] (every BVH builder and leaf size, the 4-wide and
//! the 8-wide BVH, the grid and the kd-tree, built through `AnyAccel`; plus one leaf-order
//! build): the structure validates, its closest hit equals brute force (`Linear`) bit for bit
//! (t bits, prim, u bits, v bits), queried directly and through `Coherent` (the 8-wide BVH's
//! walk for coherent rays), `occluded() == intersect().is_some()` for both, hits lie in
//! the ray's interval with barycentrics in [0, 1]; arenas one slot too small give
//! `ArenaTooSmall`; bad vertices give `BadPrimitive` (the same one `Triangle::from_f32` names);
//! spawned rays (`raykernel::spawn`) are valid and never panic. Nothing may panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::grid::GridOptions;
use raykernel::kdtree::{self, KdOptions};
use raykernel::spawn::spawn_ray;
use raykernel::{
    Accel, AccelKind, AnyAccel, Arena, BuildError, Bvh, Coherent, Hit, Linear, Node, Ray, Scalar,
    Triangle, F32_COORD_LIMIT, I16F16,
};
use raykernel_testkit::memory::OwnedMemory;

/// Reads the input front to back; past the end everything is zero.
struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
    /// Coordinates produced so far (reused to make shared and coincident vertices).
    seen: Vec<f32>,
}

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    /// A coordinate, biased toward values that make ties, shared edges and range limits.
    fn coord(&mut self) -> f32 {
        let tag = self.u8();
        let x = match tag >> 5 {
            // Small grid (quarter units): coincident vertices, axis-aligned edges, ties.
            0..=2 => f32::from(self.u8() as i8) * 0.25,
            // Grid at a power-of-two scale 2^-16 ..= 2^15.
            3 => f32::from(self.u8() as i8) * f32::powi(2.0, i32::from(tag & 31) - 16),
            // Any f32 bit pattern (NaN, inf, subnormals, out of range).
            4 => f32::from_bits(self.u32()),
            // Range limits and specials.
            5 => {
                const SPECIAL: [f32; 16] = [
                    0.0,
                    -0.0,
                    8192.0,
                    -8192.0,
                    8192.001,
                    -8192.001,
                    F32_COORD_LIMIT,
                    -F32_COORD_LIMIT,
                    1.0e-45,
                    -1.0e-45,
                    f32::MIN_POSITIVE,
                    1.0e-4,
                    1.0e4,
                    f32::NAN,
                    f32::INFINITY,
                    f32::NEG_INFINITY,
                ];
                SPECIAL[usize::from(tag & 15)]
            }
            // Value in [-8192, 8192) with 16 fraction bits of fixed-point-exact resolution.
            6 => (self.u32() as i32 >> 2) as f32 / 65536.0,
            // Reuse an earlier coordinate.
            _ => {
                let i = usize::from(self.u8());
                match self.seen.len() {
                    0 => 0.0,
                    n => self.seen[i % n],
                }
            }
        };
        self.seen.push(x);
        x
    }
    fn point(&mut self) -> [f32; 3] {
        [self.coord(), self.coord(), self.coord()]
    }
}

struct RayIn {
    o: [f32; 3],
    d: [f32; 3],
    t_min: f32,
    t_max: f32,
}

fn scene(data: &[u8]) -> (Vec<[[f32; 3]; 3]>, Vec<RayIn>) {
    let mut b = Bytes {
        data,
        pos: 0,
        seen: Vec::new(),
    };
    let n_tris = usize::from(b.u8() % 40);
    let n_rays = 1 + usize::from(b.u8() % 8);
    let mut tris: Vec<[[f32; 3]; 3]> = Vec::with_capacity(n_tris);
    for _ in 0..n_tris {
        let mut t = [[0.0; 3]; 3];
        for v in &mut t {
            let tag = b.u8();
            *v = if tag < 64 && !tris.is_empty() {
                // Reuse a vertex of an earlier triangle: shared vertices and edges.
                let k = usize::from(b.u8()) % (tris.len() * 3);
                tris[k / 3][k % 3]
            } else {
                b.point()
            };
        }
        tris.push(t);
    }
    let mut rays = Vec::with_capacity(n_rays);
    for _ in 0..n_rays {
        let o = b.point();
        let tag = b.u8();
        let d = if tag < 96 && !tris.is_empty() {
            // Aim at a vertex, an edge point or an interior point of a triangle.
            let t = tris[usize::from(b.u8()) % tris.len()];
            let (w1, w2) = match tag % 3 {
                0 => (0.0, 0.0),
                1 => (f32::from(b.u8()) / 255.0, 0.0),
                _ => (f32::from(b.u8()) / 512.0, f32::from(b.u8()) / 512.0),
            };
            let target: [f32; 3] = core::array::from_fn(|k| {
                t[0][k] + w1 * (t[1][k] - t[0][k]) + w2 * (t[2][k] - t[0][k])
            });
            core::array::from_fn(|k| target[k] - o[k])
        } else {
            b.point()
        };
        let tag = b.u8();
        let (t_min, t_max) = match tag % 4 {
            0 => (0.0, f32::INFINITY),
            1 => (b.coord(), b.coord()),
            2 => {
                let t = b.coord();
                (t, t)
            }
            _ => (0.0, b.coord()),
        };
        rays.push(RayIn { o, d, t_min, t_max });
    }
    (tris, rays)
}

trait Mode: Scalar {
    fn bits(self) -> u32;
    /// The triangle as given, without range checks (so the builder has to reject it).
    fn unchecked(v: [[f32; 3]; 3]) -> Triangle<Self>;
    fn one() -> Self;
}

impl Mode for f32 {
    fn bits(self) -> u32 {
        self.to_bits()
    }
    fn unchecked(v: [[f32; 3]; 3]) -> Triangle<f32> {
        Triangle { v }
    }
    fn one() -> Self {
        1.0
    }
}

impl Mode for I16F16 {
    fn bits(self) -> u32 {
        self.raw() as u32
    }
    fn unchecked(v: [[f32; 3]; 3]) -> Triangle<I16F16> {
        Triangle {
            v: v.map(|p| p.map(I16F16::from_f32)),
        }
    }
    fn one() -> Self {
        I16F16::ONE
    }
}

fn from_f64<S: Mode>(x: f64) -> S {
    S::from_f32_saturating(x as f32)
}

/// |cos| of the angle between a ray's (rounded) direction and the triangle's normal (0 if the
/// triangle has no normal).
fn cos_to_normal<S: Mode>(tri: &Triangle<S>, r: &Ray<S>) -> f64 {
    let v = tri.v.map(|p| p.map(S::to_f64));
    let e1: [f64; 3] = core::array::from_fn(|k| v[1][k] - v[0][k]);
    let e2: [f64; 3] = core::array::from_fn(|k| v[2][k] - v[0][k]);
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let d = S::vec_to_array(r.dir()).map(S::to_f64);
    let nn = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let dd = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if !(nn > 0.0 && dd > 0.0 && nn.is_finite()) {
        return 0.0;
    }
    ((n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / (nn * dd)).abs()
}

fn bits<S: Mode>(h: &Option<Hit<S>>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.bits(), h.prim, h.u.bits(), h.v.bits()))
}

fn check_mode<S: Mode>(tris_f32: &[[[f32; 3]; 3]], rays_in: &[RayIn]) {
    let n = tris_f32.len();
    let converted: Result<Vec<Triangle<S>>, (usize, usize, raykernel::PointError)> = tris_f32
        .iter()
        .enumerate()
        .map(|(i, t)| Triangle::<S>::from_f32(*t).map_err(|e| (i, e.vertex, e.error)))
        .collect();
    let tris = match converted {
        Ok(t) => t,
        Err((prim, vertex, error)) => {
            // The builder must refuse the unconverted scene with a typed error.
            let raw: Vec<Triangle<S>> = tris_f32.iter().map(|t| S::unchecked(*t)).collect();
            let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
            let mut ids = vec![0u32; n];
            match Bvh::build(&raw, &mut nodes, &mut ids, BuildOptions::default()) {
                Err(BuildError::BadPrimitive {
                    prim: p,
                    vertex: v,
                    error: e,
                }) => {
                    if S::NAME == "f32" {
                        assert_eq!(
                            (p, v, e),
                            (prim, vertex, error),
                            "f32 build names another vertex"
                        );
                    }
                }
                // Fixed point saturates NaN to 0 and clamps: the raw scene may be usable.
                Ok(_) if S::NAME == "fixed" => {}
                other => panic!("{} build of a bad scene: {other:?}", S::NAME),
            }
            return;
        }
    };

    // Arenas one slot too small.
    if n > 0 {
        let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n) - 1];
        let mut ids = vec![0u32; n];
        match Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()) {
            Err(BuildError::ArenaTooSmall {
                arena: Arena::Nodes,
                needed,
                ..
            }) => assert_eq!(needed, nodes_needed(n)),
            other => panic!("nodes arena short by one: {other:?}"),
        }
        let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
        let mut ids = vec![0u32; n - 1];
        match Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()) {
            Err(BuildError::ArenaTooSmall {
                arena: Arena::PrimIds,
                needed,
                ..
            }) => assert_eq!(needed, n),
            other => panic!("prim-id arena short by one: {other:?}"),
        }
    }

    let rays: Vec<Ray<S>> = rays_in
        .iter()
        .filter_map(|r| Ray::<S>::from_f32(r.o, r.d, r.t_min, r.t_max).ok())
        .collect();
    let linear = Linear::new(&tris);
    let want: Vec<Option<Hit<S>>> = rays
        .iter()
        .map(|r| {
            let h = linear.intersect(r);
            assert_eq!(linear.occluded(r), h.is_some(), "Linear occluded != hit");
            if let Some(h) = h {
                assert!(
                    h.t >= r.t_min() && h.t <= r.t_max(),
                    "hit outside interval: {h:?}"
                );
                assert!((h.prim as usize) < n);
                for w in [h.u, h.v] {
                    assert!(
                        w >= S::ZERO && w <= S::one(),
                        "{} barycentric out of [0,1]: {h:?} on {:?}, ray {r:?}",
                        S::NAME,
                        tris[h.prim as usize]
                    );
                }
                // Spawned rays (back toward the ray's side, onward through the surface, and
                // toward a vertex) must not re-hit their own triangle unless nearly tangent.
                let tri = &tris[h.prim as usize];
                let back = S::vec_to_array(r.dir()).map(|x| from_f64::<S>(-x.to_f64()));
                let back = S::array_to_vec(back);
                for dir in [back, r.dir(), S::array_to_vec(tri.v[0])] {
                    if let Ok(s) = spawn_ray(r, &h, tri, dir) {
                        let _ = linear.intersect(&s);
                        if cos_to_normal(tri, &s) >= 1e-3 {
                            assert!(
                                tri.intersect(&s).is_none(),
                                "{} self-hit: {tri:?} from {h:?}, spawned {s:?}",
                                S::NAME
                            );
                        }
                    }
                }
            }
            h
        })
        .collect();

    for kind in kinds() {
        // The grid's size depends on the geometry: its counting pass may refuse a scene with a
        // typed error. Every other structure's size depends on the count alone.
        let need = match kind.memory_needed(&tris) {
            Ok(need) => need,
            Err(_) if kind.memory_for_count(n).is_none() => continue,
            Err(e) => panic!("{} {kind}: memory: {e}", S::NAME),
        };
        let mut memory = OwnedMemory::<S>::sized(need);
        let accel = AnyAccel::build(kind, &tris, &mut memory.memory())
            .unwrap_or_else(|e| panic!("{} build {kind}: {e}", S::NAME));
        if let Err(e) = accel.validate() {
            panic!("{} {kind}: invalid: {e:?}", S::NAME);
        }
        // Every structure by its default walk and through `Coherent` (the 8-wide BVH's walk
        // for coherent rays; the others' one walk).
        let coherent = Coherent(&accel);
        for (r, w) in rays.iter().zip(&want) {
            for (walk, got, occluded) in [
                ("", accel.intersect(r), accel.occluded(r)),
                (" coherent", coherent.intersect(r), coherent.occluded(r)),
            ] {
                assert_eq!(
                    bits(&got),
                    bits(w),
                    "{} {kind}{walk}: {got:?} != Linear {w:?}",
                    S::NAME
                );
                assert_eq!(
                    occluded,
                    got.is_some(),
                    "{} {kind}{walk}: occluded",
                    S::NAME
                );
            }
        }
    }
    let mut permuted = tris.clone();
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(n)];
    let mut ids = vec![0u32; n];
    let bvh =
        Bvh::build_in_leaf_order(&mut permuted, &mut nodes, &mut ids, BuildOptions::default())
            .unwrap_or_else(|e| panic!("{} leaf-order build: {e}", S::NAME));
    for (r, w) in rays.iter().zip(&want) {
        let got = bvh.intersect(r);
        assert_eq!(
            bits(&got),
            bits(w),
            "{} leaf order: BVH {got:?} != Linear {w:?}",
            S::NAME
        );
        assert_eq!(bvh.occluded(r), got.is_some());
    }
}

/// Every structure checked against brute force: each BVH builder at leaf sizes 1, 2, 4 and 8,
/// the 4-wide and the 8-wide BVH collapsed from each builder's leaf-4 tree, the grid at three
/// densities and the kd-tree at the automatic and the deepest depth limit.
fn kinds() -> Vec<AccelKind> {
    let mut kinds = Vec::new();
    for builder in BuilderKind::ALL {
        for max_leaf_size in [1, 2, 4, 8] {
            kinds.push(AccelKind::Bvh(BuildOptions {
                builder,
                max_leaf_size,
                reinsertion: true,
            }));
        }
        let wide = BuildOptions {
            builder,
            max_leaf_size: 4,
            reinsertion: true,
        };
        kinds.push(AccelKind::Bvh4(wide));
        kinds.push(AccelKind::Bvh8(wide));
    }
    for density in [0.25, GridOptions::DEFAULT.density, 8.0] {
        kinds.push(AccelKind::Grid(GridOptions { density }));
    }
    for max_depth in [0, kdtree::MAX_DEPTH] {
        kinds.push(AccelKind::KdTree(KdOptions { max_depth }));
    }
    kinds
}

fuzz_target!(|data: &[u8]| {
    let (tris, rays) = scene(data);
    check_mode::<f32>(&tris, &rays);
    check_mode::<I16F16>(&tris, &rays);
});
