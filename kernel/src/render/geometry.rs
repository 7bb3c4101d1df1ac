//! The renderer's view of the scene's geometry: one accelerator per object, moving objects
//! behind a swept box, visible area lights; the scene-wide closest and any hit.
//!
//! Primitive ids are global: the objects' primitives in scene order, then one id per light, so
//! the closest-hit tie rule (lowest id) orders objects as well as primitives.
//!
//!
//! Motion is in [`super::motion`]; leaving a surface in [`super::surface`].

use super::features::RenderFeatures;
use super::lights::{light_geom, LightGeom, MAX_LIGHTS};
use super::memory::{memory_needed, RenderMemory};
use super::motion::{displacement, moved_into_frame, swept_box};
use super::objects::{ObjectGeom, ObjectSlot, ShapeAccel};
use super::scene::{Item, Light, Material, Object, Problem, Shape};
use super::surface::{Prim, SurfacePoint};
use super::SceneError;
use crate::accel::bvh::Bvh;
use crate::accel::{take, AccelFamily, BuildError, Counters, MemoryNeeded};
use crate::geom::spawn::{cross, sub, unit};
use crate::geom::{closer, Aabb, Barycentrics, Primitive, Ray, Sphere};
use crate::scalar::Scalar;

/// What a closest hit found.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Surface {
    /// Object `object`, its primitive `local`.
    Object { object: usize, local: u32 },
    /// Light `light`.
    Light { light: usize },
}

/// A closest hit over the whole scene. Barycentrics are not computed here: only shading a
/// surface point needs them ([`Geometry::surface_point`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SceneHit<S: Scalar> {
    /// Distance along the ray.
    pub(crate) t: S,
    /// Global primitive id (the tie rule's key).
    pub(crate) prim: u32,
    pub(crate) surface: Surface,
}

/// The closest hit so far and the far end of the search.
struct Best<S: Scalar> {
    hit: Option<SceneHit<S>>,
    t: S,
}

/// Every object and light of a scene, ready for queries at a shutter time.
#[derive(Clone, Debug)]
pub(crate) struct Geometry<'a, S: Scalar, F: AccelFamily<S>> {
    /// One filled slot per object, in scene order.
    objects: &'a [ObjectSlot<'a, S, F>],
    /// A BVH over the objects' (swept) boxes, for two objects or more: a ray visits the
    /// objects whose boxes it enters, nearest first, instead of every object in turn.
    tlas: Option<Bvh<'a, S, ObjectSlot<'a, S, F>>>,
    pub(crate) lights: heapless::Vec<LightGeom<S>, MAX_LIGHTS>,
    /// Global id of the first light.
    light_base: u32,
    /// Emissive primitives: every primitive of every object that emits
    /// ([`super::emitters`]).
    pub(crate) emitter_count: u32,
}

