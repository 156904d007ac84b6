//! `solve`: one call of a registered solver, described by the Python package.
//!
//! The package turns a call's keyword arguments into a description (JSON text, keys
//! below) and the arrays beside it; this module builds the [`Problem`] the command line
//! builds from the same flags, checks it (options, constraints, topology: before any
//! work), solves it with the GIL released and returns the map in the input's vertex
//! order with the JSON report of `--report`.
//!
//! | key | value |
//! |---|---|
//! | `target` | `plane`, `disk`, `annulus`, `sphere`, `space`, `circle-domain`, `mesh` |
//! | `boundary` | `plane`: `circle`, `square`, `free`, `keep` or `given` (`boundary_map`) |
//! | `free_radius` | `annulus`: let the inner radius move (else the input's is kept) |
//! | `goal` | `{"kind": "conformal", "p": P}`, `{"kind": "mu", "frame": F}` (`mu`), `{"kind": "mu_expr", "expr": E}`, `{"kind": "extremal"}`, `{"kind": "features", "source": S, "target": T}` (each a list of numbers per vertex row or `"mean-curvature"`) |
//! | `pins` | input vertex indices held where the solver puts them |
//! | `pin_positions` | `[[x, y], ...]`, one per pin: where each goes (libigl's `bc`) |
//! | `normal_constraint` | `space`: the weight of the normal constraint |
//! | `area_constraint` | `space`: `true` keeps the area to first order |
//! | `landmarks` | `mesh`: the text of a landmarks file |
//! | `planar_landmarks` | `disk`: `[[vertex, x, y], ...]`, boundary vertices moved to points of the unit circle |
//! | `components` | `each`: every connected component solved on its own, the planar maps side by side ([`components::solve_each`]); `largest`: the largest alone, NaN rows for the other vertices |
//! | `options` | solver options as text, `{name: value}` (`--option NAME=VALUE`) |
//! | `defaults` | the command's defaults, set when the solver declares the option |
//!
//! Ctrl-C: the solver's progress reports check Python's signals; a pending
//! `KeyboardInterrupt` cancels the solve (at its next report) and is raised.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use beltrami::landmarks::Landmarks;
use beltrami::map_file::{self, Image};
use beltrami::problem_spec::{
    BoundaryMap, BoundaryName, GoalSpec, ProblemSpec, SpecError, Spelling, TargetName,
};
use beltrami_core::{
    Constraint, Constraints, Context, Features, Landmark, Map, OptionValue, Pin, Position, Problem,
    Progress, Solution, SurfacePoint, components,
};
use beltrami_fem::{BeltramiField, Frame};
use beltrami_mesh::Mesh;
use num_complex::Complex64;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::{Map as JsonMap, Value, json};

use crate::arrays;
use crate::errors::{self, Kind};

/// The arrays of a call beside its description.
pub struct Inputs<'py> {
    boundary_map: Option<PyReadonlyArray2<'py, f64>>,
    initial: Option<PyReadonlyArray2<'py, f64>>,
    mu: Option<PyReadonlyArray1<'py, Complex64>>,
}

fn option_error(message: String) -> PyErr {
    errors::raise(Kind::Option, message)
}

fn text<'a>(spec: &'a JsonMap<String, Value>, key: &str) -> Option<&'a str> {
    spec.get(key).and_then(Value::as_str)
}

/// The problem's words of the description (module docs), its arrays read: the one
/// translation into a problem is [`ProblemSpec::problem`], shared with the command line.
fn spec_of(
    spec: &JsonMap<String, Value>,
    mesh: &Mesh,
    target_mesh: Option<&Mesh>,
    inputs: &Inputs<'_>,
) -> PyResult<ProblemSpec> {
    let name = text(spec, "target").unwrap_or("plane");
    let target = TargetName::parse(name).ok_or_else(|| {
        option_error(format!(
            "target={name:?}: expected 'plane', 'disk', 'annulus', 'sphere', 'space', 'circle-domain' or 'mesh'"
        ))
    })?;
    let mut out = ProblemSpec::new(target);
    out.spelling = Spelling::Keywords;
    out.boundary = text(spec, "boundary")
        .map(|name| {
            BoundaryName::parse(name).ok_or_else(|| {
                option_error(format!(
                    "boundary={name:?}: expected 'circle', 'square', 'free', 'keep' or 'given'"
                ))
            })
        })
        .transpose()?;
    out.boundary_map =
        match &inputs.boundary_map {
            None => None,
            Some(map) if target == TargetName::Space => Some(BoundaryMap::Spatial(
                arrays::spatial(mesh, map.as_array(), "boundary_map")?,
            )),
            Some(map) => Some(BoundaryMap::Planar(arrays::planar(
                mesh,
                map.as_array(),
                "boundary_map",
            )?)),
        };
    out.free_radius = spec.get("free_radius").and_then(Value::as_bool) == Some(true);
    out.goal = goal(spec, mesh, target_mesh, inputs)?;
    out.initial = match &inputs.initial {
        Some(initial) => Some(arrays::planar(mesh, initial.as_array(), "init")?),
        None => None,
    };
    out.constraints = constraints(spec, mesh, target_mesh)?;
    out.normal_constraint = spec.get("normal_constraint").and_then(Value::as_f64);
    out.area_constraint = spec.get("area_constraint").and_then(Value::as_bool) == Some(true);
    for (name, value) in entries(spec, "defaults") {
        out.defaults.push((name, OptionValue::Choice(value)));
    }
    for (name, value) in entries(spec, "options") {
        out.options.set_text(&name, &value);
    }
    Ok(out)
}

