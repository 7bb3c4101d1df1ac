//! The one check of a builder's input, shared by every structure.

use super::BuildError;
use crate::geom::Primitive;
use crate::scalar::Scalar;

/// Most primitives any accelerator accepts. Every structure stores primitive ids and
/// reference indices in 32-bit words, the kd-tree's node word keeps two bits of them for the
/// split axis and the leaf-order permutation one bit as a mark, so one limit below all of
/// those holds for every structure.
pub const MAX_PRIMS: usize = 1 << 28;

/// [`BuildError::TooManyPrims`] unless `count <= MAX_PRIMS`.
pub(crate) const fn check_count(count: usize) -> Result<(), BuildError> {
    if count > MAX_PRIMS {
        Err(BuildError::TooManyPrims { count })
    } else {
        Ok(())
    }
}

/// [`BuildError::BadPrimitive`] for the first primitive whose data [`Primitive::check`]
/// rejects.
pub(crate) fn check_each<S: Scalar, P: Primitive<S>>(prims: &[P]) -> Result<(), BuildError> {
    for (prim, p) in prims.iter().enumerate() {
        p.check().map_err(|e| BuildError::BadPrimitive {
            prim,
            vertex: e.vertex,
            error: e.error,
        })?;
    }
    Ok(())
}
