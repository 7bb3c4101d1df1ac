//! The generated blocks of `docs/PLATFORMS.md`, `docs/STRESS.md` and the README: each sits
//! between a begin and an end marker and is replaced whole by the command that owns it.

use std::path::{Path, PathBuf};

/// The documents that hold generated blocks.
#[derive(Clone, Copy)]
pub enum Doc {
    Platforms,
    Stress,
    Readme,
}

fn doc_path(doc: Doc) -> PathBuf {
    let file = match doc {
        Doc::Platforms => "../docs/PLATFORMS.md",
        Doc::Stress => "../docs/STRESS.md",
        Doc::Readme => "../README.md",
    };
    Path::new(env!("CARGO_MANIFEST_DIR")).join(file)
}

/// Replaces the block called `name` of `doc` with `body`; false (and a message) if the file or
/// its markers are missing.
pub fn write_block(doc: Doc, name: &str, body: &str) -> bool {
    let path = doc_path(doc);
    let begin = format!("<!-- begin {name}: generated, do not edit -->\n");
    let end = format!("<!-- end {name} -->");
    let Ok(text) = std::fs::read_to_string(&path) else {
        println!("cannot read {}", path.display());
        return false;
    };
    let Some((head, rest)) = text.split_once(&begin) else {
        println!("{}: no `{}` marker", path.display(), begin.trim());
        return false;
    };
    let Some((_, tail)) = rest.split_once(&end) else {
        println!("{}: no `{end}` marker", path.display());
        return false;
    };
    let new = format!("{head}{begin}{body}{end}{tail}");
    if new != text {
        if let Err(e) = std::fs::write(&path, new) {
            println!("cannot write {}: {e}", path.display());
            return false;
        }
    }
    println!("wrote the {name} block of {}", path.display());
    true
}
