//! The baked file's fixed layout: header fields, section offsets and the checksum.
//!
//! Little-endian throughout. A 128-byte header, then the node section at offset 128 (so a
//! buffer aligned to the node alignment has aligned nodes), the primitive ids (`u32` each),
//! then the triangles (nine coordinates each). `docs/BAKED_FORMAT.md` has the field table.

use super::error::BakeError;
use crate::accel::bvh::{BuildOptions, Node};
use crate::accel::wide::Node4;
use crate::accel::AccelKind;

/// The first eight bytes of every baked file.
pub const MAGIC: [u8; 8] = *b"RKBAKED\0";
/// The format version this kernel writes and reads.
pub const VERSION: u32 = 1;
/// Header length in bytes; the node section starts here.
pub const HEADER_LEN: usize = 128;
/// Bytes of one baked triangle: nine 32-bit coordinates.
pub const TRIANGLE_LEN: usize = 36;
/// `flags` bit: the triangles are stored in leaf order (`prims[i]` has id `prim_ids[i]`).
pub const FLAG_LEAF_ORDER: u32 = 1;

/// Byte offsets of the header fields (each a little-endian `u32` except the magic).
pub(crate) mod field {
    pub const MAGIC: usize = 0;
    pub const VERSION: usize = 8;
    pub const MODE: usize = 12;
    pub const KIND: usize = 16;
    pub const FLAGS: usize = 20;
    pub const PRIM_COUNT: usize = 24;
    pub const NODE_COUNT: usize = 28;
    pub const DEPTH: usize = 32;
    pub const NODES_OFFSET: usize = 36;
    pub const IDS_OFFSET: usize = 40;
    pub const PRIMS_OFFSET: usize = 44;
    pub const TOTAL_LEN: usize = 48;
    pub const CHECKSUM: usize = 52;
    /// First reserved byte; bytes `RESERVED..HEADER_LEN` are zero.
    pub const RESERVED: usize = 56;
}

/// Number mode of a baked file (`mode` field).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum BakedMode {
    /// `f32` coordinates (IEEE bits).
    F32 = 1,
    /// [`crate::I16F16`] coordinates (raw Q16.16 `i32`).
    Fixed = 2,
}

/// Structure kind of a baked file (`kind` field).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum BakedKind {
    /// Binary BVH: 32-byte [`Node`]s, buffer aligned to 32 bytes.
    Bvh = 1,
    /// 4-wide BVH: 128-byte [`Node4`]s, buffer aligned to 128 bytes.
    Bvh4 = 2,
}

impl BakedKind {
    /// The structure's name, as [`crate::AccelKind::name`] gives it: `bvh` or `bvh4`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Bvh => "bvh",
            Self::Bvh4 => "bvh4",
        }
    }
    /// The accelerator a tree of this kind is built as, with `options`.
    #[must_use]
    pub const fn accel(self, options: BuildOptions) -> AccelKind {
        match self {
            Self::Bvh => AccelKind::Bvh(options),
            Self::Bvh4 => AccelKind::Bvh4(options),
        }
    }
    /// Bytes of one node.
    #[must_use]
    pub const fn node_len(self) -> usize {
        match self {
            Self::Bvh => core::mem::size_of::<Node<f32>>(),
            Self::Bvh4 => core::mem::size_of::<Node4<f32>>(),
        }
    }
    /// Alignment the start of the buffer needs for zero-copy loading.
    #[must_use]
    pub const fn align(self) -> usize {
        match self {
            Self::Bvh => core::mem::align_of::<Node<f32>>(),
            Self::Bvh4 => core::mem::align_of::<Node4<f32>>(),
        }
    }
}

/// Alignment that suffices for every baked file (the 4-wide node's).
pub const MAX_ALIGN: usize = BakedKind::Bvh4.align();

/// The decoded header of a baked file whose length, layout and checksum are consistent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// Number mode.
    pub mode: BakedMode,
    /// Structure kind.
    pub kind: BakedKind,
    /// Triangles are stored in leaf order.
    pub leaf_order: bool,
    /// Triangles (and primitive ids).
    pub prim_count: u32,
    /// Nodes in use.
    pub node_count: u32,
    /// Depth of the deepest leaf (binary) or wide node (4-wide), root 0.
    pub depth: u32,
}

/// Where each section sits, in bytes from the start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Layout {
    pub nodes: usize,
    pub ids: usize,
    pub prims: usize,
    pub total: usize,
}

impl Layout {
    /// Offsets for `node_count` nodes of `kind` and `prim_count` triangles; `None` if the file
    /// would exceed `u32::MAX` bytes.
    pub(crate) fn of(kind: BakedKind, node_count: u32, prim_count: u32) -> Option<Self> {
        let (nodes, prims) = (node_count as u64, prim_count as u64);
        let ids = HEADER_LEN as u64 + nodes * kind.node_len() as u64;
        let tris = ids + prims * 4;
        let total = tris + prims * TRIANGLE_LEN as u64;
        if total > u64::from(u32::MAX) {
            return None;
        }
        Some(Self {
            nodes: HEADER_LEN,
            ids: usize::try_from(ids).ok()?,
            prims: usize::try_from(tris).ok()?,
            total: usize::try_from(total).ok()?,
        })
    }
}

