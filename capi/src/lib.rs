//! C interface to raykernel: size the memory, build into it (or load baked bytes in place),
//! refit after motion, and query closest and any hit, in `f32` or fixed point, on a binary or
//! 4-wide BVH; and render a scene tile by tile (`render.rs`). No allocation and no global state:
//! every structure lives in memory the caller passes, and an [`RkAccel`] or [`RkRenderer`] is a
//! plain value the caller keeps (it holds pointers into that memory, which must outlive it and
//! not move).
//!
//! The header `include/raykernel.h` is generated from this file by cbindgen (the test
//! `header.rs` checks the committed one matches). Every function checks its pointers for
//! null and returns an [`RkStatus`]; [`rk_status_name`] names each one.
#![cfg_attr(target_os = "none", no_std)]
#![deny(unsafe_op_in_unsafe_fn)]
#![allow(clippy::missing_safety_doc)] // every `# Safety` is the same contract, stated once below

mod render;

pub use render::*;

use core::ffi::{c_char, c_void};
use core::mem::{align_of, size_of};
use raykernel::baked::{read_header, BakedMode, BakedScalar};
use raykernel::bvh::{nodes_needed, BuildOptions, TreeShape, MAX_LEAF_SIZE};
use raykernel::bvh4::{collapse_words_needed, nodes4_needed};
use raykernel::{
    Accel, BakeError, Baked, Bvh, Bvh4, Hit, Node, Node4, Primitive, Ray, Scalar, Triangle, I16F16,
};

/// What a call did. `RK_STATUS_OK` is 0; every other value is an error that changed nothing the
/// caller can observe, except as documented per function.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RkStatus {
    /// Success.
    Ok = 0,
    /// A required pointer is null.
    ErrNull = 1,
    /// An unknown mode, kind or leaf size (or, in a scene, shape, material or light kind,
    /// sampler or filter).
    ErrBadArgument = 2,
    /// The memory passed is smaller than `rk_build_bytes` (or `rk_render_bytes`) says.
    ErrMemoryTooSmall = 3,
    /// A vertex is non-finite or outside the mode's coordinate range.
    ErrBadTriangle = 4,
    /// Baked bytes: not a baked file, unknown version, a bad header field, wrong length or
    /// checksum.
    ErrBadFile = 5,
    /// Baked bytes do not start at a multiple of `rk_baked_align()` bytes, or a scene array is
    /// not aligned for its type.
    ErrMisaligned = 6,
    /// Baked bytes: the tree or its triangles are invalid.
    ErrBadTree = 7,
    /// The ray's origin, direction or interval is unusable.
    ErrBadRay = 8,
    /// `rk_refit` on a baked (read-only) structure, or with another triangle count.
    ErrNotRefittable = 9,
    /// The `RkAccel` was not filled by `rk_build` or `rk_load_baked` (or the `RkRenderer` by
    /// `rk_renderer_init`).
    ErrNotInitialised = 10,
    /// Too many triangles (or objects) for the kernel, or sizes beyond the address space.
    ErrTooLarge = 11,
    /// A sphere's centre is non-finite or outside the mode's range, or its radius is negative.
    ErrBadSphere = 12,
    /// A scene value is NaN or infinite (`RkSceneError` says which).
    ErrNonFinite = 13,
    /// A scene value is negative.
    ErrNegative = 14,
    /// A reflectance is above 1.
    ErrAboveOne = 15,
    /// A scene value (size, spp, radius, distance) must be greater than zero.
    ErrNotPositive = 16,
    /// A scene value is outside its range (`RkSceneError::min`, `max`).
    ErrOutOfRange = 17,
    /// A rectangle light's edges span no area.
    ErrZeroArea = 18,
    /// A zero-length direction, or the camera's up parallel to its view.
    ErrDegenerate = 19,
    /// An object's material index is past the materials.
    ErrBadIndex = 20,
    /// More lights than `RK_MAX_LIGHTS`.
    ErrTooMany = 21,
    /// A tile reaches outside the image.
    ErrBadTile = 22,
    /// The output buffer is smaller than 3 bytes per pixel of the tile.
    ErrBufferTooSmall = 23,
}

