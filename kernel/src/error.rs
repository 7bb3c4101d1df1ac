//! Typed errors: small `Copy` enums that say what to do next. No strings, no allocation.

use core::fmt;

/// Why a point (vertex, sphere centre, ray origin) or radius is unusable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PointError {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// A coordinate lies outside the fixed-point coordinate range `[-limit, limit]` (world units).
    OutOfRange {
        /// The magnitude limit, [`crate::FIXED_COORD_LIMIT`].
        limit: f32,
    },
    /// A sphere radius is negative.
    NegativeRadius,
}

impl fmt::Display for PointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite => write!(f, "coordinate is NaN or infinite"),
            Self::OutOfRange { limit } => {
                write!(
                    f,
                    "coordinate outside the fixed-point range [-{limit}, {limit}]"
                )
            }
            Self::NegativeRadius => write!(f, "radius is negative"),
        }
    }
}

impl core::error::Error for PointError {}

/// Why a ray could not be constructed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayError {
    /// The origin is unusable (non-finite, or outside the fixed-point range).
    Origin(PointError),
    /// A direction component is NaN or infinite.
    NonFiniteDirection,
    /// The direction is the zero vector (or too short to normalise).
    ZeroDirection,
    /// `t_min` or `t_max` is NaN, `t_min` is negative or infinite, or `t_min > t_max`.
    InvalidInterval,
}

impl fmt::Display for RayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Origin(e) => write!(f, "ray origin: {e}"),
            Self::NonFiniteDirection => write!(f, "ray direction is NaN or infinite"),
            Self::ZeroDirection => write!(f, "ray direction has zero length"),
            Self::InvalidInterval => {
                write!(
                    f,
                    "ray interval must satisfy 0 <= t_min <= t_max, t_min finite, no NaN"
                )
            }
        }
    }
}

impl core::error::Error for RayError {}

/// Which caller-provided buffer was too small.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arena {
    /// The node slice.
    Nodes,
    /// The primitive-id slice.
    PrimIds,
    /// The uniform grid's cell slice (one offset per cell, plus one).
    Cells,
    /// The uniform grid's or kd-tree's primitive-reference slice.
    Refs,
}

/// Why an acceleration structure could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
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
    /// More primitives than a 32-bit id can address (`u32::MAX` is reserved for "miss").
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
                write!(f, "{count} primitives exceed the 32-bit id space")
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
