//! [`BeltramiFlow`]: the solver behind `--solver beltrami-flow` (crate docs).

use beltrami_core::{Context, Map, Problem, Report, Solution, Solver, SolverError, Target};
use beltrami_fem::{BeltramiField, DistortionStats, Elements, Frame, SolveOptions};
use beltrami_mesh::{Point3, VertexId};
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::NAME;
use crate::flow::{self, FlowOptions, FlowRun, Stop};
use crate::measure::Objective;
use crate::mesh_target::MeshTarget;
use crate::setup::{
    Domain, curve_roles, diagonal, domain, goals, initial_map, mesh_roles, pins, region_roles,
};
use crate::system::FlowSystem;
use crate::target::{INNER, OUTER, Role, TargetGeometry};
use crate::validate::{invalid, validate};

/// Discrete Beltrami flow onto a fixed target (crate docs).
///
/// Reads: `goal` (`Conformal { p >= 2 }` or `Prescribed(field)`), `target`
/// (`Plane(Keep | Square | Polygon | Circle)`, `Disk`, `Annulus`, `Sphere`, `Mesh` with
/// an initial map onto it — the register solver builds one — and `constraints.curves`),
/// `constraints.pins` (held where the initial map puts them), `initial` (a planar or
/// spatial map to start from; its images are projected onto the target first),
/// `params.tolerance` (largest vertex update, relative to the target's size),
/// `params.max_iterations` and `params.threads`.
#[derive(Debug, Clone, Copy, Default)]
pub struct BeltramiFlow;

/// On a target mesh, the largest vertex move tried in one step, relative to the target's
/// bounding-box diagonal ([`FlowOptions::max_move`]).
const MESH_MAX_MOVE: f64 = 0.05;

impl Solver for BeltramiFlow {
    fn name(&self) -> &'static str {
        NAME
    }

    fn description(&self) -> &'static str {
        "discrete Beltrami flow: a bijective map onto a fixed target with a prescribed mu or the smallest L^p norm of mu"
    }

    fn accepts(&self) -> &'static str {
        "triangle meshes; targets: plane (the input's own polygon, square, polygon), disk, annulus (fixed or free inner radius) for disks/annuli, sphere for closed genus 0, a target mesh of the same topology from an initial map (see register); goals: prescribed mu (global or face frame), conformal L^p (p >= 2); pins, landmarks and feature curves on target meshes"
    }

    fn check(&self, problem: &Problem<'_>) -> Result<(), SolverError> {
        validate(problem).map(|_| ())
    }

    fn solve(
        &self,
        problem: &Problem<'_>,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let goal = validate(problem)?;
        let mesh = problem.source;
        let mut report = Report::new(NAME);
        let elements = context.stage("elements", &mut report, || {
            Ok(Elements::new(mesh, goal.frame)?)
        })?;
        let initial = context.stage("initial map", &mut report, || initial_map(problem))?;
        let objective = Objective {
            areas: (0..mesh.face_count())
                .map(|f| elements.face_points(beltrami_mesh::FaceId(f as u32))[0].weight)
                .collect(),
            sigma: goal.sigma.clone(),
            p: goal.p,
        };
        let options = SolveOptions {
            threads: problem.params.threads,
            ..SolveOptions::default()
        };
        let planar = !matches!(problem.target, Target::Sphere);
        let runner = Runner {
            elements: &elements,
            objective: &objective,
            problem,
            options,
        };
        let input = |v: VertexId| mesh.vertex_map().to_input(v);
        let pins = pins(problem, &initial);
        if problem.constraints.pins.is_empty() && !pins.is_empty() {
            let names: Vec<String> = pins.iter().map(|&v| input(v).to_string()).collect();
            report.notes.push(format!(
                "pinned vertices {} (input indices) where the initial map puts them, to fix the target's conformal automorphisms",
                names.join(", ")
            ));
        }
        if let Target::Mesh(target) = &problem.target {
            let index = context.stage("target index", &mut report, || {
                SurfaceIndex::new(target).map_err(|e| invalid(format!("the target mesh: {e}")))
            })?;
            let (curves, roles) = mesh_roles(problem, target, &initial, &pins)?;
            let geometry = MeshTarget::new(&index, curves);
            let scale = diagonal(target.positions());
            let run = runner.run(
                geometry.clone(),
                roles,
                initial,
                scale,
                context,
                &mut report,
            )?;
            let points = geometry.locate_all(&run.image)?;
            let (_, faces_mu, flipped) = run.finish(false);
            return finish_solution(
                report,
                goal.frame,
                &objective,
                faces_mu,
                &flipped,
                Map::OnMesh(points),
            );
        }
        let domain = domain(problem, &initial)?;
        let image = initial;
        let outcome = match domain {
            Domain::Region(g) => {
                let scale = diagonal(&image);
                let roles = region_roles(mesh, &g, &image, &pins);
                runner
                    .run(g, roles, image, scale, context, &mut report)?
                    .finish(planar)
            }
            Domain::Disk(g) => {
                let roles = curve_roles(mesh, &pins, |_| 0);
                runner
                    .run(g, roles, image, 1.0, context, &mut report)?
                    .finish(planar)
            }
            Domain::Annulus(g, outer) => {
                let roles = curve_roles(mesh, &pins, |l| if l == outer { OUTER } else { INNER });
                let run = runner.run(g, roles, image, 1.0, context, &mut report)?;
                if g.free_inner {
                    report.notes.push(format!(
                        "inner radius {:.6} (free; started at {:.6})",
                        run.target.inner_radius, g.inner_radius
                    ));
                }
                run.finish(planar)
            }
            Domain::Sphere(g) => {
                let roles = curve_roles(mesh, &pins, |_| 0);
                runner
                    .run(g, roles, image, 1.0, context, &mut report)?
                    .finish(planar)
            }
        };
        let (map, faces_mu, flipped) = outcome;
        finish_solution(report, goal.frame, &objective, faces_mu, &flipped, map)
    }
}