/// The goal of the description, or `None` for the solver's own (the extremal map of a
/// solver that computes extremal maps, else the most conformal one).
fn goal(
    spec: &JsonMap<String, Value>,
    mesh: &Mesh,
    target_mesh: Option<&Mesh>,
    inputs: &Inputs<'_>,
) -> PyResult<Option<GoalSpec>> {
    let Some(goal) = spec.get("goal").and_then(Value::as_object) else {
        return Ok(None);
    };
    Ok(Some(match goal.get("kind").and_then(Value::as_str) {
        Some("conformal") => GoalSpec::Conformal {
            p: goal.get("p").and_then(Value::as_f64),
        },
        Some("extremal") => GoalSpec::Extremal,
        Some("mu") => {
            let Some(mu) = &inputs.mu else {
                return Err(option_error("mu is missing".into()));
            };
            let frame = match goal.get("frame").and_then(Value::as_str) {
                Some("face") => Frame::Face,
                _ => Frame::Global,
            };
            let values = arrays::faces_from_rows(mesh, mu.as_array(), "mu")?;
            GoalSpec::Mu(BeltramiField::new(frame, values))
        }
        Some("mu_expr") => GoalSpec::MuExpr(
            goal.get("expr")
                .and_then(Value::as_str)
                .unwrap_or("")
                .to_string(),
        ),
        Some("features") => {
            let Some(target_mesh) = target_mesh else {
                return Err(option_error(
                    "features need the target mesh (TV, TF)".into(),
                ));
            };
            GoalSpec::Features(Features {
                source: vertex_field(goal.get("source"), mesh, "source")?,
                target: vertex_field(goal.get("target"), target_mesh, "target")?,
            })
        }
        other => return Err(option_error(format!("goal {other:?} is not a goal"))),
    }))
}

/// A field of `features=(source, target)`: `"mean-curvature"` or one number per row of
/// the mesh's vertex array, returned per mesh vertex.
fn vertex_field(value: Option<&Value>, mesh: &Mesh, side: &str) -> PyResult<Vec<f64>> {
    let field_error = |message: String| errors::raise(Kind::Field, message);
    match value {
        Some(Value::String(name)) if name == "mean-curvature" => {
            beltrami_fem::mean_curvature::mean_curvature(mesh)
                .map_err(|e| field_error(format!("the {side} mean curvature: {e}")))
        }
        Some(Value::Array(values)) => {
            let expected = mesh.vertex_map().input_len();
            if values.len() != expected {
                return Err(field_error(format!(
                    "features: the {side} field has {} values, but its vertex array has {expected} rows",
                    values.len()
                )));
            }
            let numbers: Vec<f64> = values
                .iter()
                .enumerate()
                .map(|(i, x)| {
                    x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                        field_error(format!(
                            "features: the {side} field's value {i} is not a finite number"
                        ))
                    })
                })
                .collect::<PyResult<_>>()?;
            Ok(mesh
                .vertices()
                .map(|v| numbers[mesh.vertex_map().to_input(v)])
                .collect())
        }
        _ => Err(field_error(format!(
            "features: the {side} field is an array with one number per vertex, or 'mean-curvature'"
        ))),
    }
}

