//! Hit files of a generated mesh and ray set, through every accelerator in both modes.
//!
//! The mesh is a 24×24 heightfield of a smooth bump (1152 triangles, shared edges and
//! vertices), the rays 2048 seeded rays: most from above aiming down into the field, a quarter
//! grazing it from the side, some with a bounded interval. Everything is computed from `f32`
//! basic operations and `libm`, so every target feeds the kernel the same bits.

use raykernel::bvh::{BuildOptions, BuilderKind};
use raykernel::grid::GridOptions;
use raykernel::kdtree::KdOptions;
use raykernel::{Accel, AccelKind, AccelVisitor, AnyAccel, Ray, Scalar, Triangle, I16F16};
use raykernel_testkit::memory::OwnedMemory;
use raykernel_testkit::Rng;
use std::path::Path;

/// Heightfield cells per side.
const FIELD: usize = 24;
/// Rays in the set.
const RAYS: usize = 2048;

/// The heightfield's triangles as `f32` vertices.
fn mesh() -> Vec<[[f32; 3]; 3]> {
    let h = |i: usize, j: usize| {
        let (x, y) = (i as f32 / FIELD as f32 - 0.5, j as f32 / FIELD as f32 - 0.5);
        3.0 * libm::cosf(5.0 * x) * libm::sinf(4.0 * y + 0.5)
    };
    let p = |i: usize, j: usize| [i as f32 - 12.0, j as f32 - 12.0, h(i, j)];
    let mut out = Vec::with_capacity(2 * FIELD * FIELD);
    for i in 0..FIELD {
        for j in 0..FIELD {
            out.push([p(i, j), p(i + 1, j), p(i, j + 1)]);
            out.push([p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    out
}

/// The ray set as (origin, direction, t_min, t_max).
fn rays() -> Vec<([f32; 3], [f32; 3], f32, f32)> {
    let mut rng = Rng::new(0xd37e_4a11_57a7_e5ee);
    (0..RAYS)
        .map(|i| {
            let (o, d) = if i % 4 == 3 {
                // Grazing: from one side, nearly horizontal.
                let o = [-14.0, rng.range(-12.0, 12.0), rng.range(-3.0, 3.0)];
                (o, [1.0, rng.range(-0.3, 0.3), rng.range(-0.1, 0.1)])
            } else {
                let o = [rng.range(-10.0, 10.0), rng.range(-10.0, 10.0), 8.0];
                let target = [rng.range(-13.0, 13.0), rng.range(-13.0, 13.0), 0.0];
                (o, core::array::from_fn(|k| target[k] - o[k]))
            };
            let t_max = if i % 8 == 5 {
                rng.range(4.0, 12.0)
            } else {
                f32::INFINITY
            };
            (o, d, 0.0, t_max)
        })
        .collect()
}

/// Every structure, in file order: brute force, the SAH BVH and the 4-wide and 8-wide BVHs
/// collapsed from it, the median and midpoint BVHs (all leaf size 4), the grid and the kd-tree
/// (defaults). A BVH's file is named after its builder too (`bvh_sah`, `bvh4_sah`, `bvh8_sah`).
fn kinds() -> [AccelKind; 8] {
    let bvh = |builder| BuildOptions {
        builder,
        max_leaf_size: 4,
        reinsertion: true,
    };
    [
        AccelKind::Linear,
        AccelKind::Bvh(bvh(BuilderKind::Sah)),
        AccelKind::Bvh4(bvh(BuilderKind::Sah)),
        AccelKind::Bvh8(bvh(BuilderKind::Sah)),
        AccelKind::Bvh(bvh(BuilderKind::Median)),
        AccelKind::Bvh(bvh(BuilderKind::Midpoint)),
        AccelKind::Grid(GridOptions::DEFAULT),
        AccelKind::KdTree(KdOptions::DEFAULT),
    ]
}

/// Closest hits as hit-file records; a miss (or a ray the kernel rejects) is `+inf, u32::MAX`.
struct Trace<'r, S: Scalar>(&'r [Option<Ray<S>>]);

impl<S: Scalar> AccelVisitor<S> for Trace<'_, S> {
    type Output = Vec<u8>;
    fn visit<A: Accel<S>>(self, accel: &A) -> Vec<u8> {
        let mut out = Vec::with_capacity(8 * self.0.len());
        for r in self.0 {
            let (t, prim) = match r.as_ref().and_then(|r| accel.intersect(r)) {
                Some(hit) => (hit.t.to_f32(), hit.prim),
                None => (f32::INFINITY, u32::MAX),
            };
            out.extend_from_slice(&t.to_le_bytes());
            out.extend_from_slice(&prim.to_le_bytes());
        }
        out
    }
}

/// Writes `<accel>_<mode>.hits` for every accelerator and both modes into `dir`; returns each
/// file's name and record count.
pub fn write_all(dir: &Path) -> Result<Vec<(String, usize)>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut files = Vec::new();
    mode::<f32>(dir, &mut files)?;
    mode::<I16F16>(dir, &mut files)?;
    Ok(files)
}

fn mode<S: Scalar>(dir: &Path, files: &mut Vec<(String, usize)>) -> Result<(), String> {
    let tris = mesh()
        .into_iter()
        .map(Triangle::<S>::from_f32)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("{} mesh rejected: {e:?}", S::NAME))?;
    let rays: Vec<Option<Ray<S>>> = rays()
        .into_iter()
        .map(|(o, d, t0, t1)| Ray::from_f32(o, d, t0, t1).ok())
        .collect();
    let mut save = |accel: &str, bytes: Vec<u8>| {
        let name = format!("{accel}_{}.hits", S::NAME);
        std::fs::write(dir.join(&name), &bytes).map_err(|e| format!("{name}: {e}"))?;
        files.push((name, bytes.len() / 8));
        Ok::<(), String>(())
    };
    let fail = |kind: AccelKind, e: raykernel::BuildError| format!("{} {kind}: {e}", S::NAME);
    for kind in kinds() {
        let need = kind.memory_needed(&tris).map_err(|e| fail(kind, e))?;
        let mut memory = OwnedMemory::<S>::sized(need);
        let accel =
            AnyAccel::build(kind, &tris, &mut memory.memory()).map_err(|e| fail(kind, e))?;
        let name = match kind.build_options() {
            Some(o) => format!("{}_{}", kind.name(), o.builder.name()),
            None => kind.name().to_string(),
        };
        save(&name, accel.visit(Trace(&rays)))?;
    }
    Ok(())
}
