//! The least-squares conformal map (Levy, Petitjean, Ray, Maillot 2002) of a disk mesh
//! with a free boundary.
//!
//! A map `f` given by its vertex images `x` (complex, `f = sum_i x_i N_i` on every face)
//! is conformal where `f_zbar = 0`. LSCM minimizes the conformal energy
//!
//! ```text
//! E_C(x) = sum_q w_q |f_zbar(q)|^2 = | W^(1/2) D_zbar x |^2
//! ```
//!
//! over the quadrature points `q` of all faces (one per triangle, the 2x2 Gauss points
//! of a quad, so Q1 quads are handled the same way), with `w_q` the quadrature weights
//! and `f_zbar = (f_x + i f_y) / 2` taken in the face frames
//! ([`beltrami_fem::operators::complex_derivatives`] on [`Frame::Face`] elements). The
//! energy is invariant under similarities `x -> a x + b`, so two vertices are pinned;
//! then (on a disk) the minimizer is unique. It is a complex-linear least-squares
//! problem, solved in `N` complex unknowns through the normal equations
//! ([`LeastSquaresSolver`], sparse Cholesky).
//!
//! On a planar mesh the identity has `f_zbar = 0`, so pinning two vertices at their own
//! positions reproduces the mesh exactly. On a curved surface no map is exactly
//! conformal and the residual `E_C` measures the distortion; LSCM does not guarantee a
//! bijection, so the report counts flipped faces.

use beltrami_core::{
    Accepts, ConstraintKind, Context, Element, Extras, GoalKind, Map, Metrics, OptionSpec, Output,
    PlanarBoundary, Position, Problem, Report, Settings, Solution, Solver, SolverError, SolverInfo,
    THREADS, Target, TargetKind, Topology, topology,
};
use beltrami_fem::boundary::far_boundary_pair;
use beltrami_fem::conformal_energy::{ConformalSystem, conformal_energy, conformal_system};
use beltrami_fem::least_squares::{normal_pattern_of_cells, singular_at_node};
use beltrami_fem::operators::{beltrami_operator, weighted_residual};
use beltrami_fem::vertex_graph::{order_of_unknowns, pattern_of_unknowns, vertex_graph_pattern};
use beltrami_fem::{DofConstraints, DofMap, Elements, Frame, LeastSquaresSolver};
use beltrami_mesh::{FaceId, Mesh, VertexId};
use beltrami_sparse::SpdSolver;
use beltrami_sparse::{NESTED_DISSECTION_FROM, PlannedCholesky, nested_dissection_split};
use faer::sparse::SparseColMatRef;
use num_complex::Complex64;

use crate::{NOT_A_DISK, check_goal_and_curves, measure, solve_options};

/// The least-squares conformal map (module docs).
///
/// Reads: `target` (`Plane(Free)` only), the pins of `constraints` and the option
/// `threads`.
/// Pins: none (two boundary vertices far apart are pinned at `(0, 0)` and `(1, 0)`: the
/// boundary vertex farthest from the loop's first vertex, then the one farthest from
/// that), or exactly two (without positions: at `(0, 0)` and `(1, 0)` in order; with
/// planar positions: there), or more than two, all with planar positions. The report's
/// energy is the final `E_C`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Lscm;

const NAME: &str = "lscm";

const OPTIONS: &[OptionSpec] = &[THREADS];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    topologies: &[Topology::Disk],
    targets: &[TargetKind::PlaneFree],
    goals: &[GoalKind::Conformal],
    constraints: &[ConstraintKind::Hold, ConstraintKind::Pin],
};

/// What [`Lscm`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "least-squares conformal map (LSCM): disk into the plane with a free boundary and two pinned vertices",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Lscm {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(
        &self,
        problem: &Problem<'_>,
        _settings: &Settings,
    ) -> Result<(), SolverError> {
        pins(problem).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let mesh = problem.source;
        let mut report = Report::new(NAME);
        let mut metrics = Metrics::default();
        let pinned = pins(problem)?;
        if problem.constraints.pins().next().is_none() {
            let input = |v: VertexId| mesh.vertex_map().to_input(v);
            report.notes.push(format!(
                "pinned the boundary vertices {} (input index) at (0, 0) and {} at (1, 0), far apart",
                input(pinned[0].0),
                input(pinned[1].0)
            ));
        }
        let mut constraints = DofConstraints::new();
        for &(v, z) in &pinned {
            constraints.fix(v, z);
        }
        let (map, energy, elements) = if mesh.quad_count() == 0 {
            let map = by_sides(mesh, &constraints, settings, context, &mut report)?;
            let energy = conformal_energy(mesh, &map)?;
            (map, energy, None)
        } else {
            let dofs = DofMap::complex(mesh.vertex_count(), &constraints)?;
            let (map, energy, elements) = by_elements(mesh, &dofs, settings, context, &mut report)?;
            (map, energy, Some(elements))
        };
        metrics.energy_history.push(energy);
        let flipped = measure(
            mesh,
            elements.as_ref(),
            &map,
            context,
            &mut report,
            &mut metrics,
        )?;
        if flipped > 0 {
            report.notes.push(format!(
                "{flipped} of {} faces are flipped: LSCM does not guarantee a bijection; tutte always gives one",
                mesh.face_count()
            ));
        }
        Ok(Solution {
            output: Output::Map(Map::Planar(map)),
            metrics,
            extras: Extras::default(),
            report,
        })
    }
}

