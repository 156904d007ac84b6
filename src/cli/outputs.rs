//! Output paths, checked before any work: every command that writes files calls
//! [`check`] with all of them first, so that a run that cannot write one of its outputs
//! fails before it reads, solves or writes anything (never "exits 1 but keeps the mesh").
//!
//! Each path is checked for what can be known in advance: its folder exists and is a
//! folder the program can create files in (by creating and removing a temporary file
//! there, named like the atomic writer's, see [`beltrami_mesh::io::write_atomically`]),
//! the path itself is not a folder, and no two outputs name the same file. Failures that
//! only show while writing (a full disk, a file-size limit) still leave earlier outputs
//! written; each file on its own is complete or absent.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};

/// Checks the output `paths` of one command, given as `(flag, path)` with the flag that
/// named it (`-o`, `--report`, ...) for the messages; `None` paths (options not given)
/// are skipped.
pub fn check(paths: &[(&str, Option<&Path>)]) -> anyhow::Result<()> {
    let mut seen: Vec<(&str, PathBuf)> = Vec::new();
    for &(flag, path) in paths {
        let Some(path) = path else { continue };
        if path.is_dir() {
            bail!("{flag} {}: is a folder, not a file", path.display());
        }
        let folder = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !folder.is_dir() {
            bail!(
                "{flag} {}: the folder {} does not exist",
                path.display(),
                folder.display()
            );
        }
        tempfile::Builder::new()
            .prefix(&format!(".beltrami-{}-", std::process::id()))
            .suffix(".tmp")
            .tempfile_in(folder)
            .with_context(|| {
                format!(
                    "{flag} {}: cannot create files in {}",
                    path.display(),
                    folder.display()
                )
            })?;
        // The same file under two names (`out.obj` and `./out.obj`) is caught through
        // the canonical folder.
        let key = std::fs::canonicalize(folder)
            .unwrap_or_else(|_| folder.to_path_buf())
            .join(path.file_name().unwrap_or_default());
        if let Some((other, _)) = seen.iter().find(|(_, k)| *k == key) {
            bail!(
                "{flag} and {other} both name {}: give each output its own file",
                path.display()
            );
        }
        seen.push((flag, key));
    }
    Ok(())
}
