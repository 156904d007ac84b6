//! Atomic file output: write under a temporary name, then rename.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::WriteError;

/// Writes a file through `fill` so that `path` either gets the complete content or is left
/// as it was.
///
/// The content goes to a temporary file in the same folder (so the final rename stays on
/// one file system and is atomic), is flushed and synced, and is renamed over `path`. If
/// `fill` or any step fails, the temporary file is removed and `path` is untouched.
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    let io = |error| WriteError::Io {
        path: path.to_path_buf(),
        error,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = tempfile::Builder::new()
        .prefix(".beltrami-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io)?;
    // Temporary files are private (0600); the output gets the usual 0644.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(io)?;
    }
    let mut writer = BufWriter::new(tmp.reopen().map_err(io)?);
    fill(&mut writer).map_err(io)?;
    writer.flush().map_err(io)?;
    writer.get_ref().sync_all().map_err(io)?;
    drop(writer);
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}
