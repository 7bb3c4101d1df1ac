//! The renderer's view of the scene's geometry: one accelerator per object, moving objects
//! behind a swept box, visible area lights, and the rules for leaving a surface.
//!
//! Primitive ids are global: the objects' primitives in scene order, then one id per light, so
//! the closest-hit tie rule (lowest id) orders objects as well as primitives.
//!
//! Motion: an object moving by `motion` over the shutter sits at `+ s·motion` at shutter time
//! `s`. A ray at time `s` meets it by moving the ray into the object's frame: origin minus the
//! displacement `d(s) = round(s·motion)` (rounded once to the mode; in fixed point the shift is
//! exact). Before that, the unshifted ray must enter the object's swept box, the union of its
//! box at `s = 0` and at `s = 1`, padded by `2^-20` of the motion's largest component (in `f32`,
//! this covers the rounding of the shifted origin; the slab test's own margin covers the
//! origin's share).

use super::scene::{Object, Shape};
use super::{AccelChoice, SceneError};
use crate::accel::bvh::{self, Bvh, Node};
use crate::accel::grid::Grid;
use crate::accel::kdtree::{self, KdNode, KdTree};
use crate::accel::BuildError;
use crate::accel::{Accel, Counters, Linear, Nearest};
use crate::geom::spawn::{self, cross, sub, unit, SpawnScalar, MAX_NUDGES};
use crate::geom::{closer, Aabb, Primitive, Ray, Sphere, Triangle};
use crate::render::scene::{Item, Light, Problem};
use crate::scalar::Scalar;

/// Spheres leave their surface this many times the triangle rule's offset (the sphere test
/// solves a quadratic: its roots near the surface carry more rounding than a plane's).
pub const SPHERE_SPAWN_FACTOR: f64 = 8.0;

/// Most lights a scene may have.
pub const MAX_LIGHTS: usize = 8;

/// One object's accelerator.
#[derive(Clone, Copy, Debug)]
enum Index<'a, S: Scalar, P: Primitive<S>> {
    Linear(Linear<'a, S, P>),
    Bvh(Bvh<'a, S, P>),
    Grid(Grid<'a, S, P>),
    KdTree(KdTree<'a, S, P>),
}

impl<S: Scalar, P: Primitive<S>> Index<'_, S, P> {
    #[inline]
    fn nearest<C: Counters>(&self, ray: &Ray<S>, c: &mut C) -> Option<Nearest<S>> {
        match self {
            Self::Linear(a) => a.nearest_counted(ray, c),
            Self::Bvh(a) => a.nearest_counted(ray, c),
            Self::Grid(a) => a.nearest_counted(ray, c),
            Self::KdTree(a) => a.nearest_counted(ray, c),
        }
    }
    #[inline]
    fn occluded<C: Counters>(&self, ray: &Ray<S>, c: &mut C) -> bool {
        match self {
            Self::Linear(a) => a.occluded_counted(ray, c),
            Self::Bvh(a) => a.occluded_counted(ray, c),
            Self::Grid(a) => a.occluded_counted(ray, c),
            Self::KdTree(a) => a.occluded_counted(ray, c),
        }
    }
}

/// The caller's memory for the renderer's accelerators: one buffer per element type, each at
/// least as long as [`memory_needed`] gives for the chosen [`AccelChoice`] (longer is fine).
/// Objects take their share from the front, in scene order.
#[derive(Debug)]
pub struct AccelMemory<'a, S: Scalar> {
    /// One slot per object (every [`AccelChoice`], brute force included).
    pub objects: &'a mut [ObjectSlot<'a, S>],
    /// BVH nodes ([`AccelChoice::Bvh`]).
    pub bvh_nodes: &'a mut [Node<S>],
    /// Kd-tree nodes ([`AccelChoice::KdTree`]).
    pub kd_nodes: &'a mut [KdNode<S>],
    /// Index words: BVH primitive ids, grid cell offsets and references, kd-tree references.
    pub words: &'a mut [u32],
}

