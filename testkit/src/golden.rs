//! Golden cases, shared by the host test (`kernel/tests/golden.rs`), the host snapshot test,
//! the determinism probe and the on-target suites (`tests/qemu`, `tests/baremetal`): a generated
//! mesh and sphere set, a fixed ray set, and FNV-1a hashes of what the kernel computes on them.
//! Every side links this one module, so they hash the same inputs the same way; the expected
//! values live in one place, `tests/golden/kernel_hashes.txt`.
//!
//! `no_std`, no allocation, no recursion: everything fits the Cortex-M0's 16 KB of RAM.
//! To add a case (e.g. a render hash), add its name to [`NAMES`] and its computation to
//! [`compute`], then rewrite the table with `BLESS=1 cargo test -p raykernel --test golden`.
pub use crate::Rng;
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::render::scenes::{self, ObjectData, SceneData, ShapeRange, SphereData};
use raykernel::render::{
    AllFeatures, Camera, Filter, Integrator, Material, Object, ObjectSlot, Problem, RenderFeatures,
    RenderMemory, Renderer, SamplerKind, Settings, Shape, Tile,
};
use raykernel::{
    Accel, AccelFamily, AccelMemory, Bvh, BvhFamily, Hit, Linear, Node, Primitive, Ray, Scalar,
    Sphere, Triangle, I16F16,
};

/// Triangles of the level-1 icosphere.
pub const ICO_TRIS: usize = 80;
/// Rays in the fixed ray set.
pub const RAY_COUNT: usize = 96;
/// Spheres in the sphere set.
pub const SPHERE_COUNT: usize = 8;
/// Icosphere centre and radius (off the origin, so no coordinate is trivially symmetric).
const CENTER: [f32; 3] = [0.375, -0.25, 0.625];
const RADIUS: f32 = 2.0;

/// Every golden case, in file order.
pub const NAMES: [&str; 24] = [
    "rays_f32",
    "rays_fixed",
    "linear_f32",
    "linear_fixed",
    "spheres_f32",
    "spheres_fixed",
    "tree_f32_sah",
    "tree_f32_median",
    "tree_f32_midpoint",
    "tree_fixed_sah",
    "tree_fixed_median",
    "tree_fixed_midpoint",
    "render_cornell_f32",
    "render_cornell_fixed",
    "render_spheres_f32",
    "render_spheres_fixed",
    "render_motion_f32",
    "render_motion_fixed",
    "render_cornell_path_f32",
    "render_cornell_path_fixed",
    "render_emitters_f32",
    "render_emitters_fixed",
    "render_emitters_path_f32",
    "render_emitters_path_fixed",
];

/// What went wrong while computing a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fail {
    /// No case has this name.
    UnknownCase,
    /// The kernel rejected generated input (ray `index`, or primitive `index`).
    Rejected { index: usize },
    /// A build failed.
    Build,
    /// `validate` rejected a built tree.
    Invalid,
    /// A query through the BVH differed from brute force on ray `index`.
    Differs { index: usize },
    /// The case needs a part of the kernel this build leaves out (the path integrator without
    /// the `path-tracing` feature): it cannot be checked here, which is not a pass.
    NotLinked,
}

/// 64-bit FNV-1a over little-endian words.
#[derive(Clone, Copy, Debug)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv {
    pub const fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    pub fn u32(&mut self, x: u32) {
        for b in x.to_le_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    /// Feeds bytes in order (so `u32(x)` equals `bytes(&x.to_le_bytes())`).
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    pub fn finish(self) -> u64 {
        self.0
    }
}

/// The exact bits of a mode's value: `f32::to_bits`, or the raw `i32` of fixed point.
pub trait Bits: Scalar {
    fn bits(self) -> u32;
}
impl Bits for f32 {
    fn bits(self) -> u32 {
        self.to_bits()
    }
}
impl Bits for I16F16 {
    fn bits(self) -> u32 {
        self.raw() as u32
    }
}

fn normalize(p: [f32; 3]) -> [f32; 3] {
    let n = libm::sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    p.map(|x| x / n)
}

