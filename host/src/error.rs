//! The host's error type: one variant per source, each printing one self-contained line.

use crate::classify::ClassifyError;
use crate::obj::ObjError;
use crate::rayfile::FileError;
use raykernel::BuildError;
use std::fmt;
use std::path::PathBuf;

/// Anything a host command can fail with. Bad command lines are clap's business (exit code 2).
#[derive(Debug)]
pub enum Error {
    /// A bad or unreadable OBJ file.
    Obj(ObjError),
    /// A bad, unreadable or unwritable ray or hit file.
    File(FileError),
    /// The kernel refused to build the accelerator.
    Build {
        /// The scene.
        scene: PathBuf,
        /// Why.
        source: BuildError,
    },
    /// Two runs of the same trace gave different hits (the kernel is meant to be deterministic).
    RunsDiffer {
        /// The scene.
        scene: PathBuf,
        /// The run (1-based) that differs from the first.
        run: usize,
        /// The first ray (index in the ray file) whose hit differs.
        ray: usize,
    },
    /// `compare-hits --scene --rays`: the hits do not fit the scene or the ray file.
    Classify {
        /// The scene.
        scene: PathBuf,
        /// The ray file.
        rays: PathBuf,
        /// What does not fit.
        source: ClassifyError,
    },
    /// A bad or unreadable `.camera` file.
    Camera {
        /// The file.
        path: PathBuf,
        /// The line (1-based), if the problem is on one.
        line: Option<usize>,
        /// What is wrong.
        msg: String,
    },
    /// Arguments that parse but do not go together (exit code 2, like clap's).
    Usage(String),
    /// A bad scene: unreadable or malformed scene file, or values the kernel rejects.
    Scene {
        /// The scene file (or OBJ, or `built-in scene NAME`).
        file: String,
        /// The field, as a path into the scene file (`objects[2].spheres[0].radius`); empty
        /// when the problem is with the whole file.
        field: String,
        /// What is wrong, or what was expected.
        msg: String,
    },
    /// `host check`: two renders that must be byte-identical differ.
    Mismatch(String),
    /// An output could not be encoded or written.
    Output {
        /// The file.
        path: PathBuf,
        /// Why.
        msg: String,
    },
    /// Two hit files to compare hold different numbers of records.
    HitCountMismatch {
        /// The reference file and its record count.
        reference: (PathBuf, usize),
        /// The other file and its record count.
        other: (PathBuf, usize),
    },
}

impl Error {
    /// The process exit code for this error: 2 for [`Error::Usage`] (as for clap's argument
    /// errors), 1 otherwise.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Usage(_) => 2,
            _ => 1,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Obj(e) => e.fmt(f),
            Self::File(e) => e.fmt(f),
            Self::Build { scene, source } => {
                write!(f, "{}: cannot build the BVH: {source}", scene.display())
            }
            Self::RunsDiffer { scene, run, ray } => write!(
                f,
                "{}: run {run} gave different hits from run 1 (first at ray {ray})",
                scene.display()
            ),
            Self::Classify {
                scene,
                rays,
                source,
            } => write!(
                f,
                "cannot classify the differences against {} and {}: {source}",
                scene.display(),
                rays.display()
            ),
            Self::Camera { path, line, msg } => match line {
                Some(line) => write!(f, "{}:{line}: {msg}", path.display()),
                None => write!(f, "{}: {msg}", path.display()),
            },
            Self::Usage(msg) | Self::Mismatch(msg) => f.write_str(msg),
            Self::Scene { file, field, msg } if field.is_empty() => write!(f, "{file}: {msg}"),
            Self::Scene { file, field, msg } => write!(f, "{file}: {field}: {msg}"),
            Self::Output { path, msg } => write!(f, "{}: {msg}", path.display()),
            Self::HitCountMismatch { reference, other } => write!(
                f,
                "hit files differ in length: {} has {} records, {} has {}",
                reference.0.display(),
                reference.1,
                other.0.display(),
                other.1
            ),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Obj(e) => Some(e),
            Self::File(e) => Some(e),
            Self::Build { source, .. } => Some(source),
            Self::Classify { source, .. } => Some(source),
            Self::RunsDiffer { .. }
            | Self::Camera { .. }
            | Self::Usage(_)
            | Self::Scene { .. }
            | Self::Mismatch(_)
            | Self::Output { .. }
            | Self::HitCountMismatch { .. } => None,
        }
    }
}

impl From<ObjError> for Error {
    fn from(e: ObjError) -> Self {
        Self::Obj(e)
    }
}

impl From<FileError> for Error {
    fn from(e: FileError) -> Self {
        Self::File(e)
    }
}
