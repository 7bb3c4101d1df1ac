//! `raykernel bake` (build a BVH or 4-wide BVH over an OBJ mesh and write it as a baked file,
//! `docs/BAKED_FORMAT.md`) and `raykernel trace-baked` (load a baked file in place, as a device
//! would, and trace a ray file through it).

use crate::error::Error;
use crate::obj::load_obj;
use crate::rayfile::{read_rays, write_hits, HitRecord, RayRecord};
use crate::trace::{prepare_rays, trace_closest, Builder, Mode, NodeArena};
use clap::Args;
use raykernel::baked::{read_header, BakedKind, BakedMode, BakedScalar, MAX_ALIGN};
use raykernel::bvh::{BuildOptions, DEFAULT_LEAF_SIZE, MAX_LEAF_SIZE};
use raykernel::{AnyAccel, Baked, Triangle, I16F16};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Which tree to bake.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BakeAccel {
    /// The binary BVH.
    Bvh,
    /// The 4-wide BVH.
    Bvh4,
}

impl BakeAccel {
    /// The format's kind.
    #[must_use]
    pub fn kind(self) -> BakedKind {
        match self {
            Self::Bvh => BakedKind::Bvh,
            Self::Bvh4 => BakedKind::Bvh4,
        }
    }
}

/// `raykernel bake SCENE.obj --out FILE [--accel bvh|bvh4] [--mode f32|fixed] [--leaf N]`.
#[derive(Clone, Debug, Args)]
pub struct BakeArgs {
    /// The mesh (Wavefront OBJ).
    pub scene: PathBuf,
    /// The baked file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Tree to bake.
    #[arg(long, value_enum, default_value_t = BakeAccel::Bvh)]
    pub accel: BakeAccel,
    /// Number mode.
    #[arg(long, value_enum, default_value_t = Mode::F32)]
    pub mode: Mode,
    /// BVH builder.
    #[arg(long, value_enum, default_value_t = Builder::Sah)]
    pub builder: Builder,
    /// Largest leaf (1..=64).
    #[arg(long, default_value_t = DEFAULT_LEAF_SIZE,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_LEAF_SIZE)))]
    pub leaf: u32,
    /// Store the triangles in leaf order (one indirection fewer per leaf).
    #[arg(long)]
    pub leaf_order: bool,
}

/// The JSON report of `raykernel bake`.
#[derive(Clone, Debug, Serialize)]
pub struct BakeReport {
    /// The mesh.
    pub scene: String,
    /// The file written.
    pub out: String,
    /// `bvh` or `bvh4`.
    pub accel: &'static str,
    /// `f32` or `fixed`.
    pub mode: &'static str,
    /// Triangles.
    pub triangles: usize,
    /// Nodes stored.
    pub nodes: usize,
    /// Depth stored.
    pub depth: u32,
    /// File length.
    pub bytes: usize,
    /// Alignment the bytes need in memory.
    pub align: usize,
    /// The header's checksum.
    pub checksum: u32,
    /// [`grid_hash`] of the tree as built in this process (hex), for C and on-target checks.
    pub grid_hash: String,
}

/// Rays of the check grid (`capi/examples/common/grid_hash.h`): 32 x 32 rays from
/// `(0, 0, -10)` along `(x, y, 10)`, `x, y = -1.5 + 3 (i + 0.5) / 32`, in row order.
#[must_use]
pub fn grid_rays() -> Vec<([f32; 3], [f32; 3])> {
    const N: u32 = 32;
    let at = |i: u32| -1.5f32 + 3.0f32 * (i as f32 + 0.5) / N as f32;
    (0..N * N)
        .map(|k| ([0.0, 0.0, -10.0], [at(k % N), at(k / N), 10.0]))
        .collect()
}

