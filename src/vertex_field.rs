//! Per-vertex scalar fields of a mesh for `beltrami register --features`: a file with
//! one value per vertex, or a field computed from the mesh.
//!
//! # Format
//!
//! One number per line, for the mesh file's vertices in its own order (0-based input
//! order, [`beltrami_mesh::VertexMap`]); `#` starts a comment, blank lines are skipped.
//! Values of vertices the mesh dropped on loading (unreferenced or merged) are read and
//! ignored. Errors ([`VertexFieldError`]) name the file and the 1-based line.
//!
//! Computed fields, given by name instead of a path:
//!
//! - `mean-curvature`: the signed mean curvature of each vertex
//!   ([`beltrami_fem::mean_curvature::mean_curvature`]).

use std::path::{Path, PathBuf};

use beltrami_mesh::Mesh;
use thiserror::Error;

/// The names of the computed fields.
pub const COMPUTED: &[&str] = &["mean-curvature"];

/// Why a field could not be had.
#[derive(Debug, Error)]
pub enum VertexFieldError {
    /// The file could not be read.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        error: std::io::Error,
    },
    /// A line is not one finite number.
    #[error("{path}:{line}: expected one finite number, found {text:?}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: usize,
        /// What it holds.
        text: String,
    },
    /// The file has another number of values than the mesh file has vertices.
    #[error(
        "{path}: {found} values, but the mesh file has {expected} vertices (one value per vertex, in the file's order)"
    )]
    Count {
        /// The file.
        path: PathBuf,
        /// Values read.
        found: usize,
        /// Vertices of the mesh file.
        expected: usize,
    },
    /// A computed field failed.
    #[error("computing {name}: {reason}")]
    Computed {
        /// The field's name.
        name: String,
        /// Why.
        reason: String,
    },
}

/// The field `spec` of `mesh`, per vertex of `mesh`: a computed field's name
/// ([`COMPUTED`]) or the path of a file (module docs).
///
/// # Errors
/// [`VertexFieldError`] naming the file and line, or the computed field.
pub fn read(spec: &Path, mesh: &Mesh) -> Result<Vec<f64>, VertexFieldError> {
    if spec.as_os_str() == "mean-curvature" {
        return beltrami_fem::mean_curvature::mean_curvature(mesh).map_err(|error| {
            VertexFieldError::Computed {
                name: "mean-curvature".to_string(),
                reason: error.to_string(),
            }
        });
    }
    let text = std::fs::read_to_string(spec).map_err(|error| VertexFieldError::Io {
        path: spec.to_path_buf(),
        error,
    })?;
    let mut values = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        match line.parse::<f64>() {
            Ok(x) if x.is_finite() => values.push(x),
            _ => {
                return Err(VertexFieldError::Parse {
                    path: spec.to_path_buf(),
                    line: k + 1,
                    text: line.to_string(),
                });
            }
        }
    }
    let expected = mesh.vertex_map().input_len();
    if values.len() != expected {
        return Err(VertexFieldError::Count {
            path: spec.to_path_buf(),
            found: values.len(),
            expected,
        });
    }
    Ok(mesh
        .vertices()
        .map(|v| values[mesh.vertex_map().to_input(v)])
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::icosphere;

    #[test]
    fn a_file_is_read_in_the_mesh_order_and_bad_lines_are_named() {
        let mesh = Mesh::from_soup(&icosphere(0)).unwrap();
        let dir = std::env::temp_dir().join(format!("vertex_field_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("good.txt");
        let text: String = (0..12).map(|i| format!("{}.5 # vertex {i}\n", i)).collect();
        std::fs::write(&good, format!("# a field\n\n{text}")).unwrap();
        let values = read(&good, &mesh).unwrap();
        assert_eq!(values[3], 3.5);
        let bad = dir.join("bad.txt");
        std::fs::write(&bad, "1\n2\nnan\n").unwrap();
        let error = read(&bad, &mesh).unwrap_err().to_string();
        assert!(
            error.ends_with("bad.txt:3: expected one finite number, found \"nan\""),
            "{error}"
        );
        let short = dir.join("short.txt");
        std::fs::write(&short, "1\n2\n").unwrap();
        let error = read(&short, &mesh).unwrap_err().to_string();
        assert!(
            error.contains("2 values, but the mesh file has 12 vertices"),
            "{error}"
        );
        let curvature = read(Path::new("mean-curvature"), &mesh).unwrap();
        assert_eq!(curvature.len(), 12);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
