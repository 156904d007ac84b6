//! [`Register`]: the solver behind `beltrami register` (crate docs).

use beltrami_core::{
    Context, Goal, Map, Position, Problem, Report, Solution, Solver, SolverError, Target,
};
use beltrami_fem::ReferenceNormal;
use beltrami_fem::distortion::measure_surface;
use beltrami_flow::BeltramiFlow;
use beltrami_spatial::SurfaceIndex;

use crate::{Landmark, LandmarkTarget, check_topology, initial_map};

/// Surface registration: the initial bijection of [`initial_map`] (through a common
/// parameter domain chosen by the topology, aligned by the landmarks), then the discrete
/// Beltrami flow on the target mesh ([`BeltramiFlow`] with `Target::Mesh`).
///
/// Reads: `target` (`Mesh` only), `goal` (`Conformal { p >= 2 }` or `Prescribed`),
/// `constraints.pins` (landmarks: every pin needs a `Position::Spatial` on the target;
/// the vertex is pulled there and held), `constraints.curves` (feature curves: a source
/// chain onto a target chain, ends fixed, sliding between), `params` (as the flow). The
/// map is `Map::OnMesh`. The report has the initial map's notes (the loops cut along,
/// the alignment), its `|mu|` statistics, and the flow's history.
#[derive(Debug, Clone, Copy, Default)]
pub struct Register;

const NAME: &str = "register";

fn unsupported(message: impl Into<String>) -> SolverError {
    SolverError::Unsupported {
        solver: NAME,
        message: message.into(),
    }
}

/// The landmarks of the problem's pins.
fn landmarks(problem: &Problem<'_>) -> Result<Vec<Landmark>, SolverError> {
    problem
        .constraints
        .pins
        .iter()
        .map(|pin| match pin.position {
            Some(Position::Spatial(p)) => Ok(Landmark {
                source: pin.vertex,
                target: LandmarkTarget::Point(p),
            }),
            _ => Err(unsupported(format!(
                "pin on source vertex {} needs a point on the target (a landmark)",
                pin.vertex
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

    fn accepts(&self) -> &'static str {
        "triangle meshes, source and target of the same topology: one boundary loop, closed genus 0 or closed genus 1; goals: conformal L^p (p >= 2) or prescribed mu; landmarks, feature curves"
    }

    fn check(&self, problem: &Problem<'_>) -> Result<(), SolverError> {
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
        if let Goal::Extremal = problem.goal {
            return Err(unsupported("extremal maps come with their own solver"));
        }
        Ok(())
    }

    fn solve(
        &self,
        problem: &Problem<'_>,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        self.check(problem)?;
        let Target::Mesh(target) = &problem.target else {
            return Err(unsupported("register maps onto a target mesh"));
        };
        let source = problem.source;
        let marks = landmarks(problem)?;
        let mut report = Report::new(NAME);
        let initial = context.stage("initial map", &mut report, || {
            initial_map(source, target, &marks).map_err(|e| SolverError::InvalidInput {
                solver: NAME,
                message: e.to_string(),
            })
        })?;
        report.notes.extend(initial.notes.iter().cloned());
        // The initial map's distortion, judged against the target's normals at the images
        // (the rule of `beltrami distortion --target` and of the flow).
        let index = SurfaceIndex::new(target).map_err(|e| SolverError::InvalidInput {
            solver: NAME,
            message: format!("the target mesh: {e}"),
        })?;
        let normals = index
            .face_reference_normals(source, &initial.points)
            .map_err(|e| SolverError::InvalidInput {
                solver: NAME,
                message: format!("the initial map on the target mesh: {e}"),
            })?;
        let start = measure_surface(
            source,
            &initial.positions,
            ReferenceNormal::PerFace(&normals),
        )?;
        report.notes.push(format!(
            "initial map: mean |mu| {:.4}, max |mu| {:.4}, {} flipped faces",
            start.stats.mu_mean, start.stats.mu_max, start.stats.flipped
        ));
        let initial_distortion = Some(start.stats);
        let mut flow = problem.clone();
        flow.initial = Some(Map::OnMesh(initial.points));
        let solution = BeltramiFlow.solve(&flow, context)?;
        let mut timings = std::mem::take(&mut report.timings);
        timings.extend(solution.report.timings);
        let mut notes = report.notes;
        notes.extend(solution.report.notes);
        Ok(Solution {
            map: solution.map,
            report: Report {
                solver: NAME.into(),
                timings,
                notes,
                initial_distortion,
                ..solution.report
            },
        })
    }
}
