//! A ray-tracing kernel for anything from a Cortex-M0 to a workstation, giving the same bits on
//! every one of them.
//!
//! - `#![no_std]`, no allocator, no recursion, no panics on bad input: the caller hands over the
//!   memory (node arena, primitive-id buffer) and gets typed errors for bad data.
//! - Two number modes with one set of algorithms: `f32` (API in `glam::Vec3`) and the
//!   fixed-point [`I16F16`] (Q16.16 coordinates, Q2.30 unit directions, exact integer tests).
//! - A BVH built into caller memory by one of three builders (binned SAH, median, midpoint),
//!   traversed with a fixed stack sized from the depth cap, near child first; a uniform grid
//!   ([`Grid`], rounding-proof 3D-DDA) and a kd-tree ([`KdTree`], SAH) with the same query API.
//! - Watertight ray/triangle tests (Woop, Benthin, Wald 2013 in `f32`; exact integer edge
//!   functions in fixed point) and a conservative slab test (Ize 2013), so rays through shared
//!   edges and vertices never slip through and traversal never culls a box it should enter.
//! - Closest-hit ties go to the lowest primitive id, so every accelerator returns the same hit
//!   as brute force ([`Linear`]), bit for bit.
//!
//! ```
//! use raykernel::{bvh::{nodes_needed, BuildOptions}, Accel, Bvh, Node, Ray, Triangle};
//! use raykernel::glam::Vec3;
//!
//! const N: usize = 2;
//! let tris: [Triangle<f32>; N] = [
//!     Triangle::new(Vec3::new(-1.0, -1.0, 5.0), Vec3::new(1.0, -1.0, 5.0), Vec3::new(0.0, 1.0, 5.0)),
//!     Triangle::new(Vec3::new(-1.0, -1.0, 9.0), Vec3::new(1.0, -1.0, 9.0), Vec3::new(0.0, 1.0, 9.0)),
//! ];
//! let mut nodes = [Node::EMPTY; nodes_needed(N)];
//! let mut ids = [0u32; N];
//! let bvh = Bvh::build(&tris, &mut nodes, &mut ids, BuildOptions::default()).unwrap();
//! let hit = bvh.intersect(&Ray::new(Vec3::ZERO, Vec3::Z).unwrap()).unwrap();
//! assert_eq!((hit.t, hit.prim), (5.0, 0));
//! ```
#![no_std]
// Exceptions, each confined and documented where it is: SSE and NEON intrinsics
// (`scalar/lanes.rs`), the in-place view of checked baked bytes (`accel/baked/plain.rs`), the
// square-root instruction of Cortex-M cores with an FPU (`scalar/float/sqrt.rs`), and x86_64's
// feature detection, the calls of the traversals' AVX2 copies (`cpu.rs`,
// `accel/wide/traverse.rs`, `accel/wide/traverse8.rs`) and their 256-bit box test
// (`scalar/wide.rs`).
#![deny(unsafe_code)]
#![warn(missing_docs)]

mod accel;
pub mod cpu;
mod geom;
pub mod render;
mod scalar;

/// The number layer's errors under the path the mode files use.
mod error {
    pub(crate) use crate::scalar::{PointError, RayError};
}

pub use accel::baked::{BakeError, Baked};
pub use accel::bvh::{Bvh, Node};
pub use accel::grid::Grid;
pub use accel::kdtree::{KdNode, KdTree};
pub use accel::wide::{Bvh4, Bvh8, Node4, Node8, WideBvh, WideNode};
pub use accel::{
    Accel, AccelFamily, AccelKind, AccelMemory, AccelVisitor, AnyAccel, AnyFamily, Arena,
    BuildError, Bvh4Family, Bvh8Family, BvhFamily, Coherent, Counters, GridFamily, InvalidAccel,
    KdTreeFamily, Linear, LinearFamily, MemoryNeeded, Nearest, NoStats, Shortfall, TraversalStats,
    TrianglesOnly, UnknownAccel, MAX_PRIMS,
};
pub use geom::{
    spawn, Aabb, Barycentrics, Hit, Primitive, Ray, Sphere, Triangle, TriangleHit, VertexError,
};
pub use glam;
pub use scalar::{
    PointError, RayData, RayError, Scalar, Vec3x, F32_COORD_LIMIT, FIXED_COORD_LIMIT, I16F16,
};

/// Settings, memory sizes and limits of the binary BVH, [`Bvh`].
pub mod bvh {
    pub use crate::accel::bvh::{
        nodes_needed, BuildOptions, BuildSettings, BuilderKind, InvalidTree, Median, Midpoint,
        RefitError, Sah, SplitRule, StaticBuild, TreeShape, TreeStats, DEFAULT_LEAF_SIZE,
        MAX_DEPTH, MAX_LEAF_SIZE, MEDIAN_FALLBACK_DEPTH,
    };
}

/// The baked format: a built BVH or 4-wide BVH with its primitives as bytes, and its loader.
pub mod baked {
    pub use crate::accel::baked::{
        bake_bvh, bake_bvh4, baked_len, checksum, load_bvh, load_bvh4, read_header, BakedKind,
        BakedMode, BakedScalar, Header, FLAG_LEAF_ORDER, HEADER_LEN, MAGIC, MAX_ALIGN,
        TRIANGLE_LEN, VERSION,
    };
}

/// Memory size and node slots of the 4-wide BVH, [`Bvh4`].
pub mod bvh4 {
    pub use crate::accel::wide::{collapse_words_needed, nodes4_needed, ChildSlot};
}

/// Memory size and node slots of the 8-wide BVH, [`Bvh8`], and of wide trees in general.
pub mod bvh8 {
    pub use crate::accel::wide::{
        collapse_words_needed, nodes8_needed, wide_nodes_needed, ChildSlot,
    };
}

/// Settings, memory sizes and limits of the uniform grid, [`Grid`].
pub mod grid {
    pub use crate::accel::grid::{
        GridOptions, GridSize, GridStats, InvalidGrid, DEFAULT_DENSITY, MAILBOX, MAX_DENSITY,
        MAX_RES,
    };
}

/// Settings, memory sizes and limits of the kd-tree, [`KdTree`].
pub mod kdtree {
    pub use crate::accel::kdtree::{
        nodes_needed, refs_needed, InvalidKdTree, KdOptions, KdStats, MAX_DEPTH, NODES_PER_PRIM,
        REFS_PER_PRIM,
    };
}

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
struct ReadmeDoctests;
