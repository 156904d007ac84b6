//! The least-squares quasiconformal map of a disk mesh into the plane for a prescribed
//! Beltrami coefficient (module docs of the crate).

use beltrami_core::{
    Accepts, Constraint, ConstraintKind, Context, Element, Extras, Goal, GoalKind, Map, Metrics,
    OptionSpec, Output, PlanarBoundary, Position, Problem, Report, Settings, Solution, Solver,
    SolverError, SolverInfo, THREADS, Target, TargetKind, Topology, topology,
};
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::boundary::{self, BoundaryError};
use beltrami_fem::element::check_planar;
use beltrami_fem::operators::{beltrami_operator, weighted_residual};
use beltrami_fem::{
    BeltramiField, BoundaryMap, Distortion, DofConstraints, DofMap, Elements, FemError, Frame,
    LeastSquaresSolver, MuError,
};
use beltrami_mesh::VertexId;
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

/// The least-squares quasiconformal map (crate docs).
///
/// Reads: `goal` (`Prescribed(field)`, or `Conformal { p: 2 }` for `mu = 0`), `target`
/// (`Plane(Keep | Given | Free)`, or `Surface`: the quaternionic map into R^3 of
/// [`crate::space`], vertices held by pins with positions in space), the pins of `constraints` and the option `threads`. With a fixed
/// boundary (`Keep`, `Given`) pins add further fixed vertices; with a free boundary it
/// needs two or more pins, or none (two boundary vertices far apart are pinned at
/// `(0, 0)` and `(1, 0)`, as in lscm). A pin without a position stays where it is on a
/// planar source; on a curved source two such pins go to `(0, 0)` and `(1, 0)`. The
/// metrics hold the final `E_mu` as the energy and `|mu - target|`
/// ([`beltrami_fem::MuError`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Lsqc;

pub(crate) const NAME: &str = "lsqc";

const OPTIONS: &[OptionSpec] = &[THREADS];

const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    // Into the plane: disks (checked by `setup`, with the way out); into space: any
    // surface with held vertices.
    topologies: Topology::CONNECTED,
    targets: &[
        TargetKind::PlaneKeep,
        TargetKind::PlaneGiven,
        TargetKind::PlaneFree,
        TargetKind::Surface,
    ],
    goals: &[GoalKind::Conformal, GoalKind::Prescribed],
    constraints: &[
        ConstraintKind::Hold,
        ConstraintKind::Pin,
        ConstraintKind::Normal,
        ConstraintKind::Area,
    ],
};

/// What to do with a mesh that is not a disk.
const NOT_A_DISK: &str = "run `beltrami cut` first or use beltrami-flow";

