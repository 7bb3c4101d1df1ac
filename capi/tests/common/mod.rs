//! Shared by the render tests: the test scene (the kernel's form and, field by field, the C
//! structs), the kernel's reference render, caller memory at a chosen alignment, and calls
//! into the C functions. `examples/common/render_scene.h` is the same scene in C.
#![allow(dead_code)] // each test binary uses part of it

use core::ffi::c_void;
use raykernel::bvh::BuildOptions;
use raykernel::render::{
    memory_needed, Camera, Filter, Light, Material, Object, ObjectSlot, RenderMemory, Renderer,
    Rgb, SamplerKind, Scene, Settings, Shape,
};
use raykernel::{AccelMemory, Bvh4Family, Node, Node4, Scalar, Sphere, Triangle};
use raykernel_c::*;

/// An object's primitives as `f32` data.
#[derive(Clone, Copy, Debug)]
pub enum TestShape {
    /// Three vertices each.
    Triangles(&'static [[[f32; 3]; 3]]),
    /// Centre x y z and radius each (the C layout).
    Spheres(&'static [[f32; 4]]),
}

/// An object of the test scene.
#[derive(Clone, Copy, Debug)]
pub struct TestObject {
    pub shape: TestShape,
    pub material: u32,
    pub motion: [f32; 3],
}

/// The test scene in the kernel's terms (geometry as `f32` data).
#[derive(Clone, Debug)]
pub struct TestScene {
    pub objects: Vec<TestObject>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub camera: Camera,
    pub background: Rgb,
    pub settings: Settings,
}

const FLOOR: [[[f32; 3]; 3]; 2] = [
    [[-2.0, 0.0, -2.0], [2.0, 0.0, 2.0], [2.0, 0.0, -2.0]],
    [[-2.0, 0.0, -2.0], [-2.0, 0.0, 2.0], [2.0, 0.0, 2.0]],
];
const WALL: [[[f32; 3]; 3]; 2] = [
    [[-2.0, 0.0, -2.0], [2.0, 0.0, -2.0], [2.0, 2.0, -2.0]],
    [[-2.0, 0.0, -2.0], [2.0, 2.0, -2.0], [-2.0, 2.0, -2.0]],
];
const GLOW: [[[f32; 3]; 3]; 1] = [[[1.0, 0.9, -1.5], [1.7, 0.9, -1.5], [1.35, 1.5, -1.5]]];
const MIRROR_BALL: [[f32; 4]; 1] = [[-0.6, 0.5, 0.0, 0.5]];
const BALLS: [[f32; 4]; 2] = [[0.7, 0.35, 0.4, 0.35], [0.15, 0.15, 1.1, 0.15]];

pub const MATERIALS: [Material; 5] = [
    Material::Diffuse {
        albedo: [0.7, 0.7, 0.7],
    },
    Material::Glossy {
        reflectance: [0.8, 0.6, 0.4],
        exponent: 40.0,
    },
    Material::Mirror {
        reflectance: [0.9, 0.9, 0.9],
    },
    Material::Emissive {
        radiance: [2.0, 1.5, 1.0],
    },
    Material::Diffuse {
        albedo: [0.2, 0.5, 0.8],
    },
];
pub const LIGHTS: [Light; 2] = [
    Light::Rect {
        corner: [-0.5, 2.5, -0.5],
        edge_u: [1.0, 0.0, 0.0],
        edge_v: [0.0, 0.0, 1.0],
        radiance: [10.0, 10.0, 10.0],
    },
    Light::Point {
        position: [2.0, 2.0, 2.0],
        intensity: [1.5, 1.5, 1.5],
    },
];

/// The test scene: a floor, a glossy wall, a moving mirror ball, two diffuse balls and a
/// glowing triangle, under a rectangle and a point light, through a thin lens.
// Every field is named, but the kernel's `Settings` may gain fields: they keep their defaults.
#[allow(clippy::needless_update)]
pub fn test_scene() -> TestScene {
    let object = |shape, material, motion| TestObject {
        shape,
        material,
        motion,
    };
    TestScene {
        objects: vec![
            object(TestShape::Triangles(&FLOOR), 0, [0.0; 3]),
            object(TestShape::Triangles(&WALL), 1, [0.0; 3]),
            object(TestShape::Spheres(&MIRROR_BALL), 2, [0.25, 0.0, 0.0]),
            object(TestShape::Spheres(&BALLS), 4, [0.0; 3]),
            object(TestShape::Triangles(&GLOW), 3, [0.0; 3]),
        ],
        materials: MATERIALS.to_vec(),
        lights: LIGHTS.to_vec(),
        camera: Camera {
            eye: [0.0, 1.2, 4.5],
            look_at: [0.0, 0.6, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 45.0,
            aperture_radius: 0.02,
            focus_distance: 4.5,
        },
        background: [0.05, 0.06, 0.08],
        settings: Settings {
            width: 24,
            height: 16,
            spp: 4,
            max_depth: 3,
            sampler: SamplerKind::Stratified,
            filter: Filter::Tent,
            seed: 7,
            ..Settings::default()
        },
    }
}

/// The tile the firmware renders (also in the golden header).
pub const TILE: [u32; 4] = [8, 4, 8, 8];

pub fn fnv1a(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811c_9dc5, |h, b| {
        (h ^ u32::from(*b)).wrapping_mul(0x0100_0193)
    })
}

/// One object's primitives converted to mode `S`.
enum Prims<S: Scalar> {
    Triangles(Vec<Triangle<S>>),
    Spheres(Vec<Sphere<S>>),
}

/// The kernel's render of `data` (4-wide BVHs), whole image, sRGB.
pub fn kernel_render<S: Scalar>(data: &TestScene) -> Vec<u8> {
    let coord = |x: f32| S::coord_from_f32(x).expect("the test scene is in range");
    let prims: Vec<Prims<S>> = data
        .objects
        .iter()
        .map(|o| match o.shape {
            TestShape::Triangles(t) => Prims::Triangles(
                t.iter()
                    .map(|v| Triangle::from_f32(*v).expect("the test scene is in range"))
                    .collect(),
            ),
            TestShape::Spheres(s) => Prims::Spheres(
                s.iter()
                    .map(|c| Sphere {
                        center: [coord(c[0]), coord(c[1]), coord(c[2])],
                        radius: coord(c[3]),
                    })
                    .collect(),
            ),
        })
        .collect();
    let objects: Vec<Object<'_, S>> = data
        .objects
        .iter()
        .zip(&prims)
        .map(|(o, p)| {
            let shape = match p {
                Prims::Triangles(t) => Shape::Triangles(t),
                Prims::Spheres(s) => Shape::Spheres(s),
            };
            let mut object = Object::new(shape, o.material);
            object.motion = o.motion;
            object
        })
        .collect();
    let scene = Scene {
        objects: &objects,
        materials: &data.materials,
        lights: &data.lights,
        camera: data.camera,
        background: data.background,
    };
    let options = BuildOptions::default();
    let need = memory_needed::<S, Bvh4Family>(scene.objects, &options);
    let mut slots = vec![ObjectSlot::<S, Bvh4Family>::EMPTY; need.objects];
    let mut nodes = vec![Node::EMPTY; need.accel.nodes];
    let mut nodes4 = vec![Node4::EMPTY; need.accel.nodes4];
    let mut words = vec![0u32; need.accel.words];
    let memory = RenderMemory {
        objects: &mut slots,
        accel: AccelMemory {
            nodes: &mut nodes,
            nodes4: &mut nodes4,
            nodes8: &mut [],
            kd_nodes: &mut [],
            words: &mut words,
        },
    };
    let r = Renderer::new(&scene, data.settings, options, memory).expect("the test scene is valid");
    let s = data.settings;
    let mut out = vec![0u8; 3 * (s.width * s.height) as usize];
    r.render_srgb8(&mut out)
        .expect("the whole image is a valid tile");
    out
}

/// `data` as C structs, each kernel value mapped field by field.
pub struct CScene {
    pub objects: Vec<RkObject>,
    pub floats: Vec<Vec<f32>>,
    pub materials: Vec<RkMaterial>,
    pub lights: Vec<RkLight>,
    pub scene: RkScene,
}

impl CScene {
    pub fn new(data: &TestScene, mode: u32, kind: u32) -> Self {
        let floats: Vec<Vec<f32>> = data
            .objects
            .iter()
            .map(|o| match o.shape {
                TestShape::Triangles(t) => t.iter().flatten().flatten().copied().collect(),
                TestShape::Spheres(s) => s.iter().flatten().copied().collect(),
            })
            .collect();
        let objects = data
            .objects
            .iter()
            .zip(&floats)
            .map(|(o, f)| {
                let (shape, count) = match o.shape {
                    TestShape::Triangles(t) => (RK_SHAPE_TRIANGLES, t.len()),
                    TestShape::Spheres(s) => (RK_SHAPE_SPHERES, s.len()),
                };
                RkObject {
                    shape,
                    material: o.material,
                    count: count as u32,
                    data: f.as_ptr(),
                    motion: o.motion,
                }
            })
            .collect();
        let materials = data.materials.iter().map(c_material).collect();
        let lights = data.lights.iter().map(c_light).collect();
        let c = data.camera;
        let s = data.settings;
        let mut settings = rk_render_settings_default();
        settings.width = s.width;
        settings.height = s.height;
        settings.spp = s.spp;
        settings.max_depth = s.max_depth;
        settings.sampler = match s.sampler {
            SamplerKind::Independent => RK_SAMPLER_INDEPENDENT,
            SamplerKind::Stratified => RK_SAMPLER_STRATIFIED,
            SamplerKind::Sobol => RK_SAMPLER_SOBOL,
        };
        settings.filter = match s.filter {
            Filter::Box => RK_FILTER_BOX,
            Filter::Tent => RK_FILTER_TENT,
            Filter::Gaussian { .. } => panic!("the C interface has no Gaussian filter"),
        };
        settings.seed = s.seed;
        let mut out = Self {
            objects,
            floats,
            materials,
            lights,
            scene: RkScene {
                mode,
                kind,
                objects: std::ptr::null(),
                object_count: 0,
                materials: std::ptr::null(),
                material_count: 0,
                lights: std::ptr::null(),
                light_count: 0,
                camera: RkCamera {
                    eye: c.eye,
                    look_at: c.look_at,
                    up: c.up,
                    vfov_deg: c.vfov_deg,
                    aperture_radius: c.aperture_radius,
                    focus_distance: c.focus_distance,
                },
                background: data.background,
                settings,
            },
        };
        out.point();
        out
    }

    /// Points the scene at the (possibly edited) arrays.
    pub fn point(&mut self) -> &RkScene {
        for (o, f) in self.objects.iter_mut().zip(&self.floats) {
            o.data = f.as_ptr();
        }
        self.scene.objects = self.objects.as_ptr();
        self.scene.object_count = self.objects.len() as u32;
        self.scene.materials = self.materials.as_ptr();
        self.scene.material_count = self.materials.len() as u32;
        self.scene.lights = self.lights.as_ptr();
        self.scene.light_count = self.lights.len() as u32;
        &self.scene
    }
}

pub fn c_material(m: &Material) -> RkMaterial {
    let (kind, color, exponent) = match *m {
        Material::Diffuse { albedo } => (RK_MATERIAL_DIFFUSE, albedo, 0.0),
        Material::Mirror { reflectance } => (RK_MATERIAL_MIRROR, reflectance, 0.0),
        Material::Glossy {
            reflectance,
            exponent,
        } => (RK_MATERIAL_GLOSSY, reflectance, exponent),
        Material::Emissive { radiance } => (RK_MATERIAL_EMISSIVE, radiance, 0.0),
    };
    RkMaterial {
        kind,
        color,
        exponent,
    }
}

pub fn c_light(l: &Light) -> RkLight {
    let none = RkLight {
        kind: 0,
        position: [0.0; 3],
        edge_u: [0.0; 3],
        edge_v: [0.0; 3],
        radius: 0.0,
        color: [0.0; 3],
    };
    match *l {
        Light::Point {
            position,
            intensity,
        } => RkLight {
            kind: RK_LIGHT_POINT,
            position,
            color: intensity,
            ..none
        },
        Light::Rect {
            corner,
            edge_u,
            edge_v,
            radiance,
        } => RkLight {
            kind: RK_LIGHT_RECT,
            position: corner,
            edge_u,
            edge_v,
            color: radiance,
            ..none
        },
        Light::Sphere {
            center,
            radius,
            radiance,
        } => RkLight {
            kind: RK_LIGHT_SPHERE,
            position: center,
            radius,
            color: radiance,
            ..none
        },
    }
}

/// Caller memory of `bytes` bytes starting `offset` bytes past a 128-byte boundary.
pub struct Memory {
    buf: Vec<u8>,
    offset: usize,
}

impl Memory {
    pub fn new(bytes: usize, offset: usize) -> Self {
        let buf = vec![0xa5u8; bytes + 256];
        let skip = buf.as_ptr().align_offset(128);
        Self {
            buf,
            offset: skip + offset,
        }
    }
    pub fn ptr(&mut self) -> *mut c_void {
        self.buf[self.offset..].as_mut_ptr().cast()
    }
}

pub fn no_error() -> RkSceneError {
    RkSceneError {
        item: u32::MAX,
        index: u32::MAX,
        field: [0; RK_FIELD_LEN],
        min: 0.0,
        max: 0.0,
    }
}

pub fn field(e: &RkSceneError) -> String {
    let bytes: Vec<u8> = e
        .field
        .iter()
        .take_while(|c| **c != 0)
        .map(|c| *c as u8)
        .collect();
    String::from_utf8(bytes).unwrap()
}

pub fn init(
    scene: &RkScene,
    memory: &mut Memory,
    bytes: usize,
) -> Result<RkRenderer, (RkStatus, RkSceneError)> {
    let mut r = RkRenderer {
        opaque: [7; RK_RENDERER_WORDS],
    };
    let mut e = no_error();
    // SAFETY: every pointer is valid for the access the contract names.
    let s = unsafe { rk_renderer_init(scene, memory.ptr(), bytes, &mut r, &mut e) };
    if s == RkStatus::Ok {
        Ok(r)
    } else {
        // A failed init leaves `out` uninitialised.
        let mut px = [0u8; 3];
        // SAFETY: as above.
        let t = unsafe { rk_render_tile(&r, 0, 0, 1, 1, px.as_mut_ptr(), 3) };
        assert_eq!(t, RkStatus::ErrNotInitialised);
        Err((s, e))
    }
}

/// The whole image through the C interface, in tiles of `tw × th` (edge tiles smaller).
pub fn c_render(scene: &RkScene, tw: u32, th: u32) -> Vec<u8> {
    // SAFETY: the scene and its arrays are valid.
    let bytes = unsafe { rk_render_bytes(scene) };
    assert!(bytes > 0);
    let mut memory = Memory::new(bytes, 3);
    let r = init(scene, &mut memory, bytes).unwrap_or_else(|(s, e)| {
        panic!(
            "init: {s:?} item {} index {} field {}",
            e.item,
            e.index,
            field(&e)
        )
    });
    let (w, h) = (scene.settings.width, scene.settings.height);
    let mut image = vec![0u8; 3 * (w * h) as usize];
    for y0 in (0..h).step_by(th as usize) {
        for x0 in (0..w).step_by(tw as usize) {
            let (cw, ch) = (tw.min(w - x0), th.min(h - y0));
            let mut tile = vec![0u8; 3 * (cw * ch) as usize];
            // SAFETY: `r` came from init, its memory is alive; `tile` holds `tile.len()` bytes.
            let s = unsafe { rk_render_tile(&r, x0, y0, cw, ch, tile.as_mut_ptr(), tile.len()) };
            assert_eq!(s, RkStatus::Ok);
            for row in 0..ch {
                let at = 3 * ((y0 + row) * w + x0) as usize;
                let from = 3 * (row * cw) as usize;
                image[at..at + 3 * cw as usize]
                    .copy_from_slice(&tile[from..from + 3 * cw as usize]);
            }
        }
    }
    image
}
