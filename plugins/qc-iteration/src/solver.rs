//! [`QcIteration`]: the solver behind `--solver qc-iteration` (crate docs).

use beltrami_core::{
    Accepts, Constraint, ConstraintKind, Context, Element, Extras, Goal, GoalKind, Metrics,
    OptionKind, OptionSpec, Output, Problem, Progress, Report, Settings, Solution, Solver,
    SolverError, SolverInfo, Stop, THREADS, Target, TargetKind, Topology,
};
use beltrami_fem::element::check_planar;
use beltrami_fem::operators::beltrami_operator;
use beltrami_fem::quaternionic_lsqc::{
    AreaConstraint, NormalConstraint, SpaceSystem, undetermined,
};
use beltrami_fem::{DofConstraints, DofMap, Elements, FemError, Frame, LeastSquaresSolver};
use beltrami_mesh::{Point3, VertexId};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::line_search::best_step;
use crate::system::{Linearized, Planar, Space};
use crate::transport::Transport;

const NAME: &str = "qc-iteration";

/// The QC iteration (crate docs).
///
/// Reads: `target` (`Plane(Keep | Given)`: every boundary vertex held; `Surface`: the
/// pins' points), `goal` (`Extremal`), the constraints `Pin`, `Normal`, `Area` and
/// `ReferenceAngles` (into space), and the options `tolerance`, `max-iters`,
/// `line-search`, `threads`.
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
            min: 0,
            max: 1_000_000,
        },
        help: "iterations at most (0: the least-squares conformal map, mu = 0)",
    },
    OptionSpec {
        name: "line-search",
        kind: OptionKind::Bool { default: true },
        help: "take the best coefficient between the last and the smoothed one (Gruber-Aulisa 2022, section 5.4)",
    },
    THREADS,
];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    topologies: Topology::CONNECTED,
    targets: &[
        TargetKind::PlaneKeep,
        TargetKind::PlaneGiven,
        TargetKind::Surface,
    ],
    goals: &[GoalKind::Extremal],
    constraints: &[
        ConstraintKind::Pin,
        ConstraintKind::Normal,
        ConstraintKind::Area,
        ConstraintKind::ReferenceAngles,
    ],
};

/// What [`QcIteration`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "QC iteration towards the Teichmueller map of a boundary condition, in the plane or into R^3 (Lui et al. 2014; Gruber-Aulisa 2022)",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for QcIteration {
    fn info(&self) -> &'static SolverInfo {
        &INFO
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
        let mut report = Report::new(NAME);
        let options = SolveOptions {
            threads: settings.int("threads"),
            ..SolveOptions::default()
        };
        match setup(problem)? {
            Setup::Planar(fixed) => {
                let mesh = problem.source;
                let mut system = context.stage("assembly", &mut report, || {
                    let elements = Elements::new(mesh, Frame::Global)?;
                    let mut constraints = DofConstraints::new();
                    for &(v, z) in &fixed {
                        constraints.fix(v, z);
                    }
                    let dofs = DofMap::complex(mesh.vertex_count(), &constraints)?;
                    let zero = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
                    let operator = beltrami_operator(mesh, &elements, &zero)?;
                    let solver = LeastSquaresSolver::new(operator.symbolic(), &dofs, options)?;
                    let weights: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
                    Ok(Planar {
                        mesh,
                        rhs: vec![Complex64::new(0.0, 0.0); weights.len()],
                        elements,
                        solver,
                        weights,
                        map: Vec::new(),
                    })
                })?;
                iterate(problem, &mut system, settings, context, report)
            }
            Setup::Space(space) => {
                let mesh = problem.source;
                let mut system = context.stage("assembly", &mut report, || {
                    let elements = match &space.reference {
                        Some(angles) => Elements::with_reference_angles(mesh, angles)?,
                        None => Elements::new(mesh, Frame::Face)?,
                    };
                    let normal = space.normal.map(|w| NormalConstraint::new(mesh, w));
                    let area = space
                        .area
                        .then(|| AreaConstraint::new(&elements, mesh.positions()));
                    Ok(Space {
                        system: SpaceSystem::new(
                            elements,
                            mesh.vertex_count(),
                            &space.held,
                            normal,
                            area,
                            options,
                        )?,
                        vertex_count: mesh.vertex_count(),
                        image: Vec::new(),
                    })
                })?;
                if space.reference.is_some() {
                    report.notes.push(
                        "|mu| is measured from the reference shapes (the corner angles asked for) to the image".to_string(),
                    );
                }
                iterate(problem, &mut system, settings, context, report)
            }
        }
    }
}

