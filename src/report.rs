//! A [`Solution`] as a JSON object: what the solve measured, for scripts and batch runs
//! (the `--report` and `--json` output of the mapping commands, which add the file
//! names and the wall-clock seconds).
//!
//! # Keys
//!
//! Values a solver did not compute are `null` (or empty arrays). `|mu|` statistics are
//! those of [`beltrami_fem::DistortionStats`] ([`beltrami_core::Metrics`]).
//!
//! | key | value |
//! |---|---|
//! | `solver` | the solver's name |
//! | `iterations` | iterations done (0 for direct solvers) |
//! | `stop` | why an iterative solver stopped: `converged`, `stalled`, `iteration-limit`, `cancelled` |
//! | `flipped`, `mu_mean`, `mu_max`, `mu_std`, `mu_l2` | flipped faces and statistics of \|mu\| of the result |
//! | `initial_flipped`, `initial_mu_mean`, `initial_mu_max` | the same for the map an iterative solver started from |
//! | `mu_error` | `{rms, l2_squared, sup, sup_face}`: \|mu - target\| for a prescribed `mu` ([`beltrami_fem::MuError`]; `sup_face` a face id) |
//! | `k` | the dilatation of an extremal map |
//! | `teichmueller_bound` | the least `sup \|mu\|` of any map homotopic to the result, when known (a registration between tori, from their conformal moduli) |
//! | `factorizations`, `cg_iterations` | numeric factorizations, and conjugate-gradient iterations of steps that reused one |
//! | `annulus_radius` | the free inner radius of an annulus target |
//! | `landmarks` | a registration's landmarks: `[{index, vertex, distance}]`, the distance from each landmark's image to its target (0 to rounding on exit 0) |
//! | `landmark_max` | the largest of those distances (`null` without landmarks) |
//! | `route` | the road a registration took, in words |
//! | `features` | a registration's feature match: `{before, after, steps}`, the mean squared difference of the standardized fields at the conformal start and at the result |
//! | `energy_history`, `step_sizes` | per iteration |
//! | `seconds_per_step` | [`seconds_per_step`] |
//! | `timings` | `[{stage, seconds}]` in the order they happened |
//! | `notes` | remarks for people (prose) |
//!
//! [`mu_error_keys`] gives the flat `mu_error_*` keys of `beltrami qc`'s report, and
//! [`circles`] the `circles` of a circle-domain map. [`error_message`] is the one-line
//! text of an error and its causes, as the command-line program and the Python package
//! print it.

use beltrami_core::{Circle, InPlaceSummary, ParamSummary, Report, Solution};
use beltrami_fem::MuError;
use beltrami_mesh::Mesh;
use serde_json::{Map as JsonMap, Value, json};

/// The stages whose time makes up an iteration of the Beltrami flow (its linear solves
/// and its step searches), as recorded in [`beltrami_core::Report::timings`].
const STEP_STAGES: [&str; 2] = ["flow: solves", "flow: steps"];

/// The seconds per iteration of an iterative solve: the time recorded under the flow's
/// iteration stages (`flow: solves` and `flow: steps`) divided by the iterations;
/// `None` when no iteration was done or those stages were not timed.
pub fn seconds_per_step(solution: &Solution) -> Option<f64> {
    let iterations = solution.metrics.iterations;
    let timings = &solution.report;
    let seconds: Vec<f64> = STEP_STAGES
        .iter()
        .filter_map(|s| timings.timing(s))
        .collect();
    if iterations == 0 || seconds.is_empty() {
        return None;
    }
    Some(seconds.iter().sum::<f64>() / iterations as f64)
}