impl<S: Scalar> Default for AccelMemory<'_, S> {
    /// No memory at all: enough for a scene without objects.
    fn default() -> Self {
        Self {
            objects: &mut [],
            bvh_nodes: &mut [],
            kd_nodes: &mut [],
            words: &mut [],
        }
    }
}

/// Buffer lengths (elements, not bytes) a scene needs for an [`AccelChoice`]: the sums over
/// its objects.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryNeeded {
    /// Length of [`AccelMemory::objects`]: the scene's object count.
    pub objects: usize,
    /// Length of [`AccelMemory::bvh_nodes`].
    pub bvh_nodes: usize,
    /// Length of [`AccelMemory::kd_nodes`].
    pub kd_nodes: usize,
    /// Length of [`AccelMemory::words`].
    pub words: usize,
}

impl MemoryNeeded {
    /// The total in bytes for mode `S`.
    #[must_use]
    pub const fn bytes<S: Scalar>(&self) -> usize {
        self.objects
            .saturating_mul(core::mem::size_of::<ObjectSlot<'_, S>>())
            .saturating_add(
                self.bvh_nodes
                    .saturating_mul(core::mem::size_of::<Node<S>>()),
            )
            .saturating_add(
                self.kd_nodes
                    .saturating_mul(core::mem::size_of::<KdNode<S>>()),
            )
            .saturating_add(self.words.saturating_mul(4))
    }

    fn add(self, o: Self) -> Self {
        Self {
            objects: self.objects.saturating_add(o.objects),
            bvh_nodes: self.bvh_nodes.saturating_add(o.bvh_nodes),
            kd_nodes: self.kd_nodes.saturating_add(o.kd_nodes),
            words: self.words.saturating_add(o.words),
        }
    }
}

/// What one object's primitives need. A grid the counting pass rejects needs nothing here:
/// its build reports the error.
fn needed_for<S: Scalar, P: Primitive<S>>(prims: &[P], choice: AccelChoice) -> MemoryNeeded {
    let n = prims.len();
    let none = MemoryNeeded {
        objects: 1,
        ..MemoryNeeded::default()
    };
    match choice {
        AccelChoice::Linear => none,
        AccelChoice::Bvh(_) => MemoryNeeded {
            bvh_nodes: bvh::nodes_needed(n),
            words: n,
            ..none
        },
        AccelChoice::Grid(options) => {
            Grid::<S, P>::size_for(prims, options).map_or(none, |g| MemoryNeeded {
                words: g.cells.saturating_add(g.refs),
                ..none
            })
        }
        AccelChoice::KdTree(_) => MemoryNeeded {
            kd_nodes: kdtree::nodes_needed(n),
            words: kdtree::refs_needed(n),
            ..none
        },
    }
}

/// Takes the first `n` slots of a buffer, leaving the rest in place.
fn take<'a, T>(buf: &mut &'a mut [T], n: usize) -> &'a mut [T] {
    let all = core::mem::take(buf);
    let n = n.min(all.len());
    let (mine, rest) = all.split_at_mut(n);
    *buf = rest;
    mine
}

