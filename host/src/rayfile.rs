//! Ray and hit files (see `shared/bench/WORKLOAD.md`): headerless arrays of little-endian
//! records.
//!
//! - Ray: 32 bytes, `ox oy oz dx dy dz tmin tmax`, eight `f32`.
//! - Hit: 8 bytes, `t: f32, prim: u32`; a miss is `t = +inf, prim = u32::MAX`.

use crate::input::{read_limited, InputError};
use crate::limits::MAX_RAY_FILE_BYTES;
use std::fmt;
use std::path::{Path, PathBuf};

/// One ray as stored in a ray file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayRecord {
    /// Origin.
    pub origin: [f32; 3],
    /// Direction (need not be unit length; the kernel normalises it).
    pub dir: [f32; 3],
    /// Start of the interval.
    pub t_min: f32,
    /// End of the interval (may be `+inf`).
    pub t_max: f32,
}

impl RayRecord {
    /// Bytes per record.
    pub const SIZE: usize = 32;

    /// A ray over `[0, +inf]`.
    #[must_use]
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Self {
        Self {
            origin,
            dir,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// The little-endian record.
    #[must_use]
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        let fields = [
            self.origin[0],
            self.origin[1],
            self.origin[2],
            self.dir[0],
            self.dir[1],
            self.dir[2],
            self.t_min,
            self.t_max,
        ];
        let mut out = [0u8; Self::SIZE];
        for (chunk, x) in out.chunks_exact_mut(4).zip(fields) {
            chunk.copy_from_slice(&x.to_le_bytes());
        }
        out
    }

    /// Reads one record.
    #[must_use]
    pub fn from_bytes(b: &[u8; Self::SIZE]) -> Self {
        let f = |i: usize| f32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]]);
        Self {
            origin: [f(0), f(1), f(2)],
            dir: [f(3), f(4), f(5)],
            t_min: f(6),
            t_max: f(7),
        }
    }
}

/// One closest-hit result as stored in a hit file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// Distance along the unit direction; `+inf` on a miss.
    pub t: f32,
    /// Triangle id; `u32::MAX` on a miss.
    pub prim: u32,
}

impl HitRecord {
    /// Bytes per record.
    pub const SIZE: usize = 8;
    /// The record of a miss (also written for rays the kernel rejects).
    pub const MISS: Self = Self {
        t: f32::INFINITY,
        prim: u32::MAX,
    };

    /// True unless this is a miss.
    #[must_use]
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }

    /// The little-endian record.
    #[must_use]
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        let mut out = [0u8; Self::SIZE];
        out[..4].copy_from_slice(&self.t.to_le_bytes());
        out[4..].copy_from_slice(&self.prim.to_le_bytes());
        out
    }

    /// Reads one record.
    #[must_use]
    pub fn from_bytes(b: &[u8; Self::SIZE]) -> Self {
        Self {
            t: f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            prim: u32::from_le_bytes([b[4], b[5], b[6], b[7]]),
        }
    }
}

/// A ray or hit file could not be read, written, or has the wrong length.
#[derive(Debug)]
pub enum FileError {
    /// Reading failed (missing, not a regular file, larger than [`MAX_RAY_FILE_BYTES`]).
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: InputError,
    },
    /// Writing failed.
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The length is not a whole number of records.
    Length {
        /// The file.
        path: PathBuf,
        /// Its length in bytes.
        len: usize,
        /// `ray` or `hit`.
        what: &'static str,
        /// Bytes per record.
        record: usize,
    },
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read { path, source } => write!(f, "{}: cannot read: {source}", path.display()),
            Self::Write { path, source } => {
                write!(f, "{}: cannot write: {source}", path.display())
            }
            Self::Length {
                path,
                len,
                what,
                record,
            } => write!(
                f,
                "{}: not a {what} file: length {len} bytes is not a multiple of {record} \
                 ({} whole records and {} bytes left over)",
                path.display(),
                len / record,
                len % record
            ),
        }
    }
}

