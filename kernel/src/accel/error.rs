//! Errors of the accelerator builders: small `Copy` enums that say what to do next.

use crate::scalar::PointError;
use core::fmt;

/// Which caller-provided buffer was too small.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Arena {
    /// The node slice.
    Nodes,
    /// The primitive-id slice.
    PrimIds,
    /// The uniform grid's cell slice (one offset per cell, plus one).
    Cells,
    /// The uniform grid's or kd-tree's primitive-reference slice.
    Refs,
    /// Build scratch words (the wide BVHs' collapse cost table).
    Scratch,
}

/// Why an acceleration structure could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum BuildError {
    /// A caller-provided buffer is too small. `needed` is exact: retry with that many slots.
    ArenaTooSmall {
        /// Which buffer.
        arena: Arena,
        /// Slots needed.
        needed: usize,
        /// Slots provided.
        available: usize,
    },
    /// More than [`crate::MAX_PRIMS`] primitives.
    TooManyPrims {
        /// The number of primitives given.
        count: usize,
    },
    /// Primitive `prim` has an unusable vertex (or centre/radius for spheres): `vertex` is its
    /// index within the primitive (0..3 for triangles; 0 = centre, 1 = radius for spheres).
    BadPrimitive {
        /// Index of the primitive in the input slice.
        prim: usize,
        /// Index of the vertex within the primitive.
        vertex: usize,
        /// What is wrong with it.
        error: PointError,
    },
    /// `max_leaf_size` is zero or above [`crate::bvh::MAX_LEAF_SIZE`].
    BadLeafSize {
        /// The value given.
        max_leaf_size: u32,
    },
    /// The uniform grid would hold more primitive references than a 32-bit offset can
    /// address (`needed` is the exact count): lower the density or split the scene.
    TooManyRefs {
        /// References the grid would need.
        needed: u64,
    },
    /// The grid density (cells per primitive) is not a finite number in
    /// `(0, `[`crate::grid::MAX_DENSITY`]`]`.
    BadDensity {
        /// The value given.
        density: f32,
    },
    /// The kd-tree depth limit is above [`crate::kdtree::MAX_DEPTH`].
    BadMaxDepth {
        /// The value given.
        max_depth: u32,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ArenaTooSmall {
                arena,
                needed,
                available,
            } => {
                write!(
                    f,
                    "{arena:?} arena too small: need {needed} slots, have {available}"
                )
            }
            Self::TooManyPrims { count } => {
                write!(
                    f,
                    "{count} primitives exceed the limit of {}",
                    crate::MAX_PRIMS
                )
            }
            Self::BadPrimitive {
                prim,
                vertex,
                error,
            } => {
                write!(f, "primitive {prim}, vertex {vertex}: {error}")
            }
            Self::BadLeafSize { max_leaf_size } => {
                write!(
                    f,
                    "max_leaf_size {max_leaf_size} is outside 1..={}",
                    crate::bvh::MAX_LEAF_SIZE
                )
            }
            Self::TooManyRefs { needed } => {
                write!(
                    f,
                    "{needed} primitive references exceed the 32-bit offset space"
                )
            }
            Self::BadDensity { density } => {
                write!(
                    f,
                    "grid density {density} is outside (0, {}]",
                    crate::grid::MAX_DENSITY
                )
            }
            Self::BadMaxDepth { max_depth } => {
                write!(
                    f,
                    "kd-tree max_depth {max_depth} is above {}",
                    crate::kdtree::MAX_DEPTH
                )
            }
        }
    }
}

impl core::error::Error for BuildError {}