impl<'a, S: Scalar, F: AccelFamily<S>> Geometry<'a, S, F> {
    /// Builds every object's accelerator into the caller's memory ([`memory_needed`]).
    pub(crate) fn build<K: RenderFeatures>(
        objects: &'a [Object<'a, S>],
        materials: &[Material],
        lights: &[Light],
        options: &F::Options,
        memory: RenderMemory<'a, S, F>,
    ) -> Result<Self, SceneError> {
        let err = |index, field, problem| SceneError::new(Item::Object, index, field, problem);
        if lights.len() > MAX_LIGHTS {
            return Err(SceneError::new(
                Item::Light,
                0,
                "lights",
                Problem::TooMany { max: MAX_LIGHTS },
            ));
        }
        let RenderMemory {
            objects: mut slots,
            accel: mut memory,
        } = memory;
        let need = memory_needed::<S, F>(objects, options);
        if slots.len() < need.objects {
            let (needed, available) = (need.objects, slots.len());
            return Err(err(0, "objects", Problem::TooSmall { needed, available }));
        }
        if let Some(s) = need.accel.first_shortfall(&memory.available()) {
            let problem = Problem::TooSmall {
                needed: s.needed,
                available: s.available,
            };
            return Err(err(0, s.field, problem));
        }
        let slots = take(&mut slots, objects.len());
        let mut base = 0u32;
        let mut emitter_count = 0u32;
        for (i, (o, slot)) in objects.iter().zip(slots.iter_mut()).enumerate() {
            let bad = |e| err(i, "shape", Problem::Build(e));
            if !super::scene::finite3(o.motion) {
                return Err(err(i, "motion", Problem::NonFinite));
            }
            super::scene::check_rgb(o.emission, false).map_err(|p| err(i, "emission", p))?;
            check_vertex_normals(o).map_err(|p| err(i, "vertex_normals", p))?;
            let bounds = match o.shape {
                Shape::Triangles(t) => union_bounds(t),
                Shape::Spheres(s) if F::SPHERES => union_bounds(s),
                Shape::Spheres(_) => return Err(err(i, "shape", Problem::NotLinked)),
            };
            let accel = ShapeAccel::build(o.shape, options, &mut memory).map_err(bad)?;
            let motion = o.moves().then_some(o.motion);
            let swept = match (motion, bounds) {
                (Some(m), Some(b)) => swept_box(&b, m),
                (_, b) => b.unwrap_or(Aabb::new([S::ZERO; 3], [S::ZERO; 3])),
            };
            let len = u32::try_from(o.shape.len()).unwrap_or(u32::MAX);
            let emitted = emitted_by(o, materials);
            let emitter_base = emitter_count;
            if emitted != [0.0; 3] {
                // At most the global ids' count, checked below.
                emitter_count = emitter_count.saturating_add(len);
            }
            let g = ObjectGeom {
                accel,
                shape: o.shape,
                base,
                material: o.material,
                emission: o.emission,
                one_sided: o.one_sided,
                emitted,
                emitter_base,
                vertex_normals: o.vertex_normals,
                motion,
                swept,
            };
            *slot = ObjectSlot(Some(g));
            base = base.checked_add(len).ok_or(err(
                i,
                "shape",
                Problem::Build(BuildError::TooManyPrims {
                    count: o.shape.len(),
                }),
            ))?;
        }
        let slots: &'a [ObjectSlot<'a, S, F>] = slots;
        let tlas = if slots.len() >= 2 {
            let need = MemoryNeeded::bvh(slots.len());
            let nodes = take(&mut memory.nodes, need.nodes);
            let ids = take(&mut memory.words, need.words);
            let tree = Bvh::build(slots, nodes, ids, F::TopLevel::default())
                .map_err(|e| err(0, "objects", Problem::Build(e)))?;
            Some(tree)
        } else {
            None
        };
        let mut geo = Self {
            objects: slots,
            tlas,
            lights: heapless::Vec::new(),
            light_base: base,
            emitter_count,
        };
        for (i, l) in lights.iter().enumerate() {
            let _ = geo.lights.push(
                light_geom::<S, K>(l)
                    .map_err(|(field, problem)| SceneError::new(Item::Light, i, field, problem))?,
            );
        }
        Ok(geo)
    }

    /// Runs `query` on object `o` for `ray` at shutter time `time`. A static object sees the
    /// ray itself; a moving one is culled by its swept box first, then sees the ray moved into
    /// its frame (and is missed if the moved origin leaves the mode's range).
    #[inline]
    fn query_object<C: Counters, R>(
        o: &ObjectGeom<'a, S, F>,
        ray: &Ray<S>,
        time: f32,
        c: &mut C,
        query: impl FnOnce(&ShapeAccel<'a, S, F>, &Ray<S>, &mut C) -> R,
    ) -> Option<R> {
        let Some(m) = o.motion else {
            return Some(query(&o.accel, ray, c));
        };
        c.node();
        o.swept.slab(ray)?;
        let moved = moved_into_frame::<S>(m, ray, time)?;
        Some(query(&o.accel, &moved, c))
    }

    /// The objects with their indices, in scene order.
    #[inline]
    pub(crate) fn objects(&self) -> impl Iterator<Item = (usize, &ObjectGeom<'a, S, F>)> {
        let built = self.objects.iter().map(|s| s.0.as_ref());
        built.enumerate().filter_map(|(i, o)| o.map(|o| (i, o)))
    }

    /// The objects' slots, in scene order (all filled).
    #[inline]
    pub(crate) fn slots(&self) -> &'a [ObjectSlot<'a, S, F>] {
        self.objects
    }

    /// Object `i`.
    #[inline]
    pub(crate) fn object(&self, i: usize) -> Option<&ObjectGeom<'a, S, F>> {
        self.objects.get(i).and_then(|s| s.0.as_ref())
    }

    /// Closest hit at shutter time `time`; ties to the lowest global id.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    pub(crate) fn intersect<C: Counters>(
        &self,
        ray: &Ray<S>,
        time: f32,
        c: &mut C,
    ) -> Option<SceneHit<S>> {
        let mut best = Best {
            hit: None,
            t: ray.t_max(),
        };
        match &self.tlas {
            Some(tlas) => tlas.walk(ray, c, |i, _, c| {
                if let Some(o) = self.object(i as usize) {
                    Self::closest_in(o, i as usize, ray, time, c, &mut best);
                }
                Some(best.t)
            }),
            None => {
                for (i, o) in self.objects() {
                    Self::closest_in(o, i, ray, time, c, &mut best);
                }
            }
        }
        let Best {
            hit: mut best,
            t: mut best_t,
        } = best;
        for (i, l) in self.lights.iter().enumerate() {
            let id = self.light_base.saturating_add(i as u32);
            let t = match l {
                LightGeom::Point => None,
                LightGeom::Rect(tris, _) => {
                    let (t0, t1) = (
                        tris[0].hit_t(ray.data(), ray.t_min(), best_t),
                        tris[1].hit_t(ray.data(), ray.t_min(), best_t),
                    );
                    match (t0, t1) {
                        (Some(a), Some(b)) => Some(if b < a { b } else { a }),
                        (a, b) => a.or(b),
                    }
                }
                LightGeom::Sphere(s) => s.hit_t(ray.data(), ray.t_min(), best_t),
            };
            if let Some(t) = t {
                if best.is_none_or(|b| closer(t, id, best_t, b.prim)) {
                    best_t = t;
                    best = Some(SceneHit {
                        t,
                        prim: id,
                        surface: Surface::Light { light: i },
                    });
                }
            }
        }
        best
    }

    /// Object `o` (index `i`)'s closest hit for `ray` within `best.t`, kept in `best` if it is
    /// closer under the tie rule (global ids).
    #[cfg_attr(not(target_os = "none"), inline(always))]
    fn closest_in<C: Counters>(
        o: &ObjectGeom<'a, S, F>,
        i: usize,
        ray: &Ray<S>,
        time: f32,
        c: &mut C,
        best: &mut Best<S>,
    ) {
        // The ray itself until something is hit (copying a just-built ray stalls on store
        // forwarding, measurably per camera ray), then a copy ending at the closest hit.
        let shortened: Ray<S>;
        let r = if best.hit.is_none() {
            ray
        } else {
            let Ok(r) = ray.with_interval(ray.t_min(), best.t) else {
                return;
            };
            shortened = r;
            &shortened
        };
        let Some(h) = Self::query_object(o, r, time, c, ShapeAccel::nearest).flatten() else {
            return;
        };
        let id = o.base.saturating_add(h.prim);
        if best.hit.is_none_or(|b| closer(h.t, id, best.t, b.prim)) {
            best.t = h.t;
            best.hit = Some(SceneHit {
                t: h.t,
                prim: id,
                surface: Surface::Object {
                    object: i,
                    local: h.prim,
                },
            });
        }
    }

    /// Any object hit in the ray's interval at shutter time `time` (lights cast no shadow).
    pub(crate) fn occluded<C: Counters>(&self, ray: &Ray<S>, time: f32, c: &mut C) -> bool {
        let hit = |o: &ObjectGeom<'a, S, F>, c: &mut C| {
            Self::query_object(o, ray, time, c, ShapeAccel::occluded) == Some(true)
        };
        let Some(tlas) = &self.tlas else {
            return self.objects().any(|(_, o)| hit(o, c));
        };
        let mut found = false;
        tlas.walk(ray, c, |i, t_max, c| {
            found = self.object(i as usize).is_some_and(|o| hit(o, c));
            (!found).then_some(t_max)
        });
        found
    }

    /// The point a hit lies on: world position, unit geometric normal (not yet facing the
    /// ray), and what [`SurfacePoint::spawn_origin`] needs to leave it. `None` for lights.
    /// Inlined on hosted targets into both integrators (see `lighting::visible`).
    #[cfg_attr(not(target_os = "none"), inline(always))]
    pub(crate) fn surface_point<K: RenderFeatures>(
        &self,
        ray: &Ray<S>,
        h: &SceneHit<S>,
        time: f32,
    ) -> Option<SurfacePoint<'_, S>> {
        let Surface::Object { object, local } = h.surface else {
            return None;
        };
        let o = self.object(object)?;
        let d = o.motion.map_or([0.0; 3], |m| displacement::<S>(m, time));
        match o.shape {
            Shape::Triangles(t) => {
                let tri = t.get(local as usize)?;
                // Barycentrics as the accelerator gives them: from the ray in the object's frame.
                let Barycentrics { u: hu, v: hv } = match o.motion {
                    None => tri.hit_uv(ray.data()),
                    Some(m) => tri.hit_uv(moved_into_frame::<S>(m, ray, time)?.data()),
                };
                let v = tri.v.map(|p| p.map(S::to_f64));
                let (u, w) = (hu.to_f64(), hv.to_f64());
                let p: [f64; 3] = core::array::from_fn(|k| {
                    v[0][k] + u * (v[1][k] - v[0][k]) + w * (v[2][k] - v[0][k]) + d[k]
                });
                let n = triangle_normal(&v, ray);
                let shading = o
                    .vertex_normals
                    .get(local as usize)
                    .filter(|_| K::SMOOTH_SHADING)
                    .and_then(|corners| interpolated_normal(corners, u, w, &n))
                    .unwrap_or(n);
                Some(SurfacePoint {
                    position: p,
                    normal: n.map(|x| x as f32),
                    shading: shading.map(|x| x as f32),
                    prim: Prim::Triangle(tri, hu, hv),
                    shift: d,
                })
            }
            Shape::Spheres(s) if F::SPHERES => {
                let sp = s.get(local as usize)?;
                let c = sp.center.map(S::to_f64);
                let n = sphere_normal(sp, ray, h.t, d);
                let r = sp.radius.to_f64();
                // The point on the sphere along the normal: the offset is taken from there.
                let p: [f64; 3] = core::array::from_fn(|k| c[k] + r * n[k] + d[k]);
                Some(SurfacePoint {
                    position: p,
                    normal: n.map(|x| x as f32),
                    shading: n.map(|x| x as f32),
                    prim: Prim::Sphere(sp),
                    shift: d,
                })
            }
            Shape::Spheres(_) => None,
        }
    }
}

