//! New meshes from a mesh: `remesh` and `remesh_in_place` (through the registered solver
//! `remesh`) and `cut_to_disk`.

use std::time::Instant;

use beltrami::remesh_solver::{self, RemeshOptionError};
use beltrami_core::{
    Context, OptionValue, Options, Output, Problem, RemeshSummary, Solution, SolverError, Target,
};
use beltrami_mesh::Mesh;
use beltrami_remesh::RemeshError;
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

/// Runs the registered solver `remesh` on `mesh` with `options`, with the GIL released;
/// its error as the Python exception of its kind: a refused option (of the solver or of
/// the remeshing library, a size that would make too many vertices) is `OptionError`, a
/// mesh in pieces without `components` is `UnsupportedError` naming the argument.
fn remesh_solution(py: Python<'_>, mesh: &Mesh, options: Options) -> PyResult<(Solution, f64)> {
    let registry = beltrami::registry();
    let solver = registry
        .get(remesh_solver::NAME)
        .map_err(|e| errors::from_solver(&e))?;
    let mut problem = Problem::new(mesh, Target::Surface);
    problem.options = options;
    let start = Instant::now();
    let solution = py.detach(|| solver.solve(&problem, &mut Context::new()));
    let seconds = start.elapsed().as_secs_f64();
    let error = match solution {
        Ok(solution) => return Ok((solution, seconds)),
        Err(error) => error,
    };
    let SolverError::Plugin { error: source, .. } = &error else {
        return Err(errors::from_solver(&error));
    };
    let source: &(dyn std::error::Error + 'static) = source.as_ref();
    if source.is::<RemeshOptionError>() {
        return Err(errors::from_error(Kind::Option, source));
    }
    Err(match source.downcast_ref::<RemeshError>() {
        Some(e @ RemeshError::Components { .. }) => errors::raise(
            Kind::Unsupported,
            format!(
                "{e}: pass components='each' (every piece remeshed on its own) or components='largest' (the largest alone)"
            ),
        ),
        Some(e @ (RemeshError::TooFine { .. } | RemeshError::InvalidOption { .. })) => {
            errors::from_error(Kind::Option, e)
        }
        _ => errors::from_error(Kind::Solver, source),
    })
}

/// The new mesh of a `remesh` solution and how it was made.
fn remeshed(solution: &Solution) -> PyResult<(&Mesh, &RemeshSummary)> {
    match (&solution.output, &solution.extras.remesh) {
        (Output::Mesh(remeshed), Some(summary)) => Ok((&remeshed.mesh, summary)),
        _ => Err(errors::raise(Kind::Solver, "remesh gave no new mesh")),
    }
}

/// A new triangle mesh of the surface `V`, `F` with the asked edge length (or about
/// `vertices` vertices), made through a parameterization (`beltrami remesh`, the
/// registered solver `remesh`): returns the positions, the triangles and the JSON report
/// of `--report`.
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
    let mut options = Options::new();
    match (edge_length, vertices) {
        (Some(l), None) => options.set("edge-length", OptionValue::Float(l)),
        (None, Some(n)) => options.set("vertices", OptionValue::Int(n)),
        _ => {
            return Err(errors::raise(
                Kind::Option,
                "give one of edge_length and vertices",
            ));
        }
    };
    if let Some(other) = components.filter(|c| !matches!(*c, "each" | "largest")) {
        return Err(errors::raise(
            Kind::Option,
            format!(
                "components={other:?}: expected 'each' (every connected component remeshed on its own, the results joined) or 'largest' (the largest alone)"
            ),
        ));
    }
    if let Some(components) = components {
        options.set_text("components", components);
    }
    options
        .set_text("param", param)
        .set("min-angle", OptionValue::Float(min_angle))
        .set_text("size-field", size_field)
        .set("max-vertices", OptionValue::Int(max_vertices));
    if feature_tolerance == f64::INFINITY {
        options.set("keep-features", OptionValue::Bool(false));
    } else {
        options.set("feature-tolerance", OptionValue::Float(feature_tolerance));
    }
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let (solution, seconds) = remesh_solution(py, &mesh, options)?;
    let (out, summary) = remeshed(&solution)?;
    let RemeshSummary::Param(summary) = summary else {
        return Err(errors::raise(
            Kind::Solver,
            "remesh moved the vertices instead",
        ));
    };
    let report = py.detach(|| {
        let input = remesh_solver::remeshed_input(&mesh, summary)
            .map_err(|e| errors::from_error(Kind::Mesh, &e))?;
        let quality = beltrami_remesh::quality::measure(&input, out)
            .map_err(|e| errors::from_error(Kind::Solver, &e))?;
        Ok::<_, PyErr>(beltrami::report::remesh(
            &input,
            summary,
            &solution.report,
            &quality,
            seconds,
        ))
    })?;
    let (v, f) = mesh_arrays(out)?;
    Ok((
        v.into_pyarray(py),
        f.into_pyarray(py),
        serde_json::Value::Object(report).to_string(),
    ))
}

/// The surface `V`, `F` remeshed in place by reference angles (`beltrami remesh --method
/// qc-angles`, the registered solver `remesh` with `method=qc-angles`): returns the
/// moved positions and the JSON report of `--report`.
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
    let mut options = Options::new();
    options
        .set_text("method", "qc-angles")
        .set_text("reference", reference)
        .set_text("constraint", constraint)
        .set("max-iters", OptionValue::Int(max_iters))
        .set("tolerance", OptionValue::Float(tolerance))
        .set("feature-angle", OptionValue::Float(feature_angle))
        .set("project", OptionValue::Bool(project))
        .set("allow-flips", OptionValue::Bool(allow_flips));
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let (solution, seconds) = remesh_solution(py, &mesh, options)?;
    let (out, summary) = remeshed(&solution)?;
    let RemeshSummary::InPlace(summary) = summary else {
        return Err(errors::raise(
            Kind::Solver,
            "remesh made a new mesh instead",
        ));
    };
    let (before, after) = py
        .detach(|| {
            let before = beltrami_remesh::quality::shape(&mesh);
            let after = beltrami_remesh::quality::measure(&mesh, out)?;
            Ok((before, after))
        })
        .map_err(|e: RemeshError| errors::from_error(Kind::Solver, &e))?;
    let report =
        beltrami::report::remesh_in_place(&mesh, summary, &solution, &before, &after, seconds);
    let (v, _) = mesh_arrays(out)?;
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