/// Midpoint of an edge on the unit sphere; symmetric in its arguments (IEEE `+` commutes), so
/// neighbouring faces share the exact vertex and the mesh stays closed.
fn mid(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    normalize([a[0] + b[0], a[1] + b[1], a[2] + b[2]])
}

/// Triangle `k` (of [`ICO_TRIS`]) of the level-1 icosphere, as `f32` vertices, scaled and
/// moved. Computed one at a time, so callers need no second copy of the mesh.
pub fn ico_triangle(k: usize) -> [[f32; 3]; 3] {
    let phi = (1.0 + libm::sqrtf(5.0)) * 0.5;
    let v = crate::icosphere::corners(0.0, 1.0, phi);
    let [a, b, c] = crate::icosphere::FACES[(k / 4) % 20].map(|i| normalize(v[i as usize]));
    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
    let t = match k % 4 {
        0 => [a, ab, ca],
        1 => [ab, b, bc],
        2 => [ca, bc, c],
        _ => [ab, bc, ca],
    };
    t.map(|p| core::array::from_fn(|i| CENTER[i] + RADIUS * p[i]))
}

/// The icosphere in mode `S`, written into `out`.
pub fn icosphere<S: Scalar>(out: &mut [Triangle<S>; ICO_TRIS]) -> Result<(), Fail> {
    for (index, o) in out.iter_mut().enumerate() {
        *o = Triangle::from_f32(ico_triangle(index)).map_err(|_| Fail::Rejected { index })?;
    }
    Ok(())
}

/// An all-zero mesh buffer to fill with [`icosphere`].
pub fn empty_mesh<S: Scalar>() -> [Triangle<S>; ICO_TRIS] {
    [Triangle {
        v: [[S::ZERO; 3]; 3],
    }; ICO_TRIS]
}

/// Eight spheres of different sizes, some overlapping.
pub fn spheres<S: Scalar>() -> Result<[Sphere<S>; SPHERE_COUNT], Fail> {
    let mut rng = Rng::new(0x5eed_5f3e_7e5e_0001);
    let mut out = [Sphere {
        center: [S::ZERO; 3],
        radius: S::ZERO,
    }; SPHERE_COUNT];
    for (index, s) in out.iter_mut().enumerate() {
        let c = [0; 3].map(|_| rng.range(-2.0, 2.0));
        let r = rng.range(0.25, 1.25);
        let mut center = [S::ZERO; 3];
        for k in 0..3 {
            center[k] = S::coord_from_f32(c[k]).map_err(|_| Fail::Rejected { index })?;
        }
        *s = Sphere {
            center,
            radius: S::coord_from_f32(r).map_err(|_| Fail::Rejected { index })?,
        };
        s.check().map_err(|_| Fail::Rejected { index })?;
    }
    Ok(out)
}

/// Ray `i` of the fixed set as (origin, direction, t_min, t_max): every fourth starts inside
/// the sphere, the others start 6 to 8 units out and aim near it (some miss); some have a
/// bounded interval.
pub fn ray_spec(i: usize) -> ([f32; 3], [f32; 3], f32, f32) {
    let mut rng = Rng::new(0x0123_4567_89ab_cdef ^ (i as u64).wrapping_mul(0x9e37_79b9));
    let inside = i % 4 < 1;
    let (o, d) = if inside {
        let o = [0; 3].map(|_| rng.range(-0.75, 0.75));
        (core::array::from_fn(|k| CENTER[k] + o[k]), rng.dir())
    } else {
        let out = rng.dir();
        let dist = rng.range(3.0, 4.0);
        let o: [f32; 3] = core::array::from_fn(|k| CENTER[k] + dist * out[k]);
        let target: [f32; 3] = core::array::from_fn(|k| CENTER[k] + rng.range(-2.5, 2.5));
        (o, core::array::from_fn(|k| target[k] - o[k]))
    };
    let (t_min, t_max) = match i % 8 {
        3 => (0.0, rng.range(1.0, 6.0)),
        5 => (rng.range(0.0, 2.0), f32::INFINITY),
        _ => (0.0, f32::INFINITY),
    };
    (o, d, t_min, t_max)
}