/// Number mode: `f32`.
pub const RK_MODE_F32: u32 = 1;
/// Number mode: fixed point (Q16.16 coordinates within ±8192).
pub const RK_MODE_FIXED: u32 = 2;
/// Structure: binary BVH.
pub const RK_KIND_BVH: u32 = 1;
/// Structure: 4-wide BVH.
pub const RK_KIND_BVH4: u32 = 2;
/// `RkHit::prim` of a miss.
pub const RK_NO_HIT: u32 = u32::MAX;
/// 64-bit words of an [`RkAccel`].
pub const RK_ACCEL_WORDS: usize = 24;

/// A structure ready for queries, filled by `rk_build` or `rk_load_baked`. Opaque; copy it
/// freely (copies share the caller's memory).
#[repr(C)]
#[derive(Clone, Copy)]
pub struct RkAccel {
    /// Private.
    pub opaque: [u64; RK_ACCEL_WORDS],
}

/// A ray: origin, direction (any length but zero), interval `[t_min, t_max]` (distances
/// along the normalised direction; `t_max` may be infinity).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkRay {
    /// Origin.
    pub origin: [f32; 3],
    /// Direction.
    pub dir: [f32; 3],
    /// Nearest distance accepted.
    pub t_min: f32,
    /// Farthest distance accepted.
    pub t_max: f32,
}

/// The closest hit: distance, triangle index, barycentrics (weights of the second and third
/// vertex). `prim == RK_NO_HIT` for a miss.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RkHit {
    /// Distance along the normalised direction.
    pub t: f32,
    /// Index of the triangle hit.
    pub prim: u32,
    /// Barycentric weight of the second vertex.
    pub u: f32,
    /// Barycentric weight of the third vertex.
    pub v: f32,
}

/// A tree borrowing caller memory, built or loaded (lifetimes erased: the caller's contract).
type Tree<S> = Baked<'static, S>;

/// One of the four tree types: a binary or 4-wide BVH in either mode.
#[derive(Clone, Copy)]
enum AnyTree {
    F32(Tree<f32>),
    Fixed(Tree<I16F16>),
}

/// Where a built structure's arrays sit in the caller's memory, for `rk_refit`.
#[derive(Clone, Copy)]
struct Arrays {
    tris: *mut u8,
    ids: *mut u32,
    nodes: *mut u8,
    nodes4: *mut u8,
    /// Build scratch, `scratch_words` words (only the build reads it).
    scratch: *mut u32,
    scratch_words: usize,
    count: usize,
    shape: TreeShape,
}

/// What an [`RkAccel`] holds. `tag` first, so an uninitialised value is recognised by
/// reading one `u32`.
#[repr(C)]
#[derive(Clone, Copy)]
struct Inner {
    tag: u32,
    tree: AnyTree,
    arrays: Option<Arrays>,
}

const TAG: u32 = 0x524b_4143; // "RKAC"
const _: () = assert!(size_of::<Inner>() <= size_of::<RkAccel>());
const _: () = assert!(align_of::<Inner>() <= align_of::<RkAccel>());

/// Safety contract of every function: pointers are null or valid for the access named (and
/// aligned for their type); `RkAccel` values come from `rk_build` / `rk_load_baked` and the
/// memory they were given stays valid, unmoved and (for baked bytes) unmodified while they are
/// used; no two calls use one `RkAccel` at the same time if one of them is `rk_refit`.
fn inner(accel: *const RkAccel) -> Result<Inner, RkStatus> {
    if accel.is_null() {
        return Err(RkStatus::ErrNull);
    }
    // SAFETY: non-null and valid for reads of an `RkAccel` (contract); the first word is read
    // as a `u32`, valid for any bits.
    let tag = unsafe { accel.cast::<u32>().read() };
    if tag != TAG {
        return Err(RkStatus::ErrNotInitialised);
    }
    // SAFETY: the tag shows it was written by `store`, as an `Inner`.
    Ok(unsafe { accel.cast::<Inner>().read() })
}

fn store(out: *mut RkAccel, value: Inner) {
    // SAFETY: callers checked `out` for null; valid for writes (contract), size and
    // alignment asserted above.
    unsafe {
        out.write(RkAccel {
            opaque: [0; RK_ACCEL_WORDS],
        });
        out.cast::<Inner>().write(value);
    }
}

