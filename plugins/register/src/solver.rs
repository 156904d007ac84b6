//! [`Register`]: the solver behind `beltrami register` (crate docs).

use beltrami_core::{
    Accepts, Constraint, ConstraintKind, Constraints, Context, Element, Features, Goal, GoalKind,
    Landmark, LandmarkResidual, Map, OptionKind, OptionSpec, OptionValue, Position, Problem,
    Report, Settings, ShapeDistance, Solution, Solver, SolverError, SolverInfo, Target, TargetKind,
    solve_renumbered,
};
use beltrami_mesh::{FaceId, Mesh, Point3, SurfacePoint};
use beltrami_spatial::SurfaceIndex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Sender};

use crate::compose::flipped_faces;
use crate::feature_match::Channel;
use crate::nonrigid_icp::NormalEquations;
use crate::shape::{Placement, Shape};
use crate::{InitialMap, RegisterError, check_topology, initial_map_for, match_features_after};

/// Surface registration: the initial bijection of `initial_map` (through a common
/// parameter domain chosen by the topology, aligned by the landmarks), then the discrete
/// Beltrami flow on the target mesh ([`beltrami_flow_engine::solve`] with `Target::Mesh`).
///
/// Reads: `target` (`Mesh` only), `goal` (`Conformal { 2 <= p <= 100 }`, `Prescribed`, or
/// `Features`: fields matched in the common domain from the initial map, with no flow
/// before or after: it would pull the map towards conformal),
/// landmarks (each with a `Position::Spatial` on the target; the vertex is pulled there
/// and held), open curves (feature curves: a source chain onto a target chain, ends
/// fixed, sliding between), and the flow's options. The map is `Map::OnMesh`. The
/// metrics have the initial map's `|mu|` statistics and the flow's history; the notes
/// the loops cut along and the alignment.
///
/// A mesh whose vertices are numbered in scattered order (median index spread of a
/// face above 4096) is registered as a breadth-first renumbered copy, for cache
/// locality, and the result carried back: maps, fields and messages are in the given
/// meshes' numbering.
///
/// A registration promises a bijection: when flipped faces remain after the flow and
/// its untangling, the solve fails with [`RegisterError::Flipped`] naming them and
/// why, unless the option `allow-flips` is set (then the notes name them).
#[derive(Debug, Clone, Copy, Default)]
pub struct Register;

const NAME: &str = "register";

/// How the flow's notes begin when it was asked for no step.
const NO_STEP_NOTE: &str = "stopped at the iteration limit (0)";

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    // Every connected topology: those of the flow on a target mesh.
    topologies: beltrami_flow_engine::ACCEPTS.topologies,
    targets: &[TargetKind::Mesh],
    goals: &[
        GoalKind::Conformal,
        GoalKind::ConformalLp,
        GoalKind::Prescribed,
        GoalKind::Features,
    ],
    constraints: &[ConstraintKind::Landmark, ConstraintKind::OpenCurve],
};

/// The options register adds to the flow's.
const OWN_OPTIONS: [OptionSpec; 4] = [
    OptionSpec {
        name: "allow-flips",
        kind: OptionKind::Bool { default: false },
        help: "keep a map that still has flipped faces after the flow (they are named in the notes) instead of failing",
    },
    OptionSpec {
        name: "match-shape",
        kind: OptionKind::Bool { default: false },
        help: "from the initial map, pull each image towards where the source, aligned by a similarity, lies on the target (a bijective non-rigid ICP; disks and closed genus-0 surfaces)",
    },
    OptionSpec {
        name: "in-place",
        kind: OptionKind::Bool { default: false },
        help: "with match-shape: the meshes lie in one frame and the source near its correspondence (two surfaces of one scan, such as pial and white): take the source where it is, not aligned, and deform it with the supple end of the non-rigid ICP's schedule",
    },
    OptionSpec {
        name: "allow-missed-landmarks",
        kind: OptionKind::Bool { default: false },
        help: "keep a map whose landmarks are not all exact (their distances are in the report) instead of failing",
    },
];

