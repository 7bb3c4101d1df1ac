//! Helpers shared by the kernel's host-run test suites (each suite uses a subset).
#![allow(dead_code)]

use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind, InvalidTree, TreeStats};
use raykernel::bvh8::{collapse_words_needed, wide_nodes_needed};
use raykernel::{
    grid::GridOptions, kdtree, kdtree::KdOptions, Accel, AccelKind, AnyAccel, Bvh, Bvh4, Bvh8,
    Grid, Hit, KdNode, KdTree, Node, PointError, Primitive, Ray, Scalar, WideBvh, WideNode,
    F32_COORD_LIMIT, FIXED_COORD_LIMIT, I16F16,
};
pub use raykernel_testkit::golden::Bits;
use raykernel_testkit::memory::OwnedMemory;
use std::fmt;
use std::ops::{Add, Mul, Sub};

/// Leaf sizes every differential test builds with.
pub const LEAF_SIZES: [u32; 4] = [1, 2, 4, 8];

/// What the suites need from a number mode beyond [`Scalar`]: exact bits ([`Bits`], so `-0`
/// and `+0` differ), arithmetic for computing targets in the mode itself, tolerances and
/// per-mode bad inputs.
pub trait TestScalar:
    Scalar + Bits + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
    /// Absolute tolerance for comparing a result of this mode with an `f64` reference of
    /// magnitude `exact` (the reference is computed from the same, already rounded, inputs).
    fn tol(exact: f64) -> f64;
    /// Values every vertex/origin check must reject, with the error expected for them.
    fn bad_coords() -> Vec<(Self, PointError)>;
    /// Half of `self`, rounded as the mode rounds.
    fn half(self) -> Self;
    /// The gap from `self` (positive, finite) to the next value of the mode above it.
    fn step_above(self) -> f32;
}

impl TestScalar for f32 {
    fn tol(exact: f64) -> f64 {
        1e-5 * exact.abs().max(1.0)
    }
    fn bad_coords() -> Vec<(Self, PointError)> {
        let out = PointError::OutOfRange {
            limit: F32_COORD_LIMIT,
        };
        vec![
            (f32::NAN, PointError::NonFinite),
            (-f32::NAN, PointError::NonFinite),
            (f32::INFINITY, PointError::NonFinite),
            (f32::NEG_INFINITY, PointError::NonFinite),
            (next_up(F32_COORD_LIMIT), out),
            (-next_up(F32_COORD_LIMIT), out),
            (f32::MAX, out),
        ]
    }
    fn half(self) -> Self {
        self * 0.5
    }
    fn step_above(self) -> f32 {
        next_up(self) - self
    }
}

impl TestScalar for I16F16 {
    fn tol(exact: f64) -> f64 {
        // Q16.16 coordinates and distances (resolution 2^-16), Q2.30 directions; the slab test
        // pads by 2 raw units plus one raw unit of origin shift divided by a direction component.
        16.0 / 65536.0 + 1e-5 * exact.abs()
    }
    fn bad_coords() -> Vec<(Self, PointError)> {
        let out = PointError::OutOfRange {
            limit: FIXED_COORD_LIMIT,
        };
        vec![
            (I16F16::from_raw((1 << 29) + 1), out),
            (I16F16::from_raw(-(1 << 29) - 1), out),
            (I16F16::MAX, out),
            (I16F16::MIN, out),
        ]
    }
    fn half(self) -> Self {
        // Floor; exact for even raw values.
        I16F16::from_raw(self.raw() >> 1)
    }
    fn step_above(self) -> f32 {
        I16F16::from_raw(1).to_f32()
    }
}

/// The next `f32` above a positive finite `x`.
pub fn next_up(x: f32) -> f32 {
    f32::from_bits(x.to_bits() + 1)
}

/// A mode value from an `f32` constant that must be representable in range.
pub fn c<S: Scalar>(x: f32) -> S {
    S::coord_from_f32(x).unwrap_or_else(|e| panic!("{} constant {x}: {e}", S::NAME))
}