/// Builds one object's accelerator. Never inlined: the builders' working memory (BVH bins and
/// pending nodes, about 6 KB) then sits on the stack once, not once per primitive type.
#[inline(never)]
fn build_index<'a, S: Scalar, P: Primitive<S>>(
    prims: &'a [P],
    choice: AccelChoice,
    memory: &mut AccelMemory<'a, S>,
) -> Result<Index<'a, S, P>, BuildError> {
    match choice {
        AccelChoice::Linear => {
            for (i, p) in prims.iter().enumerate() {
                p.check()
                    .map_err(|(vertex, error)| BuildError::BadPrimitive {
                        prim: i,
                        vertex,
                        error,
                    })?;
            }
            Ok(Index::Linear(Linear::new(prims)))
        }
        AccelChoice::Bvh(options) => {
            let nodes = take(&mut memory.bvh_nodes, bvh::nodes_needed(prims.len()));
            let ids = take(&mut memory.words, prims.len());
            Ok(Index::Bvh(Bvh::build(prims, nodes, ids, options)?))
        }
        AccelChoice::Grid(options) => {
            let size = Grid::<S, P>::size_for(prims, options)?;
            let cells = take(&mut memory.words, size.cells);
            let refs = take(&mut memory.words, size.refs);
            Ok(Index::Grid(Grid::build(prims, cells, refs, options)?))
        }
        AccelChoice::KdTree(options) => {
            let nodes = take(&mut memory.kd_nodes, kdtree::nodes_needed(prims.len()));
            let refs = take(&mut memory.words, kdtree::refs_needed(prims.len()));
            Ok(Index::KdTree(KdTree::build(prims, nodes, refs, options)?))
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum ShapeIndex<'a, S: Scalar> {
    Triangles(Index<'a, S, Triangle<S>>),
    Spheres(Index<'a, S, Sphere<S>>),
}

impl<S: Scalar> ShapeIndex<'_, S> {
    #[inline]
    fn nearest<C: Counters>(&self, ray: &Ray<S>, c: &mut C) -> Option<Nearest<S>> {
        match self {
            Self::Triangles(a) => a.nearest(ray, c),
            Self::Spheres(a) => a.nearest(ray, c),
        }
    }
    #[inline]
    fn occluded<C: Counters>(&self, ray: &Ray<S>, c: &mut C) -> bool {
        match self {
            Self::Triangles(a) => a.occluded(ray, c),
            Self::Spheres(a) => a.occluded(ray, c),
        }
    }
}

/// Room for one object's built accelerator and placement in the caller's memory
/// ([`AccelMemory::objects`], one slot per object, filled by the renderer). Opaque: make
/// arrays of [`ObjectSlot::EMPTY`].
#[derive(Clone, Copy, Debug)]
pub struct ObjectSlot<'a, S: Scalar>(ObjectGeom<'a, S>);

impl<S: Scalar> ObjectSlot<'_, S> {
    /// An unused slot.
    pub const EMPTY: Self = Self(ObjectGeom {
        index: ShapeIndex::Triangles(Index::Linear(Linear::new(&[]))),
        shape: Shape::Triangles(&[]),
        base: 0,
        material: 0,
        motion: None,
        swept: Aabb::new([S::ZERO; 3], [S::ZERO; 3]),
    });
}

/// An object ready for queries.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ObjectGeom<'a, S: Scalar> {
    index: ShapeIndex<'a, S>,
    shape: Shape<'a, S>,
    /// Global id of the object's first primitive.
    base: u32,
    /// Material index (checked).
    pub(crate) material: u32,
    /// Motion over the shutter, `None` when static.
    motion: Option<[f32; 3]>,
    /// World box over the whole shutter interval (moving objects only).
    swept: Aabb<S>,
}

/// A light's visible surface.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LightGeom<S: Scalar> {
    /// Not visible.
    Point,
    /// Two triangles; the front side is the side `edge_u × edge_v` points to.
    Rect([Triangle<S>; 2], [f32; 3]),
    /// A sphere.
    Sphere(Sphere<S>),
}

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

/// Every object and light of a scene, ready for queries at a shutter time.
#[derive(Clone, Debug)]
pub(crate) struct Geometry<'a, S: Scalar> {
    /// One filled slot per object, in scene order.
    objects: &'a [ObjectSlot<'a, S>],
    pub(crate) lights: heapless::Vec<LightGeom<S>, MAX_LIGHTS>,
    /// Global id of the first light.
    light_base: u32,
}