/// Ray `i` in mode `S`.
pub fn ray<S: Scalar>(i: usize) -> Result<Ray<S>, Fail> {
    let (o, d, t_min, t_max) = ray_spec(i);
    Ray::from_f32(o, d, t_min, t_max).map_err(|_| Fail::Rejected { index: i })
}

fn hash_hit<S: Bits>(h: &mut Fnv, hit: &Option<Hit<S>>) {
    match hit {
        Some(hit) => {
            h.u32(hit.t.bits());
            h.u32(hit.prim);
            h.u32(hit.u.bits());
            h.u32(hit.v.bits());
        }
        None => h.u32(u32::MAX),
    }
}

/// The bits of every ray's origin, direction and interval as the constructors store them.
#[inline(never)] // one case's buffers on the stack at a time (the M0 has 16 KB of RAM)
pub fn hash_rays<S: Bits>() -> Result<u64, Fail> {
    let mut h = Fnv::new();
    for i in 0..RAY_COUNT {
        let r = ray::<S>(i)?;
        for x in S::vec_to_array(r.origin())
            .into_iter()
            .chain(S::vec_to_array(r.dir()))
            .chain([r.t_min(), r.t_max()])
        {
            h.u32(x.bits());
        }
    }
    Ok(h.finish())
}

/// Brute-force closest hit and any-hit of every ray.
pub fn hash_queries<S: Bits, A: Accel<S>>(accel: &A) -> Result<u64, Fail> {
    let mut h = Fnv::new();
    for i in 0..RAY_COUNT {
        let r = ray::<S>(i)?;
        hash_hit(&mut h, &accel.intersect(&r));
        h.u32(accel.occluded(&r) as u32);
    }
    Ok(h.finish())
}

/// The bits of ray `r`'s closest hit through `a`, and its any-hit answer. Not inlined, so a
/// caller comparing two accelerators holds one query's stack at a time (the M0 has 16 KB).
#[inline(never)]
fn query_bits<S: Bits, A: Accel<S>>(a: &A, r: &Ray<S>) -> (Option<[u32; 4]>, bool) {
    let hit = a
        .intersect(r)
        .map(|h| [h.t.bits(), h.prim, h.u.bits(), h.v.bits()]);
    (hit, a.occluded(r))
}

/// Every query through `a` gives the same bits as through `b`.
pub fn same_queries<S: Bits, A: Accel<S>, B: Accel<S>>(a: &A, b: &B) -> Result<(), Fail> {
    for index in 0..RAY_COUNT {
        let r = ray::<S>(index)?;
        if query_bits(a, &r) != query_bits(b, &r) {
            return Err(Fail::Differs { index });
        }
    }
    Ok(())
}

/// A built tree: every node's box bits, child/leaf fields, the primitive ids and the depth.
pub fn hash_tree<S: Bits, P: Primitive<S>>(bvh: &Bvh<'_, S, P>) -> u64 {
    let mut h = Fnv::new();
    for n in bvh.nodes() {
        let b = n.bounds();
        for x in b.lo.into_iter().chain(b.hi) {
            h.u32(x.bits());
        }
        h.u32(n.first());
        h.u32(n.count());
    }
    for &id in bvh.prim_ids() {
        h.u32(id);
    }
    h.u32(bvh.depth());
    h.finish()
}

/// Builds the icosphere with `builder` (leaves of up to 4), validates it, checks every query
/// against brute force, and hashes the tree.
#[inline(never)] // one case's buffers on the stack at a time (the M0 has 16 KB of RAM)
pub fn tree_case<S: Bits>(builder: BuilderKind) -> Result<u64, Fail> {
    let mut tris = empty_mesh::<S>();
    icosphere(&mut tris)?;
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(ICO_TRIS)];
    let mut ids = [0u32; ICO_TRIS];
    let options = BuildOptions {
        builder,
        max_leaf_size: 4,
        reinsertion: true,
    };
    let bvh = Bvh::build(&tris, &mut nodes, &mut ids, options).map_err(|_| Fail::Build)?;
    bvh.validate().map_err(|_| Fail::Invalid)?;
    same_queries(&bvh, &Linear::new(&tris))?;
    Ok(hash_tree(&bvh))
}

