//! OpenEXR output of a rendered frame: the linear image as 32-bit float RGB, the same values
//! the PFM holds (the `exr` crate, lossless compression), rows top to bottom as EXR stores them.

use crate::error::Error;
use crate::render::Frame;
use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
use std::io::Cursor;
use std::path::Path;

/// The OpenEXR bytes of `frame`: one layer with `R`, `G`, `B` channels of 32-bit floats.
///
/// # Errors
/// The encoder's message if the frame cannot be encoded (its pixels do not match its size).
pub fn encode_exr(frame: &Frame) -> Result<Vec<u8>, String> {
    let w = frame.width as usize;
    let h = frame.height as usize;
    if frame.linear.len() != w * h {
        return Err("frame size does not match its pixels".into());
    }
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = frame.linear[p.y() * w + p.x()];
        (r, g, b)
    });
    let mut bytes = Cursor::new(Vec::new());
    Image::from_channels((w, h), channels)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| format!("cannot encode OpenEXR: {e}"))?;
    Ok(bytes.into_inner())
}

/// Reads the RGB channels of an OpenEXR file's first layer as a frame (alpha, if any, is
/// dropped): the inverse of [`encode_exr`].
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
