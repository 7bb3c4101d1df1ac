//! Laying out the caller's memory and building the renderer into it.

use super::api::AnyRenderer;
use super::failure::{failure_of, Failure};
use super::types::*;
use super::view::{view, Counts, View, Which};
use crate::RkStatus;
use core::ffi::c_void;
use core::mem::{align_of, size_of};
use raykernel::bvh::BuildOptions;
use raykernel::render::{
    memory_needed, Camera, Filter, Light, Material, Object, ObjectSlot, RenderMemory, Renderer,
    SamplerKind, Scene, Settings, Shape,
};
use raykernel::{AccelFamily, AccelMemory, Node, Node4, Scalar, Sphere, Triangle};

/// Alignment of the start of the laid-out memory (the 4-wide BVH's nodes need 128).
pub(super) const ALIGN: usize = 128;

/// Byte offsets of everything in the caller's memory, from an [`ALIGN`]-aligned start; the
/// renderer's state sits at offset 0.
pub(super) struct Layout {
    triangles: usize,
    spheres: usize,
    objects: usize,
    materials: usize,
    lights: usize,
    slots: usize,
    nodes: usize,
    nodes4: usize,
    words: usize,
    pub(super) end: usize,
}

/// Places arrays one after the other, each aligned for its type.
struct Cursor(usize);

impl Cursor {
    fn place<T>(&mut self, count: usize) -> Option<usize> {
        let align = align_of::<T>();
        if align > ALIGN {
            return None;
        }
        let start = self.0.checked_add(align - 1)? / align * align;
        self.0 = start.checked_add(count.checked_mul(size_of::<T>())?)?;
        Some(start)
    }
}

pub(super) fn layout<S: Scalar, F: AccelFamily<S>>(c: &Counts) -> Option<Layout> {
    let mut at = Cursor(0);
    let state = at.place::<Renderer<'static, S, F>>(1)?;
    debug_assert_eq!(state, 0);
    Some(Layout {
        triangles: at.place::<Triangle<S>>(c.triangles)?,
        spheres: at.place::<Sphere<S>>(c.spheres)?,
        objects: at.place::<Object<'static, S>>(c.objects)?,
        materials: at.place::<Material>(c.materials)?,
        lights: at.place::<Light>(c.lights)?,
        slots: at.place::<ObjectSlot<'static, S, F>>(c.objects)?,
        nodes: at.place::<Node<S>>(c.accel.nodes)?,
        nodes4: at.place::<Node4<S>>(c.accel.nodes4)?,
        words: at.place::<u32>(c.accel.words)?,
        end: at.0,
    })
}

pub(super) fn init(
    scene: *const RkScene,
    memory: *mut c_void,
    bytes: usize,
) -> Result<AnyRenderer, Failure> {
    let view = view(scene)?;
    if memory.is_null() {
        return Err(Failure::scene(RkStatus::ErrNull, "memory"));
    }
    let counts = view.counts()?;
    let memory = memory.cast::<u8>();
    Ok(match view.which()? {
        // `which` gives linked pairs only; the constant guards drop the others from the binary.
        w @ Which::F32Bvh if w.linked() => {
            AnyRenderer::F32Bvh(init_in(&view, &counts, memory, bytes)?)
        }
        w @ Which::F32Bvh4 if w.linked() => {
            AnyRenderer::F32Bvh4(init_in(&view, &counts, memory, bytes)?)
        }
        w @ Which::FixedBvh if w.linked() => {
            AnyRenderer::FixedBvh(init_in(&view, &counts, memory, bytes)?)
        }
        w @ Which::FixedBvh4 if w.linked() => {
            AnyRenderer::FixedBvh4(init_in(&view, &counts, memory, bytes)?)
        }
        _ => return Err(Failure::scene(RkStatus::ErrBadArgument, "kind")),
    })
}

/// `count` values of `T`, each set to `value`, at `at`.
///
/// # Safety
/// `at` is aligned for `T`, valid for writes of `count` values for the rest of the program's
/// use of the renderer, and no other reference to that memory is used meanwhile.
unsafe fn filled<T: Copy>(at: *mut u8, count: usize, value: T) -> &'static mut [T] {
    let p = at.cast::<T>();
    for i in 0..count {
        // SAFETY: within the `count` values (function contract).
        unsafe { p.add(i).write(value) };
    }
    // SAFETY: all `count` values were just initialised (function contract).
    unsafe { core::slice::from_raw_parts_mut(p, count) }
}

