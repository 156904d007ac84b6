//! [`Register`]: the solver behind `beltrami register` (crate docs).

use beltrami_core::{
    Accepts, ConstraintKind, Context, Element, GoalKind, Map, OptionSpec, Position, Problem,
    Report, Settings, Solution, Solver, SolverError, Target, TargetKind, Topology,
};

use crate::{Landmark, LandmarkTarget, check_topology, initial_map};

/// Surface registration: the initial bijection of [`initial_map`] (through a common
/// parameter domain chosen by the topology, aligned by the landmarks), then the discrete
/// Beltrami flow on the target mesh ([`beltrami_flow_engine::solve`] with `Target::Mesh`).
///
/// Reads: `target` (`Mesh` only), `goal` (`Conformal { p >= 2 }` or `Prescribed`),
/// landmarks (each with a `Position::Spatial` on the target; the vertex is pulled there
/// and held), open curves (feature curves: a source chain onto a target chain, ends
/// fixed, sliding between), and the flow's options. The map is `Map::OnMesh`. The
/// metrics have the initial map's `|mu|` statistics and the flow's history; the notes
/// the loops cut along and the alignment.
#[derive(Debug, Clone, Copy, Default)]
pub struct Register;

const NAME: &str = "register";

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle],
    topologies: &[Topology::Disk, Topology::Sphere, Topology::Torus],
    targets: &[TargetKind::Mesh],
    goals: &[
        GoalKind::Conformal,
        GoalKind::ConformalLp,
        GoalKind::Prescribed,
    ],
    constraints: &[ConstraintKind::Landmark, ConstraintKind::OpenCurve],
};

fn unsupported(message: impl Into<String>) -> SolverError {
    SolverError::Unsupported {
        solver: NAME,
        message: message.into(),
    }
}

/// The problem's landmarks, as the initial map takes them.
fn landmarks(problem: &Problem<'_>) -> Result<Vec<Landmark>, SolverError> {
    problem
        .constraints
        .landmarks()
        .map(|mark| match mark.position {
            Position::Spatial(p) => Ok(Landmark {
                source: mark.vertex,
                target: LandmarkTarget::Point(p),
            }),
            Position::Planar(_) => Err(unsupported(format!(
                "the landmark on source vertex {} needs a point on the target mesh, not in the plane",
                mark.vertex
            ))),
        })
        .collect()
}

impl Solver for Register {
    fn name(&self) -> &'static str {
        NAME
    }

    fn description(&self) -> &'static str {
        "surface registration: a bijective map onto another mesh of the same topology, as conformal as the constraints allow (or with a prescribed mu)"
    }

    fn accepts(&self) -> Accepts {
        ACCEPTS
    }

    fn options(&self) -> &'static [OptionSpec] {
        beltrami_flow_engine::OPTIONS
    }

    fn check_problem(
        &self,
        problem: &Problem<'_>,
        _settings: &Settings,
    ) -> Result<(), SolverError> {
        let Target::Mesh(target) = &problem.target else {
            return Err(unsupported("register maps onto a target mesh"));
        };
        check_topology(problem.source, target).map_err(|e| unsupported(e.to_string()))?;
        for (side, mesh) in [("source", problem.source), ("target", *target)] {
            if let Some(f) = mesh.faces().find(|&f| mesh.face_degree(f) != 3) {
                return Err(unsupported(format!(
                    "the flow works on triangle meshes; {side} face {} (input index) has {} vertices: split quads into triangles first",
                    mesh.face_to_input(f),
                    mesh.face_degree(f)
                )));
            }
        }
        landmarks(problem)?;
        Ok(())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let Target::Mesh(target) = &problem.target else {
            return Err(unsupported("register maps onto a target mesh"));
        };
        let source = problem.source;
        let marks = landmarks(problem)?;
        let mut report = Report::new(NAME);
        let initial = context.stage("initial map", &mut report, || {
            initial_map(source, target, &marks).map_err(|e| SolverError::Plugin {
                solver: NAME,
                error: Box::new(e),
            })
        })?;
        report.notes.extend(initial.notes.iter().cloned());
        let mut flow = problem.clone();
        flow.initial = Some(Map::OnMesh(initial.points));
        let mut solution =
            beltrami_flow_engine::solve(&flow, settings, initial.positions, report, context)?;
        // Judged against the target's normals at the images (the rule of `beltrami
        // distortion --target` and of the flow), when the initial map was built.
        solution.metrics.initial_distortion = Some(initial.distortion);
        Ok(solution)
    }
}
