//! Wavefront OBJ reading (through `tobj`) and writing.

use std::path::Path;

use super::{RawMesh, ReadError, VertexAttributes, WriteError};
use crate::Mesh;

/// Reads an OBJ file.
pub fn read(path: &Path) -> Result<RawMesh, ReadError> {
    Err(ReadError::Obj {
        path: path.to_path_buf(),
        line: None,
        message: "not implemented yet".into(),
    })
}

/// Writes an OBJ file.
pub fn write(path: &Path, mesh: &Mesh, attributes: &VertexAttributes<'_>) -> Result<(), WriteError> {
    attributes.check(mesh)?;
    let _ = path;
    Ok(())
}