/// A static, NUL-terminated name for a status code (`"unknown status"` for other values).
#[no_mangle]
pub extern "C" fn rk_status_name(status: i32) -> *const c_char {
    let name: &'static [u8] = match status {
        0 => b"ok\0",
        1 => b"null pointer\0",
        2 => b"bad argument (unknown mode, kind, leaf size, shape, sampler or filter)\0",
        3 => b"memory too small\0",
        4 => b"bad triangle (non-finite or out-of-range vertex)\0",
        5 => b"bad baked file (magic, version, header field, length or checksum)\0",
        6 => b"baked bytes misaligned\0",
        7 => b"bad baked tree or triangles\0",
        8 => b"bad ray\0",
        9 => b"not refittable (baked structure or other triangle count)\0",
        10 => b"RkAccel or RkRenderer not initialised\0",
        11 => b"too large (too many triangles or objects)\0",
        12 => b"bad sphere (non-finite or out-of-range centre, negative radius)\0",
        13 => b"scene value not finite\0",
        14 => b"scene value negative\0",
        15 => b"reflectance above 1\0",
        16 => b"scene value not positive\0",
        17 => b"scene value out of range\0",
        18 => b"rectangle light of zero area\0",
        19 => b"degenerate direction (zero, or camera up along the view)\0",
        20 => b"material index out of range\0",
        21 => b"too many lights\0",
        22 => b"tile outside the image\0",
        23 => b"output buffer too small for the tile\0",
        _ => b"unknown status\0",
    };
    name.as_ptr().cast()
}

/// The alignment baked bytes need (128: enough for both kinds).
#[no_mangle]
pub extern "C" fn rk_baked_align() -> u32 {
    raykernel::baked::MAX_ALIGN as u32
}

/// Byte offsets of the arrays in the memory of a build, from a 128-aligned start.
struct BuildLayout {
    tris: usize,
    ids: usize,
    nodes: usize,
    nodes4: usize,
    /// The 4-wide collapse's scratch words ([`collapse_words_needed`]; none for the BVH).
    scratch: usize,
    scratch_words: usize,
    end: usize,
}

fn build_layout(mode: u32, kind: u32, count: usize) -> Option<BuildLayout> {
    let up = |x: usize, a: usize| x.checked_add(a - 1).map(|y| y / a * a);
    if mode != RK_MODE_F32 && mode != RK_MODE_FIXED {
        return None;
    }
    let tris = 0usize;
    let ids = count.checked_mul(size_of::<Triangle<f32>>())?;
    let nodes = up(ids.checked_add(count.checked_mul(4)?)?, 128)?;
    let nodes_end = nodes.checked_add(nodes_needed(count).checked_mul(size_of::<Node<f32>>())?)?;
    let (nodes4, scratch, scratch_words) = match kind {
        RK_KIND_BVH => (nodes_end, nodes_end, 0),
        RK_KIND_BVH4 => {
            let at = up(nodes_end, 128)?;
            let len = nodes4_needed(count).checked_mul(size_of::<Node4<f32>>())?;
            (at, at.checked_add(len)?, collapse_words_needed(count, 4))
        }
        _ => return None,
    };
    let end = scratch.checked_add(scratch_words.checked_mul(4)?)?;
    Some(BuildLayout {
        tris,
        ids,
        nodes,
        nodes4,
        scratch,
        scratch_words,
        end,
    })
}

/// Bytes of memory `rk_build` needs for `tri_count` triangles (any alignment; 127 bytes of it
/// are slack for aligning), or 0 for an unknown mode or kind.
#[no_mangle]
pub extern "C" fn rk_build_bytes(mode: u32, kind: u32, tri_count: u32) -> usize {
    build_layout(mode, kind, tri_count as usize)
        .and_then(|l| l.end.checked_add(127))
        .unwrap_or(0)
}