/// LSCM of a triangle mesh: the normal equations assembled face by face from the
/// sides ([`conformal_system`]: no elements, `D_zbar` or scatter maps, so a large mesh
/// touches far less memory) into the pattern of the vertex graph carried to the
/// unknowns ([`pattern_of_unknowns`]), its symbolic factorization planned on another
/// thread while the system is assembled. From the size where the order is a nested
/// dissection ([`NESTED_DISSECTION_FROM`] unknowns), the vertex graph is dissected on
/// another thread from the start, while the DOF map is made, and the order carried over
/// to the unknowns
/// ([`order_of_unknowns`]).
fn by_sides(
    mesh: &Mesh,
    constraints: &DofConstraints,
    settings: &Settings,
    context: &mut Context<'_>,
    report: &mut Report,
) -> Result<Vec<Complex64>, SolverError> {
    let options = solve_options(settings);
    let graph = vertex_graph_pattern(mesh);
    std::thread::scope(|scope| {
        let dissection = (mesh.vertex_count() >= NESTED_DISSECTION_FROM)
            .then(|| scope.spawn(|| nested_dissection_split(graph.as_ref())));
        let dofs = DofMap::complex(mesh.vertex_count(), constraints)?;
        let (pattern, system, solver) = context.stage("assembly", report, || {
            let pattern = match pattern_of_unknowns(graph.as_ref(), &dofs) {
                Some(pattern) => pattern,
                None => {
                    let faces =
                        (0..mesh.face_count()).map(|f| mesh.face_vertices(FaceId::from_usize(f)));
                    normal_pattern_of_cells(faces, &dofs)?
                }
            };
            // The symbolic factorization on another thread while the system is assembled.
            std::thread::scope(|inner| {
                let copy = pattern.clone();
                let dofs = &dofs;
                let planned = inner.spawn(move || match dissection {
                    Some(thread) => {
                        // A panic in the ordering thread is a bug; pass it on as one.
                        let split = thread
                            .join()
                            .unwrap_or_else(|p| std::panic::resume_unwind(p))?;
                        let split = order_of_unknowns(&split, dofs)?;
                        PlannedCholesky::with_dissection(copy, split, options)
                    }
                    None => PlannedCholesky::new(copy, options),
                });
                let system = conformal_system(mesh, dofs, pattern.as_ref());
                let planned = planned
                    .join()
                    .unwrap_or_else(|p| std::panic::resume_unwind(p))?;
                let solver = match dofs.reduced_len() {
                    0 => None,
                    _ => Some(SpdSolver::from_planned(planned, options)?),
                };
                Ok::<_, SolverError>((pattern, system?, solver))
            })
        })?;
        context.stage("solve", report, || {
            let ConformalSystem { values, mut rhs } = system;
            if let Some(mut solver) = solver {
                solver
                    .factorize(SparseColMatRef::new(pattern.as_ref(), &values))
                    .map_err(|e| singular_at_node(e, &dofs))?;
                drop(values);
                solver.solve_vector_in_place(&mut rhs)?;
            }
            Ok(dofs.expand(&rhs)?)
        })
    })
}

