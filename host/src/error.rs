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
    /// `raykernel check`: two renders that must be byte-identical differ.
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

/// Longest line [`for_terminal`] passes through whole, in characters.
pub const MAX_LINE_CHARS: usize = 400;

/// `text` made safe to print: control characters (other than line breaks) and the byte-order
/// mark escaped as `\u{..}`, and each line longer than [`MAX_LINE_CHARS`] cut to its start
/// and end around a note of how much was left out. Messages can quote what a file holds
/// (an unknown key, a bad token), which may be binary bytes or a string of any length.
#[must_use]
pub fn for_terminal(text: &str) -> String {
    let escape = |c: char| -> String {
        if (c.is_control() && c != '\t') || c == '\u{feff}' {
            c.escape_unicode().to_string()
        } else {
            c.to_string()
        }
    };
    text.split('\n')
        .map(|line| {
            let count = line.chars().count();
            if count <= MAX_LINE_CHARS {
                return line.chars().map(escape).collect::<String>();
            }
            let (head, tail) = (MAX_LINE_CHARS * 2 / 3, MAX_LINE_CHARS / 4);
            let start: String = line.chars().take(head).map(escape).collect();
            let end: String = line.chars().skip(count - tail).map(escape).collect();
            format!(
                "{start} [… {} characters left out …] {end}",
                count - head - tail
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// `text` with every run of more than `max` non-space characters cut to its start and end
/// around the count left out: keys and values quoted from a file stay readable, however long.
#[must_use]
pub fn shorten_long_words(text: &str, max: usize) -> String {
    let mut out = String::with_capacity(text.len().min(4 * max));
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let count = word.chars().count();
        if count > max {
            let head: String = word.chars().take(max / 2).collect();
            let tail: String = word.chars().skip(count - max / 4).collect();
            out.push_str(&format!(
                "{head}[… {} characters …]{tail}",
                count - max / 2 - max / 4
            ));
        } else {
            out.push_str(word);
        }
        word.clear();
    };
    for c in text.chars() {
        if c.is_whitespace() {
            flush(&mut word, &mut out);
            out.push(c);
        } else {
            word.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terminal_text_escapes_control_bytes_and_cuts_long_lines() {
        assert_eq!(for_terminal("plain\nlines"), "plain\nlines");
        assert_eq!(for_terminal("a\u{1b}[2Jb\0"), "a\\u{1b}[2Jb\\u{0}");
        assert_eq!(for_terminal("\u{feff}x"), "\\u{feff}x");
        let long = format!("unknown field `{}`, expected `name`", "x".repeat(100_000));
        let short = for_terminal(&long);
        assert!(short.chars().count() < MAX_LINE_CHARS + 60, "{short}");
        assert!(short.starts_with("unknown field `xxx"), "{short}");
        assert!(short.ends_with("expected `name`"), "{short}");
        assert!(short.contains("characters left out"), "{short}");
    }

    #[test]
    fn long_words_are_cut_in_the_middle() {
        assert_eq!(shorten_long_words("a bb  ccc", 3), "a bb  ccc");
        assert_eq!(
            shorten_long_words("key `abcdefghijkl`, x", 8),
            "key `abc[… 9 characters …]`, x"
        );
    }
}