/// Builds a BVH (`kind` `RK_KIND_BVH`) or 4-wide BVH (`RK_KIND_BVH4`) over `tri_count`
/// triangles (`vertices`: nine floats each, x y z of three vertices), in `mode`, with leaves
/// of at most `max_leaf_size` (1..64; 0 for the default) triangles, into `memory`
/// (`memory_bytes >= rk_build_bytes(mode, kind, tri_count)`), and fills `out`. The vertices
/// are copied (converted to the mode); `vertices` need not outlive the call.
#[no_mangle]
pub unsafe extern "C" fn rk_build(
    mode: u32,
    kind: u32,
    max_leaf_size: u32,
    vertices: *const f32,
    tri_count: u32,
    memory: *mut c_void,
    memory_bytes: usize,
    out: *mut RkAccel,
) -> RkStatus {
    if out.is_null() || memory.is_null() || (vertices.is_null() && tri_count > 0) {
        return RkStatus::ErrNull;
    }
    let count = tri_count as usize;
    let Some(layout) = build_layout(mode, kind, count) else {
        return RkStatus::ErrBadArgument;
    };
    let leaf = if max_leaf_size == 0 {
        BuildOptions::default().max_leaf_size
    } else {
        max_leaf_size
    };
    if leaf > MAX_LEAF_SIZE {
        return RkStatus::ErrBadArgument;
    }
    let base = memory.cast::<u8>();
    let skip = base.align_offset(128);
    if skip > 127 || skip.saturating_add(layout.end) > memory_bytes {
        return RkStatus::ErrMemoryTooSmall;
    }
    // SAFETY: `vertices` is valid for `9 * tri_count` floats (contract).
    let verts: &[f32] = if count == 0 {
        &[]
    } else {
        unsafe { core::slice::from_raw_parts(vertices, 9 * count) }
    };
    // SAFETY: `skip + layout.end <= memory_bytes`, so the region lies in the caller's memory,
    // which is valid for writes (contract). Zeroing initialises it for the typed slices below.
    let start = unsafe {
        let start = base.add(skip);
        start.write_bytes(0, layout.end);
        start
    };
    let arrays = Arrays {
        // SAFETY (all five): offsets within the zeroed region, aligned (128-aligned start,
        // offsets multiples of the types' alignments).
        tris: unsafe { start.add(layout.tris) },
        ids: unsafe { start.add(layout.ids) }.cast(),
        nodes: unsafe { start.add(layout.nodes) },
        nodes4: unsafe { start.add(layout.nodes4) },
        scratch: unsafe { start.add(layout.scratch) }.cast(),
        scratch_words: layout.scratch_words,
        count,
        shape: TreeShape {
            node_count: 0,
            depth: 0,
            leaf_order: false,
        },
    };
    let options = BuildOptions {
        max_leaf_size: leaf,
        ..BuildOptions::default()
    };
    let built = match mode {
        RK_MODE_F32 => {
            build_in::<f32>(verts, arrays, kind, options).map(|(t, a)| (AnyTree::F32(t), a))
        }
        _ => build_in::<I16F16>(verts, arrays, kind, options).map(|(t, a)| (AnyTree::Fixed(t), a)),
    };
    match built {
        Ok((tree, arrays)) => {
            store(
                out,
                Inner {
                    tag: TAG,
                    tree,
                    arrays: Some(arrays),
                },
            );
            RkStatus::Ok
        }
        Err(e) => e,
    }
}

/// The typed slices of `arrays` (zeroed, aligned memory of the build layout).
///
/// # Safety
/// `arrays` points into memory laid out by `build_layout` for `arrays.count` triangles and
/// `S`, valid for the rest of the program's use of the structure, and not otherwise borrowed.
#[allow(clippy::type_complexity)]
unsafe fn slices<S: Scalar>(
    a: &Arrays,
) -> (
    &'static mut [Triangle<S>],
    &'static mut [u32],
    &'static mut [Node<S>],
    &'static mut [Node4<S>],
) {
    let n = a.count;
    // SAFETY: per the function's contract; all-zero bytes are valid values of every type.
    unsafe {
        (
            core::slice::from_raw_parts_mut(a.tris.cast(), n),
            core::slice::from_raw_parts_mut(a.ids, n),
            core::slice::from_raw_parts_mut(a.nodes.cast(), nodes_needed(n)),
            core::slice::from_raw_parts_mut(a.nodes4.cast(), nodes4_needed(n)),
        )
    }
}

/// Converts `verts` into triangles of mode `S` in `out` (all checked before any is written).
fn convert<S: Scalar>(verts: &[f32], out: &mut [Triangle<S>]) -> Result<(), RkStatus> {
    let tri = |c: &[f32]| -> Result<Triangle<S>, RkStatus> {
        let v: [[f32; 3]; 3] = core::array::from_fn(|i| core::array::from_fn(|k| c[3 * i + k]));
        Triangle::from_f32(v).map_err(|_| RkStatus::ErrBadTriangle)
    };
    for c in verts.chunks_exact(9) {
        tri(c)?.check().map_err(|_| RkStatus::ErrBadTriangle)?;
    }
    for (slot, c) in out.iter_mut().zip(verts.chunks_exact(9)) {
        *slot = tri(c)?;
    }
    Ok(())
}