/// How many options register takes: the flow's and its own.
const OPTION_COUNT: usize = beltrami_flow_engine::OPTIONS.len() + OWN_OPTIONS.len();

/// The flow's options, `allow-flips`, `match-shape`, `in-place` and
/// `allow-missed-landmarks`.
const OPTIONS: [OptionSpec; OPTION_COUNT] = {
    let flow = beltrami_flow_engine::OPTIONS;
    let mut options = [OWN_OPTIONS[0]; OPTION_COUNT];
    let mut i = 0;
    while i < flow.len() {
        options[i] = flow[i];
        i += 1;
    }
    let mut j = 0;
    while j < OWN_OPTIONS.len() {
        options[flow.len() + j] = OWN_OPTIONS[j];
        j += 1;
    }
    options
};

/// A landmark is exact when its image is within this of its target, relative to the
/// target's bounding-box diagonal (rounding of barycentric coordinates is ~1e-16).
pub const LANDMARK_TOLERANCE: f64 = 1e-9;

/// A registration error as a solver error: [`SolverError::plugin`] of register, except
/// a cancelled inner solve, which stays [`SolverError::Cancelled`].
fn registration_error(error: RegisterError) -> SolverError {
    match error {
        // A Ctrl-C during an inner solve is the caller's cancellation, not a failure.
        RegisterError::Sphere {
            error: SolverError::Cancelled,
            ..
        }
        | RegisterError::Stopped => SolverError::Cancelled,
        error => SolverError::plugin(NAME, error),
    }
}

/// Most flipped faces named in an error or a note.
const NAMED_FLIPS: usize = 10;

/// The `flipped` faces of a map of `source` (with the largest angle between the
/// target's normals at their corners, [`flipped_faces`]), as an error, or as a note
/// when `allowed`.
fn judge_flips(
    source: &Mesh,
    flipped: &[(FaceId, f64)],
    allowed: bool,
    report: &mut Report,
) -> Result<(), RegisterError> {
    if flipped.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = flipped
        .iter()
        .take(NAMED_FLIPS)
        .map(|&(f, _)| source.face_to_input(f).to_string())
        .collect();
    let more = if flipped.len() > NAMED_FLIPS {
        ", .."
    } else {
        ""
    };
    let folds = flipped
        .iter()
        .filter(|&&(_, angle)| angle > FOLD_DEGREES)
        .count();
    let widest = flipped.iter().map(|&(_, a)| a).fold(0.0, f64::max);
    let ears = flipped
        .iter()
        .filter(|&&(f, _)| {
            source
                .face_halfedges(f)
                .filter(|&h| source.face(source.twin(h)).is_none())
                .count()
                >= 2
        })
        .count();
    let why = if ears > 0 {
        format!(
            "{ears} of them are ears (faces with two boundary edges): their three corners slide along the target's boundary, and an ear whose corners lie on one straight stretch of it is flat; split the ears (or give the target's boundary a corner for each)"
        )
    } else if folds > 0 {
        format!(
            "{folds} of them have corners on target faces whose normals differ by more than {FOLD_DEGREES} degrees (up to {widest:.0}): the target folds within one source face there, finer than the source resolves"
        )
    } else {
        format!(
            "the target's normals at their corners differ by at most {widest:.0} degrees: the flow found no step that removes them"
        )
    };
    let error = RegisterError::Flipped {
        count: flipped.len(),
        faces: format!("{}{more}", names.join(", ")),
        why,
    };
    keep_or_fail(error, allowed.then_some("allow-flips"), report)
}

/// `error` as a note naming the `option` that keeps the map when it is set, else as
/// the error.
fn keep_or_fail(
    error: RegisterError,
    option: Option<&str>,
    report: &mut Report,
) -> Result<(), RegisterError> {
    match option {
        Some(option) => {
            report
                .notes
                .push(format!("kept as asked ({option}): {error}"));
            Ok(())
        }
        None => Err(error),
    }
}

