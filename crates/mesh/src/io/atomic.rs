//! Atomic file output: write under a temporary name, then rename.
//!
//! On Linux the content is written to an unnamed file in the destination's folder
//! (`open(2)` with `O_TMPFILE`): until it is complete and synced it has no name, so a
//! process killed outright (`SIGKILL`, a power cut) leaves nothing behind. It is then
//! linked under a temporary name and renamed over the destination, a window of two
//! system calls. Where the folder's file system has no unnamed files (or off Linux), the
//! content is written under the temporary name from the start.
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
    #[cfg(target_os = "linux")]
    if let Some(file) = unnamed::open(dir) {
        let file = fill_and_sync(file, fill).map_err(io)?;
        return unnamed::publish(&file, dir, path).map_err(io);
    }
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
    fill_and_sync(tmp.reopen().map_err(io)?, fill).map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Fills `file` through a buffer, flushes and syncs it, and gives it back.
fn fill_and_sync(
    file: File,
    fill: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> std::io::Result<File> {
    let mut writer = BufWriter::new(file);
    fill(&mut writer)?;
    writer.flush()?;
    let file = writer.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    Ok(file)
}

/// Unnamed files (`O_TMPFILE`, Linux 3.11 and later; tmpfs, ext4, xfs, btrfs).
#[cfg(target_os = "linux")]
mod unnamed {
    use std::ffi::CString;
    use std::fs::File;
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
    use std::os::unix::io::AsRawFd;
    use std::path::Path;
    use std::sync::atomic::{AtomicU64, Ordering};

    use super::{InFlight, PREFIX, SUFFIX};

    /// An unnamed file in `dir` with mode 0644, or `None` where the file system (or a
    /// missing `/proc`, needed to name it later) rules them out; the caller then writes
    /// under a name. Any other failure also gives `None`: the named road reports it.
    pub(super) fn open(dir: &Path) -> Option<File> {
        if !Path::new("/proc/self/fd").exists() {
            return None;
        }
        let file = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_TMPFILE)
            .mode(0o600)
            .open(dir)
            .ok()?;
        // The output gets the usual 0644 whatever the umask.
        file.set_permissions(std::fs::Permissions::from_mode(0o644))
            .ok()?;
        Some(file)
    }

    /// Gives the complete, synced unnamed `file` a temporary name in `dir` and renames it
    /// over `path`.
    pub(super) fn publish(file: &File, dir: &Path, path: &Path) -> std::io::Result<()> {
        let source = CString::new(format!("/proc/self/fd/{}", file.as_raw_fd()))
            .map_err(std::io::Error::other)?;
        loop {
            let name = dir.join(temporary_name());
            let target =
                CString::new(name.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
            // SAFETY: both paths are NUL-terminated strings that outlive the call.
            let linked = unsafe {
                libc::linkat(
                    libc::AT_FDCWD,
                    source.as_ptr(),
                    libc::AT_FDCWD,
                    target.as_ptr(),
                    libc::AT_SYMLINK_FOLLOW,
                )
            };
            if linked != 0 {
                let error = std::io::Error::last_os_error();
                if error.kind() == std::io::ErrorKind::AlreadyExists {
                    continue;
                }
                return Err(error);
            }
            let _registered = InFlight::new(&name);
            return std::fs::rename(&name, path).inspect_err(|_| {
                let _ = std::fs::remove_file(&name);
            });
        }
    }

    /// `.beltrami-<pid>-<n>.tmp`, `n` distinct within the process and across runs.
    fn temporary_name() -> String {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        format!("{PREFIX}{}-{nanos:x}{n:x}{SUFFIX}", std::process::id())
    }
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

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// Names in `dir` that start like a temporary file.
    fn temporary_files(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .filter_map(|e| e.file_name().to_str().map(str::to_owned))
            .filter(|n| n.starts_with(PREFIX))
            .collect()
    }

    #[test]
    fn a_write_in_progress_has_no_name_where_the_file_system_allows() {
        let dir = tempfile::tempdir().unwrap();
        if unnamed::open(dir.path()).is_none() {
            eprintln!(
                "SKIPPED: the file system of {:?} has no O_TMPFILE",
                dir.path()
            );
            return;
        }
        let out = dir.path().join("out.txt");
        write_atomically(&out, |w| {
            w.write_all(b"half")?;
            w.flush()?;
            assert_eq!(temporary_files(dir.path()), Vec::<String>::new());
            w.write_all(b" and the rest")
        })
        .unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"half and the rest");
        assert!(temporary_files(dir.path()).is_empty());
        let mode = std::os::unix::fs::PermissionsExt::mode(&out.metadata().unwrap().permissions());
        assert_eq!(mode & 0o777, 0o644);
    }

    #[test]
    fn a_write_replaces_the_old_content_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.txt");
        std::fs::write(&out, b"old").unwrap();
        write_atomically(&out, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"new");
        assert!(temporary_files(dir.path()).is_empty());
        let failed = write_atomically(&out, |_| Err(std::io::Error::other("fill failed")));
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&out).unwrap(), b"new");
        assert!(temporary_files(dir.path()).is_empty());
    }
}