#[inline(never)] // one case's buffers on the stack at a time (the M0 has 16 KB of RAM)
fn linear_case<S: Bits>() -> Result<u64, Fail> {
    let mut tris = empty_mesh::<S>();
    icosphere(&mut tris)?;
    hash_queries(&Linear::new(&tris))
}

#[inline(never)] // one case's buffers on the stack at a time (the M0 has 16 KB of RAM)
fn spheres_case<S: Bits>() -> Result<u64, Fail> {
    let s = spheres::<S>()?;
    let mut nodes = [Node::<S>::EMPTY; nodes_needed(SPHERE_COUNT)];
    let mut ids = [0u32; SPHERE_COUNT];
    let bvh =
        Bvh::build(&s, &mut nodes, &mut ids, BuildOptions::default()).map_err(|_| Fail::Build)?;
    bvh.validate().map_err(|_| Fail::Invalid)?;
    let linear = Linear::new(&s);
    same_queries(&bvh, &linear)?;
    hash_queries(&linear)
}

/// Largest built-in scene, in triangles, spheres and objects (the buffers below are sized
/// for it; a bigger scene fails with [`Fail::Rejected`]).
const RENDER_TRIS: usize = 24;
/// The default scene under the path integrator (four bounces), small enough for the M0's
/// render time: every path feature (diffuse, glossy and mirror bounces, light sampling with
/// MIS, Russian roulette) with the lens, motion and the area light.
pub const CORNELL_PATH: SceneData<'static> = SceneData {
    settings: Settings {
        width: 32,
        height: 32,
        spp: 4,
        integrator: Integrator::Path { max_length: 5 },
        ..scenes::CORNELL.settings
    },
    ..scenes::CORNELL
};

/// Lit by emissive geometry alone: a one-sided emissive quad mesh in the ceiling and a small
/// sphere that both reflects and emits, over a floor, before a one-sided back wall, with a
/// one-sided panel turned away from the camera (black, yet casting its shadow) and a diffuse
/// sphere. Direct integrator.
pub const EMITTERS: SceneData<'static> = SceneData {
    name: "emitters",
    triangles: &EMITTERS_TRIANGLES,
    vertex_normals: &[],
    spheres: &[
        SphereData {
            center: [-0.4, 0.3, 0.1],
            radius: 0.3,
        },
        SphereData {
            center: [0.5, 1.2, -0.5],
            radius: 0.12,
        },
    ],
    objects: &[
        emitters_object(
            ShapeRange::Triangles { first: 0, count: 2 },
            0,
            false,
            [0.0; 3],
        ),
        emitters_object(
            ShapeRange::Triangles { first: 2, count: 2 },
            1,
            true,
            [0.0; 3],
        ),
        emitters_object(
            ShapeRange::Triangles { first: 4, count: 2 },
            0,
            true,
            [0.0; 3],
        ),
        emitters_object(
            ShapeRange::Triangles { first: 6, count: 2 },
            2,
            true,
            [0.0; 3],
        ),
        emitters_object(
            ShapeRange::Spheres { first: 0, count: 1 },
            1,
            false,
            [0.0; 3],
        ),
        emitters_object(
            ShapeRange::Spheres { first: 1, count: 1 },
            0,
            false,
            [2.0, 0.8, 0.3],
        ),
    ],
    materials: &[
        Material::Diffuse {
            albedo: [0.7, 0.7, 0.7],
        },
        Material::Diffuse {
            albedo: [0.3, 0.5, 0.8],
        },
        Material::Emissive {
            radiance: [4.0, 4.0, 3.5],
        },
    ],
    lights: &[],
    camera: Camera {
        eye: [0.0, 1.0, 3.0],
        look_at: [0.0, 0.7, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 45.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    },
    background: [0.0; 3],
    settings: Settings {
        width: 24,
        height: 24,
        spp: 4,
        max_depth: 2,
        integrator: Integrator::Direct,
        sampler: SamplerKind::Stratified,
        filter: Filter::Box,
        seed: 5,
    },
};