/// The distance from each landmark's image to its target (`targets`, in the order of
/// the problem's landmarks: the target vertex or the closest point of the target).
fn landmark_residuals(
    problem: &Problem<'_>,
    targets: &[Point3<f64>],
    positions: &[Point3<f64>],
) -> Vec<LandmarkResidual> {
    problem
        .constraints
        .landmarks()
        .zip(targets)
        .enumerate()
        .map(|(i, (mark, goal))| LandmarkResidual {
            index: i,
            vertex: mark.vertex,
            distance: (positions[mark.vertex.idx()] - goal).norm(),
        })
        .collect()
}

/// The landmarks farther than [`LANDMARK_TOLERANCE`] from their targets, as an error,
/// or as a note when `allowed`.
fn judge_landmarks(
    source: &Mesh,
    residuals: &[LandmarkResidual],
    diagonal: f64,
    allowed: bool,
    report: &mut Report,
) -> Result<(), RegisterError> {
    let missed: Vec<&LandmarkResidual> = residuals
        .iter()
        .filter(|r| r.distance.is_nan() || r.distance > LANDMARK_TOLERANCE * diagonal)
        .collect();
    let Some(worst) = missed
        .iter()
        .max_by(|a, b| a.distance.total_cmp(&b.distance))
    else {
        return Ok(());
    };
    let error = RegisterError::LandmarksMissed {
        count: missed.len(),
        total: residuals.len(),
        index: worst.index,
        vertex: source.vertex_map().to_input(worst.vertex),
        distance: worst.distance,
        relative: worst.distance / diagonal,
    };
    keep_or_fail(error, allowed.then_some("allow-missed-landmarks"), report)
}

/// Corners whose target normals differ by more than this lie across a fold.
const FOLD_DEGREES: f64 = 90.0;

/// The problem's landmarks, in their order.
fn landmarks(problem: &Problem<'_>) -> Vec<Landmark> {
    problem.constraints.landmarks().copied().collect()
}

/// What [`Register`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "surface registration: a bijective map onto another mesh of the same topology, as conformal as the constraints allow (or with a prescribed mu)",
    accepts: ACCEPTS,
    options: &OPTIONS,
};

impl Solver for Register {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(&self, problem: &Problem<'_>, settings: &Settings) -> Result<(), SolverError> {
        let Target::Mesh(target) = &problem.target else {
            return Err(SolverError::unsupported(
                NAME,
                "register maps onto a target mesh",
            ));
        };
        let topology = check_topology(problem.source, target)
            .map_err(|e| SolverError::unsupported(NAME, e.to_string()))?;
        for (side, mesh) in [("source", problem.source), ("target", *target)] {
            if let Some(f) = mesh.faces().find(|&f| mesh.face_degree(f) != 3) {
                return Err(SolverError::unsupported(
                    NAME,
                    format!(
                        "the flow works on triangle meshes; {side} face {} (input index) has {} vertices: split quads into triangles first",
                        mesh.face_to_input(f),
                        mesh.face_degree(f)
                    ),
                ));
            }
        }
        let features = match &problem.goal {
            Goal::Features(features) => Some(features),
            _ => None,
        };
        let shape = settings.flag("match-shape");
        if settings.flag("in-place") && !shape {
            return Err(SolverError::invalid(
                NAME,
                "in-place says where the shape match takes the source from: give it with match-shape",
            ));
        }
        if (features.is_some() || shape) && problem.constraints.curves().next().is_some() {
            return Err(SolverError::unsupported(
                NAME,
                "feature curves and matched fields (features, match-shape) together are not matched yet: give landmarks along the curves instead",
            ));
        }
        crate::check_features(topology, features, shape, problem.source, target)
            .map_err(registration_error)?;
        crate::consistency::check(problem, target).map_err(registration_error)?;
        Ok(())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        solve_renumbered(problem, |problem| register(problem, settings, context))
    }
}

