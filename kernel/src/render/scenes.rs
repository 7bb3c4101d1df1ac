//! Built-in scenes as plain `f32` data (no files, no allocation), and the conversion of such
//! data into a kernel [`Scene`] in either number mode. The host's scene files load into the
//! same [`SceneData`] shape, so built-in and file scenes take one path.

use super::sampling::SamplerKind;
use super::scene::{
    Camera, Filter, Integrator, Item, Light, Material, Object, Problem, Rgb, Scene, SceneError,
    Settings, Shape,
};
use crate::geom::{Sphere, Triangle};
use crate::scalar::Scalar;

/// A sphere as data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereData {
    /// Centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
}

/// Which primitives of a [`SceneData`] an object owns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeRange {
    /// `triangles[first..first + count]`.
    Triangles {
        /// First triangle.
        first: u32,
        /// Number of triangles.
        count: u32,
    },
    /// `spheres[first..first + count]`.
    Spheres {
        /// First sphere.
        first: u32,
        /// Number of spheres.
        count: u32,
    },
}

/// An object as data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectData {
    /// Its primitives.
    pub shape: ShapeRange,
    /// Material index.
    pub material: u32,
    /// Displacement over the shutter interval (zero: static).
    pub motion: [f32; 3],
    /// Emitted radiance ([`Object::emission`]).
    pub emission: Rgb,
    /// Front side only ([`Object::one_sided`]).
    pub one_sided: bool,
}

/// A whole scene as `f32` data, with the settings it is meant to be rendered with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneData<'d> {
    /// Short name (command lines, hash files).
    pub name: &'d str,
    /// Every triangle, objects' ranges index into it.
    pub triangles: &'d [[[f32; 3]; 3]],
    /// Vertex normals per triangle ([`Object::vertex_normals`]): empty (flat shading) or one
    /// entry per triangle, all zero for a triangle shaded flat.
    pub vertex_normals: &'d [[[f32; 3]; 3]],
    /// Every sphere.
    pub spheres: &'d [SphereData],
    /// Objects.
    pub objects: &'d [ObjectData],
    /// Materials.
    pub materials: &'d [Material],
    /// Lights.
    pub lights: &'d [Light],
    /// Camera.
    pub camera: Camera,
    /// Background radiance.
    pub background: Rgb,
    /// Suggested settings.
    pub settings: Settings,
}

impl<'d> SceneData<'d> {
    /// Converts every triangle into `out` (at least `triangles.len()` entries).
    ///
    /// # Errors
    /// [`Item::Object`] errors naming the first object whose triangle has an unusable vertex
    /// (non-finite, or outside the fixed-point range), or `out` too small.
    pub fn triangles_into<S: Scalar>(&self, out: &mut [Triangle<S>]) -> Result<(), SceneError> {
        if out.len() < self.triangles.len() {
            let p = Problem::TooSmall {
                needed: self.triangles.len(),
                available: out.len(),
            };
            return Err(SceneError::new(Item::Object, 0, "triangles", p));
        }
        for (i, (t, slot)) in self.triangles.iter().zip(out.iter_mut()).enumerate() {
            *slot = Triangle::from_f32(*t).map_err(|e| {
                let p = Problem::Build(crate::accel::BuildError::BadPrimitive {
                    prim: i,
                    vertex: e.vertex,
                    error: e.error,
                });
                SceneError::new(Item::Object, self.owner(i, false), "triangles", p)
            })?;
        }
        Ok(())
    }

    /// Converts every sphere into `out` (at least `spheres.len()` entries).
    ///
    /// # Errors
    /// As [`SceneData::triangles_into`], for centres and radii.
    pub fn spheres_into<S: Scalar>(&self, out: &mut [Sphere<S>]) -> Result<(), SceneError> {
        if out.len() < self.spheres.len() {
            let p = Problem::TooSmall {
                needed: self.spheres.len(),
                available: out.len(),
            };
            return Err(SceneError::new(Item::Object, 0, "spheres", p));
        }
        for (i, (s, slot)) in self.spheres.iter().zip(out.iter_mut()).enumerate() {
            let bad = |vertex, e| {
                let p = Problem::Build(crate::accel::BuildError::BadPrimitive {
                    prim: i,
                    vertex,
                    error: e,
                });
                SceneError::new(Item::Object, self.owner(i, true), "spheres", p)
            };
            let mut c = [S::ZERO; 3];
            for (slot, x) in c.iter_mut().zip(s.center) {
                *slot = S::coord_from_f32(x).map_err(|e| bad(0, e))?;
            }
            if s.radius < 0.0 {
                return Err(bad(1, crate::scalar::PointError::NegativeRadius));
            }
            let r = S::coord_from_f32(s.radius).map_err(|e| bad(1, e))?;
            *slot = Sphere {
                center: c,
                radius: r,
            };
        }
        Ok(())
    }