fn init_in<S: Scalar, F: AccelFamily<S, Options = BuildOptions>>(
    view: &View<'_>,
    counts: &Counts,
    memory: *mut u8,
    bytes: usize,
) -> Result<*const Renderer<'static, S, F>, Failure> {
    let too_large = Failure::scene(RkStatus::ErrTooLarge, "objects");
    let l = layout::<S, F>(counts).ok_or(too_large)?;
    let skip = memory.align_offset(ALIGN);
    if skip >= ALIGN || skip.saturating_add(l.end) > bytes {
        return Err(Failure::scene(RkStatus::ErrMemoryTooSmall, "memory"));
    }
    // SAFETY: `skip + l.end <= bytes`, so the region lies in the caller's memory, valid for
    // writes while the renderer is used (contract).
    let start = unsafe { memory.add(skip) };
    // SAFETY (every `filled` and `add` below): the offsets come from `layout`, which aligns
    // each array for its type from the `ALIGN`-aligned `start` and keeps them apart within
    // `l.end` bytes.
    let (tris, spheres) = unsafe {
        let zero = [S::ZERO; 3];
        (
            filled(
                start.add(l.triangles),
                counts.triangles,
                Triangle { v: [zero; 3] },
            ),
            filled(
                start.add(l.spheres),
                counts.spheres,
                Sphere {
                    center: zero,
                    radius: S::ZERO,
                },
            ),
        )
    };
    convert_primitives(view, tris, spheres)?;
    let (tris, spheres): (&'static [Triangle<S>], &'static [Sphere<S>]) = (tris, spheres);
    let empty = Object::new(Shape::Triangles(&[]), 0);
    // SAFETY: as above.
    let objects = unsafe { filled(start.add(l.objects), counts.objects, empty) };
    let (mut t, mut s) = (0usize, 0usize);
    for (slot, o) in objects.iter_mut().zip(view.objects) {
        let n = o.count as usize;
        // The ranges lie within the arrays (sized by the same counts): `get` never fails.
        let shape = if o.shape == RK_SHAPE_SPHERES {
            s += n;
            Shape::Spheres(spheres.get(s - n..s).unwrap_or_default())
        } else {
            t += n;
            Shape::Triangles(tris.get(t - n..t).unwrap_or_default())
        };
        // From `Object::new`: fields the C struct does not have keep their defaults.
        let mut object = Object::new(shape, o.material);
        object.motion = o.motion;
        *slot = object;
    }
    let options = BuildOptions::default();
    debug_assert_eq!(
        memory_needed::<S, F>(objects, &options).accel,
        counts.accel,
        "`counts` sizes the accelerators as the kernel does"
    );
    let placeholder = Material::Diffuse { albedo: [0.0; 3] };
    // SAFETY: as above.
    let materials = unsafe { filled(start.add(l.materials), counts.materials, placeholder) };
    for (i, (slot, m)) in materials.iter_mut().zip(view.materials).enumerate() {
        *slot = material(m).ok_or(Failure::new(
            RkStatus::ErrBadArgument,
            RK_ITEM_MATERIAL,
            i,
            "kind",
        ))?;
    }
    let placeholder = Light::Point {
        position: [0.0; 3],
        intensity: [0.0; 3],
    };
    // SAFETY: as above.
    let lights = unsafe { filled(start.add(l.lights), counts.lights, placeholder) };
    for (i, (slot, light)) in lights.iter_mut().zip(view.lights).enumerate() {
        *slot = light_of(light).ok_or(Failure::new(
            RkStatus::ErrBadArgument,
            RK_ITEM_LIGHT,
            i,
            "kind",
        ))?;
    }
    let settings = settings(&view.scene.settings)?;
    // SAFETY: as above.
    let memory = unsafe {
        RenderMemory {
            objects: filled(start.add(l.slots), counts.objects, ObjectSlot::EMPTY),
            accel: AccelMemory {
                nodes: filled(start.add(l.nodes), counts.accel.nodes, Node::EMPTY),
                nodes4: filled(start.add(l.nodes4), counts.accel.nodes4, Node4::EMPTY),
                nodes8: &mut [],
                kd_nodes: &mut [],
                words: filled(start.add(l.words), counts.accel.words, 0u32),
            },
        }
    };
    let c = &view.scene.camera;
    let scene = Scene {
        objects,
        materials,
        lights,
        camera: Camera {
            eye: c.eye,
            look_at: c.look_at,
            up: c.up,
            vfov_deg: c.vfov_deg,
            aperture_radius: c.aperture_radius,
            focus_distance: c.focus_distance,
        },
        background: view.scene.background,
    };
    let renderer = Renderer::<'static, S, F>::new(&scene, settings, options, memory)
        .map_err(|e| failure_of(&e, view.objects))?;
    let state = start.cast::<Renderer<'static, S, F>>();
    // SAFETY: offset 0 of the region is reserved for the state, aligned for it (`layout`).
    unsafe { state.write(renderer) };
    Ok(state)
}