/// The registration `solution` of `flow` (onto its target mesh `target`; the initial
/// map: [`route`]) bent in the common domain so that `features` match and, with `shape`, the source's
/// coordinates placed so (modules `feature_match`, `shape`), then measured by the flow
/// engine with no step (a step would pull it back towards conformal).
fn after_features(
    flow: &Problem<'_>,
    target: &Mesh,
    initial: &InitialMap,
    features: Option<&Features>,
    shape: Option<&Shape>,
    solution: Solution,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let Some(Map::OnMesh(points)) = solution.map() else {
        return Ok(solution);
    };
    let mut channels: Vec<Channel> = features
        .map(|f| Channel {
            source: f.source.clone(),
            target: f.target.clone(),
            standardize: true,
        })
        .into_iter()
        .collect();
    if let Some(fitted) = shape {
        channels.extend(fitted.channels(target));
    }
    let mut report = solution.report.clone();
    let mut notes = Vec::new();
    let (matched, mismatch) = context.stage("feature match", &mut report, || {
        match_features_after(flow.source, target, initial, points, &channels, &mut notes)
            .map_err(registration_error)
    })?;
    report.notes.extend(notes);
    let distance = shape.map(|s| ShapeDistance {
        before: s.distance(flow.source, target, points),
        after: s.distance(flow.source, target, &matched),
    });
    let mut measure = flow.clone();
    let positions = matched.iter().map(|p| p.position(target)).collect();
    measure.initial = Some(Map::OnMesh(matched));
    let mut measured = flow_from(&measure, None, positions, report, context)?;
    measured.extras.features = Some(mismatch);
    measured.extras.shape = distance;
    Ok(measured)
}

/// What the shape template needs before the initial map: the target's index (its
/// closest points on both cores: fsaverage5's template 2.8 s -> 2.3 s, the same points,
/// each search being exact) and the source's non-rigid ICP equations, their symbolic
/// factorization done.
struct TemplateSetup<'t> {
    index: SurfaceIndex<'t>,
    equations: NormalEquations,
}

impl<'t> TemplateSetup<'t> {
    fn new(source: &Mesh, target: &'t Mesh, placement: Placement) -> Result<Self, RegisterError> {
        Ok(Self {
            index: SurfaceIndex::new(target)?.with_threads(0),
            equations: NormalEquations::new(source, placement.schedule())?,
        })
    }
}

/// The source's shape placed on `target` (module `shape`) from the images `points` of
/// its vertices, asking `stopped` between rounds.
fn shape_template(
    source: &Mesh,
    target: &Mesh,
    setup: &mut TemplateSetup<'_>,
    points: &[SurfacePoint],
    placement: Placement,
    stopped: &dyn Fn() -> bool,
) -> Result<Shape, RegisterError> {
    Shape::new(
        source,
        target,
        &setup.index,
        &mut setup.equations,
        points,
        placement,
        stopped,
    )?
    .ok_or_else(|| RegisterError::Features {
        reason: "the initial map's images lie on a line: no similarity places the source for match-shape".to_string(),
    })
}

/// The road of a registration from `initial`, in words: the initial map's, then the
/// flow, or the feature match when `matched`.
///
/// A map to be matched takes no flow step before the match: the flow would make it
/// conformal on the target, sliding it away from the correspondence the initial map
/// fixed by the landmarks and the spatial alignment, which the match then has to find
/// again (fsaverage5 pial onto white from the truth by shape 1.291 -> 1.275 mm, by the
/// sulcal depth 0.625 -> 0.584 mm, with the 24 landmarks as well 0.452 -> 0.392 mm, in
/// place 0.481 -> 0.455 mm; docs/register.md). The flow engine's untangling still
/// runs, with no flow step: it unfolds the faces the initial map folds before the
/// match, and those the match leaves after it (the hemisphere onto the face: 6 -> 0
/// before, 8 -> 0 after).
fn route(initial: &InitialMap, landmarks: bool, matched: bool) -> String {
    let held = if landmarks {
        " with every landmark held"
    } else {
        ""
    };
    let then = if matched {
        "then the feature match bends it (no flow before it)".to_string()
    } else {
        format!("then the flow on the target mesh{held}")
    };
    format!("{}; {then}", initial.route)
}