impl<'a, S: Scalar, F: AccelFamily<S>> Geometry<'a, S, F> {
    /// The unit geometric normal [`Geometry::surface_point`] gives for hit `h`, without the
    /// rest of the surface point (no barycentrics). `None` for lights.
    pub(crate) fn normal_at(&self, ray: &Ray<S>, h: &SceneHit<S>, time: f32) -> Option<[f32; 3]> {
        let Surface::Object { object, local } = h.surface else {
            return None;
        };
        let o = self.object(object)?;
        match o.shape {
            // A translation does not turn a triangle: no motion needed.
            Shape::Triangles(t) => {
                let v = t.get(local as usize)?.v.map(|p| p.map(S::to_f64));
                Some(triangle_normal(&v, ray).map(|x| x as f32))
            }
            Shape::Spheres(s) if F::SPHERES => {
                let d = o.motion.map_or([0.0; 3], |m| displacement::<S>(m, time));
                let n = sphere_normal(s.get(local as usize)?, ray, h.t, d);
                Some(n.map(|x| x as f32))
            }
            Shape::Spheres(_) => None,
        }
    }
}

/// A triangle's unit geometric normal `(v1 − v0) × (v2 − v0)` (degenerate: against the ray).
fn triangle_normal<S: Scalar>(v: &[[f64; 3]; 3], ray: &Ray<S>) -> [f64; 3] {
    unit(cross(&sub(&v[1], &v[0]), &sub(&v[2], &v[0])))
        .unwrap_or_else(|| S::ray_dir(ray.data()).map(|x| -x.to_f64()))
}