/// What [`Lsqc`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: NAME,
    description: "least-squares quasiconformal map for a prescribed Beltrami coefficient (one linear solve)",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Lsqc {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(
        &self,
        problem: &Problem<'_>,
        _settings: &Settings,
    ) -> Result<(), SolverError> {
        if matches!(problem.target, Target::Surface) {
            return crate::space::setup(problem).map(|_| ());
        }
        setup(problem).map(|_| ())
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        if matches!(problem.target, Target::Surface) {
            return crate::space::run(problem, settings, context);
        }
        let mesh = problem.source;
        let mut report = Report::new(NAME);
        let mut metrics = Metrics::default();
        let Setup {
            field,
            fixed,
            default_pins,
        } = setup(problem)?;
        if let Some((a, b)) = default_pins {
            let input = |v: VertexId| mesh.vertex_map().to_input(v);
            report.notes.push(format!(
                "pinned the boundary vertices {} (input index) at (0, 0) and {} at (1, 0), far apart",
                input(a),
                input(b)
            ));
        }
        let (elements, operator, mut solver) = context.stage("assembly", &mut report, || {
            let elements = Elements::new(mesh, field.frame)?;
            let operator = beltrami_operator(mesh, &elements, &field.mu)?;
            let mut constraints = DofConstraints::new();
            for &(v, z) in &fixed {
                constraints.fix(v, z);
            }
            let dofs = DofMap::complex(mesh.vertex_count(), &constraints)?;
            let options = SolveOptions {
                threads: settings.int("threads"),
                ..SolveOptions::default()
            };
            let solver = LeastSquaresSolver::new(operator.symbolic(), &dofs, options)?;
            Ok((elements, operator, solver))
        })?;
        let weights: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
        let map = context.stage("solve", &mut report, || {
            let zero = vec![Complex64::new(0.0, 0.0); operator.nrows()];
            Ok(solver.solve(operator.as_ref(), Some(&weights), &zero)?)
        })?;
        let energy = weighted_residual(&operator, &map, &weights);
        metrics.energy_history.push(energy);

        let distortion = context.stage("distortion", &mut report, || {
            let derivatives = planar_map(&elements, mesh.vertex_count(), &map)?;
            Ok(Distortion::from_derivatives(&elements, &derivatives)?)
        })?;
        metrics.mu_error = Some(MuError::new(&elements, &distortion.field.mu, &field.mu)?);
        let flipped = distortion.stats.flipped;
        if flipped > 0 {
            report.notes.push(format!(
                "{flipped} of {} faces are flipped: the least-squares map is not guaranteed to be a bijection; beltrami-flow keeps faces unflipped",
                mesh.face_count()
            ));
        }
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

/// What the capability check finds: the field in the frame the elements use, the fixed
/// vertices with their images, and the default pins if they were chosen.
struct Setup {
    field: BeltramiField,
    fixed: Vec<(VertexId, Complex64)>,
    default_pins: Option<(VertexId, VertexId)>,
}

/// The capability check: topology, goal, curves, boundary and pins.
fn setup(problem: &Problem<'_>) -> Result<Setup, SolverError> {
    let mesh = problem.source;
    topology::require_disk(NAME, mesh, NOT_A_DISK)?;
    let planar = check_planar(mesh);
    let field = field_of(problem, &planar)?;
    check_constraints(problem)?;
    let pins = pins(problem, planar.is_ok())?;
    let boundary_map = boundary_map_of(problem)?;
    let (fixed, default_pins) = fixed_vertices(problem, boundary_map, &pins)?;
    Ok(Setup {
        field,
        fixed,
        default_pins,
    })
}

/// The Beltrami field of the goal (zero for the conformal map), refused when it is in
/// the global frame on a source that is not in the plane (`planar`) or when the goal
/// is not one lsqc follows.
fn field_of(
    problem: &Problem<'_>,
    planar: &Result<(), FemError>,
) -> Result<BeltramiField, SolverError> {
    let mesh = problem.source;
    match &problem.goal {
        Goal::Prescribed(field) => {
            // Names the first face with |mu| >= 1 or a non-finite value.
            field.check(mesh.face_count())?;
            if field.frame == Frame::Global
                && let Err(FemError::NotPlanar { vertex, z }) = planar
            {
                return Err(SolverError::unsupported(
                    NAME,
                    format!(
                        "the Beltrami field is in the global frame, which needs a mesh in the plane z = 0, but vertex {vertex} has z = {z:e}; give the field in the face frame"
                    ),
                ));
            }
            Ok(field.clone())
        }
        Goal::Conformal { p } if *p == 2.0 => {
            Ok(BeltramiField::zero(Frame::Face, mesh.face_count()))
        }
        Goal::Conformal { p } => Err(SolverError::unsupported(
            NAME,
            format!(
                "lsqc minimizes a least-squares (p = 2) energy, not the L^{p} norm of mu; use beltrami-flow for p > 2"
            ),
        )),
        Goal::Extremal => Err(SolverError::unsupported(
            NAME,
            "lsqc follows a prescribed Beltrami coefficient; for extremal (Teichmueller) maps use teichmuller",
        )),
        Goal::Features(_) => Err(SolverError::unsupported(
            NAME,
            "lsqc follows a prescribed Beltrami coefficient; features are matched by register",
        )),
    }
}

/// Refuses the constraints lsqc does not take: curves, and the normal and area
/// constraints of maps into space.
fn check_constraints(problem: &Problem<'_>) -> Result<(), SolverError> {
    if problem.constraints.curves().next().is_some() {
        return Err(SolverError::unsupported(
            NAME,
            "lsqc does not make vertices follow curves yet; use beltrami-flow",
        ));
    }
    if problem
        .constraints
        .iter()
        .any(|c| matches!(c, Constraint::Normal { .. } | Constraint::Area))
    {
        return Err(SolverError::unsupported(
            NAME,
            "the normal and area constraints keep a map into space near the surface; they have no meaning in the plane: use --target space",
        ));
    }
    Ok(())
}

/// The boundary held by the target: the source's own (keep), a given one, or none
/// (free); other targets are refused.
fn boundary_map_of(problem: &Problem<'_>) -> Result<Option<BoundaryMap>, SolverError> {
    let mesh = problem.source;
    match &problem.target {
        Target::Plane(PlanarBoundary::Free) => Ok(None),
        Target::Plane(PlanarBoundary::Keep) => {
            Ok(Some(boundary::keep(mesh).map_err(|e| match e {
                BoundaryError::NotPlanar { vertex, z } => SolverError::unsupported(
                    NAME,
                    format!(
                        "keeping the boundary needs a source in the plane z = 0, but vertex {vertex} has z = {z:e}; give the boundary (a map) or leave it free"
                    ),
                ),
                error => SolverError::Boundary {
                    solver: NAME,
                    error,
                },
            })?))
        }
        Target::Plane(PlanarBoundary::Given(values)) => Ok(Some(
            boundary::given(mesh, values)
                .map_err(|error| SolverError::Boundary { solver: NAME, error })?,
        )),
        Target::Plane(_) => Err(SolverError::unsupported(
            NAME,
            "lsqc keeps the source's boundary, takes a given boundary map or leaves the boundary free; map the boundary first (tutte, harmonic) and pass it as a given boundary",
        )),
        _ => Err(SolverError::unsupported(
            NAME,
            "lsqc maps into the plane; for the disk, annulus, sphere or a target mesh use beltrami-flow",
        )),
    }
}

/// The vertices held with their positions, and the two boundary vertices pinned by
/// default ([`Setup::fixed`], [`Setup::default_pins`]).
type Held = (Vec<(VertexId, Complex64)>, Option<(VertexId, VertexId)>);

/// The vertices held and where, and the two boundary vertices pinned by default: the
/// boundary map with the pins, or with a free boundary the pins (two without positions
/// go to 0 and 1; none: two boundary vertices far apart).
fn fixed_vertices(
    problem: &Problem<'_>,
    boundary_map: Option<BoundaryMap>,
    pins: &[(VertexId, Option<Complex64>)],
) -> Result<Held, SolverError> {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    match boundary_map {
        Some(map) => {
            let mut fixed: Vec<(VertexId, Complex64)> =
                map.vertices.into_iter().zip(map.positions).collect();
            for (v, z) in pins {
                let z = z.ok_or_else(|| {
                    SolverError::unsupported(
                        NAME,
                        format!(
                            "the pin on vertex {v} has no position and the source is not planar; give it a position"
                        ),
                    )
                })?;
                fixed.push((*v, z));
            }
            Ok((fixed, None))
        }
        None => match pins {
            [] => {
                let (a, b) = boundary::far_boundary_pair(problem.source);
                Ok((vec![(a, zero), (b, one)], Some((a, b))))
            }
            [(v, _)] => Err(SolverError::unsupported(
                NAME,
                format!(
                    "with a free boundary lsqc needs two pinned vertices (or none, to pin two boundary vertices far apart), but only vertex {v} was pinned"
                ),
            )),
            [(a, None), (b, None)] => Ok((vec![(*a, zero), (*b, one)], None)),
            pins => {
                let fixed = pins
                    .iter()
                    .map(|&(v, z)| {
                        z.map(|z| (v, z)).ok_or_else(|| {
                            SolverError::unsupported(
                                NAME,
                                format!(
                                    "the pin on vertex {v} has no position; give every pin a position, or none of two pins (then they go to (0, 0) and (1, 0))"
                                ),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                if fixed.iter().all(|&(_, z)| z == fixed[0].1) {
                    return Err(SolverError::invalid(
                        NAME,
                        format!(
                            "all pins are at the same position {}: the map would collapse to a point",
                            fixed[0].1
                        ),
                    ));
                }
                Ok((fixed, None))
            }
        },
    }
}

/// The pins with their planar positions: given ones, the vertex's own position for a
/// pin without one on a planar source, `None` otherwise.
fn pins(
    problem: &Problem<'_>,
    planar: bool,
) -> Result<Vec<(VertexId, Option<Complex64>)>, SolverError> {
    let mesh = problem.source;
    problem
        .constraints
        .pins()
        .map(|pin| {
            let v = pin.vertex;
            if v.idx() >= mesh.vertex_count() {
                return Err(SolverError::invalid(
                    NAME,
                    format!(
                        "a pin is on vertex {v}, but the mesh has {} vertices",
                        mesh.vertex_count()
                    ),
                ));
            }
            match pin.position {
                Some(Position::Planar(z)) if z.is_finite() => Ok((v, Some(z))),
                Some(Position::Planar(_)) => Err(SolverError::invalid(
                    NAME,
                    format!(
                        "the position of the pin on vertex {v} is not finite"
                    ),
                )),
                Some(Position::Spatial(_) | Position::TargetVertex(_)) => Err(SolverError::unsupported(
                    NAME,
                    format!(
                        "lsqc maps into the plane, but the pin on vertex {v} has a position in space"
                    ),
                )),
                None if planar => {
                    let p = mesh.position(v);
                    Ok((v, Some(Complex64::new(p.x, p.y))))
                }
                None => Ok((v, None)),
            }
        })
        .collect()
}