/// [`EMITTERS`] under the path integrator (four segments).
pub const EMITTERS_PATH: SceneData<'static> = SceneData {
    settings: Settings {
        integrator: Integrator::Path { max_length: 4 },
        ..EMITTERS.settings
    },
    ..EMITTERS
};

/// Floor (front up), back wall (front to the camera), a panel turned away from the camera,
/// and the ceiling light (front down), each two triangles.
const EMITTERS_TRIANGLES: [[[f32; 3]; 3]; 8] = [
    [[-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, -1.0]],
    [[-1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [-1.0, 0.0, -1.0]],
    [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 2.0, -1.0]],
    [[-1.0, 0.0, -1.0], [1.0, 2.0, -1.0], [-1.0, 2.0, -1.0]],
    [[0.8, 0.0, 0.2], [0.2, 0.0, 0.2], [0.2, 0.6, 0.2]],
    [[0.8, 0.0, 0.2], [0.2, 0.6, 0.2], [0.8, 0.6, 0.2]],
    [[-0.4, 1.9, -0.4], [0.4, 1.9, -0.4], [0.4, 1.9, 0.4]],
    [[-0.4, 1.9, -0.4], [0.4, 1.9, 0.4], [-0.4, 1.9, 0.4]],
];

const fn emitters_object(
    shape: ShapeRange,
    material: u32,
    one_sided: bool,
    emission: [f32; 3],
) -> ObjectData {
    ObjectData {
        shape,
        material,
        motion: [0.0; 3],
        emission,
        one_sided,
    }
}

const RENDER_SPHERES: usize = 4;
const RENDER_OBJECTS: usize = 8;
/// Widest built-in render (pixels), for the one-row buffer.
const RENDER_WIDTH: usize = 64;

/// Renders built-in scene `data` at its own settings, one row at a time
/// (so the M0 needs no framebuffer), and hashes the 8-bit sRGB bytes in row-major order: the
/// same value as FNV-1a over the whole image's bytes.
#[inline(never)] // one case's buffers on the stack at a time (the M0 has 16 KB of RAM)
pub fn render_hash<S: Bits + Scalar>(data: &SceneData<'_>) -> Result<u64, Fail> {
    render_hash_with::<S, BvhFamily, AllFeatures>(data, BuildOptions::default())
}

/// As [`render_hash`], each object's BVH (and the objects' top-level BVH) built by family `F`
/// with `options`, by a renderer linking the parts `K` names: every family gives the same
/// bytes, and so does every `K` that links what the scene needs (else [`Fail::NotLinked`]).
#[inline(never)]
pub fn render_hash_with<S: Bits + Scalar, F: AccelFamily<S>, K: RenderFeatures>(
    data: &SceneData<'_>,
    options: F::Options,
) -> Result<u64, Fail> {
    let reject = |_| Fail::Rejected { index: 0 };
    let mut tris = [Triangle::<S> {
        v: [[S::ZERO; 3]; 3],
    }; RENDER_TRIS];
    let mut spheres = [Sphere::<S> {
        center: [S::ZERO; 3],
        radius: S::ZERO,
    }; RENDER_SPHERES];
    let (nt, ns) = (data.triangles.len(), data.spheres.len());
    let tris = tris.get_mut(..nt).ok_or(Fail::Rejected { index: nt })?;
    let spheres = spheres.get_mut(..ns).ok_or(Fail::Rejected { index: ns })?;
    data.triangles_into(tris).map_err(reject)?;
    data.spheres_into(spheres).map_err(reject)?;
    let mut objects = [Object::new(Shape::Triangles(&[]), 0); RENDER_OBJECTS];
    let scene = data.scene(tris, spheres, &mut objects).map_err(reject)?;
    // Every object's BVH, then the top-level BVH over the objects.
    let mut nodes = [Node::<S>::EMPTY;
        nodes_needed(RENDER_TRIS) + nodes_needed(RENDER_SPHERES) + 4 * RENDER_OBJECTS];
    let mut ids = [0u32; RENDER_TRIS + RENDER_SPHERES + RENDER_OBJECTS];
    let mut slots = [ObjectSlot::<S, F>::EMPTY; RENDER_OBJECTS];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            words: &mut ids,
            ..AccelMemory::default()
        },
    };
    let r = Renderer::<S, F, K>::with_features(&scene, data.settings, options, memory).map_err(
        |e| {
            if e.problem == Problem::NotLinked {
                Fail::NotLinked
            } else {
                Fail::Rejected { index: 0 }
            }
        },
    )?;
    let width = data.settings.width as usize;
    let mut row = [0u8; 3 * RENDER_WIDTH];
    let row = row
        .get_mut(..3 * width)
        .ok_or(Fail::Rejected { index: width })?;
    let mut h = Fnv::new();
    for y in 0..data.settings.height {
        let tile = Tile {
            x: 0,
            y,
            width: data.settings.width,
            height: 1,
        };
        r.render_tile_srgb8(tile, row).map_err(reject)?;
        h.bytes(row);
    }
    Ok(h.finish())
}