    /// The object owning triangle (or sphere) `i`, for error messages (0 if none).
    fn owner(&self, i: usize, sphere: bool) -> usize {
        self.objects
            .iter()
            .position(|o| match o.shape {
                ShapeRange::Triangles { first, count } if !sphere => {
                    (first as usize..first as usize + count as usize).contains(&i)
                }
                ShapeRange::Spheres { first, count } if sphere => {
                    (first as usize..first as usize + count as usize).contains(&i)
                }
                _ => false,
            })
            .unwrap_or(0)
    }

    /// The kernel scene over converted primitives (from [`SceneData::triangles_into`] and
    /// [`SceneData::spheres_into`]), writing the objects into `objects` (at least
    /// `self.objects.len()` entries).
    ///
    /// # Errors
    /// [`Item::Object`] errors for a range outside the primitive lists or `objects` too small.
    pub fn scene<'a, S: Scalar>(
        &self,
        triangles: &'a [Triangle<S>],
        spheres: &'a [Sphere<S>],
        objects: &'a mut [Object<'a, S>],
    ) -> Result<Scene<'a, S>, SceneError>
    where
        'd: 'a,
    {
        if objects.len() < self.objects.len() {
            let p = Problem::TooSmall {
                needed: self.objects.len(),
                available: objects.len(),
            };
            return Err(SceneError::new(Item::Object, 0, "objects", p));
        }
        for (i, (o, slot)) in self.objects.iter().zip(objects.iter_mut()).enumerate() {
            let range = |first: u32, count: u32, len: usize| {
                let (a, b) = (first as usize, first as usize + count as usize);
                if b > len {
                    Err(SceneError::new(
                        Item::Object,
                        i,
                        "shape",
                        Problem::Index { len },
                    ))
                } else {
                    Ok(a..b)
                }
            };
            let (shape, vertex_normals) = match o.shape {
                ShapeRange::Triangles { first, count } => {
                    let r = range(first, count, triangles.len())?;
                    let normals = self.vertex_normals.get(r.clone()).unwrap_or_default();
                    (
                        Shape::Triangles(triangles.get(r).unwrap_or_default()),
                        normals,
                    )
                }
                ShapeRange::Spheres { first, count } => {
                    let r = range(first, count, spheres.len())?;
                    (Shape::Spheres(spheres.get(r).unwrap_or_default()), &[][..])
                }
            };
            *slot = Object {
                shape,
                material: o.material,
                motion: o.motion,
                emission: o.emission,
                one_sided: o.one_sided,
                vertex_normals,
            };
        }
        let n = self.objects.len();
        let objects: &'a [Object<'a, S>] = objects;
        Ok(Scene {
            objects: objects.get(..n).unwrap_or_default(),
            materials: self.materials,
            lights: self.lights,
            camera: self.camera,
            background: self.background,
        })
    }
}

const fn quad(a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3]) -> [[[f32; 3]; 3]; 2] {
    [[a, b, c], [a, c, d]]
}

const fn tris(first: u32, count: u32) -> ShapeRange {
    ShapeRange::Triangles { first, count }
}

const fn spheres(first: u32, count: u32) -> ShapeRange {
    ShapeRange::Spheres { first, count }
}

const fn still(shape: ShapeRange, material: u32) -> ObjectData {
    ObjectData {
        shape,
        material,
        motion: [0.0; 3],
        emission: [0.0; 3],
        one_sided: false,
    }
}

const fn flatten<const N: usize, const M: usize>(q: [[[[f32; 3]; 3]; 2]; N]) -> [[[f32; 3]; 3]; M] {
    let mut out = [[[0.0; 3]; 3]; M];
    let mut i = 0;
    while i < N && 2 * i + 1 < M {
        out[2 * i] = q[i][0];
        out[2 * i + 1] = q[i][1];
        i += 1;
    }
    out
}