/// The flow of `flow` from `positions` (the images of its initial map), with the
/// settings `steps`, or with no step (the flow engine's measure and untangling only)
/// when `None`: a map to be matched, before and after the match.
fn flow_from(
    flow: &Problem<'_>,
    steps: Option<&Settings>,
    positions: Vec<Point3<f64>>,
    report: Report,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let no_steps;
    let settings = match steps {
        Some(settings) => settings,
        None => {
            let mut options = flow.options.clone();
            options.set("max-iters", OptionValue::Int(0));
            no_steps = Settings::resolve(NAME, &OPTIONS, &options).map_err(SolverError::from)?;
            &no_steps
        }
    };
    let mut solution =
        beltrami_flow_engine::solve(flow, settings, positions, None, report, context)?;
    if steps.is_none() {
        // No step was taken by design: the stop is not news.
        solution
            .report
            .notes
            .retain(|n| !n.starts_with(NO_STEP_NOTE));
    }
    Ok(solution)
}

/// The conformal registration of `problem` onto its target mesh `target`: the initial
/// map (whose images are sent on `initial_images`, when given, as soon as it is made)
/// and the flow from it, which takes no step when the map is to be matched (`matched`:
/// [`route`]). Returns the initial map, the flow's problem and its solution.
fn conformal_registration<'p>(
    problem: &Problem<'p>,
    target: &Mesh,
    settings: &Settings,
    matched: bool,
    initial_images: Option<Sender<Vec<SurfacePoint>>>,
    mut report: Report,
    context: &mut Context<'_>,
) -> Result<(InitialMap, Problem<'p>, Solution), SolverError> {
    let marks = landmarks(problem);
    let cancel = context.cancel_flag();
    let initial = context.stage("initial map", &mut report, || {
        initial_map_for(problem.source, target, &marks, matched, &cancel)
            .map_err(registration_error)
    })?;
    if let Some(images) = initial_images {
        // A template that failed in its setup no longer listens: its error comes after
        // the flow.
        let _ = images.send(initial.points.clone());
    }
    report.notes.extend(initial.notes.iter().cloned());
    let mut flow = problem.clone();
    // With features the flow takes no step: it only measures the map they start from.
    flow.goal = match &problem.goal {
        Goal::Features(_) => Goal::default(),
        goal => goal.clone(),
    };
    // The flow holds each landmark where the initial map put it, on its target: the
    // closest point of the target to the given point (the flow would pull a vertex
    // towards the given point itself, off the surface).
    let mut held = Constraints::new();
    let mut goals = initial.landmark_targets.iter();
    for constraint in problem.constraints.iter() {
        held.push(match constraint {
            Constraint::Landmark(mark) => Constraint::Landmark(beltrami_core::Landmark {
                vertex: mark.vertex,
                position: goals
                    .next()
                    .map_or(mark.position, |goal| Position::Spatial(*goal)),
            }),
            other => other.clone(),
        });
    }
    flow.constraints = held;
    flow.initial = Some(Map::OnMesh(initial.points.clone()));
    // A map to be matched starts from the initial map (`route`).
    let steps = (!matched).then_some(settings);
    let positions = initial.positions.clone();
    let solution = flow_from(&flow, steps, positions, report, context)?;
    Ok((initial, flow, solution))
}