/// The JSON object of `solution` (the keys of the module docs).
pub fn solution_json(solution: &Solution) -> JsonMap<String, Value> {
    let (r, m, x) = (&solution.report, &solution.metrics, &solution.extras);
    let d = m.distortion.as_ref();
    let initial = m.initial_distortion.as_ref();
    let value = json!({
        "solver": r.solver,
        "iterations": m.iterations,
        "stop": m.stop.as_ref().map(|s| s.name()),
        "flipped": d.map(|d| d.flipped),
        "mu_mean": d.map(|d| d.mu_mean),
        "mu_max": d.map(|d| d.mu_max),
        "mu_std": d.map(|d| d.mu_std),
        "mu_l2": d.map(|d| d.mu_l2),
        "initial_flipped": initial.map(|d| d.flipped),
        "initial_mu_mean": initial.map(|d| d.mu_mean),
        "initial_mu_max": initial.map(|d| d.mu_max),
        "mu_error": m.mu_error.as_ref().map(|e| json!({
            "rms": e.rms, "l2_squared": e.l2_squared, "sup": e.sup, "sup_face": e.sup_face.idx(),
        })),
        "k": m.k,
        "teichmueller_bound": m.teichmueller_bound,
        "factorizations": m.factorizations,
        "cg_iterations": m.cg_iterations,
        "annulus_radius": x.annulus_radius.map(|a| a.radius),
        "landmarks": x.landmarks.iter().map(|l| json!({
            "index": l.index, "vertex": l.vertex.idx(), "distance": l.distance,
        })).collect::<Vec<_>>(),
        "landmark_max": x.landmarks.iter().map(|l| l.distance).reduce(f64::max),
        "route": x.route,
        "features": x.features.map(|f| json!({
            "before": f.before, "after": f.after, "steps": f.steps,
        })),
        "shape": x.shape.map(|s| json!({"before": s.before, "after": s.after})),
        "energy_history": m.energy_history,
        "step_sizes": m.step_sizes,
        "seconds_per_step": seconds_per_step(solution),
        "timings": r.timings.iter().map(|(k, v)| json!({"stage": k, "seconds": v})).collect::<Vec<_>>(),
        "notes": r.notes,
    });
    match value {
        Value::Object(map) => map,
        _ => JsonMap::new(),
    }
}

/// The flat keys `beltrami qc` reports beside `mu_error`: `mu_error_l2` (the RMS),
/// `mu_error_l2_squared`, `mu_error_sup` and `mu_error_sup_face` (a face id), each
/// `null` without an error.
pub fn mu_error_keys(error: Option<&MuError>) -> JsonMap<String, Value> {
    let mut keys = JsonMap::new();
    keys.insert("mu_error_l2".into(), json!(error.map(|e| e.rms)));
    keys.insert(
        "mu_error_l2_squared".into(),
        json!(error.map(|e| e.l2_squared)),
    );
    keys.insert("mu_error_sup".into(), json!(error.map(|e| e.sup)));
    keys.insert(
        "mu_error_sup_face".into(),
        json!(error.map(|e| e.sup_face.idx())),
    );
    keys
}