/// A sphere's unit outward normal at the ray's hit `t`, the sphere displaced by `d` (the hit
/// point from the ray in the sphere's frame; at the centre: against the ray).
fn sphere_normal<S: Scalar>(sp: &Sphere<S>, ray: &Ray<S>, t: S, d: [f64; 3]) -> [f64; 3] {
    let c = sp.center.map(S::to_f64);
    let o3 = S::vec_to_array(ray.origin()).map(S::to_f64);
    let dir = S::ray_dir(ray.data()).map(S::to_f64);
    let t = t.to_f64();
    let q: [f64; 3] = core::array::from_fn(|k| o3[k] - d[k] + t * dir[k]);
    unit(sub(&q, &c)).unwrap_or(dir.map(|x| -x))
}

/// What object `o` emits: its emission plus its material's if that is emissive (checked
/// values: finite, non-negative; a sum past `f32::MAX` saturates).
pub(super) fn emitted_by<S: Scalar>(
    o: &Object<'_, S>,
    materials: &[Material],
) -> super::scene::Rgb {
    let e = match materials.get(o.material as usize) {
        Some(Material::Emissive { radiance }) => *radiance,
        _ => [0.0; 3],
    };
    core::array::from_fn(|k| {
        let s = o.emission[k] + e[k];
        if s > f32::MAX {
            f32::MAX
        } else {
            s
        }
    })
}

