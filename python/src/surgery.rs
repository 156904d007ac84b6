//! New meshes from a mesh: `remesh` and `cut_to_disk`.

use std::time::Instant;

use beltrami_core::Context;
use beltrami_mesh::Mesh;
use beltrami_remesh::components::{Coverage, remesh_covering};
use beltrami_remesh::{RemeshError, RemeshOptions, Resolution, SizeField};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use serde_json::json;

use crate::arrays;
use crate::errors::{self, Kind};

/// The positions `(n, 3)` and faces `(m, k)` of a mesh built here.
fn mesh_arrays(mesh: &Mesh) -> PyResult<(Array2<f64>, Array2<i64>)> {
    arrays::own_order(mesh)
        .ok_or_else(|| errors::raise(Kind::Solver, "the new mesh mixes triangles and quads"))
}

/// A new triangle mesh of the surface `V`, `F` with the asked edge length (or about
/// `vertices` vertices), made through a parameterization (`beltrami remesh`): returns
/// the positions, the triangles and the JSON report of `--report`.
#[pyfunction]
#[pyo3(signature = (v, f, edge_length=None, vertices=None, param="auto", min_angle=30.0, size_field="uniform", max_vertices=5_000_000, feature_tolerance=beltrami_remesh::FEATURE_TOLERANCE, components=None))]
// The arguments are the Python function's keyword arguments, the user API.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn remesh<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    edge_length: Option<f64>,
    vertices: Option<usize>,
    param: &str,
    min_angle: f64,
    size_field: &str,
    max_vertices: usize,
    feature_tolerance: f64,
    components: Option<&str>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>, String)> {
    let resolution = match (edge_length, vertices) {
        (Some(l), None) => Resolution::EdgeLength(l),
        (None, Some(n)) => Resolution::Vertices(n),
        _ => {
            return Err(errors::raise(
                Kind::Option,
                "give one of edge_length and vertices",
            ));
        }
    };
    let size_field = match size_field {
        "uniform" => SizeField::Uniform,
        "curvature" => SizeField::Curvature,
        other => {
            return Err(errors::raise(
                Kind::Option,
                format!("size_field={other:?}: expected 'uniform' or 'curvature'"),
            ));
        }
    };
    let options = RemeshOptions {
        resolution,
        min_angle,
        size_field,
        max_vertices,
        feature_tolerance,
    };
    let remesh_error = |e: &RemeshError| match e {
        RemeshError::Components { .. } => errors::raise(
            Kind::Unsupported,
            format!(
                "{e}: pass components='each' (every piece remeshed on its own) or components='largest' (the largest alone)"
            ),
        ),
        RemeshError::TooFine { .. } => errors::from_error(Kind::Option, e),
        other => errors::from_error(Kind::Solver, other),
    };
    options
        .validate()
        .map_err(|e| errors::from_error(Kind::Option, &e))?;
    if let Some(other) = components.filter(|c| !matches!(*c, "each" | "largest")) {
        return Err(errors::raise(
            Kind::Option,
            format!(
                "components={other:?}: expected 'each' (every connected component remeshed on its own, the results joined) or 'largest' (the largest alone)"
            ),
        ));
    }
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let registry = beltrami::registry();
    let choose = |part: &Mesh| beltrami_remesh::param::chosen(&registry, part, param);
    let start = Instant::now();
    let coverage = match components {
        Some("each") => Coverage::Each,
        Some("largest") => Coverage::Largest,
        _ => Coverage::Whole,
    };
    let result = py.detach(|| {
        let covered = remesh_covering(&mesh, coverage, choose, &options, &mut Context::new())?;
        let quality = beltrami_remesh::quality::measure(covered.input(&mesh), &covered.mesh)?;
        Ok::<_, RemeshError>((covered, quality))
    });
    let (covered, quality) = result.map_err(|e| remesh_error(&e))?;
    let seconds = start.elapsed().as_secs_f64();
    let mut report =
        beltrami::report::remesh(covered.input(&mesh), &covered.summary, &quality, seconds);
    if !covered.components.is_empty() {
        report.insert(
            "components".into(),
            beltrami::report::remesh_components(&covered.components),
        );
    }
    let out = covered.mesh;
    let (v, f) = mesh_arrays(&out)?;
    Ok((
        v.into_pyarray(py),
        f.into_pyarray(py),
        serde_json::Value::Object(report).to_string(),
    ))
}