/// A mode point from `f32` constants.
pub fn p<S: Scalar>(x: [f32; 3]) -> [S; 3] {
    x.map(c::<S>)
}

/// The exact bits of a hit (t, prim, u, v).
pub fn hit_bits<S: TestScalar>(h: &Option<Hit<S>>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.bits(), h.prim, h.u.bits(), h.v.bits()))
}

/// Compares two closest hits bit for bit; the error names both hits.
pub fn same_hit<S: TestScalar>(got: &Option<Hit<S>>, want: &Option<Hit<S>>) -> Result<(), String> {
    if hit_bits(got) == hit_bits(want) {
        Ok(())
    } else {
        Err(format!(
            "hits differ: got {got:?} (bits {:x?}), want {want:?} (bits {:x?})",
            hit_bits(got),
            hit_bits(want)
        ))
    }
}

/// A ray as given to [`Ray::from_f32`]; printed with values and bits so a failure can be
/// replayed exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaySpec {
    pub o: [f32; 3],
    pub d: [f32; 3],
    pub t_min: f32,
    pub t_max: f32,
}

impl RaySpec {
    pub fn new(o: [f32; 3], d: [f32; 3]) -> Self {
        Self {
            o,
            d,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }
    pub fn interval(self, t_min: f32, t_max: f32) -> Self {
        Self {
            t_min,
            t_max,
            ..self
        }
    }
    /// The ray in mode `S`; panics (naming the ray) if the kernel rejects it.
    pub fn ray<S: Scalar>(&self) -> Ray<S> {
        Ray::from_f32(self.o, self.d, self.t_min, self.t_max)
            .unwrap_or_else(|e| panic!("{} ray {self}: {e:?}", S::NAME))
    }
}

impl fmt::Display for RaySpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = |v: [f32; 3]| v.map(f32::to_bits);
        write!(
            f,
            "origin {:?} (bits {:#010x?}) dir {:?} (bits {:#010x?}) t [{}, {}]",
            self.o,
            b(self.o),
            self.d,
            b(self.d),
            self.t_min,
            self.t_max
        )
    }
}

/// `b - a` in `f32`, and `+z` if that is the zero vector.
pub fn dir_to(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    if d == [0.0; 3] {
        [0.0, 0.0, 1.0]
    } else {
        d
    }
}

/// Builds a BVH into freshly allocated arenas of exactly the documented size and hands it to `f`.
pub fn with_bvh<S, P, R>(
    prims: &[P],
    options: BuildOptions,
    f: impl FnOnce(&Bvh<'_, S, P>) -> R,
) -> R
where
    S: Scalar,
    P: Primitive<S>,
{
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(prims.len())];
    let mut ids = vec![0u32; prims.len()];
    let bvh = Bvh::build(prims, &mut nodes, &mut ids, options).unwrap_or_else(|e| {
        panic!(
            "{} build ({} prims, {options:?}) failed: {e}",
            S::NAME,
            prims.len()
        )
    });
    f(&bvh)
}