/// FNV-1a over the check grid's answers through `accel`: per ray the closest hit's
/// primitive and distance bits (`u32::MAX` and 0 for a miss, little-endian) and one byte for
/// the any-hit answer; what the C interface's `rk_grid_hash` computes.
#[must_use]
pub fn grid_hash<S: raykernel::Scalar, A: raykernel::Accel<S>>(accel: &A) -> u32 {
    let mut h = 0x811c_9dc5u32;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
    };
    for (o, d) in grid_rays() {
        let Ok(ray) = raykernel::Ray::<S>::from_f32(o, d, 0.0, f32::INFINITY) else {
            continue;
        };
        let (prim, t) = accel
            .intersect(&ray)
            .map_or((u32::MAX, 0), |hit| (hit.prim, hit.t.to_f32().to_bits()));
        eat(&prim.to_le_bytes());
        eat(&t.to_le_bytes());
        eat(&[u8::from(accel.occluded(&ray))]);
    }
    h
}

/// Builds the tree `args` asks for and returns the baked bytes.
///
/// # Errors
/// A bad OBJ, a vertex the mode cannot hold, a build the kernel refuses.
pub fn bake_mesh_file(args: &BakeArgs) -> Result<(Vec<u8>, u32), Error> {
    let mesh = load_obj(&args.scene)?;
    let options = BuildOptions {
        builder: args.builder.into(),
        max_leaf_size: args.leaf,
        ..BuildOptions::default()
    };
    match args.mode {
        Mode::F32 => bake_triangles(mesh.kernel_triangles::<f32>(&args.scene)?, args, options),
        Mode::Fixed => bake_triangles(mesh.kernel_triangles::<I16F16>(&args.scene)?, args, options),
    }
}

/// Builds (and for `bvh4` collapses) over `tris` and bakes the result; also returns the
/// built tree's [`grid_hash`].
fn bake_triangles<S: BakedScalar>(
    mut tris: Vec<Triangle<S>>,
    args: &BakeArgs,
    options: BuildOptions,
) -> Result<(Vec<u8>, u32), Error> {
    let build_error = |source| Error::Build {
        scene: args.scene.clone(),
        source,
    };
    let accel = args.accel.kind().accel(options);
    let mut arena = NodeArena::<S>::for_accel(accel, &tris);
    let mut memory = arena.memory();
    let built = if args.leaf_order {
        AnyAccel::build_in_leaf_order(accel, &mut tris, &mut memory)
    } else {
        AnyAccel::build(accel, &tris, &mut memory)
    }
    .map_err(build_error)?;
    let too_large = || Error::Output {
        path: args.out.clone(),
        msg: "tree too large for the baked format".into(),
    };
    let bake_error = |e: raykernel::BakeError| Error::Output {
        path: args.out.clone(),
        msg: e.to_string(),
    };
    // A BVH kind always builds a BVH; `too_large` is never reached through `from_any`.
    let tree = Baked::from_any(built).ok_or_else(too_large)?;
    let mut out = vec![0u8; tree.baked_len().ok_or_else(too_large)?];
    tree.bake(&mut out).map_err(bake_error)?;
    Ok((out, grid_hash(&tree)))
}

/// `raykernel bake`: build, bake, write.
///
/// # Errors
/// As [`bake_mesh_file`]; an unwritable output.
pub fn run_bake(args: &BakeArgs) -> Result<BakeReport, Error> {
    let (bytes, hash) = bake_mesh_file(args)?;
    let header = read_header(&bytes).map_err(|e| Error::Output {
        path: args.out.clone(),
        msg: e.to_string(),
    })?;
    std::fs::write(&args.out, &bytes).map_err(|e| Error::Output {
        path: args.out.clone(),
        msg: e.to_string(),
    })?;
    Ok(BakeReport {
        scene: args.scene.display().to_string(),
        out: args.out.display().to_string(),
        accel: header.kind.name(),
        mode: args.mode.name(),
        triangles: header.prim_count as usize,
        nodes: header.node_count as usize,
        depth: header.depth,
        bytes: bytes.len(),
        align: header.kind.align(),
        checksum: raykernel::baked::checksum(&bytes),
        grid_hash: format!("{hash:08x}"),
    })
}

/// `raykernel trace-baked FILE RAYS --out HITS`.
#[derive(Clone, Debug, Args)]
pub struct TraceBakedArgs {
    /// The baked file (from `raykernel bake`).
    pub baked: PathBuf,
    /// The rays: 32-byte records `ox oy oz dx dy dz tmin tmax`, little-endian f32.
    pub rays: PathBuf,
    /// Where to write the hits: 8-byte records `t: f32, prim: u32` per traced ray.
    #[arg(long)]
    pub out: PathBuf,
}

