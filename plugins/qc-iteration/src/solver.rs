//! [`QcIteration`]: the solver behind `--solver qc-iteration` (crate docs).

use beltrami_core::{
    Accepts, Context, Element, Extras, Goal, GoalKind, Map, Metrics, OptionKind, OptionSpec,
    Output, Problem, Progress, Report, Settings, Solution, Solver, SolverError, Stop, THREADS,
    TargetKind, Topology,
};
use beltrami_fem::beltrami::{face_mu, planar_map};
use beltrami_fem::element::check_planar;
use beltrami_fem::operators::beltrami_operator;
use beltrami_fem::{
    Distortion, DofConstraints, DofMap, Elements, FemError, Frame, LeastSquaresSolver, SolveOptions,
};
use beltrami_mesh::{Mesh, VertexId};
use num_complex::Complex64;

const NAME: &str = "qc-iteration";

/// The QC iteration (crate docs).
///
/// Reads: `target` (`Plane(Keep | Given)`: every boundary vertex held), `goal`
/// (`Extremal`) and the options `tolerance`, `max-iters`, `threads`.
#[derive(Debug, Clone, Copy, Default)]
pub struct QcIteration;

const OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        name: "tolerance",
        kind: OptionKind::Float {
            default: 1e-6,
            min: 0.0,
            max: 1.0,
        },
        help: "stop when no face's mu moves by more than this in an iteration",
    },
    OptionSpec {
        name: "max-iters",
        kind: OptionKind::Int {
            default: 500,
            min: 1,
            max: 1_000_000,
        },
        help: "iterations at most",
    },
    THREADS,
];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    topologies: &[
        Topology::Disk,
        Topology::Annulus,
        Topology::MultiplyConnected,
    ],
    targets: &[TargetKind::PlaneKeep, TargetKind::PlaneGiven],
    goals: &[GoalKind::Extremal],
    constraints: &[],
};

impl Solver for QcIteration {
    fn name(&self) -> &'static str {
        NAME
    }

    fn description(&self) -> &'static str {
        "QC iteration towards the Teichmueller map of a boundary condition (Lui et al. 2014; Gruber-Aulisa 2022, planar case)"
    }

    fn accepts(&self) -> Accepts {
        ACCEPTS
    }

    fn options(&self) -> &'static [OptionSpec] {
        OPTIONS
    }

    fn check_problem(&self, problem: &Problem<'_>, _: &Settings) -> Result<(), SolverError> {
        setup(problem).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let mesh = problem.source;
        let mut report = Report::new(NAME);
        let fixed = setup(problem)?;
        let tolerance = settings.float("tolerance");
        let max_iters = settings.int("max-iters");
        let elements = Elements::new(mesh, Frame::Global)?;
        let areas = elements.face_areas();
        let neighbours = face_neighbours(mesh);
        let mut mu = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
        let mut solver = context.stage("assembly", &mut report, || {
            let mut constraints = DofConstraints::new();
            for &(v, z) in &fixed {
                constraints.fix(v, z);
            }
            let dofs = DofMap::complex(mesh.vertex_count(), &constraints)?;
            let operator = beltrami_operator(mesh, &elements, &mu)?;
            let options = SolveOptions {
                threads: settings.int("threads"),
                ..SolveOptions::default()
            };
            Ok(LeastSquaresSolver::new(
                operator.symbolic(),
                &dofs,
                options,
            )?)
        })?;
        let weights: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
        let zero = vec![Complex64::new(0.0, 0.0); elements.point_count()];
        let mut solve = |mu: &[Complex64]| -> Result<Vec<Complex64>, SolverError> {
            let operator = beltrami_operator(mesh, &elements, mu)?;
            Ok(solver.solve(operator.as_ref(), Some(&weights), &zero)?)
        };
        let mut map = solve(&mu)?;
        let mut metrics = Metrics {
            initial_distortion: Some(measure(mesh, &elements, &map)?.stats),
            ..Metrics::default()
        };
        let mut k = 0.0;
        let mut stop = Stop::IterationLimit;
        let iterate = std::time::Instant::now();
        for iteration in 0..max_iters {
            if context.is_cancelled() {
                stop = Stop::Cancelled;
                break;
            }
            let measured = measured_mu(&elements, &map)?;
            let smoothed = smooth(&measured, &neighbours);
            k = weighted_mean(smoothed.iter().map(|m| m.norm()), &areas);
            let next: Vec<Complex64> = smoothed
                .iter()
                .map(|m| {
                    if m.norm() > 0.0 {
                        m * (k / m.norm())
                    } else {
                        *m
                    }
                })
                .collect();
            let change = next
                .iter()
                .zip(&mu)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            mu = next;
            map = solve(&mu)?;
            let spread =
                weighted_mean(measured.iter().map(|m| (m.norm() - k).powi(2)), &areas).sqrt();
            metrics.energy_history.push(spread);
            metrics.iterations = iteration + 1;
            context.report(&Progress {
                stage: "iteration",
                done: iteration + 1,
                total: Some(max_iters),
                energy: Some(spread),
            });
            if change <= tolerance {
                stop = Stop::Converged { tolerance };
                break;
            }
        }
        report
            .timings
            .push(("iterations".to_string(), iterate.elapsed().as_secs_f64()));
        let distortion = measure(mesh, &elements, &map)?;
        if distortion.stats.flipped > 0 {
            report.notes.push(format!(
                "{} of {} faces are flipped",
                distortion.stats.flipped,
                mesh.face_count()
            ));
        }
        metrics.k = Some(k);
        metrics.stop = Some(stop);
        metrics.mu = Some(distortion.field);
        metrics.distortion = Some(distortion.stats);
        Ok(Solution {
            output: Output::Map(Map::Planar(map)),
            metrics,
            extras: Extras::default(),
            report,
        })
    }
}