fn build_in<S: BakedScalar>(
    verts: &[f32],
    mut arrays: Arrays,
    kind: u32,
    options: BuildOptions,
) -> Result<(Tree<S>, Arrays), RkStatus> {
    // SAFETY: `arrays` was just laid out and zeroed by `rk_build` for this mode and count.
    let (tris, ids, nodes, nodes4) = unsafe { slices::<S>(&arrays) };
    convert(verts, tris)?;
    let tris: &'static [Triangle<S>] = tris;
    let bvh = Bvh::build(tris, nodes, ids, options).map_err(|_| RkStatus::ErrTooLarge)?;
    if kind == RK_KIND_BVH {
        arrays.shape = bvh.shape();
        return Ok((Baked::Bvh(bvh), arrays));
    }
    // SAFETY: as for `slices`: zeroed, aligned words of the layout, borrowed nowhere else.
    let scratch = unsafe { core::slice::from_raw_parts_mut(arrays.scratch, arrays.scratch_words) };
    let wide = Bvh4::collapse(&bvh, nodes4, scratch).map_err(|_| RkStatus::ErrTooLarge)?;
    arrays.shape = wide.shape();
    Ok((Baked::Bvh4(wide), arrays))
}

/// Loads baked bytes (`raykernel bake`'s output, e.g. in flash) in place and fills `out`: every
/// byte is checked, nothing is copied. `bytes` must start at a multiple of
/// `rk_baked_align()` and stay unmodified while `out` is used.
#[no_mangle]
pub unsafe extern "C" fn rk_load_baked(
    bytes: *const u8,
    len: usize,
    out: *mut RkAccel,
) -> RkStatus {
    if bytes.is_null() || out.is_null() {
        return RkStatus::ErrNull;
    }
    // SAFETY: valid for reads of `len` bytes, unmodified while used (contract).
    let bytes: &'static [u8] = unsafe { core::slice::from_raw_parts(bytes, len) };
    let tree = match read_header(bytes).map(|h| h.mode) {
        Ok(BakedMode::F32) => Baked::<f32>::load(bytes).map(AnyTree::F32),
        Ok(BakedMode::Fixed) => Baked::<I16F16>::load(bytes).map(AnyTree::Fixed),
        Err(e) => Err(e),
    };
    match tree {
        Ok(tree) => {
            store(
                out,
                Inner {
                    tag: TAG,
                    tree,
                    arrays: None,
                },
            );
            RkStatus::Ok
        }
        Err(e) => bake_status(e),
    }
}

fn bake_status(e: BakeError) -> RkStatus {
    match e {
        BakeError::Misaligned { .. } => RkStatus::ErrMisaligned,
        BakeError::BadPrimitive { .. } | BakeError::LeafTooSmall { .. } | BakeError::Tree(_) => {
            RkStatus::ErrBadTree
        }
        _ => RkStatus::ErrBadFile,
    }
}

/// After the caller moved the vertices (same triangles, same order, `tri_count` as built),
/// updates every box of a structure from `rk_build` in place (no rebuild). On an error nothing
/// changed.
#[no_mangle]
pub unsafe extern "C" fn rk_refit(
    accel: *mut RkAccel,
    vertices: *const f32,
    tri_count: u32,
) -> RkStatus {
    if vertices.is_null() && tri_count > 0 {
        return RkStatus::ErrNull;
    }
    let mut value = match inner(accel) {
        Ok(v) => v,
        Err(e) => return e,
    };
    let Some(arrays) = value.arrays else {
        return RkStatus::ErrNotRefittable;
    };
    if tri_count as usize != arrays.count {
        return RkStatus::ErrNotRefittable;
    }
    // SAFETY: valid for `9 * tri_count` floats (contract).
    let verts: &[f32] = if arrays.count == 0 {
        &[]
    } else {
        unsafe { core::slice::from_raw_parts(vertices, 9 * arrays.count) }
    };
    let refit = match value.tree {
        AnyTree::F32(t) => refit_in::<f32>(t, verts, &arrays).map(AnyTree::F32),
        AnyTree::Fixed(t) => refit_in::<I16F16>(t, verts, &arrays).map(AnyTree::Fixed),
    };
    match refit {
        Ok(tree) => {
            value.tree = tree;
            store(accel, value);
            RkStatus::Ok
        }
        Err(e) => e,
    }
}