/// The JSON report of `raykernel trace-baked`.
#[derive(Clone, Debug, Serialize)]
pub struct TraceBakedReport {
    /// The baked file.
    pub baked: String,
    /// `bvh` or `bvh4`.
    pub accel: &'static str,
    /// `f32` or `fixed`.
    pub mode: &'static str,
    /// Triangles.
    pub triangles: usize,
    /// Rays traced.
    pub rays: usize,
    /// Rays that hit.
    pub hits: usize,
    /// Wall time of the load (all checks), milliseconds.
    pub load_ms: f64,
    /// Wall time of the trace, milliseconds.
    pub trace_ms: f64,
    /// [`grid_hash`] of the loaded tree (hex).
    pub grid_hash: String,
}

/// A copy of `bytes` starting at a multiple of [`MAX_ALIGN`] (a `Vec<u8>` is only
/// byte-aligned): the buffer and the offset of the copy in it.
#[must_use]
pub fn aligned_copy(bytes: &[u8]) -> (Vec<u8>, usize) {
    let mut buf = vec![0u8; bytes.len() + MAX_ALIGN];
    let offset = buf.as_ptr().align_offset(MAX_ALIGN).min(MAX_ALIGN);
    buf[offset..offset + bytes.len()].copy_from_slice(bytes);
    (buf, offset)
}

/// Loads `bytes` (aligned) as a baked tree and traces `rays`; also returns the load and trace
/// milliseconds and the loaded tree's [`grid_hash`].
///
/// # Errors
/// The loader's refusal, as [`Error::Scene`] naming `path`.
pub fn trace_baked_bytes(
    bytes: &[u8],
    path: &Path,
    rays: &[RayRecord],
) -> Result<(Vec<HitRecord>, f64, f64, u32), Error> {
    let refused = |e: raykernel::BakeError| Error::Scene {
        file: path.display().to_string(),
        field: String::new(),
        msg: e.to_string(),
    };
    let header = read_header(bytes).map_err(refused)?;
    match header.mode {
        BakedMode::F32 => trace_in::<f32>(bytes, rays).map_err(refused),
        BakedMode::Fixed => trace_in::<I16F16>(bytes, rays).map_err(refused),
    }
}

fn trace_in<S: BakedScalar>(
    bytes: &[u8],
    rays: &[RayRecord],
) -> Result<(Vec<HitRecord>, f64, f64, u32), raykernel::BakeError> {
    let start = std::time::Instant::now();
    let baked = Baked::<S>::load(bytes)?;
    let load_ms = crate::trace::millis(start);
    let prepared = prepare_rays::<S>(rays);
    let (hits, trace_ms) = trace_closest(&baked, &prepared);
    Ok((hits, load_ms, trace_ms, grid_hash(&baked)))
}

/// `raykernel trace-baked`: load the baked file, trace, write the hits.
///
/// # Errors
/// Unreadable inputs, a baked file the loader refuses, an unwritable output.
pub fn run_trace_baked(args: &TraceBakedArgs) -> Result<TraceBakedReport, Error> {
    let raw = std::fs::read(&args.baked).map_err(|e| Error::Scene {
        file: args.baked.display().to_string(),
        field: String::new(),
        msg: e.to_string(),
    })?;
    let (buf, offset) = aligned_copy(&raw);
    let bytes = &buf[offset..offset + raw.len()];
    let rays = read_rays(&args.rays)?;
    let (hits, load_ms, trace_ms, hash) = trace_baked_bytes(bytes, &args.baked, &rays)?;
    write_hits(&args.out, &hits)?;
    let header = read_header(bytes).ok();
    Ok(TraceBakedReport {
        baked: args.baked.display().to_string(),
        accel: header.map_or(BakedKind::Bvh, |h| h.kind).name(),
        mode: match header.map(|h| h.mode) {
            Some(BakedMode::Fixed) => "fixed",
            _ => "f32",
        },
        triangles: header.map_or(0, |h| h.prim_count as usize),
        rays: hits.len(),
        hits: hits.iter().filter(|h| h.is_hit()).count(),
        load_ms,
        trace_ms,
        grid_hash: format!("{hash:08x}"),
    })
}