/// The capability check: a planar mesh, the extremal goal, every boundary vertex held.
/// Returns the held vertices with their images.
fn setup(problem: &Problem<'_>) -> Result<Vec<(VertexId, Complex64)>, SolverError> {
    let mesh = problem.source;
    if problem.goal != Goal::Extremal {
        return Err(unsupported(
            "the QC iteration looks for the Teichmueller map of a boundary condition (no --mu, --mu-expr or --conformal); for a prescribed mu use lsqc",
        ));
    }
    if let Err(FemError::NotPlanar { vertex, z }) = check_planar(mesh) {
        return Err(unsupported(format!(
            "the QC iteration maps planar meshes (z = 0), but vertex {vertex} has z = {z:e}; flatten the surface first or use extremal, which flattens curved disks"
        )));
    }
    match problem.planar_boundary_values() {
        Some(values) => values.map_err(|message| SolverError::InvalidInput {
            solver: NAME,
            message,
        }),
        None => Err(unsupported(
            "the QC iteration needs the boundary values: keep the source's boundary or give a boundary map (`--boundary given --boundary-map MAP`)",
        )),
    }
}

fn unsupported(message: impl Into<String>) -> SolverError {
    SolverError::Unsupported {
        solver: NAME,
        message: message.into(),
    }
}

/// `mu` of the planar map per face (global frame).
fn measured_mu(elements: &Elements, map: &[Complex64]) -> Result<Vec<Complex64>, SolverError> {
    let point_mu: Vec<Complex64> = planar_map(elements, map.len(), map)?
        .iter()
        .map(|d| d.mu())
        .collect();
    Ok(face_mu(elements, &point_mu))
}

/// `|mu|` statistics and flips of the planar map.
fn measure(mesh: &Mesh, elements: &Elements, map: &[Complex64]) -> Result<Distortion, SolverError> {
    let d = planar_map(elements, mesh.vertex_count(), map)?;
    Ok(Distortion::from_derivatives(elements, &d)?)
}

/// Per face, the faces across its edges.
fn face_neighbours(mesh: &Mesh) -> Vec<Vec<usize>> {
    mesh.faces()
        .map(|f| {
            mesh.face_halfedges(f)
                .filter_map(|h| mesh.face(mesh.twin(h)))
                .map(|g| g.idx())
                .collect()
        })
        .collect()
}

/// One Jacobi step of the face graph: each face's value averaged with its neighbours'.
fn smooth(values: &[Complex64], neighbours: &[Vec<usize>]) -> Vec<Complex64> {
    values
        .iter()
        .zip(neighbours)
        .map(|(&v, around)| {
            let sum: Complex64 = around.iter().map(|&g| values[g]).sum::<Complex64>() + v;
            sum / (around.len() + 1) as f64
        })
        .collect()
}

/// `sum_f a_f x_f / sum_f a_f`.
fn weighted_mean(values: impl Iterator<Item = f64>, areas: &[f64]) -> f64 {
    let (sum, total) = values
        .zip(areas)
        .fold((0.0, 0.0), |(s, t), (x, a)| (s + a * x, t + a));
    if total > 0.0 { sum / total } else { 0.0 }
}