/// As [`with_bvh`], built with the primitives permuted into leaf order in place
/// (`Bvh::build_in_leaf_order`).
pub fn with_bvh_in_leaf_order<S, P, R>(
    prims: &mut [P],
    options: BuildOptions,
    f: impl FnOnce(&Bvh<'_, S, P>) -> R,
) -> R
where
    S: Scalar,
    P: Primitive<S> + Copy,
{
    let count = prims.len();
    let mut nodes = vec![Node::<S>::EMPTY; nodes_needed(count)];
    let mut ids = vec![0u32; count];
    let bvh = Bvh::build_in_leaf_order(prims, &mut nodes, &mut ids, options).unwrap_or_else(|e| {
        panic!(
            "{} leaf-order build ({count} prims, {options:?}) failed: {e}",
            S::NAME
        )
    });
    f(&bvh)
}

/// Collapses `bvh` into a `W`-wide BVH in an arena of exactly
/// [`wide_nodes_needed`]`(n, W)` slots (and [`collapse_words_needed`] scratch words) and hands it to `f` (validation is the caller's).
pub fn with_wide<const W: usize, S, P, R>(
    bvh: &Bvh<'_, S, P>,
    f: impl FnOnce(&WideBvh<'_, S, P, W>) -> R,
) -> R
where
    S: Scalar,
    P: Primitive<S>,
{
    let n = bvh.prims().len();
    let mut nodes = vec![WideNode::<S, W>::EMPTY; wide_nodes_needed(n, W)];
    let mut scratch = vec![0u32; collapse_words_needed(n, W)];
    let wide = WideBvh::collapse(bvh, &mut nodes, &mut scratch).unwrap_or_else(|e| {
        panic!(
            "{} {W}-wide collapse ({} prims) failed: {e}",
            S::NAME,
            bvh.prims().len()
        )
    });
    f(&wide)
}

/// A wide BVH of either width, so a test is written once over the width: the kernel writes
/// `validate` per width (each with its traversal's stack bound), and this trait reaches it.
/// Generic tests ask for it as `for<'a> WideBvh<'a, S, P, W>: WideTree<S>`.
pub trait WideTree<S: Scalar>: Accel<S> {
    /// `bvh4` or `bvh8`, for messages.
    const NAME: &'static str;
    /// [`Bvh4::validate`] or [`Bvh8::validate`].
    fn check(&self) -> Result<TreeStats, InvalidTree>;
}

impl<S: Scalar, P: Primitive<S>> WideTree<S> for Bvh4<'_, S, P> {
    const NAME: &'static str = "bvh4";
    fn check(&self) -> Result<TreeStats, InvalidTree> {
        self.validate()
    }
}

impl<S: Scalar, P: Primitive<S>> WideTree<S> for Bvh8<'_, S, P> {
    const NAME: &'static str = "bvh8";
    fn check(&self) -> Result<TreeStats, InvalidTree> {
        self.validate()
    }
}

/// Grid densities the differential tests build with: coarse, the default, fine.
pub const GRID_DENSITIES: [f32; 3] = [0.25, raykernel::grid::DEFAULT_DENSITY, 8.0];
/// Kd-tree depth limits the differential tests build with (0 = the automatic rule).
pub const KD_DEPTHS: [u32; 3] = [0, 3, kdtree::MAX_DEPTH];

