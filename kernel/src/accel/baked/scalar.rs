//! How each number mode's coordinates are stored.

use super::format::BakedMode;
use super::plain::Plain;
use crate::scalar::{Scalar, I16F16};

/// A number mode that can be baked: `f32` (IEEE bits) and [`I16F16`] (raw `i32` bits), each
/// stored as one little-endian 32-bit word.
pub trait BakedScalar: Scalar + Plain {
    /// The `mode` field of files in this mode.
    const MODE: BakedMode;
    /// The stored word.
    fn to_word(self) -> u32;
}

impl BakedScalar for f32 {
    const MODE: BakedMode = BakedMode::F32;
    fn to_word(self) -> u32 {
        self.to_bits()
    }
}

impl BakedScalar for I16F16 {
    const MODE: BakedMode = BakedMode::Fixed;
    fn to_word(self) -> u32 {
        self.raw() as u32
    }
}