/// The registration of `problem`, in the numbering of its meshes ([`Register`]).
pub(crate) fn register(
    problem: &Problem<'_>,
    settings: &Settings,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let Target::Mesh(target) = problem.target else {
        return Err(SolverError::unsupported(
            NAME,
            "register maps onto a target mesh",
        ));
    };
    let source = problem.source;
    let features = match &problem.goal {
        Goal::Features(features) => Some(features),
        _ => None,
    };
    let shape = settings.flag("match-shape").then(|| {
        if settings.flag("in-place") {
            Placement::InPlace
        } else {
            Placement::Aligned
        }
    });
    let matched = features.is_some() || shape.is_some();
    let cancel = context.cancel_flag();
    // The shape template needs only the initial map: it is fitted on a second thread
    // while the flow runs (g0_spot onto its deformation: 1.6 s -> 1.2 s; the flow's
    // images as its start measured 0.0143 from the truth, the initial map's 0.0147),
    // and what it needs before that map is made while the map is (fsaverage5: the
    // non-rigid ICP's symbolic factorization, 0.22 s).
    let stop = AtomicBool::new(false);
    let (send_images, receive_images) = mpsc::channel();
    let flowed = std::thread::scope(|scope| {
        let template = shape.map(|placement| {
            let (stop, cancel) = (&stop, &cancel);
            scope.spawn(move || {
                let stopped = || stop.load(Ordering::Relaxed) || cancel.load(Ordering::Relaxed);
                let mut setup = TemplateSetup::new(source, target, placement)?;
                // No images come when the initial map failed: nothing to fit.
                let points: Vec<SurfacePoint> =
                    receive_images.recv().map_err(|_| RegisterError::Stopped)?;
                shape_template(source, target, &mut setup, &points, placement, &stopped)
            })
        });
        let report = Report::new(NAME);
        let flowed = conformal_registration(
            problem,
            target,
            settings,
            matched,
            shape.is_some().then_some(send_images),
            report,
            context,
        )
        .and_then(|(initial, flow, mut solution)| {
            // Timed as the wait for the template after the flow (the stages add up
            // to the run's time).
            let fitted = template
                .map(|handle| {
                    context.stage("shape template", &mut solution.report, || {
                        handle
                            .join()
                            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                            .map_err(registration_error)
                    })
                })
                .transpose()?;
            Ok((initial, flow, solution, fitted))
        });
        // An error (a Ctrl-C) ends the template's rounds before the scope joins it.
        if flowed.is_err() {
            stop.store(true, Ordering::Relaxed);
        }
        flowed
    });
    let (initial, flow, mut solution, template) = flowed?;
    if matched {
        let shape = template.as_ref();
        solution = after_features(&flow, target, &initial, features, shape, solution, context)?;
    }
    // Judged against the target's normals at the images (the rule of `beltrami
    // distortion --target` and of the flow), when the initial map was built.
    solution.metrics.initial_distortion = Some(initial.distortion);
    solution.metrics.teichmueller_bound = initial.teichmueller_bound;
    solution.extras.route = Some(route(
        &initial,
        problem.constraints.landmarks().next().is_some(),
        matched,
    ));
    let Some(Map::OnMesh(points)) = solution.map().cloned() else {
        return Ok(solution);
    };
    let positions: Vec<_> = points.iter().map(|p| p.position(target)).collect();
    solution.extras.landmarks = landmark_residuals(problem, &initial.landmark_targets, &positions);
    judge_landmarks(
        source,
        &solution.extras.landmarks,
        target.bounding_box().diagonal(),
        settings.flag("allow-missed-landmarks"),
        &mut solution.report,
    )
    .map_err(registration_error)?;
    if solution.metrics.flipped().unwrap_or(0) > 0 {
        let index = SurfaceIndex::new(target).map_err(|e| registration_error(e.into()))?;
        // The flow counts on its own measure; a face it leaves flat (an ear whose corners
        // lie on one straight stretch of the target's boundary) can count either way
        // there. The report gives what `beltrami distortion --target` measures.
        let (measured, flipped) =
            flipped_faces(source, &index, &points, &positions).map_err(registration_error)?;
        solution.metrics.distortion = Some(measured);
        judge_flips(
            source,
            &flipped,
            settings.flag("allow-flips"),
            &mut solution.report,
        )
        .map_err(registration_error)?;
    }
    Ok(solution)
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_core::{Landmark, Renumbered};
    use beltrami_fem::ReferenceNormal;
    use beltrami_fem::distortion::measure_surface;
    use beltrami_mesh::primitives::{self, icosphere, octahedral_sphere};
    use beltrami_mesh::{PolygonSoup, VertexId};
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    fn scattered(soup: &PolygonSoup) -> Mesh {
        Mesh::from_soup(&primitives::scattered(soup)).unwrap()
    }

    #[test]
    fn a_cancelled_registration_stops_in_the_sphere_maps() {
        let source = Mesh::from_soup(&folded(icosphere(2))).unwrap();
        let target = Mesh::from_soup(&folded(octahedral_sphere(3))).unwrap();
        let cancel = Arc::new(AtomicBool::new(true));
        let error = crate::initial_map_for(&source, &target, &[], false, &cancel).unwrap_err();
        assert!(matches!(registration_error(error), SolverError::Cancelled));
        assert!(crate::initial_map_for(&source, &target, &[], false, &Arc::default()).is_ok());
    }

    #[test]
    fn a_registration_by_shape_cancelled_in_its_initial_map_ends_cancelled() {
        // The template's thread waits for the initial map's images; when the map is
        // cancelled none come, and the registration ends as cancelled instead of
        // waiting for them.
        let source = Mesh::from_soup(&folded(icosphere(2))).unwrap();
        let target = Mesh::from_soup(&folded(octahedral_sphere(3))).unwrap();
        let mut problem = Problem::new(&source, Target::Mesh(&target));
        problem.options.set("match-shape", OptionValue::Bool(true));
        let settings = Register.check(&problem).unwrap();
        let mut context = Context::new().with_cancel_flag(Arc::new(AtomicBool::new(true)));
        let error = register(&problem, &settings, &mut context).unwrap_err();
        assert!(matches!(error, SolverError::Cancelled), "{error:?}");
    }

    #[test]
    fn a_stopped_shape_template_is_a_cancellation() {
        // The template fitted beside the flow asks its stop between rounds; stopped, the
        // registration ends as cancelled, not as a failure.
        let source = Mesh::from_soup(&icosphere(2)).unwrap();
        let target = Mesh::from_soup(&octahedral_sphere(3)).unwrap();
        let initial = crate::initial_map_for(&source, &target, &[], true, &Arc::default()).unwrap();
        let mut setup = TemplateSetup::new(&source, &target, Placement::Aligned).unwrap();
        for placement in [Placement::Aligned, Placement::InPlace] {
            let points = &initial.points;
            let stopped = shape_template(&source, &target, &mut setup, points, placement, &|| true);
            let error = stopped.err().map(registration_error);
            assert!(matches!(error, Some(SolverError::Cancelled)), "{error:?}");
            let fitted = shape_template(&source, &target, &mut setup, points, placement, &|| false);
            assert!(fitted.is_ok());
        }
    }

    /// A sphere with five deep radial folds (ridges along meridians), the positions of
    /// `soup` (on the unit sphere) pushed out to `1 + 0.3 sin(5 phi) (1 - z^2)`.
    fn folded(mut soup: PolygonSoup) -> PolygonSoup {
        for p in &mut soup.positions {
            let u = p.coords.normalize();
            let r = 1.0 + 0.3 * (5.0 * u.y.atan2(u.x)).sin() * (1.0 - u.z * u.z);
            *p = Point3::from(u * r);
        }
        soup
    }

    /// An inversion in the sphere of radius 2 about `(3, 0.5, -0.4)` after a mirror in
    /// the plane x = 0: conformal (each reverses orientation, together they keep it) but
    /// not a similarity.
    fn inversion(p: &Point3<f64>) -> Point3<f64> {
        let c = nalgebra::Vector3::new(3.0, 0.5, -0.4);
        let mirrored = nalgebra::Vector3::new(-p.x, p.y, p.z);
        let d = mirrored - c;
        Point3::from(c + d * (4.0 / d.norm_squared()))
    }

    /// Registers the folded icosphere of `level` onto the inverted folded octahedral
    /// sphere of `level + 2` with `marks` landmarks at the truth; returns the mean
    /// distance of the images from the truth relative to the target's diagonal.
    fn folded_onto_its_inversion(level: usize, marks: usize) -> f64 {
        let source = Mesh::from_soup(&folded(icosphere(level))).unwrap();
        let mut soup = folded(octahedral_sphere(level + 2));
        for p in &mut soup.positions {
            *p = inversion(p);
        }
        let target = Mesh::from_soup(&soup).unwrap();
        let mut problem = Problem::new(&source, Target::Mesh(&target));
        let step = source.vertex_count() / marks;
        let landmarks: Vec<VertexId> = (0..marks).map(|k| VertexId((k * step) as u32)).collect();
        for &vertex in &landmarks {
            problem.constraints.push(Constraint::Landmark(Landmark {
                vertex,
                position: Position::Spatial(inversion(&source.position(vertex))),
            }));
        }
        let settings = Register.check(&problem).unwrap();
        let solution = register(&problem, &settings, &mut Context::new()).unwrap();
        let Some(Map::OnMesh(points)) = solution.map() else {
            panic!("a map onto the target mesh");
        };
        assert_eq!(solution.metrics.flipped(), Some(0), "level {level}");
        let diagonal = target.bounding_box().diagonal();
        assert_eq!(solution.extras.landmarks.len(), marks);
        for mark in &solution.extras.landmarks {
            assert!(
                mark.distance <= 1e-12 * diagonal,
                "level {level}: landmark {} at {:e}",
                mark.index,
                mark.distance
            );
        }
        let total: f64 = source
            .vertices()
            .map(|v| (points[v.idx()].position(&target) - inversion(&source.position(v))).norm())
            .sum();
        total / source.vertex_count() as f64 / diagonal
    }

    #[test]
    fn a_folded_sphere_goes_onto_its_inversion_with_every_landmark_exact() {
        // The inversion is conformal, so it is the map the registration approaches: the
        // error to it comes from the two meshes' discretizations and falls under
        // refinement, while every landmark is exact and no face flips.
        let coarse = folded_onto_its_inversion(3, 8);
        let fine = folded_onto_its_inversion(4, 8);
        assert!(fine < 0.7 * coarse, "error {coarse:e} -> {fine:e}");
        assert!(fine < 5e-3, "{fine:e}");
    }

    #[test]
    fn a_registration_of_renumbered_meshes_is_the_registration_of_the_given_ones() {
        let source = scattered(&octahedral_sphere(3));
        let mut soup = icosphere(3);
        for p in &mut soup.positions {
            *p = Point3::new(1.6 * p.x, p.y + 0.2 * p.x * p.x, 0.8 * p.z);
        }
        let target = scattered(&soup);
        let mut problem = Problem::new(&source, Target::Mesh(&target));
        // Two landmarks, onto vertices of the target (apart on its surface).
        let marks = [(VertexId(3), VertexId(10)), (VertexId(40), VertexId(100))];
        for (vertex, onto) in marks {
            problem.constraints.push(Constraint::Landmark(Landmark {
                vertex,
                position: Position::Spatial(target.position(onto)),
            }));
        }
        let settings = Register.check(&problem).unwrap();
        let given = register(&problem, &settings, &mut Context::new()).unwrap();
        // Every mesh renumbered (spread 0).
        let renumbered = Renumbered::new(&problem, 0).unwrap().unwrap();
        let local = renumbered.problem(&problem);
        assert!(!std::ptr::eq(local.source, &source));
        let solution =
            renumbered.solution_to_old(register(&local, &settings, &mut Context::new()).unwrap());
        let Some(Map::OnMesh(points)) = solution.map() else {
            panic!("a map onto the target mesh");
        };
        let image: Vec<Point3<f64>> = points.iter().map(|p| p.position(&target)).collect();
        for (vertex, onto) in marks {
            let at = image[vertex.idx()];
            assert!(
                (at - target.position(onto)).norm() < 1e-12,
                "{vertex}: {at}"
            );
        }
        // The map, read in the given numbering, has the distortion the solution reports
        // for each face of the given numbering.
        let measured = measure_surface(&source, &image, ReferenceNormal::Radial).unwrap();
        let reported = &solution.metrics.mu.as_ref().unwrap().mu;
        for (f, (m, r)) in measured.field.mu.iter().zip(reported).enumerate() {
            assert!(
                (m.norm() - r.norm()).abs() < 1e-9,
                "face {f}: |mu| {m} against {r}"
            );
        }
        // Another numbering rounds differently and the flow stalls elsewhere (after 6
        // and 13 steps here), at about the same energy.
        let energy = |s: &Solution| *s.metrics.energy_history.last().unwrap();
        assert!((energy(&given) - energy(&solution)).abs() < 1e-2 * energy(&given));
        assert!(
            renumbered
                .note()
                .contains("the source (median index spread")
        );
    }
}