/// The Cornell box's walls (floor, ceiling, back: white; left: red; right: green) then a
/// rotated block (top and four sides, 1.2 high).
const CORNELL_TRIANGLES: [[[f32; 3]; 3]; 20] = {
    let walls: [[[f32; 3]; 3]; 10] = flatten([
        quad(
            [-1.0, 0.0, -1.0],
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, -1.0],
        ),
        quad(
            [-1.0, 2.0, -1.0],
            [1.0, 2.0, -1.0],
            [1.0, 2.0, 1.0],
            [-1.0, 2.0, 1.0],
        ),
        quad(
            [-1.0, 0.0, -1.0],
            [1.0, 0.0, -1.0],
            [1.0, 2.0, -1.0],
            [-1.0, 2.0, -1.0],
        ),
        quad(
            [-1.0, 0.0, -1.0],
            [-1.0, 2.0, -1.0],
            [-1.0, 2.0, 1.0],
            [-1.0, 0.0, 1.0],
        ),
        quad(
            [1.0, 0.0, -1.0],
            [1.0, 0.0, 1.0],
            [1.0, 2.0, 1.0],
            [1.0, 2.0, -1.0],
        ),
    ]);
    let block: [[[f32; 3]; 3]; 10] = [
        [
            [0.3005, 1.2, -0.7563],
            [0.6763, 1.2, -0.6195],
            [0.5395, 1.2, -0.2437],
        ],
        [
            [0.3005, 1.2, -0.7563],
            [0.5395, 1.2, -0.2437],
            [0.1637, 1.2, -0.3805],
        ],
        [
            [0.3005, 0.0, -0.7563],
            [0.6763, 0.0, -0.6195],
            [0.6763, 1.2, -0.6195],
        ],
        [
            [0.3005, 0.0, -0.7563],
            [0.6763, 1.2, -0.6195],
            [0.3005, 1.2, -0.7563],
        ],
        [
            [0.6763, 0.0, -0.6195],
            [0.5395, 0.0, -0.2437],
            [0.5395, 1.2, -0.2437],
        ],
        [
            [0.6763, 0.0, -0.6195],
            [0.5395, 1.2, -0.2437],
            [0.6763, 1.2, -0.6195],
        ],
        [
            [0.5395, 0.0, -0.2437],
            [0.1637, 0.0, -0.3805],
            [0.1637, 1.2, -0.3805],
        ],
        [
            [0.5395, 0.0, -0.2437],
            [0.1637, 1.2, -0.3805],
            [0.5395, 1.2, -0.2437],
        ],
        [
            [0.1637, 0.0, -0.3805],
            [0.3005, 0.0, -0.7563],
            [0.3005, 1.2, -0.7563],
        ],
        [
            [0.1637, 0.0, -0.3805],
            [0.3005, 1.2, -0.7563],
            [0.1637, 1.2, -0.3805],
        ],
    ];
    let mut out = [[[0.0; 3]; 3]; 20];
    let mut i = 0;
    while i < 10 {
        out[i] = walls[i];
        out[10 + i] = block[i];
        i += 1;
    }
    out
};

const CORNELL_SPHERES: [SphereData; 3] = [
    // Mirror, glossy, moving.
    SphereData {
        center: [-0.45, 0.4, -0.35],
        radius: 0.4,
    },
    SphereData {
        center: [0.45, 0.35, 0.3],
        radius: 0.35,
    },
    SphereData {
        center: [-0.35, 0.22, 0.75],
        radius: 0.22,
    },
];

const CORNELL_MATERIALS: [Material; 7] = [
    Material::Diffuse {
        albedo: [0.73, 0.73, 0.73],
    },
    Material::Diffuse {
        albedo: [0.63, 0.065, 0.05],
    },
    Material::Diffuse {
        albedo: [0.14, 0.45, 0.09],
    },
    Material::Mirror {
        reflectance: [0.9, 0.9, 0.9],
    },
    Material::Glossy {
        reflectance: [0.9, 0.7, 0.3],
        exponent: 60.0,
    },
    Material::Diffuse {
        albedo: [0.15, 0.3, 0.85],
    },
    Material::Diffuse {
        albedo: [0.8, 0.8, 0.75],
    },
];

