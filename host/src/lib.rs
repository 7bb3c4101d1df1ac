//! Host side of raykernel: OBJ scenes, ray and hit files, and the `host` command line.
//!
//! Everything the binary does lives here so it can be tested without spawning it:
//! - [`obj`]: OBJ reader with `file:line` errors, [`mtl`]: its MTL materials,
//! - [`gltf`]: glTF 2.0 scenes,
//! - [`rayfile`]: ray and hit file records,
//! - [`trace`]: build an accelerator and trace rays, generic over the kernel's scalar modes,
//! - [`compare`]: agreement between two hit files,
//! - [`classify`]: whether rays on which two hit files differ pass within quantization error of
//!   an edge,
//! - [`spec`]: a scene the host owns, and kernel errors mapped back to its fields,
//! - [`scenefile`]: the JSON scene format (load, dump),
//! - [`scene`]: what a SCENE argument names (built-in, scene file, OBJ with camera and lights),
//! - [`render`]: parallel tiles over the kernel's distribution ray tracer, PNG and PFM out,
//!   [`exr`]: OpenEXR out,
//! - [`check`]: every way of rendering gives the same bytes,
//! - [`snapshot`]: exact comparison with golden images and hashes,
//! - [`bench`]: `host bench`, speed and accuracy with peers in one run (report, data, plots),
//! - [`cli`]: the command line (clap) and the commands behind it,
//! - [`error`]: the error type `main` turns into a message and an exit code.
#![forbid(unsafe_code)]

pub mod bench;
pub mod check;
pub mod classify;
pub mod cli;
pub mod compare;
pub mod error;
pub mod exr;
pub mod gltf;
pub mod mesh;
pub mod mtl;
pub mod obj;
pub mod rayfile;
pub mod render;
pub mod scene;
pub mod scenefile;
pub mod snapshot;
pub mod spec;
pub mod trace;

pub use error::Error;
pub use obj::{load_obj, parse_obj, Mesh, ObjError, ObjErrorKind};
pub use rayfile::{FileError, HitRecord, RayRecord};