/// Buffer lengths a scene's objects need with `choice` (all zero for `Linear`).
#[must_use]
pub fn memory_needed<S: Scalar>(objects: &[Object<'_, S>], choice: AccelChoice) -> MemoryNeeded {
    objects.iter().fold(MemoryNeeded::default(), |sum, o| {
        sum.add(match o.shape {
            Shape::Triangles(t) => needed_for(t, choice),
            Shape::Spheres(s) => needed_for(s, choice),
        })
    })
}

/// `+ d` in the mode, rounded once.
fn shifted<S: SpawnScalar>(p: [S; 3], d: [f64; 3], sign: f64) -> [S; 3] {
    S::point_from_f64(core::array::from_fn(|k| p[k].to_f64() + sign * d[k]))
}

impl<'a, S: SpawnScalar> Geometry<'a, S> {
    /// Builds every object's accelerator into the caller's memory ([`memory_needed`]).
    pub(crate) fn build(
        objects: &'a [Object<'a, S>],
        lights: &[Light],
        choice: AccelChoice,
        mut memory: AccelMemory<'a, S>,
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
        let need = memory_needed(objects, choice);
        for (field, needed, available) in [
            ("objects", need.objects, memory.objects.len()),
            ("bvh_nodes", need.bvh_nodes, memory.bvh_nodes.len()),
            ("kd_nodes", need.kd_nodes, memory.kd_nodes.len()),
            ("words", need.words, memory.words.len()),
        ] {
            if available < needed {
                return Err(err(0, field, Problem::TooSmall { needed, available }));
            }
        }
        let slots = take(&mut memory.objects, objects.len());
        let mut base = 0u32;
        for (i, (o, slot)) in objects.iter().zip(slots.iter_mut()).enumerate() {
            let bad = |e| err(i, "shape", Problem::Build(e));
            if !super::scene::finite3(o.motion) {
                return Err(err(i, "motion", Problem::NonFinite));
            }
            let (index, bounds) = match o.shape {
                Shape::Triangles(t) => (
                    ShapeIndex::Triangles(build_index(t, choice, &mut memory).map_err(bad)?),
                    union_bounds(t),
                ),
                Shape::Spheres(s) => (
                    ShapeIndex::Spheres(build_index(s, choice, &mut memory).map_err(bad)?),
                    union_bounds(s),
                ),
            };
            let motion = o.moves().then_some(o.motion);
            let swept = match (motion, bounds) {
                (Some(m), Some(b)) => swept_box(&b, m),
                (_, b) => b.unwrap_or(Aabb::new([S::ZERO; 3], [S::ZERO; 3])),
            };
            let len = u32::try_from(o.shape.len()).unwrap_or(u32::MAX);
            let g = ObjectGeom {
                index,
                shape: o.shape,
                base,
                material: o.material,
                motion,
                swept,
            };
            *slot = ObjectSlot(g);
            base = base.checked_add(len).ok_or(err(
                i,
                "shape",
                Problem::Build(BuildError::TooManyPrims {
                    count: o.shape.len(),
                }),
            ))?;
        }
        let mut geo = Self {
            objects: slots,
            lights: heapless::Vec::new(),
            light_base: base,
        };
        for (i, l) in lights.iter().enumerate() {
            let _ = geo.lights.push(
                light_geom(l)
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
        o: &ObjectGeom<'a, S>,
        ray: &Ray<S>,
        time: f32,
        c: &mut C,
        query: impl FnOnce(&ShapeIndex<'a, S>, &Ray<S>, &mut C) -> R,
    ) -> Option<R> {
        let Some(m) = o.motion else {
            return Some(query(&o.index, ray, c));
        };
        c.node();
        o.swept.slab(ray)?;
        let moved = moved_into_frame::<S>(m, ray, time)?;
        Some(query(&o.index, &moved, c))
    }

    /// The objects, in scene order.
    #[inline]
    pub(crate) fn objects(&self) -> impl Iterator<Item = &ObjectGeom<'a, S>> {
        self.objects.iter().map(|s| &s.0)
    }

    /// Object `i`.
    #[inline]
    pub(crate) fn object(&self, i: usize) -> Option<&ObjectGeom<'a, S>> {
        self.objects.get(i).map(|s| &s.0)
    }

    /// Closest hit at shutter time `time`; ties to the lowest global id.
    #[cfg_attr(not(target_os = "none"), inline(always))]
    pub(crate) fn intersect<C: Counters>(
        &self,
        ray: &Ray<S>,
        time: f32,
        c: &mut C,
    ) -> Option<SceneHit<S>> {
        let mut best: Option<SceneHit<S>> = None;
        let mut best_t = ray.t_max();
        let mut shortened: Ray<S>;
        for (i, o) in self.objects().enumerate() {
            // The ray itself until something is hit (copying a just-built ray stalls on store
            // forwarding, measurably per camera ray), then a copy ending at the closest hit.
            let r = if best.is_none() {
                ray
            } else {
                let Ok(r) = ray.with_interval(ray.t_min(), best_t) else {
                    continue;
                };
                shortened = r;
                &shortened
            };
            let h = Self::query_object(o, r, time, c, ShapeIndex::nearest).flatten();
            if let Some(h) = h {
                let id = o.base.saturating_add(h.prim);
                if best.is_none_or(|b| closer(h.t, id, best_t, b.prim)) {
                    best_t = h.t;
                    best = Some(SceneHit {
                        t: h.t,
                        prim: id,
                        surface: Surface::Object {
                            object: i,
                            local: h.prim,
                        },
                    });
                }
            }
        }
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

    /// Any object hit in the ray's interval at shutter time `time` (lights cast no shadow).
    pub(crate) fn occluded<C: Counters>(&self, ray: &Ray<S>, time: f32, c: &mut C) -> bool {
        self.objects()
            .any(|o| Self::query_object(o, ray, time, c, ShapeIndex::occluded) == Some(true))
    }

    /// The point a hit lies on: world position, unit geometric normal (not yet facing the
    /// ray), and what [`SurfacePoint::spawn_origin`] needs to leave it. `None` for lights.
    pub(crate) fn surface_point(
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
                let (hu, hv) = match o.motion {
                    None => tri.hit_uv(ray.data()),
                    Some(m) => tri.hit_uv(moved_into_frame::<S>(m, ray, time)?.data()),
                };
                let v = tri.v.map(|p| p.map(S::to_f64));
                let (u, w) = (hu.to_f64(), hv.to_f64());
                let p: [f64; 3] = core::array::from_fn(|k| {
                    v[0][k] + u * (v[1][k] - v[0][k]) + w * (v[2][k] - v[0][k]) + d[k]
                });
                let n = unit(cross(&sub(&v[1], &v[0]), &sub(&v[2], &v[0])))
                    .unwrap_or_else(|| S::ray_dir(ray.data()).map(|x| -x.to_f64()));
                Some(SurfacePoint {
                    position: p,
                    normal: n.map(|x| x as f32),
                    prim: Prim::Triangle(tri, hu, hv),
                    shift: d,
                })
            }
            Shape::Spheres(s) => {
                let sp = s.get(local as usize)?;
                let c = sp.center.map(S::to_f64);
                // The hit point from the ray in the object's frame, then shifted back.
                let o3 = S::vec_to_array(ray.origin()).map(S::to_f64);
                let dir = S::ray_dir(ray.data()).map(S::to_f64);
                let t = h.t.to_f64();
                let q: [f64; 3] = core::array::from_fn(|k| o3[k] - d[k] + t * dir[k]);
                let n = unit(sub(&q, &c)).unwrap_or(dir.map(|x| -x));
                let r = sp.radius.to_f64();
                // The point on the sphere along the normal: the offset is taken from there.
                let p: [f64; 3] = core::array::from_fn(|k| c[k] + r * n[k] + d[k]);
                Some(SurfacePoint {
                    position: p,
                    normal: n.map(|x| x as f32),
                    prim: Prim::Sphere(sp),
                    shift: d,
                })
            }
        }
    }
}