/// The unit shading normal at barycentrics `(u, w)` (weights of the second and third corner):
/// the corners' unit normals blended and normalised, turned to the side of the unit geometric
/// normal `geometric`. `None` when the corners' normals are zero or blend to zero.
fn interpolated_normal(
    corners: &[[f32; 3]; 3],
    u: f64,
    w: f64,
    geometric: &[f64; 3],
) -> Option<[f64; 3]> {
    let weights = [1.0 - u - w, u, w];
    let mut blend = [0.0f64; 3];
    for (corner, weight) in corners.iter().zip(weights) {
        if let Some(c) = unit(corner.map(f64::from)) {
            for (b, x) in blend.iter_mut().zip(c) {
                *b += weight * x;
            }
        }
    }
    let s = unit(blend)?;
    let toward = s[0] * geometric[0] + s[1] * geometric[1] + s[2] * geometric[2];
    Some(if toward < 0.0 { s.map(|x| -x) } else { s })
}

/// Vertex normals: none, or one finite triple per triangle of a triangle shape.
fn check_vertex_normals<S: Scalar>(o: &Object<'_, S>) -> Result<(), Problem> {
    if o.vertex_normals.is_empty() {
        return Ok(());
    }
    let expected = match o.shape {
        Shape::Triangles(t) => t.len(),
        Shape::Spheres(_) => 0,
    };
    if o.vertex_normals.len() != expected {
        return Err(Problem::Length { expected });
    }
    if o.vertex_normals
        .iter()
        .flatten()
        .all(|n| super::scene::finite3(*n))
    {
        Ok(())
    } else {
        Err(Problem::NonFinite)
    }
}

fn union_bounds<S: Scalar, P: Primitive<S>>(prims: &[P]) -> Option<Aabb<S>> {
    let mut it = prims.iter();
    let first = it.next()?.bounds();
    Some(it.fold(first, |b, p| b.union(&p.bounds())))
}