/// The iteration itself (crate docs), on either linearized problem.
fn iterate(
    problem: &Problem<'_>,
    system: &mut dyn Linearized,
    settings: &Settings,
    context: &mut Context<'_>,
    mut report: Report,
) -> Result<Solution, SolverError> {
    let mesh = problem.source;
    let tolerance = settings.float("tolerance");
    let max_iters = settings.int("max-iters");
    let line_search = settings.flag("line-search");
    let areas = system.elements().face_areas();
    let transport = Transport::new(mesh, system.elements());
    let mut mu = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
    system.solve(&mu)?;
    let mut metrics = Metrics {
        initial_distortion: Some(system.distortion()?.stats),
        ..Metrics::default()
    };
    let mut stop = Stop::IterationLimit;
    let started = std::time::Instant::now();
    for iteration in 0..max_iters {
        if context.is_cancelled() {
            stop = Stop::Cancelled;
            break;
        }
        let measured = system.measured()?;
        let k = weighted_mean(measured.iter().map(|m| m.norm()), &areas);
        let mut next: Vec<Complex64> = transport
            .smooth(&measured)
            .into_iter()
            .map(|m| {
                if m.norm() > 0.0 {
                    m * (k / m.norm())
                } else {
                    m
                }
            })
            .collect();
        let mut step = 1.0;
        if line_search {
            step = best_step(&system.residual(&mu)?, &system.residual(&next)?);
            for (n, m) in next.iter_mut().zip(&mu) {
                *n = m + (*n - m) * step;
            }
        }
        let change = next
            .iter()
            .zip(&mu)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        mu = next;
        system.solve(&mu)?;
        let spread = weighted_mean(measured.iter().map(|m| (m.norm() - k).powi(2)), &areas).sqrt();
        metrics.energy_history.push(spread);
        metrics.step_sizes.push(step);
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
        .push(("iterations".to_string(), started.elapsed().as_secs_f64()));
    let distortion = system.distortion()?;
    if distortion.stats.flipped > 0 {
        report.notes.push(format!(
            "{} of {} faces are flipped",
            distortion.stats.flipped,
            mesh.face_count()
        ));
    }
    // The k of the map returned (the mean |mu| the last step aimed at belongs to the map
    // before it; with no step at all, the start map's).
    let k = weighted_mean(system.measured()?.iter().map(|m| m.norm()), &areas);
    metrics.k = Some(k);
    metrics.stop = Some(stop);
    metrics.mu = Some(distortion.field);
    metrics.distortion = Some(distortion.stats);
    Ok(Solution {
        output: Output::Map(system.map()),
        metrics,
        extras: Extras::default(),
        report,
    })
}

/// What the capability check finds.
enum Setup {
    /// A planar mesh with its held boundary values.
    Planar(Vec<(VertexId, Complex64)>),
    /// A map into R^3.
    Space(SpaceSetup),
}

/// The held vertices and constraints of a map into R^3.
struct SpaceSetup {
    held: Vec<(VertexId, Point3<f64>)>,
    /// The normal penalty's weight.
    normal: Option<f64>,
    area: bool,
    /// Corner angles per halfedge.
    reference: Option<Vec<f64>>,
}

/// The capability check (crate docs).
fn setup(problem: &Problem<'_>) -> Result<Setup, SolverError> {
    let mesh = problem.source;
    if problem.goal != Goal::Extremal {
        return Err(SolverError::unsupported(
            NAME,
            "the QC iteration looks for the Teichmueller map of a boundary condition (no --mu, --mu-expr or --conformal); for a prescribed mu use lsqc",
        ));
    }
    if matches!(problem.target, Target::Surface) {
        let held = problem
            .spatial_pins()
            .map_err(|message| SolverError::invalid(NAME, message))?;
        let mut space = SpaceSetup {
            held,
            normal: None,
            area: false,
            reference: None,
        };
        for c in problem.constraints.iter() {
            match c {
                Constraint::Normal { weight } => space.normal = Some(*weight),
                Constraint::Area => space.area = true,
                Constraint::ReferenceAngles(angles) => space.reference = Some(angles.clone()),
                _ => {}
            }
        }
        if let Some(message) = undetermined(
            space.held.len(),
            space.normal.is_some(),
            space.area,
            mesh.boundary_loop_list().is_empty(),
        ) {
            return Err(SolverError::unsupported(NAME, message));
        }
        return Ok(Setup::Space(space));
    }
    if let Some(c) = problem.constraints.iter().find(|c| {
        matches!(
            c,
            Constraint::Normal { .. } | Constraint::Area | Constraint::ReferenceAngles(_)
        )
    }) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the {} constraint shapes a map into space; use --target space",
                c.kind().name()
            ),
        ));
    }
    if mesh.quad_count() > 0 {
        return Err(SolverError::unsupported(
            NAME,
            "the QC iteration in the plane maps triangle meshes; map a quad mesh with --target space",
        ));
    }
    if let Err(FemError::NotPlanar { vertex, z }) = check_planar(mesh) {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the QC iteration in the plane maps planar meshes (z = 0), but vertex {vertex} has z = {z:e}; map the surface into space (--target space) or use extremal, which flattens curved disks"
            ),
        ));
    }
    match problem.planar_boundary_values() {
        Some(values) => values
            .map(Setup::Planar)
            .map_err(|message| SolverError::invalid(NAME, message)),
        None => Err(SolverError::unsupported(
            NAME,
            "the QC iteration needs the boundary values: keep the source's boundary or give a boundary map (`--boundary given --boundary-map MAP`)",
        )),
    }
}

/// `sum_f a_f x_f / sum_f a_f`.
fn weighted_mean(values: impl Iterator<Item = f64>, areas: &[f64]) -> f64 {
    let (sum, total) = values
        .zip(areas)
        .fold((0.0, 0.0), |(s, t), (x, a)| (s + a * x, t + a));
    if total > 0.0 { sum / total } else { 0.0 }
}