const CORNELL_OBJECTS: [ObjectData; 8] = [
    still(tris(0, 6), 0),
    still(tris(6, 2), 1),
    still(tris(8, 2), 2),
    still(tris(10, 10), 6),
    still(spheres(0, 1), 3),
    still(spheres(1, 1), 4),
    ObjectData {
        shape: spheres(2, 1),
        material: 5,
        motion: [0.3, 0.0, 0.0],
        emission: [0.0; 3],
        one_sided: false,
    },
    // Empty objects are allowed (and cost nothing).
    still(tris(20, 0), 0),
];

const CORNELL_LIGHTS: [Light; 1] = [Light::Rect {
    corner: [-0.3, 1.98, -0.3],
    edge_u: [0.6, 0.0, 0.0],
    edge_v: [0.0, 0.0, 0.6],
    radiance: [14.0, 12.0, 8.0],
}];

/// The default scene: a Cornell box with a mirror sphere, a glossy sphere, a block, a moving
/// sphere, a rectangular area light, and an open aperture focused on the glossy sphere. Every
/// effect of the renderer is visible.
pub const CORNELL: SceneData<'static> = SceneData {
    name: "cornell",
    triangles: &CORNELL_TRIANGLES,
    vertex_normals: &[],
    spheres: &CORNELL_SPHERES,
    objects: &CORNELL_OBJECTS,
    materials: &CORNELL_MATERIALS,
    lights: &CORNELL_LIGHTS,
    camera: Camera {
        eye: [0.0, 1.0, 3.6],
        look_at: [0.0, 0.9, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 38.0,
        aperture_radius: 0.04,
        focus_distance: 3.35,
    },
    background: [0.0; 3],
    settings: Settings {
        width: 64,
        height: 64,
        spp: 8,
        max_depth: 4,
        integrator: Integrator::Direct,
        sampler: SamplerKind::Stratified,
        filter: Filter::Box,
        seed: 1,
    },
};

const SPHERES_TRIANGLES: [[[f32; 3]; 3]; 2] = [
    [[-4.0, 0.0, -4.0], [-4.0, 0.0, 4.0], [4.0, 0.0, 4.0]],
    [[-4.0, 0.0, -4.0], [4.0, 0.0, 4.0], [4.0, 0.0, -4.0]],
];

const SPHERES_SPHERES: [SphereData; 4] = [
    SphereData {
        center: [-1.1, 0.5, 0.0],
        radius: 0.5,
    },
    SphereData {
        center: [0.0, 0.5, 0.0],
        radius: 0.5,
    },
    SphereData {
        center: [1.1, 0.5, 0.0],
        radius: 0.5,
    },
    SphereData {
        center: [0.55, 0.25, 1.0],
        radius: 0.25,
    },
];

const SPHERES_MATERIALS: [Material; 4] = [
    Material::Diffuse {
        albedo: [0.6, 0.6, 0.55],
    },
    Material::Mirror {
        reflectance: [0.95, 0.95, 0.95],
    },
    Material::Diffuse {
        albedo: [0.7, 0.2, 0.2],
    },
    Material::Emissive {
        radiance: [2.0, 3.0, 4.0],
    },
];

const SPHERES_OBJECTS: [ObjectData; 4] = [
    still(tris(0, 2), 0),
    still(spheres(0, 1), 2),
    still(spheres(1, 1), 1),
    still(spheres(2, 2), 2),
];

const SPHERES_LIGHTS: [Light; 2] = [
    Light::Point {
        position: [2.0, 4.0, 3.0],
        intensity: [12.0, 12.0, 12.0],
    },
    Light::Point {
        position: [-3.0, 2.0, 1.0],
        intensity: [1.0, 2.0, 4.0],
    },
];

/// Hard shadows from two point lights, a mirror sphere, and a sky: pinhole camera, Sobol
/// samples with a tent filter, nothing moving.
pub const SPHERES: SceneData<'static> = SceneData {
    name: "spheres",
    triangles: &SPHERES_TRIANGLES,
    vertex_normals: &[],
    spheres: &SPHERES_SPHERES,
    objects: &SPHERES_OBJECTS,
    materials: &SPHERES_MATERIALS,
    lights: &SPHERES_LIGHTS,
    camera: Camera {
        eye: [0.0, 1.6, 4.5],
        look_at: [0.0, 0.4, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 40.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    },
    background: [0.25, 0.35, 0.5],
    settings: Settings {
        width: 64,
        height: 48,
        spp: 4,
        max_depth: 3,
        integrator: Integrator::Direct,
        sampler: SamplerKind::Sobol,
        filter: Filter::Tent,
        seed: 7,
    },
};