/// The solution with its measured `mu`, statistics and a note on remaining flips.
fn finish_solution(
    mut report: Report,
    frame: Frame,
    objective: &Objective,
    faces_mu: Vec<Complex64>,
    flipped: &[bool],
    map: Map,
) -> Result<Solution, SolverError> {
    let stats = DistortionStats::new(&faces_mu, &objective.areas, flipped)?;
    if stats.flipped > 0 {
        report.notes.push(format!(
            "{} faces are flipped: the initial map had flips the flow could not remove",
            stats.flipped
        ));
    }
    report.mu = Some(BeltramiField::new(frame, faces_mu));
    report.distortion = Some(stats);
    Ok(Solution { map, report })
}

/// What every flow run of one solve shares.
struct Runner<'a, 'p> {
    elements: &'a Elements,
    objective: &'a Objective,
    problem: &'a Problem<'p>,
    options: SolveOptions,
}

impl Runner<'_, '_> {
    /// Runs the flow on `target` from `image` with `roles` (tolerances relative to
    /// `scale`) and records its history in `report`.
    fn run<G: TargetGeometry>(
        &self,
        target: G,
        roles: Vec<Role>,
        image: Vec<Point3<f64>>,
        scale: f64,
        context: &mut Context<'_>,
        report: &mut Report,
    ) -> Result<FlowRun<G>, SolverError> {
        let (elements, objective, problem, options) =
            (self.elements, self.objective, self.problem, self.options);
        let mut system = context.stage("symbolic", report, || {
            FlowSystem::new(elements, &target, &image, roles, options)
        })?;
        let flow_options = FlowOptions {
            tolerance: problem.params.tolerance * scale,
            max_iterations: problem.params.max_iterations,
            solve: options,
            max_move: if matches!(problem.target, Target::Mesh(_)) {
                MESH_MAX_MOVE * scale
            } else {
                f64::INFINITY
            },
        };
        let run = report.time("flow", || {
        flow::run(
            elements,
            target,
            &mut system,
            image,
            &goals(problem),
            objective,
            flow_options,
            context,
        )
    })
    .map_err(|e| match e {
        SolverError::Solve(beltrami_fem::SolveError::Singular { .. } | beltrami_fem::SolveError::NotPositiveDefinite { .. }) => invalid(
            "the flow is not determined: pin more vertices (disk: one interior and one boundary vertex; annulus: one boundary vertex; sphere: three vertices)",
        ),
        e => e,
    })?;
        report
            .timings
            .push(("flow: solves".into(), run.solve_seconds));
        report
            .timings
            .push(("flow: steps".into(), run.step_seconds));
        report.iterations = run.iterations();
        report.notes.push(format!(
            "{} numeric factorizations; {} conjugate-gradient iterations on steps that reused one",
            run.factorizations, run.cg_iterations
        ));
        report.energy_history = run.energy_history.clone();
        report.step_sizes = run.step_sizes.clone();
        report.notes.push(match run.stop {
        Stop::Converged => format!(
            "converged after {} iterations: largest vertex update below {:.1e}",
            run.iterations(),
            flow_options.tolerance
        ),
        Stop::Stalled => format!(
            "stopped after {} iterations: no step above the tolerance decreased the error further",
            run.iterations()
        ),
        Stop::IterationLimit => format!(
            "stopped at the iteration limit ({}) before converging",
            run.iterations()
        ),
        Stop::Cancelled => format!(
            "cancelled after {} iterations: the map is the best one so far",
            run.iterations()
        ),
    });
        Ok(run)
    }
}

impl<G> FlowRun<G> {
    /// The map, the per-face `mu` and flip flags.
    fn finish(self, planar: bool) -> (Map, Vec<Complex64>, Vec<bool>) {
        let mu = self.faces.iter().map(|f| f.mu()).collect();
        let flipped = self.faces.iter().map(|f| f.flipped()).collect();
        let map = if planar {
            Map::Planar(
                self.image
                    .iter()
                    .map(|p| Complex64::new(p.x, p.y))
                    .collect(),
            )
        } else {
            Map::Spatial(self.image)
        };
        (map, mu, flipped)
    }
}