impl std::error::Error for FileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Read { source, .. } => Some(source),
            Self::Write { source, .. } => Some(source),
            Self::Length { .. } => None,
        }
    }
}

fn read(path: &Path) -> Result<Vec<u8>, FileError> {
    read_limited(path, MAX_RAY_FILE_BYTES).map_err(|source| FileError::Read {
        path: path.to_path_buf(),
        source,
    })
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    std::fs::write(path, bytes).map_err(|source| FileError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Splits `bytes` into `N`-byte records, or explains why it cannot.
fn records<'b, const N: usize>(
    bytes: &'b [u8],
    path: &Path,
    what: &'static str,
) -> Result<impl Iterator<Item = &'b [u8; N]>, FileError> {
    if bytes.len() % N == 0 {
        // Every chunk has N bytes, so the conversion cannot fail.
        Ok(bytes.chunks_exact(N).flat_map(<&[u8; N]>::try_from))
    } else {
        Err(FileError::Length {
            path: path.to_path_buf(),
            len: bytes.len(),
            what,
            record: N,
        })
    }
}

/// Parses a ray file's bytes; `path` only labels errors.
///
/// # Errors
/// [`FileError::Length`] unless the length is a multiple of 32.
pub fn parse_rays(bytes: &[u8], path: &Path) -> Result<Vec<RayRecord>, FileError> {
    Ok(records::<{ RayRecord::SIZE }>(bytes, path, "ray")?
        .map(RayRecord::from_bytes)
        .collect())
}

/// The records a trace at `stride` takes (`0, stride, 2·stride, ...`; stride 0 counts as 1),
/// copied next to each other.
///
/// Gathered once, before any timing, by whoever owns the records: timed loops then read their
/// records in order. Read in place at a stride of 8, the 32-byte records of a ray file are 256
/// bytes apart, each on its own cache line, and a large file costs a memory access per ray
/// that a caller reading its rays in order does not pay (and that depended on how much of it
/// the code around the loop happened to hide).
#[must_use]
pub fn every(rays: &[RayRecord], stride: usize) -> Vec<RayRecord> {
    rays.iter().step_by(stride.max(1)).copied().collect()
}

/// Reads a ray file.
///
/// # Errors
/// [`FileError::Read`] or [`FileError::Length`].
pub fn read_rays(path: &Path) -> Result<Vec<RayRecord>, FileError> {
    parse_rays(&read(path)?, path)
}

/// The bytes of a ray file.
#[must_use]
pub fn encode_rays(rays: &[RayRecord]) -> Vec<u8> {
    rays.iter().flat_map(RayRecord::to_bytes).collect()
}

/// Writes a ray file.
///
/// # Errors
/// [`FileError::Write`].
pub fn write_rays(path: &Path, rays: &[RayRecord]) -> Result<(), FileError> {
    write(path, &encode_rays(rays))
}

/// Parses a hit file's bytes; `path` only labels errors.
///
/// # Errors
/// [`FileError::Length`] unless the length is a multiple of 8.
pub fn parse_hits(bytes: &[u8], path: &Path) -> Result<Vec<HitRecord>, FileError> {
    Ok(records::<{ HitRecord::SIZE }>(bytes, path, "hit")?
        .map(HitRecord::from_bytes)
        .collect())
}

/// Reads a hit file.
///
/// # Errors
/// [`FileError::Read`] or [`FileError::Length`].
pub fn read_hits(path: &Path) -> Result<Vec<HitRecord>, FileError> {
    parse_hits(&read(path)?, path)
}

/// The bytes of a hit file.
#[must_use]
pub fn encode_hits(hits: &[HitRecord]) -> Vec<u8> {
    hits.iter().flat_map(HitRecord::to_bytes).collect()
}

/// Writes a hit file.
///
/// # Errors
/// [`FileError::Write`].
pub fn write_hits(path: &Path, hits: &[HitRecord]) -> Result<(), FileError> {
    write(path, &encode_hits(hits))
}