/// `ray` moved into the frame of an object moving by `motion`, at shutter time `time`: origin
/// minus the displacement. `None` if the moved origin leaves the mode's range.
fn moved_into_frame<S: SpawnScalar>(motion: [f32; 3], ray: &Ray<S>, time: f32) -> Option<Ray<S>> {
    let origin = shifted(
        S::vec_to_array(ray.origin()),
        displacement::<S>(motion, time),
        -1.0,
    );
    ray.moved(origin).ok()
}

/// `round(time·motion)` in the mode, as `f64` (exact).
fn displacement<S: SpawnScalar>(m: [f32; 3], time: f32) -> [f64; 3] {
    let d = S::point_from_f64(m.map(|x| f64::from(x) * f64::from(time)));
    d.map(S::to_f64)
}

/// The primitive a surface point lies on (in its object's frame at shutter open).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim<'a, S: Scalar> {
    Triangle(&'a Triangle<S>, S, S),
    Sphere(&'a Sphere<S>),
}

/// A point on a surface, and how to leave it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfacePoint<'a, S: Scalar> {
    /// World position (`f64`).
    pub(crate) position: [f64; 3],
    /// Unit geometric normal (triangles: `(v1−v0)×(v2−v0)`; spheres: outward).
    pub(crate) normal: [f32; 3],
    prim: Prim<'a, S>,
    /// The object's displacement at the ray's time (zero when static).
    shift: [f64; 3],
}

