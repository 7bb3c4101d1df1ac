//! The benchmark's error: a host error (scene, ray file, build), or a missing input or failed
//! step of the benchmark itself, said with what to do about it.

use std::fmt;

/// Why the benchmark stopped.
#[derive(Debug)]
pub enum Error {
    /// Loading a scene or ray file, or a build the kernel refused.
    Host(host::Error),
    /// A missing input (scenes, ray files, the scripts) or a failed step.
    Bench(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Host(e) => e.fmt(f),
            Self::Bench(msg) => write!(f, "bench: {msg}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Host(e) => Some(e),
            Self::Bench(_) => None,
        }
    }
}

impl From<host::Error> for Error {
    fn from(e: host::Error) -> Self {
        Self::Host(e)
    }
}

impl From<host::ObjError> for Error {
    fn from(e: host::ObjError) -> Self {
        Self::Host(e.into())
    }
}

impl From<host::FileError> for Error {
    fn from(e: host::FileError) -> Self {
        Self::Host(e.into())
    }
}
