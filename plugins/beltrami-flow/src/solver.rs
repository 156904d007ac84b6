//! [`BeltramiFlow`]: the solver behind `--solver beltrami-flow` (crate docs): the
//! initial map (given, or the boundary-first or Tutte disk, or the sphere
//! initialization), then the flow
//! engine ([`beltrami_flow_engine::solve`]).

use beltrami_atlas::unit_disk::map_to_unit_disk;
use beltrami_core::{
    Context, Map, Output, PlanarBoundary, Problem, Report, Settings, Solution, Solver, SolverError,
    SolverInfo, Target, solve_renumbered,
};
use beltrami_fem::element::is_planar;
use beltrami_flow_engine::system::VertexOrder;
use beltrami_flow_engine::{ACCEPTS, NAME, ON_TARGET, OPTIONS, annulus_of, given_initial};
use beltrami_init::{Sphere, Tutte};
use beltrami_mesh::Point3;

/// Discrete Beltrami flow onto a fixed target (crate docs).
///
/// Reads what [`beltrami_flow_engine::solve`] reads; without a given initial map it
/// starts from the source itself (a planar source already on the target), the
/// boundary-first conformal map onto the unit disk (Tutte's where it folds), Tutte's
/// map onto the target's polygon, a radial stretch onto the annulus, or the sphere
/// initialization.
#[derive(Debug, Clone, Copy, Default)]
pub struct BeltramiFlow;

/// What [`BeltramiFlow`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "discrete Beltrami flow: a bijective map onto a fixed target with a prescribed mu or the smallest L^p norm of mu",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for BeltramiFlow {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(
        &self,
        problem: &Problem<'_>,
        _settings: &Settings,
    ) -> Result<(), SolverError> {
        beltrami_flow_engine::validate(problem)
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        solve_renumbered(problem, |problem| flow(problem, settings, context))
    }
}

/// The flow of `problem`, in the numbering of its meshes.
fn flow(
    problem: &Problem<'_>,
    settings: &Settings,
    context: &mut Context<'_>,
) -> Result<Solution, SolverError> {
    let mut report = Report::new(NAME);
    let threads = settings.int("threads");
    let mut inner = context.inner();
    // The flow's vertex order does not depend on the initial map: computed beside it,
    // on a second core (the hand's disk map: 0.18 s of ordering beside a 0.19-s map).
    let (initial, order) = std::thread::scope(|scope| {
        let order = scope.spawn(|| VertexOrder::of(problem.source));
        let initial = context.stage("initial map", &mut report, || {
            initial_map(problem, threads, &mut inner)
        });
        let order = order
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (initial, order)
    });
    let (initial, order) = (initial?, order?);
    beltrami_flow_engine::solve(problem, settings, initial, Some(&order), report, context)
}

/// The map the flow starts from, as points of R^3 (z = 0 for planar targets): the given
/// one, or one built here. `threads` is passed to the initialization's factorizations,
/// `context` (the caller's [`Context::inner`]) to its solve.
fn initial_map(
    problem: &Problem<'_>,
    threads: usize,
    context: &mut Context<'_>,
) -> Result<Vec<Point3<f64>>, SolverError> {
    let mesh = problem.source;
    if let Some(given) = given_initial(problem)? {
        return Ok(given);
    }
    let planar_points = |output: Output| match output {
        Output::Map(Map::Planar(z)) => Ok(z.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect()),
        _ => Err(SolverError::invalid(NAME, "the initial map is not planar")),
    };
    let identity = || {
        mesh.positions()
            .iter()
            .map(|p| Point3::new(p.x, p.y, 0.0))
            .collect()
    };
    let mut init = Problem::new(mesh, problem.target.clone());
    init.options
        .set("threads", beltrami_core::OptionValue::Int(threads));
    match &problem.target {
        Target::Plane(PlanarBoundary::Keep) => Ok(identity()),
        Target::Plane(b @ (PlanarBoundary::Square { .. } | PlanarBoundary::Polygon(_))) => {
            init.target = Target::Plane(b.clone());
            planar_points(Tutte.solve(&init, context)?.output)
        }
        Target::Plane(_) | Target::Disk => {
            let on_circle = is_planar(mesh)
                && mesh.boundary_loop_list()[0]
                    .vertices
                    .iter()
                    .all(|&v| (mesh.position(v).coords.xy().norm() - 1.0).abs() <= ON_TARGET);
            if on_circle {
                return Ok(identity());
            }
            // The boundary-first conformal map (exactly on the circle): on the human
            // face the flow's error starts at 2.4e-5 from it (2.2e-5 at the end), at
            // 4.5e-2 from Tutte's map, whose max |mu| is 0.93.
            let boundary_first =
                map_to_unit_disk(mesh).map_err(|error| SolverError::plugin(NAME, error))?;
            if let Ok(points) = boundary_first {
                return Ok(points
                    .iter()
                    .map(|&[x, y]| Point3::new(x, y, 0.0))
                    .collect());
            }
            init.target = Target::Plane(PlanarBoundary::Circle);
            planar_points(Tutte.solve(&init, context)?.output)
        }
        Target::Annulus { inner_radius } => {
            let (r0, _) = annulus_of(mesh)?;
            let r = inner_radius.unwrap_or(r0);
            // Radial stretch of [r0, 1] onto [r, 1]: a homeomorphism onto the target.
            Ok(mesh
                .positions()
                .iter()
                .map(|p| {
                    let rho = p.coords.xy().norm();
                    let new = r + (rho - r0) * (1.0 - r) / (1.0 - r0);
                    let s = if rho > 0.0 { new / rho } else { 1.0 };
                    Point3::new(p.x * s, p.y * s, 0.0)
                })
                .collect())
        }
        Target::Sphere => {
            let on_sphere = mesh
                .positions()
                .iter()
                .all(|p| (p.coords.norm() - 1.0).abs() <= ON_TARGET);
            if on_sphere {
                return Ok(mesh.positions().to_vec());
            }
            match Sphere.solve(&init, context)?.output {
                Output::Map(Map::Spatial(p)) => Ok(p),
                _ => Err(SolverError::invalid(
                    NAME,
                    "the sphere initialization did not give points of R^3",
                )),
            }
        }
        _ => Err(SolverError::unsupported(
            NAME,
            "no initial map for this target",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::{Mesh, primitives};
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    #[test]
    fn the_initial_map_stops_when_its_caller_is_cancelled() {
        let mut soup = primitives::icosphere(2);
        for p in &mut soup.positions {
            *p = Point3::from(p.coords * 2.0);
        }
        let mesh = Mesh::from_soup(&soup).unwrap();
        let problem = Problem::new(&mesh, Target::Sphere);
        let cancelled = Context::new().with_cancel_flag(Arc::new(AtomicBool::new(true)));
        assert!(matches!(
            initial_map(&problem, 1, &mut cancelled.inner()),
            Err(SolverError::Cancelled)
        ));
        let map = initial_map(&problem, 1, &mut Context::new()).unwrap();
        assert!(map.iter().all(|p| (p.coords.norm() - 1.0).abs() < 1e-9));
    }
}
