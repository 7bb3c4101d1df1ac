//! Errors of the number layer: unusable coordinates and rays. Small `Copy` enums, no strings.

use core::fmt;

/// Why a point (vertex, sphere centre, ray origin) or radius is unusable.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
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
#[non_exhaustive]
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
