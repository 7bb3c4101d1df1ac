//! Host side of raykernel: OBJ scenes, ray and hit files, and the `raykernel` command line.
//!
//! Everything the binary does lives here so it can be tested without spawning it:
//! - [`input`]: reading input files (regular files only, size-capped),
//! - [`limits`]: bounds on every resource a file or flag can request, and the memory check,
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
//! - [`render`]: parallel tiles over the kernel's renderer, PNG and PFM out,
//!   [`exr`]: OpenEXR out,
//! - [`check`]: every way of rendering gives the same bytes,
//! - [`snapshot`]: exact comparison with golden images and hashes,
//! - [`cli`]: the command line (clap) and the commands behind it,
//! - [`console`]: lines for people (summaries, warnings, progress) apart from the report,
//! - [`output`]: output files checked and reserved before the work,
//! - [`error`]: the error type `main` turns into a message and an exit code.
#![deny(unsafe_code)]

pub mod bake;
pub mod check;
pub mod classify;
pub mod cli;
pub mod compare;
pub mod console;
pub mod error;
pub mod exr;
pub mod gltf;
pub mod input;
pub mod limits;
pub mod mtl;
pub mod obj;
pub mod output;
pub mod pages;
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
