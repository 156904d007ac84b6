//! Texture atlases: `atlas`.

use std::time::Instant;

use beltrami_atlas::{AtlasOptions, ChartCount, ConeCount};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::arrays;
use crate::errors::{self, Kind};

/// The texture atlas of the triangle mesh `V`, `F` (`beltrami atlas`): returns the UVs
/// `(k, 2)`, per face the UV index of each corner `(m, 3)` (column `c` is the corner at
/// `F[i, c]`), and the JSON report of `--report`.
#[pyfunction]
#[pyo3(signature = (v, f, cones=None, max_stretch=1.1, padding=0.004, charts=None))]
#[allow(clippy::type_complexity)]
pub fn atlas<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    cones: Option<usize>,
    max_stretch: f64,
    padding: f64,
    charts: Option<usize>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>, String)> {
    let options = AtlasOptions {
        cones: cones.map_or(ConeCount::Auto, ConeCount::Exactly),
        charts: charts.map_or(ChartCount::Auto, ChartCount::AtLeast),
        max_stretch,
        padding,
    };
    options
        .validate()
        .map_err(|e| errors::from_error(Kind::Option, &e))?;
    let rows = f.as_array();
    let mesh = arrays::mesh(v.as_array(), rows)?;
    let start = Instant::now();
    let result = py
        .detach(|| beltrami_atlas::atlas(&mesh, &options))
        .map_err(|e| errors::from_error(Kind::Solver, &e))?;
    let seconds = start.elapsed().as_secs_f64();
    let report = beltrami::report::atlas(&mesh, &result, &options, seconds);
    let uv = Array2::from_shape_fn((result.uv.uvs.len(), 2), |(i, c)| result.uv.uvs[i][c]);
    let mut fuv = Array2::<i64>::zeros((rows.nrows(), 3));
    let map = mesh.vertex_map();
    for face in mesh.faces() {
        let row = mesh.face_to_input(face);
        for (k, vertex) in mesh.face_vertices(face).enumerate() {
            let input = map.to_input(vertex) as i64;
            if let Some(c) = (0..rows.ncols()).find(|&c| rows[[row, c]] == input) {
                fuv[[row, c]] = i64::from(result.uv.corners[face.idx()][k]);
            }
        }
    }
    Ok((
        uv.into_pyarray(py),
        fuv.into_pyarray(py),
        serde_json::Value::Object(report).to_string(),
    ))
}