/// The pins and landmarks of the description.
fn constraints(
    spec: &JsonMap<String, Value>,
    mesh: &Mesh,
    target_mesh: Option<&Mesh>,
) -> PyResult<Constraints> {
    let mut out = Constraints::new();
    let pins = spec.get("pins").and_then(Value::as_array);
    let positions = spec.get("pin_positions").and_then(Value::as_array);
    for (k, pin) in pins.into_iter().flatten().enumerate() {
        let index = pin.as_i64().ok_or_else(|| {
            errors::raise(Kind::Constraint, format!("pin {pin}: not a vertex index"))
        })?;
        let position = positions.and_then(|p| p.get(k)).map(|xy| {
            let xy = xy.as_array().map(Vec::as_slice).unwrap_or_default();
            match xy {
                [x, y] => Ok(Position::Planar(Complex64::new(
                    x.as_f64().unwrap_or(f64::NAN),
                    y.as_f64().unwrap_or(f64::NAN),
                ))),
                _ => Err(errors::raise(
                    Kind::Constraint,
                    format!("bc row {k}: expected a position (x, y)"),
                )),
            }
        });
        out.push(Constraint::Pin(Pin {
            vertex: arrays::vertex(mesh, index, "pins")?,
            position: position.transpose()?,
        }));
    }
    for mark in spec
        .get("planar_landmarks")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        let fields = mark.as_array().map(Vec::as_slice).unwrap_or_default();
        let (Some(v), Some(x), Some(y)) = (match fields {
            [v, x, y] => (v.as_i64(), x.as_f64(), y.as_f64()),
            _ => (None, None, None),
        }) else {
            return Err(errors::raise(
                Kind::Constraint,
                format!("landmark {mark}: expected (vertex, (x, y))"),
            ));
        };
        out.push(Constraint::Landmark(Landmark {
            vertex: arrays::vertex(mesh, v, "landmarks")?,
            position: Position::Planar(Complex64::new(x, y)),
        }));
    }
    if let (Some(source), Some(target)) = (text(spec, "landmarks"), target_mesh) {
        let marks = Landmarks::parse(Path::new("landmarks"), source, mesh, target)
            .map_err(|e| errors::from_error(Kind::Constraint, &e))?;
        out.extend(marks.constraints().iter().cloned());
    }
    Ok(out)
}

/// The `{name: value}` entries of `key` (`options` or `defaults`), values as text.
fn entries(spec: &JsonMap<String, Value>, key: &str) -> Vec<(String, String)> {
    spec.get(key)
        .and_then(Value::as_object)
        .into_iter()
        .flatten()
        .map(|(k, v)| {
            (
                k.clone(),
                v.as_str().map_or_else(|| v.to_string(), str::to_string),
            )
        })
        .collect()
}

/// Checks and runs `solver` on `problem` with the GIL released; Python's signals are
/// checked at every progress report (and `progress`, a Python callable, called with
/// `(stage, done, total, energy)`), a `KeyboardInterrupt` or an exception of the
/// callable cancelling the solve.
fn run(
    py: Python<'_>,
    solver: &dyn beltrami_core::Solver,
    problem: &Problem<'_>,
    each_component: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Solution, f64)> {
    let settings = if each_component {
        None
    } else {
        Some(solver.check(problem).map_err(|e| errors::from_solver(&e))?)
    };
    let cancel = Arc::new(AtomicBool::new(false));
    let mut pending: Option<PyErr> = None;
    let start = Instant::now();
    let result = py.detach(|| {
        let flag = Arc::clone(&cancel);
        let mut context = Context::new()
            .with_cancel_flag(Arc::clone(&cancel))
            .with_progress(|p: &Progress| {
                if pending.is_some() {
                    return;
                }
                let outcome = Python::attach(|py| {
                    py.check_signals()?;
                    if let Some(callback) = &progress {
                        callback.call1(py, (p.stage, p.done, p.total, p.energy))?;
                    }
                    Ok::<(), PyErr>(())
                });
                if let Err(e) = outcome {
                    pending = Some(e);
                    flag.store(true, Ordering::Relaxed);
                }
            });
        match &settings {
            Some(settings) => solver.run(problem, settings, &mut context),
            None => components::solve_each(solver, problem, &mut context),
        }
    });
    let seconds = start.elapsed().as_secs_f64();
    if let Some(e) = pending {
        return Err(e);
    }
    let solution = result.map_err(|e| errors::from_solver(&e))?;
    Ok((solution, seconds))
}

/// The report of `--report` for `solution` (without the file names).
fn report(mesh: &Mesh, solution: &Solution, seconds: f64) -> String {
    let mut report = beltrami::report::solution_json(solution);
    report.insert("seconds".into(), json!(seconds));
    report.extend(beltrami::report::mu_error_keys(
        solution.metrics.mu_error.as_ref(),
    ));
    let fits = beltrami::report::circle_fits(mesh, solution);
    if !fits.is_empty() {
        report.insert("circles".into(), beltrami::report::circles(&fits));
    }
    Value::Object(report).to_string()
}

