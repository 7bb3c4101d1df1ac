//! The run-time description of an accelerator: which structure, with which options.

use super::bvh::BuildOptions;
use super::family::{
    AccelFamily, Bvh4Family, Bvh8Family, BvhFamily, GridFamily, KdTreeFamily, LinearFamily,
};
use super::grid::GridOptions;
use super::kdtree::KdOptions;
use super::{BuildError, MemoryNeeded};
use crate::geom::Primitive;
use crate::scalar::Scalar;
use core::fmt;
use core::str::FromStr;

/// Which accelerator to build, with its options. [`crate::AnyAccel::build`] builds any of them;
/// every one returns the same hits, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AccelKind {
    /// Brute force, [`crate::Linear`]: no memory, the reference.
    Linear,
    /// A binary BVH, [`crate::Bvh`].
    Bvh(BuildOptions),
    /// A 4-wide BVH, [`crate::Bvh4`], collapsed from a binary BVH built with these options.
    Bvh4(BuildOptions),
    /// An 8-wide BVH, [`crate::Bvh8`], collapsed from a binary BVH built with these options.
    Bvh8(BuildOptions),
    /// A uniform grid, [`crate::Grid`].
    Grid(GridOptions),
    /// A kd-tree, [`crate::KdTree`].
    KdTree(KdOptions),
}

impl Default for AccelKind {
    /// A binary BVH with the default options.
    fn default() -> Self {
        Self::Bvh(BuildOptions::DEFAULT)
    }
}

/// A name [`AccelKind::from_name`] does not know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownAccel;

impl fmt::Display for UnknownAccel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown accelerator; expected one of ")?;
        for (i, kind) in AccelKind::ALL.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            write!(f, "{sep}{}", kind.name())?;
        }
        Ok(())
    }
}

impl core::error::Error for UnknownAccel {}

impl AccelKind {
    /// Every structure with its default options, the fastest first.
    pub const ALL: [Self; 6] = [
        Self::Bvh4(BuildOptions::DEFAULT),
        Self::Bvh8(BuildOptions::DEFAULT),
        Self::Bvh(BuildOptions::DEFAULT),
        Self::KdTree(KdOptions::DEFAULT),
        Self::Grid(GridOptions::DEFAULT),
        Self::Linear,
    ];

    /// The name on command lines: `linear`, `bvh`, `bvh4`, `bvh8`, `grid` or `kdtree`.
    #[must_use]
    pub const fn name(&self) -> &'static str {
        match self {
            Self::Linear => "linear",
            Self::Bvh(_) => "bvh",
            Self::Bvh4(_) => "bvh4",
            Self::Bvh8(_) => "bvh8",
            Self::Grid(_) => "grid",
            Self::KdTree(_) => "kdtree",
        }
    }

    /// The structure named `name` (as [`AccelKind::name`] gives it), with default options.
    ///
    /// # Errors
    /// [`UnknownAccel`] for any other name.
    pub fn from_name(name: &str) -> Result<Self, UnknownAccel> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or(UnknownAccel)
    }

    /// The BVH build options, for the three BVH structures.
    #[must_use]
    pub const fn build_options(&self) -> Option<BuildOptions> {
        match self {
            Self::Bvh(o) | Self::Bvh4(o) | Self::Bvh8(o) => Some(*o),
            Self::Linear | Self::Grid(_) | Self::KdTree(_) => None,
        }
    }

    /// The same structure built with `options` if it is a BVH; any other kind unchanged.
    #[must_use]
    pub const fn with_build_options(self, options: BuildOptions) -> Self {
        match self {
            Self::Bvh(_) => Self::Bvh(options),
            Self::Bvh4(_) => Self::Bvh4(options),
            Self::Bvh8(_) => Self::Bvh8(options),
            other => other,
        }
    }

    /// True for brute force.
    #[must_use]
    pub const fn is_brute_force(&self) -> bool {
        matches!(self, Self::Linear)
    }

    /// True if [`crate::AnyAccel::build_in_leaf_order`] permutes the primitives (the BVHs).
    #[must_use]
    pub const fn permutes_into_leaf_order(&self) -> bool {
        matches!(self, Self::Bvh(_) | Self::Bvh4(_) | Self::Bvh8(_))
    }

    /// The exact memory a build over `count` primitives takes, for the structures whose size
    /// depends on the count alone (`None` for the grid: see [`AccelKind::memory_needed`]).
    #[must_use]
    pub const fn memory_for_count(&self, count: usize) -> Option<MemoryNeeded> {
        match self {
            Self::Linear => Some(MemoryNeeded::NONE),
            Self::Bvh(_) => Some(MemoryNeeded::bvh(count)),
            Self::Bvh4(_) => Some(MemoryNeeded::bvh4(count)),
            Self::Bvh8(_) => Some(MemoryNeeded::bvh8(count)),
            Self::KdTree(_) => Some(MemoryNeeded::kdtree(count)),
            Self::Grid(_) => None,
        }
    }

    /// The exact memory a build over `prims` takes from an [`crate::AccelMemory`].
    ///
    /// # Errors
    /// [`BuildError::TooManyPrims`]; for the grid, whatever its counting pass rejects.
    pub fn memory_needed<S: Scalar, P: Primitive<S>>(
        &self,
        prims: &[P],
    ) -> Result<MemoryNeeded, BuildError> {
        match self {
            Self::Linear => LinearFamily::memory_needed(&(), prims),
            Self::Bvh(o) => BvhFamily::memory_needed(o, prims),
            Self::Bvh4(o) => Bvh4Family::memory_needed(o, prims),
            Self::Bvh8(o) => Bvh8Family::memory_needed(o, prims),
            Self::Grid(o) => GridFamily::memory_needed(o, prims),
            Self::KdTree(o) => KdTreeFamily::memory_needed(o, prims),
        }
    }
}

impl fmt::Display for AccelKind {
    /// The name and the options: `linear`, `bvh sah leaf 3`, `bvh4 median leaf 1`,
    /// `grid density 2`, `kdtree depth auto`, `kdtree depth 12`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())?;
        match self {
            Self::Linear => Ok(()),
            Self::Bvh(o) | Self::Bvh4(o) | Self::Bvh8(o) => {
                write!(f, " {} leaf {}", o.builder.name(), o.max_leaf_size)?;
                if o.reinsertion {
                    Ok(())
                } else {
                    write!(f, " no reinsertion")
                }
            }
            Self::Grid(o) => write!(f, " density {}", o.density),
            Self::KdTree(o) if o.max_depth == 0 => write!(f, " depth auto"),
            Self::KdTree(o) => write!(f, " depth {}", o.max_depth),
        }
    }
}

impl FromStr for AccelKind {
    type Err = UnknownAccel;
    fn from_str(s: &str) -> Result<Self, UnknownAccel> {
        Self::from_name(s)
    }
}