impl<S: SpawnScalar> SurfacePoint<'_, S> {
    /// An origin for a ray leaving the surface towards `toward` (any length), off the surface
    /// on `toward`'s side by the spawn rule of [`crate::spawn`], checked in the object's frame
    /// after the motion shift (so the object's own test sees it on the right side).
    pub(crate) fn spawn_origin(&self, toward: [f32; 3]) -> [S; 3] {
        let dir_s = dir_in_mode::<S>(toward);
        match self.prim {
            Prim::Triangle(tri, u, v) => {
                let local = spawn::offset_origin(tri, u, v, dir_s);
                if self.shift == [0.0; 3] {
                    return local;
                }
                let want = S::side(&tri.v, &local);
                let mut world = shifted(local, self.shift, 1.0);
                if want == 0 {
                    return world;
                }
                let n = self.normal;
                let axis = dominant(n);
                let up = (n[axis] > 0.0) == (want > 0);
                for _ in 0..MAX_NUDGES {
                    if S::side(&tri.v, &shifted(world, self.shift, -1.0)) == want {
                        break;
                    }
                    world[axis] = S::step(world[axis], up);
                }
                world
            }
            Prim::Sphere(sp) => {
                let n = self.normal.map(f64::from);
                let t = toward.map(f64::from);
                let outside = n[0] * t[0] + n[1] * t[1] + n[2] * t[2] >= 0.0;
                let c = sp.center.map(S::to_f64);
                let r = sp.radius.to_f64();
                let m = c.iter().fold(r, |m, x| libm::fmax(m, libm::fabs(*x) + r));
                let delta = SPHERE_SPAWN_FACTOR * S::offset(m);
                let s = if outside { 1.0 } else { -1.0 };
                let local: [f64; 3] = core::array::from_fn(|k| c[k] + (r + s * delta) * n[k]);
                let mut world = shifted(S::point_from_f64(local), self.shift, 1.0);
                let axis = dominant(self.normal);
                let up = (n[axis] > 0.0) == outside;
                for _ in 0..MAX_NUDGES {
                    let q = shifted(world, self.shift, -1.0).map(S::to_f64);
                    let dq = sub(&q, &c);
                    let dist2 = dq[0] * dq[0] + dq[1] * dq[1] + dq[2] * dq[2];
                    if (dist2 > r * r) == outside && dist2 != r * r {
                        break;
                    }
                    world[axis] = S::step(world[axis], up);
                }
                world
            }
        }
    }
}

/// A direction in the mode, scaled by 1024 so fixed point keeps its precision (ray
/// constructors normalise; the scale is a power of two, exact in `f32`).
pub(crate) fn dir_in_mode<S: Scalar>(d: [f32; 3]) -> S::Vec3 {
    S::array_to_vec(d.map(|x| S::from_f32_saturating(x * 1024.0)))
}

fn dominant(n: [f32; 3]) -> usize {
    let a = n.map(libm::fabsf);
    if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    }
}

fn union_bounds<S: Scalar, P: Primitive<S>>(prims: &[P]) -> Option<Aabb<S>> {
    let mut it = prims.iter();
    let first = it.next()?.bounds();
    Some(it.fold(first, |b, p| b.union(&p.bounds())))
}

