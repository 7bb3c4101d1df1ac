//! Output files reserved before any work: the name must end in the extension of the format
//! written, and the file is opened (created if new) at once, so a missing or unwritable
//! directory fails before a render rather than after it.
//!
//! A reserved file is only truncated when its contents are written; one created by the
//! reservation and never written is removed again, so a failed command leaves no empty file.

use crate::error::Error;
use std::fs::{File, OpenOptions};
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

/// What an output holds, which fixes its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG (`--out`).
    Png,
    /// Linear PFM (`--linear`).
    Pfm,
    /// Linear OpenEXR (`--exr`).
    Exr,
    /// A scene file (`--dump-scene`).
    SceneFile,
}

impl Format {
    /// The extension a file of this format must have (compared case-insensitively).
    #[must_use]
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Pfm => "pfm",
            Self::Exr => "exr",
            Self::SceneFile => "json",
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Self::Png => "a PNG image (8-bit sRGB); PNG is the only image format of --out",
            Self::Pfm => "a PFM image (linear radiance)",
            Self::Exr => "an OpenEXR image (linear radiance)",
            Self::SceneFile => "a scene file (JSON)",
        }
    }
}

/// An output file opened ahead of the work that fills it.
#[derive(Debug)]
pub struct Reserved {
    path: PathBuf,
    file: Option<File>,
    created: bool,
}

impl Reserved {
    /// Checks `path`'s extension against `format` and opens it for writing, creating it if
    /// it does not exist (an existing file keeps its contents until [`Reserved::write`]).
    /// `flag` names the option in messages.
    ///
    /// # Errors
    /// [`Error::Usage`] for another extension; [`Error::Output`] if the directory does not
    /// exist or the file cannot be opened for writing.
    pub fn new(path: &Path, format: Format, flag: &str) -> Result<Self, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if ext.as_deref() != Some(format.extension()) {
            let found = ext.map_or("no extension".to_string(), |e| format!("`.{e}`"));
            return Err(Error::Usage(format!(
                "{flag} {}: {found}, but it writes {}: name the file `.{}`",
                path.display(),
                format.describe(),
                format.extension()
            )));
        }
        let fail = |msg: String| Error::Output {
            path: path.to_path_buf(),
            msg,
        };
        let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
        if let Some(dir) = parent {
            if !dir.is_dir() {
                return Err(fail(format!(
                    "cannot write: the directory {} does not exist",
                    dir.display()
                )));
            }
        }
        let created = !path.exists();
        let file = OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| fail(format!("cannot write: {e}")))?;
        Ok(Self {
            path: path.to_path_buf(),
            file: Some(file),
            created,
        })
    }

    /// The path.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Replaces the file's contents with `bytes`.
    ///
    /// # Errors
    /// [`Error::Output`] if writing fails.
    pub fn write(mut self, bytes: &[u8]) -> Result<(), Error> {
        let mut file = self.file.take().ok_or_else(|| Error::Output {
            path: self.path.clone(),
            msg: "written twice".into(),
        })?;
        let written = file
            .set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| file.write_all(bytes))
            .and_then(|()| file.flush());
        self.created = false;
        written.map_err(|e| Error::Output {
            path: self.path.clone(),
            msg: format!("cannot write: {e}"),
        })
    }
}

impl Drop for Reserved {
    fn drop(&mut self) {
        if self.created && self.file.take().is_some() {
            // Best effort: the command is failing already.
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty directory for one test.
    fn dir(name: &str) -> PathBuf {
        let pid = std::process::id();
        raykernel_testkit::empty_dir(
            std::env::temp_dir().join(format!("raykernel-out-{name}-{pid}")),
        )
    }

    #[test]
    fn the_extension_must_name_the_format() {
        let d = dir("ext");
        let e = Reserved::new(&d.join("pic.jpg"), Format::Png, "--out").unwrap_err();
        assert!(matches!(e, Error::Usage(_)), "{e}");
        assert!(e.to_string().contains("`.jpg`, but it writes a PNG"), "{e}");
        assert!(!d.join("pic.jpg").exists());
        assert!(Reserved::new(&d.join("PIC.PNG"), Format::Png, "--out").is_ok());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_missing_directory_fails_at_once_and_unused_files_are_removed() {
        let d = dir("missing");
        let e = Reserved::new(&d.join("no/such/pic.png"), Format::Png, "--out").unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let p = d.join("unused.png");
        drop(Reserved::new(&p, Format::Png, "--out").unwrap());
        assert!(!p.exists(), "an unwritten new file is removed");
        std::fs::write(&p, b"old contents").unwrap();
        drop(Reserved::new(&p, Format::Png, "--out").unwrap());
        assert_eq!(std::fs::read(&p).unwrap(), b"old contents");
        Reserved::new(&p, Format::Png, "--out")
            .unwrap()
            .write(b"new")
            .unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
