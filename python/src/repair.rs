//! Mending a mesh's arrays: `repair`, the command line's `--repair` for numpy users.

use beltrami_mesh::{BuildOptions, Mesh, Repair};
use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use serde_json::json;

use crate::arrays;
use crate::errors::{self, Kind};

/// The arrays of a repaired mesh: positions `(n', 3)` and faces `(m', k)` in the mesh's
/// own order, the new row of every input vertex (`-1` for a vertex no kept face uses)
/// and the input row of every kept face.
type Repaired<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    String,
);

/// `V`, `F` rebuilt with the asked repairs (`info --repair`): vertices at bit-identical
/// positions merged into the first, faces with a repeated vertex or zero area dropped,
/// faces with the vertex set of an earlier face dropped; every face then oriented
/// consistently with its component. Returns the new arrays, the vertex and face index
/// maps and the report as JSON (what changed, by input index).
#[pyfunction]
#[pyo3(signature = (v, f, merge_vertices=true, drop_degenerate_faces=true, drop_duplicate_faces=true))]
pub fn repair<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    merge_vertices: bool,
    drop_degenerate_faces: bool,
    drop_duplicate_faces: bool,
) -> PyResult<Repaired<'py>> {
    let soup = arrays::soup(v.as_array(), f.as_array())?;
    let options = BuildOptions {
        repair: Repair {
            drop_degenerate_faces,
            drop_duplicate_faces,
            merge_coincident_vertices: merge_vertices,
        },
        ..BuildOptions::default()
    };
    let (mesh, report) = py
        .detach(|| Mesh::build(&soup, &options))
        .map_err(|e| errors::from_error(Kind::Mesh, &e))?;
    let (positions, faces) = arrays::own_order(&mesh).ok_or_else(|| {
        errors::raise(
            Kind::Mesh,
            "the repaired mesh mixes triangles and quads; F holds one face size",
        )
    })?;
    let map = mesh.vertex_map();
    let vertex_index: Array1<i64> = (0..map.input_len())
        .map(|i| map.from_input(i).map_or(-1, |v| v.idx() as i64))
        .collect();
    let face_index: Array1<i64> = mesh.faces().map(|f| mesh.face_to_input(f) as i64).collect();
    let info = json!({
        "merged_vertices": report.merged_vertices,
        "dropped_degenerate_faces": report.dropped_degenerate_faces,
        "dropped_duplicate_faces": report.dropped_duplicate_faces,
        "unreferenced_vertices": report.unreferenced_vertices,
        "faces_reoriented": report.faces_reoriented,
    });
    Ok((
        positions.into_pyarray(py),
        faces.into_pyarray(py),
        vertex_index.into_pyarray(py),
        face_index.into_pyarray(py),
        info.to_string(),
    ))
}
