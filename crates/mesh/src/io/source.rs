//! Reading input files with bounds: only regular files, never more than they hold at the
//! start of the read, and never more than [`MAX_FILE_BYTES`].
//!
//! `std::fs::read` on a device (`/dev/zero`), a FIFO or a file that keeps growing reads
//! until memory runs out; a glTF buffer URI or a symbolic link named like a mesh can point
//! there. Every reader of user-named files goes through this module instead.

use std::fs::File;
use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The largest input file read, 4 GiB: beltrami addresses vertices and faces with `u32`
/// indices, and a mesh file that large would already exceed them.
pub const MAX_FILE_BYTES: u64 = 1 << 32;

/// Opens `path` if it is a regular file (after following links) and returns it with its
/// length, refusing devices, FIFOs, sockets, folders and files over [`MAX_FILE_BYTES`].
fn open_regular(path: &Path) -> Result<(File, u64), Error> {
    let file = File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            "not a regular file (a folder, device, FIFO or socket)",
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!(
                "the file has {} bytes, more than the {MAX_FILE_BYTES} bytes beltrami reads",
                meta.len()
            ),
        ));
    }
    Ok((file, meta.len()))
}

/// The length of the regular file `path` (refusing what [`read_bytes`] refuses).
pub fn regular_file_length(path: &Path) -> Result<u64, Error> {
    open_regular(path).map(|(_, len)| len)
}

/// The bytes of the regular file `path`, at most as many as it had when opened.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    let (file, len) = open_regular(path)?;
    read_exactly_up_to(file, len)
}

/// The text of the regular file `path` (UTF-8), at most as many bytes as it had when
/// opened.
pub fn read_text(path: &Path) -> Result<String, Error> {
    String::from_utf8(read_bytes(path)?)
        .map_err(|_| Error::new(ErrorKind::InvalidData, "the file is not UTF-8 text"))
}

/// The first `length` bytes of the regular file `path`; fails, before reading, when the
/// file is shorter.
pub fn read_prefix(path: &Path, length: u64) -> Result<Vec<u8>, Error> {
    let (file, len) = open_regular(path)?;
    if len < length {
        return Err(Error::new(
            ErrorKind::UnexpectedEof,
            format!("the file has {len} bytes, fewer than the {length} declared"),
        ));
    }
    read_exactly_up_to(file, length)
}

/// Up to `length` bytes of `file` (fewer if it shrank meanwhile).
fn read_exactly_up_to(file: File, length: u64) -> Result<Vec<u8>, Error> {
    // `length` <= MAX_FILE_BYTES fits in usize on 64-bit targets; elsewhere reserve lazily.
    let mut out = Vec::with_capacity(usize::try_from(length).unwrap_or(0));
    file.take(length).read_to_end(&mut out)?;
    Ok(out)
}
