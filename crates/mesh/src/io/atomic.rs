//! Atomic file output: write under a temporary name, then rename.
//!
//! Temporary files are named `.beltrami-<pid>-<random>.tmp` in the destination's folder.
//! They are removed on every failure the process sees (an error while filling, flushing,
//! syncing or renaming; a full disk; a file-size limit, once the program ignores
//! `SIGXFSZ` so that the write fails with `EFBIG` instead of killing it). A process that
//! is killed outright cannot clean up: the next write into the same folder removes the
//! temporary files of processes that no longer run ([`remove_stale`]). A process asked
//! to end (the command line's `SIGTERM`, which a batch job gets when its batch dies)
//! removes the temporary files it is writing first ([`remove_in_flight`]).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::WriteError;

/// The start of every temporary file name, followed by the writer's process id.
const PREFIX: &str = ".beltrami-";
/// The end of every temporary file name.
const SUFFIX: &str = ".tmp";

/// The temporary files this process is writing (registered while they exist).
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Keeps a temporary file's path in [`IN_FLIGHT`] while it lives.
struct InFlight(PathBuf);

impl InFlight {
    fn new(path: &Path) -> Self {
        if let Ok(mut list) = IN_FLIGHT.lock() {
            list.push(path.to_path_buf());
        }
        Self(path.to_path_buf())
    }
}

impl Drop for InFlight {
    fn drop(&mut self) {
        if let Ok(mut list) = IN_FLIGHT.lock()
            && let Some(k) = list.iter().position(|p| *p == self.0)
        {
            list.swap_remove(k);
        }
    }
}

/// Removes the temporary files this process is writing now, and returns how many: for
/// a process about to end on a signal (the writes in progress never finish). Their
/// destinations are left as they were.
pub fn remove_in_flight() -> usize {
    let Ok(list) = IN_FLIGHT.lock() else {
        return 0;
    };
    list.iter()
        .filter(|path| std::fs::remove_file(path).is_ok())
        .count()
}

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
    remove_stale(dir);
    let prefix = format!("{PREFIX}{}-", std::process::id());
    let tmp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(SUFFIX)
        .tempfile_in(dir)
        .map_err(io)?;
    let _registered = InFlight::new(tmp.path());
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

/// Removes the temporary files in `dir` left by beltrami processes that no longer run
/// (names `.beltrami-<pid>-*.tmp` whose process is gone). Only on systems with `/proc`,
/// where a process's liveness can be told without extra dependencies; failures are
/// ignored (a stale file is harmless, and the write itself does not depend on this).
pub fn remove_stale(dir: &Path) {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(PREFIX))
            .filter(|n| n.ends_with(SUFFIX))
            .and_then(|n| n.split_once('-'))
            .and_then(|(pid, _)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !proc.join(pid.to_string()).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}