/// Solves one call (module docs) and returns a dict: `image` (`(n, 2)` planar images or
/// `(n, 3)` points, rows in the input's vertex order), `kind` (`uv` or `xyz`), `report`
/// (JSON text), and when the solver gives them `face` and `bary` (a map onto a target
/// mesh: the target face row and barycentric coordinates per vertex), `qd` (the
/// quadratic differential per face row of an extremal map).
#[pyfunction]
#[pyo3(signature = (solver, v, f, spec, boundary_map=None, initial=None, mu=None, target_v=None, target_f=None, progress=None))]
// The arguments are the Python function's keyword arguments, the user API.
#[allow(clippy::too_many_arguments)]
pub fn solve<'py>(
    py: Python<'py>,
    solver: &str,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    spec: &str,
    boundary_map: Option<PyReadonlyArray2<'py, f64>>,
    initial: Option<PyReadonlyArray2<'py, f64>>,
    mu: Option<PyReadonlyArray1<'py, Complex64>>,
    target_v: Option<PyReadonlyArray2<'_, f64>>,
    target_f: Option<PyReadonlyArray2<'_, i64>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec: Value = serde_json::from_str(spec)
        .map_err(|e| option_error(format!("the call's description is not JSON: {e}")))?;
    let spec = spec.as_object().cloned().unwrap_or_default();
    let inputs = Inputs {
        boundary_map,
        initial,
        mu,
    };
    let registry = beltrami::registry();
    let solver = registry.get(solver).map_err(|e| errors::from_solver(&e))?;
    // `solve` returns maps; the remeshing makes a new mesh, refused before any work.
    if solver.name() == beltrami::remesh_solver::NAME {
        return Err(errors::raise(
            Kind::Solver,
            format!(
                "{} makes a new mesh, not a map of this one: call beltrami.remesh or beltrami.remesh_in_place",
                solver.name()
            ),
        ));
    }
    let mesh = arrays::mesh(v.as_array(), f.as_array())?;
    let target_mesh = match (target_v, target_f) {
        (Some(tv), Some(tf)) => Some(arrays::mesh(tv.as_array(), tf.as_array())?),
        _ => None,
    };

    let problem = spec_of(&spec, &mesh, target_mesh.as_ref(), &inputs)?
        .problem(&mesh, target_mesh.as_ref(), solver)
        .map_err(|e| match e {
            SpecError::Field { .. } => errors::from_error(Kind::Field, &e),
            SpecError::Words { .. } => errors::from_error(Kind::Option, &e),
        })?;

    let pieces = pieces_of(&spec)?;
    let parts = match pieces {
        Pieces::Largest if mesh.component_count() > 1 => {
            Some(components::parts(&mesh).map_err(|e| errors::from_error(Kind::Mesh, &e))?)
        }
        _ => None,
    };
    let largest = parts
        .as_ref()
        .and_then(|p| components::largest(p).map(|k| &p[k]));
    let (solution, seconds) = match largest {
        Some(part) => {
            let count = parts.as_ref().map_or(0, Vec::len);
            solve_largest(py, solver, &problem, part, count, progress)?
        }
        None => run(py, solver, &problem, pieces == Pieces::Each, progress)?,
    };
    let solved = largest.map_or(&mesh, |part| &part.mesh);
    let out = PyDict::new(py);
    let Some(map) = solution.map() else {
        return Err(errors::raise(
            Kind::Solver,
            format!("{} gave no map of this mesh", solver.name()),
        ));
    };
    let image = map_file::image(solved, map, target_mesh.as_ref())
        .map_err(|e| errors::from_error(Kind::Solver, &e))?;
    set_image(py, &out, &mesh, largest, image)?;
    if let (Map::OnMesh(points), Some(target)) = (map, target_mesh.as_ref()) {
        set_target_faces(py, &out, &mesh, target, points)?;
    }
    if let Some(qd) = &solution.extras.quadratic_differential {
        let nan = Complex64::new(f64::NAN, f64::NAN);
        out.set_item(
            "qd",
            arrays::face_rows(&mesh, &qd.values, nan).into_pyarray(py),
        )?;
    }
    out.set_item("report", report(solved, &solution, seconds))?;
    Ok(out)
}