/// LSCM through the elements (quads, or any mesh): `E_C = |W^(1/2) D_zbar x|^2` as a
/// weighted least-squares problem ([`LeastSquaresSolver`]), its symbolic factorization
/// planned on another thread while the elements and `D_zbar` are assembled. Returns the
/// map, its energy `sum_q w_q |f_zbar(q)|^2` and the elements (the distortion is measured
/// on them).
fn by_elements(
    mesh: &Mesh,
    dofs: &DofMap<Complex64>,
    settings: &Settings,
    context: &mut Context<'_>,
    report: &mut Report,
) -> Result<(Vec<Complex64>, f64, Elements), SolverError> {
    let (elements, dzbar, mut solver) = context.stage("assembly", report, || {
        // The symbolic factorization (elimination order, analysis, the factor's
        // storage) needs only the mesh's connectivity: it is computed on another
        // thread while the elements and D_zbar are assembled (on a large mesh the
        // two take about as long).
        std::thread::scope(|scope| {
            let planned = scope.spawn(|| {
                let faces =
                    (0..mesh.face_count()).map(|f| mesh.face_vertices(FaceId::from_usize(f)));
                PlannedCholesky::new(
                    normal_pattern_of_cells(faces, dofs)?,
                    solve_options(settings),
                )
            });
            let elements = Elements::new(mesh, Frame::Face)?;
            // D_zbar is the Beltrami operator of mu = 0.
            let conformal = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
            let dzbar = beltrami_operator(mesh, &elements, &conformal)?;
            let solver = LeastSquaresSolver::with_planned(
                dzbar.symbolic(),
                dofs,
                solve_options(settings),
                // A panic in the ordering thread is a bug; pass it on as one.
                || {
                    planned
                        .join()
                        .unwrap_or_else(|p| std::panic::resume_unwind(p))
                },
            )?;
            Ok((elements, dzbar, solver))
        })
    })?;
    let weights: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
    let map = context.stage("solve", report, || {
        let zero = vec![Complex64::new(0.0, 0.0); dzbar.nrows()];
        Ok(solver.solve(dzbar.as_ref(), Some(&weights), &zero)?)
    })?;
    let energy = weighted_residual(&dzbar, &map, &weights);
    Ok((map, energy, elements))
}

/// The capability check, returning the pinned vertices and their images.
fn pins(problem: &Problem<'_>) -> Result<Vec<(VertexId, Complex64)>, SolverError> {
    let mesh = problem.source;
    topology::require_disk(NAME, mesh, NOT_A_DISK)?;
    check_goal_and_curves(NAME, problem)?;
    match &problem.target {
        Target::Plane(PlanarBoundary::Free) => {}
        Target::Plane(_) | Target::Disk => {
            return Err(SolverError::unsupported(
                NAME,
                "lscm leaves the boundary free; for a fixed boundary use harmonic or tutte",
            ));
        }
        _ => {
            return Err(SolverError::unsupported(
                NAME,
                "lscm maps into the plane with a free boundary; for other targets use beltrami-flow, lsqc or qcmc",
            ));
        }
    }
    let given: Vec<_> = problem.constraints.pins().collect();
    for pin in &given {
        if pin.vertex.idx() >= mesh.vertex_count() {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "a pin is on vertex {}, but the mesh has {} vertices",
                    pin.vertex,
                    mesh.vertex_count()
                ),
            ));
        }
    }
    let positions: Vec<Option<Complex64>> = given
        .iter()
        .map(|pin| match pin.position {
            None => Ok(None),
            Some(Position::Planar(z)) if z.is_finite() => Ok(Some(z)),
            Some(Position::Planar(_)) => Err(SolverError::invalid(
                NAME,
                format!(
                    "the position of the pin on vertex {} is not finite",
                    pin.vertex
                ),
            )),
            Some(Position::Spatial(_) | Position::TargetVertex(_)) => Err(SolverError::unsupported(
                NAME,
                format!(
                    "lscm maps into the plane, but the pin on vertex {} has a position in space",
                    pin.vertex
                ),
            )),
        })
        .collect::<Result<_, _>>()?;
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    let pinned: Vec<(VertexId, Complex64)> = match given.len() {
        0 => {
            let (a, b) = far_boundary_pair(mesh);
            vec![(a, zero), (b, one)]
        }
        1 => {
            return Err(SolverError::unsupported(
                NAME,
                format!(
                    "lscm needs two pinned vertices (or none, to pin two boundary vertices far apart), but only vertex {} was pinned",
                    given[0].vertex
                ),
            ));
        }
        2 => match (positions[0], positions[1]) {
            (None, None) => vec![(given[0].vertex, zero), (given[1].vertex, one)],
            (Some(p), Some(q)) => vec![(given[0].vertex, p), (given[1].vertex, q)],
            _ => {
                return Err(SolverError::unsupported(
                    NAME,
                    "give positions to both pins or to neither (then they go to (0, 0) and (1, 0))",
                ));
            }
        },
        n => given
            .iter()
            .zip(&positions)
            .map(|(pin, z)| {
                z.map(|z| (pin.vertex, z)).ok_or_else(|| {
                    SolverError::unsupported(
                        NAME,
                        format!(
                            "with {n} pins every pin needs a position, but the pin on vertex {} has none",
                            pin.vertex
                        ),
                    )
                })
            })
            .collect::<Result<_, _>>()?,
    };
    // Pins that all coincide let the whole mesh collapse onto one point (zero energy).
    if pinned.iter().all(|&(_, z)| z == pinned[0].1) {
        return Err(SolverError::invalid(
            NAME,
            format!(
                "all pins are at the same position {}: the map would collapse to a point",
                pinned[0].1
            ),
        ));
    }
    Ok(pinned)
}
