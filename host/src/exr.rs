//! OpenEXR output of a rendered frame: the linear image as 32-bit float RGB, the same values
//! the PFM holds (the `exr` crate, lossless compression), rows top to bottom as EXR stores them.

use crate::error::Error;
use crate::render::Frame;
use std::path::Path;

/// Writes `frame` as an OpenEXR file with `R`, `G`, `B` channels of 32-bit floats.
///
/// # Errors
/// [`Error::Output`] if it cannot be encoded or written.
pub fn write_exr(path: &Path, frame: &Frame) -> Result<(), Error> {
    let w = frame.width as usize;
    let fail = |msg: String| Error::Output {
        path: path.to_path_buf(),
        msg,
    };
    if frame.linear.len() != w * frame.height as usize {
        return Err(fail("frame size does not match its pixels".into()));
    }
    exr::prelude::write_rgb_file(path, w, frame.height as usize, |x, y| {
        let [r, g, b] = frame.linear[y * w + x];
        (r, g, b)
    })
    .map_err(|e| fail(format!("cannot write OpenEXR: {e}")))
}

/// Reads the RGB channels of an OpenEXR file's first layer as a frame (alpha, if any, is
/// dropped): the inverse of [`write_exr`].
///
/// # Errors
/// [`Error::Output`] if the file cannot be read or is not an RGB(A) OpenEXR image.
pub fn read_exr(path: &Path) -> Result<Frame, Error> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| Frame {
            width: size.width() as u32,
            height: size.height() as u32,
            linear: vec![[0.0; 3]; size.width() * size.height()],
        },
        |frame, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = frame.width as usize;
            frame.linear[pos.y() * w + pos.x()] = [r, g, b];
        },
    )
    .map_err(|e| Error::Output {
        path: path.to_path_buf(),
        msg: format!("cannot read OpenEXR: {e}"),
    })?;
    Ok(image.layer_data.channel_data.pixels)
}
