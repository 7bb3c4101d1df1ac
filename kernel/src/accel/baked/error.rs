//! Why baked bytes were refused, or could not be written.

use crate::accel::bvh::InvalidTree;
use core::fmt;

/// Why [`super::read_header`], a loader or a writer refused. Every variant is a property of the
/// bytes (or the buffer) alone: loading the same bytes again gives the same error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BakeError {
    /// Fewer bytes than the header (or, for a writer, the output buffer is too small).
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        available: usize,
    },
    /// The length is not the one the header's counts give.
    WrongLength {
        /// Length the header implies.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// Not a baked file: the first eight bytes are not [`super::MAGIC`].
    BadMagic,
    /// A format version this kernel does not read.
    UnsupportedVersion {
        /// The version found.
        version: u32,
    },
    /// A header field holds an impossible value (unknown mode or kind, unknown flag bit,
    /// non-zero reserved byte, counts no tree has, an offset or length that disagrees with the
    /// counts). `offset` is the field's byte offset in the header.
    BadField {
        /// Byte offset of the field.
        offset: u32,
    },
    /// The checksum field does not match the bytes.
    BadChecksum {
        /// The value in the header.
        stored: u32,
        /// The value of the bytes.
        computed: u32,
    },
    /// The file is valid but of another number mode or structure than asked for.
    WrongStructure,
    /// The buffer does not start at a multiple of `required` bytes, so its nodes cannot be
    /// read in place (copy it into a buffer with that alignment).
    Misaligned {
        /// The alignment needed.
        required: usize,
    },
    /// This target is big-endian: baked bytes (little-endian) cannot be read in place.
    BigEndianTarget,
    /// A triangle has a non-finite or out-of-range coordinate.
    BadPrimitive {
        /// Index of the triangle in the file's triangle section.
        index: u32,
    },
    /// A leaf's box does not hold its triangles' boxes padded by the traversal margin.
    LeafTooSmall {
        /// Index of the node (4-wide: of the node whose slot holds the leaf).
        node: u32,
    },
    /// The tree's structure is invalid (links, child boxes, leaf ranges, primitive ids, depth).
    Tree(InvalidTree),
    /// A writer was given a tree too large for the format (over `u32::MAX` bytes).
    TooLarge,
}

impl fmt::Display for BakeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Truncated { needed, available } => {
                write!(f, "baked data truncated: {available} bytes, need {needed}")
            }
            Self::WrongLength { expected, found } => {
                write!(f, "baked data is {found} bytes, its header says {expected}")
            }
            Self::BadMagic => write!(f, "not a baked raykernel file (bad magic)"),
            Self::UnsupportedVersion { version } => {
                write!(f, "baked format version {version} is not supported")
            }
            Self::BadField { offset } => write!(f, "bad header field at byte {offset}"),
            Self::BadChecksum { stored, computed } => write!(
                f,
                "checksum mismatch: header {stored:#010x}, data {computed:#010x}"
            ),
            Self::WrongStructure => write!(f, "baked file has another mode or structure"),
            Self::Misaligned { required } => {
                write!(f, "baked data must start at a multiple of {required} bytes")
            }
            Self::BigEndianTarget => write!(
                f,
                "baked data cannot be read in place on big-endian targets"
            ),
            Self::BadPrimitive { index } => write!(f, "baked triangle {index} is unusable"),
            Self::LeafTooSmall { node } => {
                write!(f, "leaf box of node {node} does not hold its triangles")
            }
            Self::Tree(e) => write!(f, "baked tree: {e}"),
            Self::TooLarge => write!(f, "tree too large for the baked format"),
        }
    }
}

impl core::error::Error for BakeError {}

impl From<InvalidTree> for BakeError {
    fn from(e: InvalidTree) -> Self {
        match e {
            InvalidTree::LeafTooSmall { node } => Self::LeafTooSmall { node: node as u32 },
            e => Self::Tree(e),
        }
    }
}