/// The box over the whole shutter, padded as the module docs state.
fn swept_box<S: SpawnScalar>(b: &Aabb<S>, m: [f32; 3]) -> Aabb<S> {
    let d = displacement::<S>(m, 1.0);
    let pad = m
        .iter()
        .fold(0.0f64, |a, x| libm::fmax(a, libm::fabs(f64::from(*x))))
        / 1_048_576.0;
    let lo: [f64; 3] = core::array::from_fn(|k| {
        let x = b.lo[k].to_f64();
        libm::fmin(x, x + d[k]) - pad
    });
    let hi: [f64; 3] = core::array::from_fn(|k| {
        let x = b.hi[k].to_f64();
        libm::fmax(x, x + d[k]) + pad
    });
    // Round outward: one unit past the nearest value.
    let lo = S::point_from_f64(lo).map(|x| S::step(x, false));
    let hi = S::point_from_f64(hi).map(|x| S::step(x, true));
    let (lo, hi) = S::pad_bounds(lo, hi);
    Aabb::new(lo, hi)
}

fn light_geom<S: Scalar>(l: &Light) -> Result<LightGeom<S>, (&'static str, Problem)> {
    let pt = |p: [f32; 3], field| -> Result<[S; 3], (&'static str, Problem)> {
        let mut out = [S::ZERO; 3];
        for k in 0..3 {
            out[k] = S::coord_from_f32(p[k]).map_err(|e| (field, point_problem(e)))?;
        }
        Ok(out)
    };
    match *l {
        Light::Point {
            position,
            intensity,
        } => {
            pt(position, "position")?;
            super::scene::check_rgb(intensity, false).map_err(|p| ("intensity", p))?;
            Ok(LightGeom::Point)
        }
        Light::Rect {
            corner,
            edge_u,
            edge_v,
            radiance,
        } => {
            super::scene::check_rgb(radiance, false).map_err(|p| ("radiance", p))?;
            if !super::scene::finite3(edge_u) {
                return Err(("edge_u", Problem::NonFinite));
            }
            if !super::scene::finite3(edge_v) {
                return Err(("edge_v", Problem::NonFinite));
            }
            let n = cross(&edge_u.map(f64::from), &edge_v.map(f64::from));
            let Some(n) = unit(n) else {
                return Err(("edge_v", Problem::ZeroArea));
            };
            let add = |a: [f32; 3], b: [f32; 3]| core::array::from_fn(|k| a[k] + b[k]);
            let a = pt(corner, "corner")?;
            let b = pt(add(corner, edge_u), "edge_u")?;
            let c = pt(add(add(corner, edge_u), edge_v), "edge_v")?;
            let d = pt(add(corner, edge_v), "edge_v")?;
            Ok(LightGeom::Rect(
                [Triangle { v: [a, b, c] }, Triangle { v: [a, c, d] }],
                n.map(|x| x as f32),
            ))
        }
        Light::Sphere {
            center,
            radius,
            radiance,
        } => {
            super::scene::check_rgb(radiance, false).map_err(|p| ("radiance", p))?;
            if !radius.is_finite() {
                return Err(("radius", Problem::NonFinite));
            }
            if radius <= 0.0 {
                return Err(("radius", Problem::NotPositive));
            }
            let c = pt(center, "center")?;
            let r = S::coord_from_f32(radius).map_err(|e| ("radius", point_problem(e)))?;
            let s = Sphere {
                center: c,
                radius: r,
            };
            s.check().map_err(|(_, e)| ("radius", point_problem(e)))?;
            Ok(LightGeom::Sphere(s))
        }
    }
}

pub(crate) fn point_problem(e: crate::scalar::PointError) -> Problem {
    match e {
        crate::scalar::PointError::NonFinite => Problem::NonFinite,
        crate::scalar::PointError::OutOfRange { limit } => Problem::OutOfRange {
            min: -limit,
            max: limit,
        },
        crate::scalar::PointError::NegativeRadius => Problem::Negative,
    }
}