/// FNV-1a (32-bit) of the whole file with the four checksum bytes skipped: the value of the
/// `checksum` field. `bytes` shorter than the header are hashed as they are.
#[must_use]
pub fn checksum(bytes: &[u8]) -> u32 {
    const OFFSET_BASIS: u32 = 0x811c_9dc5;
    const PRIME: u32 = 0x0100_0193;
    let skip = field::CHECKSUM..field::CHECKSUM + 4;
    let mut h = OFFSET_BASIS;
    for (i, &b) in bytes.iter().enumerate() {
        if !skip.contains(&i) {
            h = (h ^ u32::from(b)).wrapping_mul(PRIME);
        }
    }
    h
}

/// The little-endian `u32` at `offset` (0 past the end, which callers rule out first).
pub(crate) fn word(bytes: &[u8], offset: usize) -> u32 {
    let mut w = [0u8; 4];
    if let Some(src) = bytes.get(offset..offset + 4) {
        w.copy_from_slice(src);
    }
    u32::from_le_bytes(w)
}

/// Reads and checks the header: magic, version, mode, kind, flags, reserved bytes, counts,
/// section offsets, total length (must equal `bytes.len()`) and checksum. Does not look at
/// the sections' contents or the buffer's alignment.
///
/// # Errors
/// The first inconsistency: [`BakeError::Truncated`], [`BakeError::BadMagic`],
/// [`BakeError::UnsupportedVersion`], [`BakeError::BadField`], [`BakeError::WrongLength`] (with the field's offset),
/// [`BakeError::BadChecksum`].
pub fn read_header(bytes: &[u8]) -> Result<Header, BakeError> {
    checked_header(bytes, None).map(|(header, _)| header)
}

/// [`read_header`], with the section layout it checked the header against. With `expect`,
/// a file of another mode or kind is refused as soon as those fields are read
/// ([`BakeError::WrongStructure`]), so a loader links the checks of its own kind only.
pub(crate) fn checked_header(
    bytes: &[u8],
    expect: Option<(BakedMode, BakedKind)>,
) -> Result<(Header, Layout), BakeError> {
    if bytes.len() < HEADER_LEN {
        return Err(BakeError::Truncated {
            needed: HEADER_LEN,
            available: bytes.len(),
        });
    }
    // As a fixed-size array, compared in two words (a slice comparison calls `memcmp`).
    let magic: Option<[u8; 8]> = bytes
        .get(field::MAGIC..field::MAGIC + 8)
        .and_then(|m| m.try_into().ok());
    if magic != Some(MAGIC) {
        return Err(BakeError::BadMagic);
    }
    let version = word(bytes, field::VERSION);
    if version != VERSION {
        return Err(BakeError::UnsupportedVersion { version });
    }
    let bad = |offset: usize| BakeError::BadField {
        offset: offset as u32,
    };
    let mode = match word(bytes, field::MODE) {
        1 => BakedMode::F32,
        2 => BakedMode::Fixed,
        _ => return Err(bad(field::MODE)),
    };
    let kind = match word(bytes, field::KIND) {
        1 => BakedKind::Bvh,
        2 => BakedKind::Bvh4,
        _ => return Err(bad(field::KIND)),
    };
    if expect.is_some_and(|wanted| wanted != (mode, kind)) {
        return Err(BakeError::WrongStructure);
    }
    let flags = word(bytes, field::FLAGS);
    if flags & !FLAG_LEAF_ORDER != 0 {
        return Err(bad(field::FLAGS));
    }
    if let Some(at) = (field::RESERVED..HEADER_LEN).find(|&i| bytes.get(i) != Some(&0)) {
        return Err(bad(at));
    }
    let prim_count = word(bytes, field::PRIM_COUNT);
    let node_count = word(bytes, field::NODE_COUNT);
    // A tree over n primitives uses 0 nodes if n == 0, otherwise at least 1 and at most the
    // builder's worst case.
    let most = match kind {
        BakedKind::Bvh => crate::bvh::nodes_needed(prim_count as usize),
        BakedKind::Bvh4 => crate::bvh4::nodes4_needed(prim_count as usize),
    };
    if prim_count == u32::MAX {
        return Err(bad(field::PRIM_COUNT));
    }
    if node_count as usize > most || (node_count == 0) != (prim_count == 0) {
        return Err(bad(field::NODE_COUNT));
    }
    let depth = word(bytes, field::DEPTH);
    if depth as usize > crate::bvh::MAX_DEPTH {
        return Err(bad(field::DEPTH));
    }
    let layout = Layout::of(kind, node_count, prim_count).ok_or(bad(field::NODE_COUNT))?;
    let expect = [
        (field::NODES_OFFSET, layout.nodes),
        (field::IDS_OFFSET, layout.ids),
        (field::PRIMS_OFFSET, layout.prims),
        (field::TOTAL_LEN, layout.total),
    ];
    for (at, value) in expect {
        if word(bytes, at) as usize != value {
            return Err(bad(at));
        }
    }
    if bytes.len() != layout.total {
        return Err(BakeError::WrongLength {
            expected: layout.total,
            found: bytes.len(),
        });
    }
    let (stored, computed) = (word(bytes, field::CHECKSUM), checksum(bytes));
    if stored != computed {
        return Err(BakeError::BadChecksum { stored, computed });
    }
    let header = Header {
        mode,
        kind,
        leaf_order: flags & FLAG_LEAF_ORDER != 0,
        prim_count,
        node_count,
        depth,
    };
    Ok((header, layout))
}