/// Builds a uniform grid into arenas of exactly the size the counting pass reports, checks
/// `validate()`, and hands it to `f`.
pub fn with_grid<S, P, R>(
    prims: &[P],
    options: GridOptions,
    f: impl FnOnce(&Grid<'_, S, P>) -> R,
) -> R
where
    S: Scalar,
    P: Primitive<S>,
{
    let size = Grid::size_for(prims, options).unwrap_or_else(|e| {
        panic!(
            "{} grid size ({} prims, {options:?}): {e}",
            S::NAME,
            prims.len()
        )
    });
    let mut cells = vec![0u32; size.cells];
    let mut refs = vec![0u32; size.refs];
    let grid = Grid::build(prims, &mut cells, &mut refs, options).unwrap_or_else(|e| {
        panic!(
            "{} grid build ({} prims, {options:?}): {e}",
            S::NAME,
            prims.len()
        )
    });
    grid.validate()
        .unwrap_or_else(|e| panic!("{} grid ({options:?}): {e}", S::NAME));
    assert_eq!(grid.refs().len(), size.refs, "counting pass must be exact");
    f(&grid)
}

/// Builds a kd-tree into arenas of exactly the documented budgets, checks `validate()`, and
/// hands it to `f`.
pub fn with_kdtree<S, P, R>(
    prims: &[P],
    options: KdOptions,
    f: impl FnOnce(&KdTree<'_, S, P>) -> R,
) -> R
where
    S: Scalar,
    P: Primitive<S>,
{
    let mut nodes = vec![KdNode::<S>::EMPTY; kdtree::nodes_needed(prims.len())];
    let mut refs = vec![0u32; kdtree::refs_needed(prims.len())];
    let tree = KdTree::build(prims, &mut nodes, &mut refs, options).unwrap_or_else(|e| {
        panic!(
            "{} kd-tree build ({} prims, {options:?}): {e}",
            S::NAME,
            prims.len()
        )
    });
    let stats = tree
        .validate()
        .unwrap_or_else(|e| panic!("{} kd-tree ({options:?}): {e}", S::NAME));
    if options.max_depth > 0 {
        assert!(
            stats.depth <= options.max_depth as usize,
            "{} kd-tree too deep",
            S::NAME
        );
    }
    f(&tree)
}

/// Builds `kind` over `prims` through [`AnyAccel::build`] into exactly
/// [`AccelKind::memory_needed`], checks `validate()` (and a kd-tree's depth limit), and hands
/// it to `f`.
pub fn with_accel<S, P, R>(
    kind: AccelKind,
    prims: &[P],
    f: impl FnOnce(&AnyAccel<'_, S, P>) -> R,
) -> R
where
    S: Scalar,
    P: Primitive<S>,
{
    let mut arena = OwnedMemory::<S>::for_kind(kind, prims);
    let accel = AnyAccel::build(kind, prims, &mut arena.memory())
        .unwrap_or_else(|e| panic!("{} build {kind} ({} prims): {e}", S::NAME, prims.len()));
    accel
        .validate()
        .unwrap_or_else(|e| panic!("{} {kind}: {e}", S::NAME));
    if let AccelKind::KdTree(o) = kind {
        assert!(
            o.max_depth == 0 || accel.depth() <= o.max_depth,
            "{} {kind} too deep",
            S::NAME
        );
    }
    f(&accel)
}

/// Every (builder, leaf size) combination the differential tests cover, each with
/// reinsertion, plus SAH without it.
pub fn all_options() -> impl Iterator<Item = BuildOptions> {
    let with = BuilderKind::ALL.map(|builder| (builder, true));
    let kinds = with.into_iter().chain([(BuilderKind::Sah, false)]);
    kinds.flat_map(|(builder, reinsertion)| {
        LEAF_SIZES
            .into_iter()
            .map(move |max_leaf_size| BuildOptions {
                builder,
                max_leaf_size,
                reinsertion,
            })
    })
}

/// Closest hit of `accel`, plus a check that its any-hit query agrees.
pub fn query<S: TestScalar, A: Accel<S>>(
    accel: &A,
    ray: &Ray<S>,
) -> Result<Option<Hit<S>>, String> {
    let hit = accel.intersect(ray);
    let occluded = accel.occluded(ray);
    if occluded != hit.is_some() {
        return Err(format!("occluded() = {occluded} but intersect() = {hit:?}"));
    }
    // `nearest` is `intersect` without barycentrics: the same t bits and primitive.
    let nearest = accel.nearest(ray).map(|n| (n.t.bits(), n.prim));
    if nearest != hit.map(|h| (h.t.bits(), h.prim)) {
        return Err(format!("nearest() = {nearest:?} but intersect() = {hit:?}"));
    }
    Ok(hit)
}

/// Renders `scene` whole into linear RGB (row-major) with the default accelerator, memory
/// sized by [`raykernel::render::memory_needed`].
pub fn render_linear<S: raykernel::Scalar>(
    scene: &raykernel::render::Scene<'_, S>,
    settings: raykernel::render::Settings,
) -> Result<Vec<[f32; 3]>, raykernel::render::SceneError> {
    use raykernel::render::{memory_needed, ObjectSlot, RenderMemory, Renderer, Tile};
    let accel = AccelKind::default();
    let n = memory_needed::<S, raykernel::AnyFamily>(scene.objects, &accel);
    let mut objects = vec![ObjectSlot::<S>::EMPTY; n.objects];
    let mut owned = OwnedMemory::<S>::sized(n.accel);
    let memory = RenderMemory {
        objects: &mut objects,
        accel: owned.memory(),
    };
    let r = Renderer::new(scene, settings, accel, memory)?;
    let (width, height) = (settings.width, settings.height);
    let mut out = vec![[0.0f32; 3]; (width * height) as usize];
    let tile = Tile {
        x: 0,
        y: 0,
        width,
        height,
    };
    r.render_tile(tile, &mut out)?;
    Ok(out)
}