/// Computes the render case called `name` (kept apart from [`compute`] so a binary that checks
/// only the kernel cases does not link the renderer).
pub fn compute_render(name: &str) -> Result<u64, Fail> {
    match name {
        "render_cornell_f32" => render_hash::<f32>(&scenes::CORNELL),
        "render_cornell_fixed" => render_hash::<I16F16>(&scenes::CORNELL),
        "render_spheres_f32" => render_hash::<f32>(&scenes::SPHERES),
        "render_spheres_fixed" => render_hash::<I16F16>(&scenes::SPHERES),
        "render_motion_f32" => render_hash::<f32>(&scenes::MOTION),
        "render_motion_fixed" => render_hash::<I16F16>(&scenes::MOTION),
        "render_cornell_path_f32" => render_hash::<f32>(&CORNELL_PATH),
        "render_cornell_path_fixed" => render_hash::<I16F16>(&CORNELL_PATH),
        "render_emitters_f32" => render_hash::<f32>(&EMITTERS),
        "render_emitters_fixed" => render_hash::<I16F16>(&EMITTERS),
        "render_emitters_path_f32" => render_hash::<f32>(&EMITTERS_PATH),
        "render_emitters_path_fixed" => render_hash::<I16F16>(&EMITTERS_PATH),
        _ => Err(Fail::UnknownCase),
    }
}

/// Computes any case, kernel or render.
pub fn compute_any(name: &str) -> Result<u64, Fail> {
    match compute(name) {
        Err(Fail::UnknownCase) => compute_render(name),
        r => r,
    }
}

/// Computes the kernel (non-render) case called `name`.
pub fn compute(name: &str) -> Result<u64, Fail> {
    use BuilderKind::{Median, Midpoint, Sah};
    match name {
        "rays_f32" => hash_rays::<f32>(),
        "rays_fixed" => hash_rays::<I16F16>(),
        "linear_f32" => linear_case::<f32>(),
        "linear_fixed" => linear_case::<I16F16>(),
        "spheres_f32" => spheres_case::<f32>(),
        "spheres_fixed" => spheres_case::<I16F16>(),
        "tree_f32_sah" => tree_case::<f32>(Sah),
        "tree_f32_median" => tree_case::<f32>(Median),
        "tree_f32_midpoint" => tree_case::<f32>(Midpoint),
        "tree_fixed_sah" => tree_case::<I16F16>(Sah),
        "tree_fixed_median" => tree_case::<I16F16>(Median),
        "tree_fixed_midpoint" => tree_case::<I16F16>(Midpoint),
        _ => Err(Fail::UnknownCase),
    }
}

/// Parses the golden file's `name = 0x<16 hex digits>` lines (`#` starts a comment) and calls
/// `f(line_number, name, value)` for each. Errors name the first malformed line.
pub fn parse_golden(text: &str, mut f: impl FnMut(&str, u64)) -> Result<(), usize> {
    for (no, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let (name, value) = line.split_once('=').ok_or(no + 1)?;
        let hex = value.trim().strip_prefix("0x").ok_or(no + 1)?;
        let v = u64::from_str_radix(hex, 16).map_err(|_| no + 1)?;
        f(name.trim(), v);
    }
    Ok(())
}