/// The report of a texture atlas of `mesh` (`beltrami atlas --report` without the file
/// names): sizes, charts and cones, Sander's stretch, flipped faces, `|mu|` (mean and
/// max, as `beltrami distortion` measures the written file), the seams (edges,
/// length, share of the total edge length), the splits by reason, the options, each
/// chart's faces and cones (as input vertex indices) and the seconds.
pub fn atlas(
    mesh: &Mesh,
    atlas: &beltrami_atlas::Atlas,
    options: &beltrami_atlas::AtlasOptions,
    seconds: f64,
) -> JsonMap<String, Value> {
    let seams = atlas.uv.seams(mesh);
    let total: f64 = mesh.edges().map(|e| mesh.edge_length(e)).sum();
    let seam_length: f64 = seams.iter().map(|&e| mesh.edge_length(e)).sum();
    let s = &atlas.stretch;
    // |mu| as `beltrami distortion` measures the written file.
    let frame = if beltrami_fem::element::is_planar(mesh) {
        beltrami_fem::Frame::Global
    } else {
        beltrami_fem::Frame::Face
    };
    let mu = crate::mapped::measure_seamed(mesh, &atlas.uv, frame)
        .ok()
        .map(|d| json!({"mean": d.stats.mu_mean, "max": d.stats.mu_max}));
    let value = json!({
        "topology": beltrami_core::topology::describe(mesh),
        "vertices": mesh.vertex_count(),
        "faces": mesh.face_count(),
        "uvs": atlas.uv.uvs.len(),
        "charts": atlas.charts.len(),
        "cones": atlas.charts.iter().map(|c| c.cones.len()).sum::<usize>(),
        "stretch": {"l2": s.l2, "linf": s.linf, "area_distortion": s.area_distortion},
        "flipped_faces": s.flipped_faces,
        "mu": mu,
        "seams": {"edges": seams.len(), "length": seam_length, "length_share": seam_length / total},
        "splits": {
            "overlap": atlas.splits.overlap,
            "flipped": atlas.splits.flipped,
            "stretch": atlas.splits.stretch,
            "charts": atlas.splits.charts,
        },
        "options": {
            "cones": match options.cones {
                beltrami_atlas::ConeCount::Auto => json!("auto"),
                beltrami_atlas::ConeCount::Exactly(n) => json!(n),
            },
            "charts": match options.charts {
                beltrami_atlas::ChartCount::Auto => json!("auto"),
                beltrami_atlas::ChartCount::AtLeast(n) => json!(n),
            },
            "max_stretch": options.max_stretch,
            "padding": options.padding,
        },
        "chart_list": atlas.charts.iter().map(|c| json!({
            "faces": c.faces,
            "cones": c.cones.iter().map(|v| mesh.vertex_map().to_input(*v)).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "seconds": seconds,
    });
    match value {
        Value::Object(map) => map,
        _ => JsonMap::new(),
    }
}

/// The stage timings of `report` as a JSON object: stage name to seconds.
fn timings_object(report: &Report) -> Value {
    Value::Object(
        report
            .timings
            .iter()
            .map(|(name, s)| (name.clone(), json!(s)))
            .collect(),
    )
}

/// The report of a remeshing through a parameterization (`beltrami remesh --report`
/// without the file names): the method and parameterizer of `summary`, sizes, angles,
/// edge lengths and distances of the quality `q` of the new mesh against `input` (the
/// surface remeshed, [`crate::remesh_solver::remeshed_input`]; distances also relative
/// to its bounding-box diagonal), the seconds, the timings and notes of the solution's
/// `report`, and per component (`components`, when they were remeshed one by one) its
/// input faces, parameterizer, opening, edge length and new vertex and face counts.
pub fn remesh(
    input: &Mesh,
    summary: &ParamSummary,
    report: &Report,
    q: &beltrami_remesh::Quality,
    seconds: f64,
) -> JsonMap<String, Value> {
    let value = json!({
        "method": "param",
        "parameterizer": summary.parameterizer,
        "opening": summary.opening,
        "topology": beltrami_core::topology::describe(input),
        "input_vertices": input.vertex_count(),
        "input_faces": input.face_count(),
        "edge_length": summary.edge_length,
        "vertices": q.vertices,
        "faces": q.faces,
        "min_angle": q.min_angle,
        "mean_angle": q.mean_angle,
        "share_below_30": q.share_below_30,
        "edge_min": q.edge_min,
        "edge_mean": q.edge_mean,
        "edge_max": q.edge_max,
        "edge_spread": q.edge_spread,
        "edge_mean_over_asked": q.edge_mean / summary.edge_length,
        "hausdorff": q.hausdorff,
        "mean_distance": q.mean_distance,
        "diagonal": q.diagonal,
        "hausdorff_over_diagonal": q.hausdorff / q.diagonal,
        "mean_distance_over_diagonal": q.mean_distance / q.diagonal,
        "size_passes": summary.size_passes,
        "seconds": seconds,
        "timings": timings_object(report),
        "notes": report.notes,
    });
    let Value::Object(mut map) = value else {
        return JsonMap::new();
    };
    if !summary.components.is_empty() {
        let components = summary
            .components
            .iter()
            .map(|c| {
                json!({
                    "input_faces": c.input_faces,
                    "parameterizer": c.parameterizer,
                    "opening": c.opening,
                    "edge_length": c.edge_length,
                    "vertices": c.vertices,
                    "faces": c.faces,
                })
            })
            .collect();
        map.insert("components".into(), Value::Array(components));
    }
    map
}

/// The report of an in-place remeshing by reference angles (`beltrami remesh --method
/// qc-angles`): the reference and constraint of `summary`, the angles before and after,
/// the distance to the input (also relative to its bounding-box diagonal), the QC
/// iteration's `k`, `|mu|` statistics (from the reference shapes), iterations, stop and
/// `|mu|` spread history (the metrics of `solution`), flips, seconds, and the timings and
/// notes of the solution's report.
pub fn remesh_in_place(
    input: &Mesh,
    summary: &InPlaceSummary,
    solution: &Solution,
    before: &beltrami_remesh::Quality,
    after: &beltrami_remesh::Quality,
    seconds: f64,
) -> JsonMap<String, Value> {
    let metrics = &solution.metrics;
    let angles = |q: &beltrami_remesh::Quality| {
        json!({
            "min_angle": q.min_angle,
            "mean_angle": q.mean_angle,
            "share_below_30": q.share_below_30,
            "edge_spread": q.edge_spread,
        })
    };
    let value = json!({
        "method": "qc-angles",
        "reference": summary.reference,
        "constraint": summary.constraint,
        "projected": summary.projected,
        "topology": beltrami_core::topology::describe(input),
        "vertices": input.vertex_count(),
        "faces": input.face_count(),
        "before": angles(before),
        "after": angles(after),
        "min_angle": after.min_angle,
        "share_below_30": after.share_below_30,
        "hausdorff": after.hausdorff,
        "mean_distance": after.mean_distance,
        "diagonal": after.diagonal,
        "hausdorff_over_diagonal": after.hausdorff / after.diagonal,
        "k": metrics.k,
        "mu_mean": metrics.distortion.as_ref().map(|d| d.mu_mean),
        "mu_std": metrics.distortion.as_ref().map(|d| d.mu_std),
        "mu_max": metrics.distortion.as_ref().map(|d| d.mu_max),
        "iterations": metrics.iterations,
        "stop": metrics.stop.as_ref().map(|s| s.name()),
        "mu_spread_history": metrics.energy_history,
        "flipped": summary.flipped,
        "input_flipped": summary.input_flipped,
        "pulled_back": summary.pulled,
        "feature_angle": summary.feature_angle,
        "feature_vertices": summary.features,
        "seconds": seconds,
        "timings": timings_object(&solution.report),
        "notes": solution.report.notes,
    });
    match value {
        Value::Object(map) => map,
        _ => JsonMap::new(),
    }
}

/// A circle of a circle-domain map with how far its boundary loop's images are from it:
/// `deviation` is the largest `| |g - c| - r | / r` over the loop's images `g` (NaN when
/// the loop index is not one of `mesh`'s loops).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleFit {
    /// The circle the solver reports.
    pub circle: Circle,
    /// The largest relative distance of the loop's images from the circle.
    pub deviation: f64,
}

/// The circles of a circle-domain map (`extras.circles` of `solution`, a map of `mesh`)
/// with their deviations; empty for other solutions.
pub fn circle_fits(mesh: &Mesh, solution: &Solution) -> Vec<CircleFit> {
    let (Some(circles), Some(map)) = (&solution.extras.circles, solution.planar()) else {
        return Vec::new();
    };
    let loops = mesh.boundary_loop_list();
    circles
        .iter()
        .map(|c| CircleFit {
            circle: *c,
            deviation: loops.get(c.boundary_loop).map_or(f64::NAN, |l| {
                l.vertices
                    .iter()
                    .map(|v| ((map[v.idx()] - c.center).norm() - c.radius).abs() / c.radius)
                    .fold(0.0, f64::max)
            }),
        })
        .collect()
}

/// The report's `circles`: per circle of [`circle_fits`], `{loop, center: [x, y],
/// radius, deviation}`.
pub fn circles(fits: &[CircleFit]) -> Value {
    fits.iter()
        .map(|f| {
            json!({
                "loop": f.circle.boundary_loop,
                "center": [f.circle.center.re, f.circle.center.im],
                "radius": f.circle.radius,
                "deviation": f.deviation,
            })
        })
        .collect()
}

/// The error and its causes joined by `: `, each cause left out when the text before it
/// already quotes it (library errors that wrap another show it in their own message and
/// keep it as their source for callers that downcast).
pub fn error_message(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = String::new();
    let mut cause = Some(error);
    while let Some(e) = cause {
        let line = e.to_string();
        if !text.contains(&line) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&line);
        }
        cause = e.source();
    }
    text
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use beltrami_core::{Context, Goal, Map, PlanarBoundary, Problem, Report, Target};
    use beltrami_fem::{BeltramiField, Frame};
    use beltrami_mesh::Mesh;
    use beltrami_mesh::primitives::{Cells, jittered_grid};
    use num_complex::Complex64;

    /// lsqc on an irregular planar grid with the input's boundary kept and a constant
    /// prescribed mu: the map cannot meet it everywhere, so the error is not zero. Also
    /// the map of [`crate::map_file`]'s tests.
    pub(crate) fn lsqc_solution() -> (Mesh, Solution) {
        let mesh = Mesh::from_soup(&jittered_grid(6, 6, Cells::Triangles, 0.2, 7)).unwrap();
        let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Keep));
        problem.goal = Goal::Prescribed(BeltramiField::new(
            Frame::Global,
            vec![Complex64::new(0.2, 0.1); mesh.face_count()],
        ));
        let registry = crate::registry();
        let solver = registry.get("lsqc").unwrap();
        let solution = solver.solve(&problem, &mut Context::new()).unwrap();
        (mesh, solution)
    }

    #[test]
    fn an_lsqc_solution_reports_its_metrics() {
        let (_, solution) = lsqc_solution();
        let json = solution_json(&solution);
        let (m, d) = (&solution.metrics, solution.metrics.distortion.unwrap());
        assert_eq!(json["solver"], "lsqc");
        assert_eq!(json["iterations"], 0);
        assert_eq!(json["stop"], Value::Null);
        assert_eq!(json["flipped"], d.flipped);
        assert_eq!(json["mu_mean"], d.mu_mean);
        assert_eq!(json["mu_max"], d.mu_max);
        assert_eq!(json["mu_std"], d.mu_std);
        assert_eq!(json["mu_l2"], d.mu_l2);
        assert_eq!(json["initial_mu_mean"], Value::Null);
        let error = m.mu_error.unwrap();
        assert!(error.rms > 0.0 && error.sup >= error.rms);
        assert_eq!(
            json["mu_error"],
            json!({
                "rms": error.rms,
                "l2_squared": error.l2_squared,
                "sup": error.sup,
                "sup_face": error.sup_face.idx(),
            })
        );
        assert_eq!(json["k"], Value::Null);
        assert_eq!(json["annulus_radius"], Value::Null);
        assert_eq!(json["seconds_per_step"], Value::Null);
        let stages: Vec<&str> = json["timings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["stage"].as_str().unwrap())
            .collect();
        let expected: Vec<&str> = solution
            .report
            .timings
            .iter()
            .map(|(s, _)| s.as_str())
            .collect();
        assert_eq!(stages, expected);
        assert!(stages.contains(&"solve"));
        assert_eq!(json["notes"], json!(solution.report.notes));
        // The whole object is valid JSON text (no NaN or infinity).
        let text = Value::Object(json).to_string();
        assert!(serde_json::from_str::<Value>(&text).is_ok());

        let flat = mu_error_keys(m.mu_error.as_ref());
        assert_eq!(flat["mu_error_l2"], error.rms);
        assert_eq!(flat["mu_error_l2_squared"], error.l2_squared);
        assert_eq!(flat["mu_error_sup"], error.sup);
        assert_eq!(flat["mu_error_sup_face"], error.sup_face.idx());
        assert!(mu_error_keys(None).values().all(Value::is_null));
        assert_eq!(mu_error_keys(None).len(), 4);
    }

    #[test]
    fn seconds_per_step_divides_the_flow_stages_by_the_iterations() {
        let mut report = Report::new("beltrami-flow");
        report.timings = vec![
            ("initial map".into(), 5.0),
            ("flow: solves".into(), 1.5),
            ("flow: steps".into(), 0.5),
        ];
        let mut solution = Solution::from_map(Map::Planar(Vec::new()), report);
        assert_eq!(seconds_per_step(&solution), None);
        solution.metrics.iterations = 4;
        assert_eq!(seconds_per_step(&solution), Some(0.5));
        assert_eq!(solution_json(&solution)["seconds_per_step"], 0.5);
        solution.report.timings.truncate(1);
        assert_eq!(seconds_per_step(&solution), None);
    }
}