/// Converts every object's floats into the mode, triangles and spheres in scene order.
fn convert_primitives<S: Scalar>(
    view: &View<'_>,
    tris: &mut [Triangle<S>],
    spheres: &mut [Sphere<S>],
) -> Result<(), Failure> {
    let (mut tris, mut spheres) = (tris.iter_mut(), spheres.iter_mut());
    for (i, o) in view.objects.iter().enumerate() {
        let data = view.data(i, o)?;
        if o.shape == RK_SHAPE_SPHERES {
            let bad = Failure::new(RkStatus::ErrBadSphere, RK_ITEM_OBJECT, i, "data");
            // The data first: `zip` stops on it without taking a slot past the object's.
            for (c, slot) in data.chunks_exact(4).zip(spheres.by_ref()) {
                *slot = sphere(c).ok_or(bad)?;
            }
        } else {
            let bad = Failure::new(RkStatus::ErrBadTriangle, RK_ITEM_OBJECT, i, "data");
            for (c, slot) in data.chunks_exact(9).zip(tris.by_ref()) {
                let c: &[f32; 9] = c.try_into().map_err(|_| bad)?;
                let v = [[c[0], c[1], c[2]], [c[3], c[4], c[5]], [c[6], c[7], c[8]]];
                *slot = Triangle::from_f32(v).map_err(|_| bad)?;
            }
        }
    }
    Ok(())
}

/// A sphere from centre x y z and radius: finite, in the mode's range, radius not negative.
fn sphere<S: Scalar>(c: &[f32]) -> Option<Sphere<S>> {
    let mut center = [S::ZERO; 3];
    for (slot, x) in center.iter_mut().zip(c) {
        *slot = S::coord_from_f32(*x).ok()?;
    }
    let r = *c.get(3)?;
    if r < 0.0 {
        return None;
    }
    Some(Sphere {
        center,
        radius: S::coord_from_f32(r).ok()?,
    })
}

fn material(m: &RkMaterial) -> Option<Material> {
    Some(match m.kind {
        RK_MATERIAL_DIFFUSE => Material::Diffuse { albedo: m.color },
        RK_MATERIAL_MIRROR => Material::Mirror {
            reflectance: m.color,
        },
        RK_MATERIAL_GLOSSY => Material::Glossy {
            reflectance: m.color,
            exponent: m.exponent,
        },
        RK_MATERIAL_EMISSIVE => Material::Emissive { radiance: m.color },
        _ => return None,
    })
}

fn light_of(l: &RkLight) -> Option<Light> {
    Some(match l.kind {
        RK_LIGHT_POINT => Light::Point {
            position: l.position,
            intensity: l.color,
        },
        RK_LIGHT_RECT => Light::Rect {
            corner: l.position,
            edge_u: l.edge_u,
            edge_v: l.edge_v,
            radiance: l.color,
        },
        RK_LIGHT_SPHERE => Light::Sphere {
            center: l.position,
            radius: l.radius,
            radiance: l.color,
        },
        _ => return None,
    })
}

/// The kernel's settings: the C fields over the kernel's defaults (fields the C struct does not
/// have keep them).
fn settings(c: &RkRenderSettings) -> Result<Settings, Failure> {
    let bad = |field| Failure::new(RkStatus::ErrBadArgument, RK_ITEM_SETTINGS, 0, field);
    let sampler = match c.sampler {
        RK_SAMPLER_INDEPENDENT => SamplerKind::Independent,
        RK_SAMPLER_STRATIFIED => SamplerKind::Stratified,
        RK_SAMPLER_SOBOL => SamplerKind::Sobol,
        _ => return Err(bad("sampler")),
    };
    let filter = match c.filter {
        RK_FILTER_BOX => Filter::Box,
        RK_FILTER_TENT => Filter::Tent,
        _ => return Err(bad("filter")),
    };
    // The kernel's `Settings` may gain fields the C struct does not have yet.
    #[allow(clippy::needless_update)]
    Ok(Settings {
        width: c.width,
        height: c.height,
        spp: c.spp,
        max_depth: c.max_depth,
        sampler,
        filter,
        seed: c.seed,
        ..Settings::default()
    })
}