const MOTION_TRIANGLES: [[[f32; 3]; 3]; 12] = {
    flatten::<6, 12>([
        // Ground.
        quad(
            [-3.0, 0.0, -3.0],
            [-3.0, 0.0, 3.0],
            [3.0, 0.0, 3.0],
            [3.0, 0.0, -3.0],
        ),
        // A moving open box: top and four sides of [-0.9,-0.3] x [0,0.6] x [-0.3,0.3].
        quad(
            [-0.9, 0.6, -0.3],
            [-0.9, 0.6, 0.3],
            [-0.3, 0.6, 0.3],
            [-0.3, 0.6, -0.3],
        ),
        quad(
            [-0.9, 0.0, 0.3],
            [-0.3, 0.0, 0.3],
            [-0.3, 0.6, 0.3],
            [-0.9, 0.6, 0.3],
        ),
        quad(
            [-0.9, 0.0, -0.3],
            [-0.9, 0.6, -0.3],
            [-0.3, 0.6, -0.3],
            [-0.3, 0.0, -0.3],
        ),
        quad(
            [-0.9, 0.0, -0.3],
            [-0.9, 0.0, 0.3],
            [-0.9, 0.6, 0.3],
            [-0.9, 0.6, -0.3],
        ),
        quad(
            [-0.3, 0.0, -0.3],
            [-0.3, 0.6, -0.3],
            [-0.3, 0.6, 0.3],
            [-0.3, 0.0, 0.3],
        ),
    ])
};

const MOTION_SPHERES: [SphereData; 2] = [
    SphereData {
        center: [0.7, 0.35, 0.0],
        radius: 0.35,
    },
    SphereData {
        center: [0.0, 0.3, -1.2],
        radius: 0.3,
    },
];

const MOTION_MATERIALS: [Material; 4] = [
    Material::Diffuse {
        albedo: [0.5, 0.5, 0.5],
    },
    Material::Diffuse {
        albedo: [0.8, 0.5, 0.1],
    },
    Material::Glossy {
        reflectance: [0.8, 0.8, 0.9],
        exponent: 20.0,
    },
    Material::Diffuse {
        albedo: [0.2, 0.6, 0.3],
    },
];

const MOTION_OBJECTS: [ObjectData; 4] = [
    still(tris(0, 2), 0),
    ObjectData {
        shape: tris(2, 10),
        material: 1,
        motion: [0.0, 0.0, 0.5],
        emission: [0.0; 3],
        one_sided: false,
    },
    ObjectData {
        shape: spheres(0, 1),
        material: 2,
        motion: [0.0, 0.4, 0.0],
        emission: [0.0; 3],
        one_sided: false,
    },
    still(spheres(1, 1), 3),
];

const MOTION_LIGHTS: [Light; 2] = [
    Light::Sphere {
        center: [1.5, 2.5, 1.5],
        radius: 0.5,
        radiance: [8.0, 8.0, 7.0],
    },
    Light::Point {
        position: [-2.0, 3.0, -1.0],
        intensity: [3.0, 3.0, 4.0],
    },
];

/// Motion blur on a mesh and a sphere, a sphere light (soft shadows) and a point light,
/// independent samples, a glossy moving sphere.
pub const MOTION: SceneData<'static> = SceneData {
    name: "motion",
    triangles: &MOTION_TRIANGLES,
    vertex_normals: &[],
    spheres: &MOTION_SPHERES,
    objects: &MOTION_OBJECTS,
    materials: &MOTION_MATERIALS,
    lights: &MOTION_LIGHTS,
    camera: Camera {
        eye: [0.0, 1.5, 3.5],
        look_at: [0.0, 0.3, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_deg: 45.0,
        aperture_radius: 0.0,
        focus_distance: 1.0,
    },
    background: [0.05, 0.05, 0.08],
    settings: Settings {
        width: 48,
        height: 48,
        spp: 6,
        max_depth: 2,
        integrator: Integrator::Direct,
        sampler: SamplerKind::Independent,
        filter: Filter::Box,
        seed: 3,
    },
};

/// Every built-in scene; the first is the default.
pub const ALL: [SceneData<'static>; 3] = [CORNELL, SPHERES, MOTION];

/// The built-in scene called `name`.
#[must_use]
pub fn by_name(name: &str) -> Option<SceneData<'static>> {
    ALL.iter().find(|s| s.name == name).copied()
}
