//! Reading validated bytes as nodes, ids and triangles in place: the baked loader's only
//! `unsafe`.
//!
//! Why not safe code: a safe loader must copy (or decode on every access) the nodes, ids and
//! triangles, so the structure would need as much RAM as the file has bytes, where in place
//! it stays in flash and needs none; and a decoding view would need its own traversal, a
//! second copy of the one every tree uses. The cast is sound because every bit pattern is a
//! valid value of the target types (checked here: size, alignment), and the loader checks
//! every invariant the safe code relies on before handing the slices out.

use super::format::TRIANGLE_LEN;
use crate::accel::bvh::Node;
use crate::accel::wide::Node4;
use crate::geom::Triangle;
use crate::scalar::{Scalar, I16F16};

/// Plain old data: every bit pattern of `size_of::<Self>()` bytes is a valid value, the
/// type has no interior mutability, and its bytes are the baked format's little-endian
/// encoding on a little-endian target.
///
/// # Safety
/// Implement only for types with those properties (the list below is the complete one).
#[allow(unsafe_code)]
pub unsafe trait Plain: Copy {}

// SAFETY: integers and IEEE floats of 32 bits; any bits are a value.
#[allow(unsafe_code)]
unsafe impl Plain for u32 {}
// SAFETY: as for u32 (NaNs are values; the loader rejects them where they matter).
#[allow(unsafe_code)]
unsafe impl Plain for f32 {}
// SAFETY: `#[repr(transparent)]` over `i32`.
#[allow(unsafe_code)]
unsafe impl Plain for I16F16 {}
// SAFETY: one field, `[[S; 3]; 3]` of a `Plain` S; the asserts below show the struct is
// exactly that array (no padding, field at offset 0) for both scalars.
#[allow(unsafe_code)]
unsafe impl<S: Scalar + Plain> Plain for Triangle<S> {}
// SAFETY: `#[repr(C)]` of `[S; 3]`, `u32`, `[S; 3]`, `u32`, all `Plain`.
#[allow(unsafe_code)]
unsafe impl<S: Scalar + Plain> Plain for Node<S> {}
// SAFETY: `#[repr(C)]` of arrays of `S` and `u32`, all `Plain`.
#[allow(unsafe_code)]
unsafe impl<S: Scalar + Plain> Plain for Node4<S> {}

const _: () = {
    use core::mem::{offset_of, size_of};
    assert!(size_of::<Triangle<f32>>() == TRIANGLE_LEN);
    assert!(size_of::<Triangle<I16F16>>() == TRIANGLE_LEN);
    assert!(offset_of!(Triangle<f32>, v) == 0 && offset_of!(Triangle<I16F16>, v) == 0);
    assert!(size_of::<I16F16>() == 4 && size_of::<f32>() == 4);
    assert!(size_of::<Node<I16F16>>() == 32 && size_of::<Node4<I16F16>>() == 128);
};

/// The `count` values of `T` stored from byte `start` of `bytes`, in place, if they lie within
/// `bytes`, their start is aligned for `T` and the target is little-endian.
pub(crate) fn cast_section<T: Plain>(bytes: &[u8], start: usize, count: usize) -> Option<&[T]> {
    let len = count.checked_mul(core::mem::size_of::<T>())?;
    let section = bytes.get(start..start.checked_add(len)?)?;
    let aligned = (section.as_ptr() as usize) % core::mem::align_of::<T>() == 0;
    if cfg!(target_endian = "big") || !aligned {
        return None;
    }
    // SAFETY: the pointer is non-null, aligned for `T` (checked) and valid for reads of
    // `count * size_of::<T>()` bytes (the whole of `section`) for the lifetime of `bytes`, which
    // nobody can mutate meanwhile (shared borrow; `T` has no interior mutability). Every bit
    // pattern is a valid `T` (`Plain`).
    #[allow(unsafe_code)]
    let slice = unsafe { core::slice::from_raw_parts(section.as_ptr().cast::<T>(), count) };
    Some(slice)
}