fn refit_in<S: BakedScalar>(
    tree: Tree<S>,
    verts: &[f32],
    arrays: &Arrays,
) -> Result<Tree<S>, RkStatus> {
    // SAFETY: `arrays` came from `rk_build` for this mode; the old tree (which borrows the
    // same memory) is not used again: the caller stores the refitted one in its place.
    let (tris, ids, nodes, nodes4) = unsafe { slices::<S>(arrays) };
    convert(verts, tris)?;
    let (tris, ids): (&'static [Triangle<S>], &'static [u32]) = (tris, ids);
    Baked::refit(tree.kind(), tris, nodes, nodes4, ids, arrays.shape)
        .map_err(|_| RkStatus::ErrNotRefittable)
}

fn ray_of<S: Scalar>(r: &RkRay) -> Result<Ray<S>, RkStatus> {
    Ray::from_f32(r.origin, r.dir, r.t_min, r.t_max).map_err(|_| RkStatus::ErrBadRay)
}

fn hit_of<S: Scalar>(h: Option<Hit<S>>) -> RkHit {
    h.map_or(
        RkHit {
            t: 0.0,
            prim: RK_NO_HIT,
            u: 0.0,
            v: 0.0,
        },
        |h| RkHit {
            t: h.t.to_f32(),
            prim: h.prim,
            u: h.u.to_f32(),
            v: h.v.to_f32(),
        },
    )
}

fn intersect_in<S: BakedScalar>(tree: &Tree<S>, ray: &RkRay) -> Result<RkHit, RkStatus> {
    let ray = ray_of::<S>(ray)?;
    Ok(hit_of(tree.intersect(&ray)))
}

fn occluded_in<S: BakedScalar>(tree: &Tree<S>, ray: &RkRay) -> Result<bool, RkStatus> {
    let ray = ray_of::<S>(ray)?;
    Ok(tree.occluded(&ray))
}

/// The closest hit of `ray` (ties go to the lowest triangle index), into `hit`
/// (`hit->prim == RK_NO_HIT` for a miss).
#[no_mangle]
pub unsafe extern "C" fn rk_intersect(
    accel: *const RkAccel,
    ray: *const RkRay,
    hit: *mut RkHit,
) -> RkStatus {
    if ray.is_null() || hit.is_null() {
        return RkStatus::ErrNull;
    }
    let value = match inner(accel) {
        Ok(v) => v,
        Err(e) => return e,
    };
    // SAFETY: non-null, valid (contract).
    let ray = unsafe { ray.read() };
    let found = match &value.tree {
        AnyTree::F32(t) => intersect_in(t, &ray),
        AnyTree::Fixed(t) => intersect_in(t, &ray),
    };
    match found {
        Ok(h) => {
            // SAFETY: non-null, valid for writes (contract).
            unsafe { hit.write(h) };
            RkStatus::Ok
        }
        Err(e) => e,
    }
}

/// Whether anything is hit within the ray's interval (shadow rays), into `occluded`.
#[no_mangle]
pub unsafe extern "C" fn rk_occluded(
    accel: *const RkAccel,
    ray: *const RkRay,
    occluded: *mut bool,
) -> RkStatus {
    if ray.is_null() || occluded.is_null() {
        return RkStatus::ErrNull;
    }
    let value = match inner(accel) {
        Ok(v) => v,
        Err(e) => return e,
    };
    // SAFETY: non-null, valid (contract).
    let ray = unsafe { ray.read() };
    let any = match &value.tree {
        AnyTree::F32(t) => occluded_in(t, &ray),
        AnyTree::Fixed(t) => occluded_in(t, &ray),
    };
    match any {
        Ok(b) => {
            // SAFETY: non-null, valid for writes (contract).
            unsafe { occluded.write(b) };
            RkStatus::Ok
        }
        Err(e) => e,
    }
}

#[cfg(target_os = "none")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