/// `components=` of the call's description: the whole mesh, each component, or the
/// largest alone.
fn pieces_of(spec: &JsonMap<String, Value>) -> PyResult<Pieces> {
    match text(spec, "components") {
        None => Ok(Pieces::Whole),
        Some("each") => Ok(Pieces::Each),
        Some("largest") => Ok(Pieces::Largest),
        Some(other) => Err(option_error(format!(
            "components={other:?}: expected 'each' (every connected component mapped on its own, side by side) or 'largest' (the largest alone, NaN rows elsewhere)"
        ))),
    }
}

/// Solves `problem` on its largest component `part` alone (of `count` components),
/// noting it in the report.
fn solve_largest(
    py: Python<'_>,
    solver: &dyn beltrami_core::Solver,
    problem: &Problem<'_>,
    part: &components::Part,
    count: usize,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Solution, f64)> {
    let on_part = part
        .problem(problem, solver.name())
        .map_err(|e| errors::from_solver(&e))?;
    let (mut solution, seconds) = run(py, solver, &on_part, false, progress)?;
    solution.report.notes.push(format!(
        "the largest of {count} components mapped ({} of {} faces); the other vertices' rows are NaN",
        part.mesh.face_count(),
        problem.source.face_count()
    ));
    Ok((solution, seconds))
}

/// Rows of the solved mesh's vertices (`columns` values each) as rows of the whole
/// `mesh`'s: unchanged, or with only the `largest` component solved, NaN off it.
fn on_whole_mesh(
    values: Vec<Vec<f64>>,
    columns: usize,
    mesh: &Mesh,
    largest: Option<&components::Part>,
) -> Vec<Vec<f64>> {
    match largest {
        None => values,
        Some(part) => {
            let mut out = vec![vec![f64::NAN; columns]; mesh.vertex_count()];
            for (k, row) in values.into_iter().enumerate() {
                out[part.vertices[k].idx()] = row;
            }
            out
        }
    }
}

/// Sets `kind` (`uv` or `xyz`) and `image` (rows in the input's vertex order) of the
/// result dict `out` from the map's `image`.
fn set_image(
    py: Python<'_>,
    out: &Bound<'_, PyDict>,
    mesh: &Mesh,
    largest: Option<&components::Part>,
    image: Image,
) -> PyResult<()> {
    match image {
        Image::Uv(uv) => {
            out.set_item("kind", "uv")?;
            let rows = on_whole_mesh(
                uv.iter().map(|t| vec![t.x, t.y]).collect(),
                2,
                mesh,
                largest,
            );
            out.set_item(
                "image",
                arrays::vertex_rows(mesh, &rows, 2, Clone::clone).into_pyarray(py),
            )?;
        }
        Image::Positions(p) => {
            out.set_item("kind", "xyz")?;
            let rows = on_whole_mesh(
                p.iter().map(|p| vec![p.x, p.y, p.z]).collect(),
                3,
                mesh,
                largest,
            );
            out.set_item(
                "image",
                arrays::vertex_rows(mesh, &rows, 3, Clone::clone).into_pyarray(py),
            )?;
        }
    }
    Ok(())
}

/// Sets `face` (the target face row per vertex, -1 for none) and `bary` (barycentric
/// coordinates) of the result dict `out` for a map onto the target mesh `target`.
fn set_target_faces(
    py: Python<'_>,
    out: &Bound<'_, PyDict>,
    mesh: &Mesh,
    target: &Mesh,
    points: &[SurfacePoint],
) -> PyResult<()> {
    let face: Vec<f64> = points
        .iter()
        .map(|p| target.face_to_input(p.face) as f64)
        .collect();
    let degree = points
        .iter()
        .map(|p| target.face_degree(p.face))
        .max()
        .unwrap_or(3);
    let rows = arrays::vertex_rows(mesh, &face, 1, |&f| vec![f]);
    let face: Array1<i64> = rows
        .column(0)
        .mapv(|x| if x.is_nan() { -1 } else { x as i64 });
    let bary: Array2<f64> = arrays::vertex_rows(mesh, points, degree, |p| {
        p.coords[..target.face_degree(p.face)].to_vec()
    });
    out.set_item("face", face.into_pyarray(py))?;
    out.set_item("bary", bary.into_pyarray(py))?;
    Ok(())
}

/// `components=`: the whole mesh as one problem, every component on its own, or the
/// largest alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pieces {
    Whole,
    Each,
    Largest,
}

/// Every registered solver as the JSON text of `beltrami solvers --json`.
#[pyfunction]
pub fn solvers() -> String {
    let registry = beltrami::registry();
    Value::Array(
        registry
            .iter()
            .map(beltrami::catalog::solver_json)
            .collect(),
    )
    .to_string()
}