/// The surface `V`, `F` remeshed in place by reference angles (`beltrami remesh --method
/// qc-angles`, [`beltrami_remesh::in_place`]): returns the moved positions and the JSON
/// report of `--report`.
#[pyfunction]
#[pyo3(signature = (v, f, reference="optimized", constraint="normal", max_iters=10, tolerance=1e-4, feature_angle=60.0, project=true, allow_flips=false))]
// The arguments are the Python function's keyword arguments, the user API.
#[allow(clippy::too_many_arguments)]
pub fn remesh_in_place<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    reference: &str,
    constraint: &str,
    max_iters: usize,
    tolerance: f64,
    feature_angle: f64,
    project: bool,
    allow_flips: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, String)> {
    use beltrami_remesh::in_place::{InPlaceOptions, Keep, remesh_in_place};
    use beltrami_remesh::reference_angles::Reference;
    let reference = match reference {
        "optimized" => Reference::Optimized,
        "equiangular" => Reference::Equiangular,
        other => {
            return Err(errors::raise(
                Kind::Option,
                format!("reference={other:?}: expected 'optimized' or 'equiangular'"),
            ));
        }
    };
    let keep = match constraint {
        "normal" => Keep::Normal,
        "area" => Keep::Area,
        other => {
            return Err(errors::raise(
                Kind::Option,
                format!("constraint={other:?}: expected 'normal' or 'area'"),
            ));
        }
    };
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(errors::raise(
            Kind::Option,
            format!("tolerance={tolerance}: give a positive number"),
        ));
    }
    if !(feature_angle > 0.0 && feature_angle <= 180.0) {
        return Err(errors::raise(
            Kind::Option,
            format!("feature_angle={feature_angle}: give an angle in (0, 180] degrees"),
        ));
    }
    let options = InPlaceOptions {
        reference,
        keep,
        max_iters,
        tolerance,
        project,
        feature_angle,
        allow_flips,
    };
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let registry = beltrami::registry();
    let solver = registry
        .get("qc-iteration")
        .map_err(|e| errors::from_error(Kind::Unsupported, &e))?;
    let start = Instant::now();
    let result = py.detach(|| {
        let mut context = Context::new();
        let result = remesh_in_place(&mesh, solver, &options, &mut context)?;
        let before = beltrami_remesh::quality::shape(&mesh);
        let after = beltrami_remesh::quality::measure(&mesh, &result.mesh)?;
        Ok((result, before, after))
    });
    let (result, before, after) =
        result.map_err(|e: beltrami_remesh::RemeshError| errors::from_error(Kind::Solver, &e))?;
    let seconds = start.elapsed().as_secs_f64();
    let report =
        beltrami::report::remesh_in_place(&mesh, &result, &options, &before, &after, seconds);
    let (v, _) = mesh_arrays(&result.mesh)?;
    Ok((
        v.into_pyarray(py),
        serde_json::Value::Object(report).to_string(),
    ))
}

/// The surface `V`, `F` (genus >= 1 or several boundary loops) cut into a topological
/// disk along a greedy shortest system of loops (`beltrami cut`): returns the cut
/// mesh's positions and faces (face `i` is face `i` of `F`), the input vertex of every
/// cut-mesh vertex, and a report (`genus`, `boundary_loops`, `cut_edges`, `cut_length`,
/// `boundary_edges`, `boundary_length`).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn cut_to_disk<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<i64>>,
    String,
)> {
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let cut = py
        .detach(|| beltrami_mesh::cut_to_disk(&mesh))
        .map_err(|e| errors::from_error(Kind::Unsupported, &e))?;
    let (cv, cf) = mesh_arrays(&cut.mesh)?;
    let original: Array1<i64> = cut
        .to_original
        .iter()
        .map(|&o| mesh.vertex_map().to_input(o) as i64)
        .collect();
    let component = cut.cut.components[0];
    let report = json!({
        "genus": component.genus,
        "boundary_loops": component.boundary_loops,
        "cut_edges": cut.cut.edges.len(),
        "cut_length": cut.cut.length(&mesh),
        "vertices": cut.mesh.vertex_count(),
        "faces": cut.mesh.face_count(),
        "boundary_edges": cut.boundary.len(),
        "boundary_length": cut.boundary_length(),
    });
    Ok((
        cv.into_pyarray(py),
        cf.into_pyarray(py),
        original.into_pyarray(py),
        report.to_string(),
    ))
}
