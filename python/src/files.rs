//! Mesh files: `read_mesh` and `write_mesh` (OBJ, PLY, STL, OFF, glTF, GLB by extension).

use std::path::PathBuf;

use beltrami_mesh::io::{self, VertexAttributes};
use beltrami_mesh::{BuildOptions, Vector2};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::arrays;
use crate::errors::{self, Kind};

/// The positions `(n, 3)`, faces `(m, 3|4)` and, when the file gives one texture
/// coordinate per vertex, the texture coordinates `(n, 2)` of a mesh file, validated
/// like the command line's input (a non-manifold or degenerate mesh is a `MeshError`
/// naming the element). Faces come in the file's order, oriented consistently.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn read_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Option<Bound<'py, PyArray2<f64>>>,
)> {
    let loaded = py.detach(|| {
        let raw = io::read_raw(&path)?;
        let positions = raw.soup.positions.clone();
        io::build_raw(&path, raw, &BuildOptions::default()).map(|l| (positions, l))
    });
    let (positions, loaded) = loaded.map_err(|e| errors::from_read(&e))?;
    let mesh = &loaded.mesh;
    let mut v = Array2::zeros((positions.len(), 3));
    for (i, p) in positions.iter().enumerate() {
        for c in 0..3 {
            v[[i, c]] = p[c];
        }
    }
    let f = arrays::faces(mesh).ok_or_else(|| {
        errors::raise(
            Kind::Mesh,
            format!(
                "{}: the mesh mixes triangles and quads; F holds one face size",
                path.display()
            ),
        )
    })?;
    let uv = loaded
        .vertex_uvs()
        .map(|uv| arrays::vertex_rows(mesh, &uv, 2, |t| vec![t.x, t.y]).into_pyarray(py));
    Ok((v.into_pyarray(py), f.into_pyarray(py), uv))
}

/// Writes the mesh `V`, `F` to `path` (format by extension), with texture coordinates
/// `uv` `(n, 2)` when given, atomically: an existing file is replaced only by a complete
/// one.
#[pyfunction]
#[pyo3(signature = (path, v, f, uv=None))]
pub fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    uv: Option<PyReadonlyArray2<'_, f64>>,
) -> PyResult<()> {
    if io::Format::from_path(&path).is_none() {
        return Err(errors::raise(
            Kind::File,
            format!(
                "{}: unknown output format (expected {})",
                path.display(),
                io::Format::EXTENSIONS
            ),
        ));
    }
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let uvs = uv
        .map(|uv| {
            arrays::rows_to_vertices(&mesh, uv.as_array(), &[2], "uv", |r| {
                Vector2::new(r[0], r[1])
            })
        })
        .transpose()?;
    let attributes = VertexAttributes {
        uvs: uvs.as_deref(),
        ..VertexAttributes::default()
    };
    py.detach(|| io::write(&path, &mesh, &attributes))
        .map_err(|e| errors::from_write(&e))
}
