//! Reading input files: regular files only, never more than a stated number of bytes.
//!
//! A named pipe would block, `/dev/zero` would be read until memory runs out and a directory
//! gives an unhelpful OS error; each is refused up front with a message that says what the
//! path is. The size is checked twice: from the metadata before reading, and by reading at
//! most one byte past the limit (a file that grows while it is read is still bounded).

use std::fmt;
use std::io::Read;
use std::path::Path;

/// Why an input file could not be read.
#[derive(Debug)]
pub enum InputError {
    /// The OS refused (missing file, no permission, ...).
    Io(std::io::Error),
    /// The path exists but is not a regular file (a directory, pipe, socket or device).
    NotAFile {
        /// What it is instead: `a directory`, `a named pipe`, ...
        kind: &'static str,
    },
    /// The file is larger than the reader accepts.
    TooLarge {
        /// The file's size in bytes (or a lower bound, if it grew while being read).
        size: u64,
        /// The largest size accepted.
        limit: u64,
    },
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io(e) => write!(f, "{e}"),
            Self::NotAFile { kind } => write!(f, "is {kind}, not a regular file"),
            Self::TooLarge { size, limit } => write!(
                f,
                "file is {} bytes; at most {} bytes ({}) are accepted",
                size,
                limit,
                crate::limits::human_bytes(*limit)
            ),
        }
    }
}

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io(e) => Some(e),
            _ => None,
        }
    }
}

/// What a path that is not a regular file is, for messages.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
    }
    "not a regular file"
}

/// Reads the whole of `path`, which must be a regular file of at most `limit` bytes.
///
/// # Errors
/// [`InputError::NotAFile`] for directories, pipes, sockets and devices (checked before
/// opening, so a pipe never blocks), [`InputError::TooLarge`] past `limit`, and
/// [`InputError::Io`] for what the OS refuses.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    let meta = std::fs::metadata(path).map_err(InputError::Io)?;
    if !meta.is_file() {
        return Err(InputError::NotAFile {
            kind: kind_of(&meta),
        });
    }
    if meta.len() > limit {
        return Err(InputError::TooLarge {
            size: meta.len(),
            limit,
        });
    }
    let file = std::fs::File::open(path).map_err(InputError::Io)?;
    // The metadata's size, capped: a file that claims more than it holds is no problem.
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(InputError::Io)?;
    let read = bytes.len() as u64;
    if read > limit {
        return Err(InputError::TooLarge { size: read, limit });
    }
    Ok(bytes)
}

/// As [`read_limited`], as UTF-8 text without a leading byte-order mark.
///
/// # Errors
/// As [`read_limited`]; invalid UTF-8 is an [`InputError::Io`] of kind `InvalidData`.
pub fn read_text_limited(path: &Path, limit: u64) -> Result<String, InputError> {
    let bytes = read_limited(path, limit)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        InputError::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        ))
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("raykernel-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn regular_files_within_the_limit_are_read_whole() {
        let p = temp("ok.txt");
        std::fs::write(&p, b"\xef\xbb\xbfhello").unwrap();
        assert_eq!(read_limited(&p, 8).unwrap(), b"\xef\xbb\xbfhello");
        assert_eq!(read_text_limited(&p, 8).unwrap(), "hello");
        let e = read_limited(&p, 7).unwrap_err();
        assert!(
            matches!(e, InputError::TooLarge { size: 8, limit: 7 }),
            "{e}"
        );
    }

    #[test]
    fn directories_and_devices_are_refused_before_reading() {
        let dir = std::env::temp_dir();
        let e = read_limited(&dir, 1 << 20).unwrap_err();
        assert_eq!(e.to_string(), "is a directory, not a regular file");
        #[cfg(unix)]
        {
            let e = read_limited(Path::new("/dev/zero"), 1 << 20).unwrap_err();
            assert_eq!(e.to_string(), "is a device, not a regular file");
        }
    }
}
