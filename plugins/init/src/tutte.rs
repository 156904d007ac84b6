//! Tutte's embedding: a disk mesh onto a convex boundary with every interior vertex at a
//! weighted mean of its neighbours.
//!
//! With the boundary vertices fixed at positions `x_b` (a [`BoundaryMap`]), the interior
//! vertices solve
//!
//! ```text
//! sum_j w_ij (x_i - x_j) = 0            for every interior vertex i,
//! ```
//!
//! the sparse system `L_II x_I = L_IB x_B` of [`beltrami_fem::weighted_mean`] (sparse
//! Cholesky for symmetric weights, sparse LU for mean-value weights).
//!
//! Tutte (1963) for uniform weights and Floater (2003) for any positive weights: if the
//! boundary goes onto a convex polygon, in order, the map is a bijection onto its interior
//! (no flipped faces), except for faces whose vertices all land on one straight side,
//! which collapse ([`beltrami_fem::boundary::collapsed_faces`]). [`Tutte`] accepts
//! uniform (default) and mean-value weights; the cotangent weights belong to
//! [`crate::Harmonic`], which shares this module's machinery.

use beltrami_core::{
    Accepts, ConstraintKind, Context, Element, Extras, GoalKind, Map, Metrics, OptionSpec, Output,
    PlanarBoundary, Problem, Report, Settings, Solution, Solver, SolverError, SolverInfo, THREADS,
    Target, TargetKind, Topology, topology,
};
use beltrami_fem::boundary::{self, BoundaryError, BoundaryMap};
use beltrami_fem::{EdgeWeights, WeightError, WeightedMeanSystem};
use beltrami_mesh::VertexId;
use num_complex::Complex64;

use crate::{
    NOT_A_DISK, Weights, check_goal_and_curves, edge_weights, measure, solve_options, weights_of,
    weights_option,
};

/// Tutte's embedding (module docs): a disk mesh onto a fixed convex boundary, interior
/// vertices at weighted means of their neighbours, uniform (default) or mean-value
/// weights.
///
/// Reads: `target` (`Plane(Circle | Square | Polygon | Keep | Given)` or `Disk`, which
/// is the circle fixed by arc length), the options `weights` (`uniform`, `mean-value`)
/// and `threads`, and at most one pin without a position, on the boundary, which
/// chooses the vertex that goes to `(1, 0)` on the circle or to the first corner of a
/// polygon. The report's energy is `E = (1/2) sum_{edges ij} w_ij |x_i - x_j|^2` for
/// uniform weights (none for the non-symmetric mean-value weights).
#[derive(Debug, Clone, Copy, Default)]
pub struct Tutte;

/// What [`Tutte`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: "tutte",
    description: "Tutte embedding: disk onto a convex boundary, interior vertices at weighted means (uniform or mean-value weights); bijective for a convex boundary",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Tutte {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(
        &self,
        problem: &Problem<'_>,
        _settings: &Settings,
    ) -> Result<(), SolverError> {
        FIXED_TUTTE.check(problem)
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        FIXED_TUTTE.run(problem, settings, context)
    }
}

const FIXED_TUTTE: FixedBoundary = FixedBoundary { solver: "tutte" };

const OPTIONS: &[OptionSpec] = &[
    weights_option(
        "uniform",
        &["uniform", "mean-value"],
        "edge weights: uniform (Tutte) or mean-value (Floater); cotangent weights are the harmonic solver's",
    ),
    THREADS,
];

/// What [`Tutte`] and [`crate::Harmonic`] accept.
pub(crate) const ACCEPTS: Accepts = Accepts {
    elements: &[Element::Triangle, Element::Quad],
    topologies: &[Topology::Disk],
    targets: &[
        TargetKind::PlaneCircle,
        TargetKind::PlaneSquare,
        TargetKind::PlanePolygon,
        TargetKind::PlaneKeep,
        TargetKind::PlaneGiven,
        TargetKind::Disk,
    ],
    goals: &[GoalKind::Conformal],
    constraints: &[ConstraintKind::Hold],
};

/// A linear map with a fixed boundary: the shared machinery of [`Tutte`] and
/// [`crate::Harmonic`], which differ in their name and weights (their `weights` option).
pub(crate) struct FixedBoundary {
    /// The solver's name.
    pub(crate) solver: &'static str,
}

/// Words for a weight kind in messages.
fn weight_name(w: Weights) -> &'static str {
    match w {
        Weights::Uniform => "uniform",
        Weights::MeanValue => "mean-value",
        Weights::Cotan => "cotangent",
    }
}

impl FixedBoundary {
    /// The capability check of the solver.
    pub(crate) fn check(&self, problem: &Problem<'_>) -> Result<(), SolverError> {
        self.prepare(problem).map(|_| ())
    }

    /// The capability check, which also builds the boundary map (cheap, and it holds the
    /// checks of the polygon and of the corner vertices).
    fn prepare(&self, problem: &Problem<'_>) -> Result<BoundaryMap, SolverError> {
        let solver = self.solver;
        let mesh = problem.source;
        topology::require_disk(solver, mesh, NOT_A_DISK)?;
        check_goal_and_curves(solver, problem)?;
        let start = self.start_vertex(problem)?;
        let invalid = |error: BoundaryError| SolverError::Boundary { solver, error };
        match &problem.target {
            Target::Disk | Target::Plane(PlanarBoundary::Circle) => boundary::circle(mesh, start),
            Target::Plane(PlanarBoundary::Square { corners }) => {
                boundary::square(mesh, *corners, start)
            }
            Target::Plane(PlanarBoundary::Polygon(corners)) => {
                boundary::polygon(mesh, corners, start)
            }
            Target::Plane(PlanarBoundary::Keep) => match boundary::keep(mesh) {
                Err(BoundaryError::NotPlanar { vertex, z }) => {
                    return Err(SolverError::unsupported(
                        self.solver,
                        format!(
                            "keeping the boundary needs a source in the plane z = 0, but vertex {vertex} has z = {z:e}; map it onto a circle, square or polygon instead"
                        ),
                    ));
                }
                other => other,
            },
            Target::Plane(PlanarBoundary::Given(values)) => boundary::given(mesh, values),
            Target::Plane(PlanarBoundary::Free) => {
                return Err(SolverError::unsupported(
                    self.solver,
                    format!(
                        "{solver} needs a fixed boundary (circle, square, polygon); for a free boundary use lscm"
                    ),
                ));
            }
            Target::Annulus { .. } | Target::CircleDomain => {
                return Err(SolverError::unsupported(
                    self.solver,
                    format!(
                        "{solver} maps onto a disk or a convex polygon; annuli and circle domains need a multiply-connected mesh and qcmc"
                    ),
                ));
            }
            Target::Sphere => {
                return Err(SolverError::unsupported(
                    self.solver,
                    format!(
                        "{solver} maps into the plane; for the sphere use beltrami-flow"
                    ),
                ));
            }
            Target::Mesh(_) | Target::Surface => {
                return Err(SolverError::unsupported(
                    self.solver,
                    format!(
                        "{solver} maps into the plane; for maps onto a surface use beltrami-flow or lsqc"
                    ),
                ));
            }
        }
        .map_err(invalid)
    }

    /// The start vertex chosen by a pin, if any: at most one pin, without a position, and
    /// only for targets that have a free start (circle, disk, automatic square, polygon).
    fn start_vertex(&self, problem: &Problem<'_>) -> Result<Option<VertexId>, SolverError> {
        let solver = self.solver;
        let pins: Vec<_> = problem.constraints.pins().collect();
        let Some(pin) = pins.first() else {
            return Ok(None);
        };
        if pins.len() > 1 {
            return Err(SolverError::unsupported(
                self.solver,
                format!(
                    "{solver} fixes the whole boundary and takes at most one pin (the vertex that starts the boundary), {} were given; for several pins use lscm",
                    pins.len()
                ),
            ));
        }
        if pin.position.is_some() {
            return Err(SolverError::unsupported(
                self.solver,
                format!(
                    "{solver} places the boundary itself; the pin on vertex {} may choose where it starts but cannot have a position",
                    pin.vertex
                ),
            ));
        }
        let start_is_free = matches!(
            problem.target,
            Target::Disk
                | Target::Plane(
                    PlanarBoundary::Circle
                        | PlanarBoundary::Square { corners: None }
                        | PlanarBoundary::Polygon(_)
                )
        );
        if !start_is_free {
            return Err(SolverError::unsupported(
                self.solver,
                format!("the target fixes where the boundary starts, so {solver} takes no pin"),
            ));
        }
        Ok(Some(pin.vertex))
    }

    /// Builds the boundary, the weights and the system, solves it, measures the
    /// distortion and explains flips in the notes.
    pub(crate) fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        let solver = self.solver;
        let mesh = problem.source;
        let mut report = Report::new(solver);
        let mut metrics = Metrics::default();
        let boundary = context.stage("boundary", &mut report, || self.prepare(problem))?;
        let kind = weights_of(settings);
        let (weights, system) = context.stage("assembly", &mut report, || {
            let weights = edge_weights(mesh, kind).map_err(|e| match e {
                WeightError::Fem(e) => SolverError::Fem(e),
                error @ WeightError::NonFinite { .. } => SolverError::Weights { solver, error },
            })?;
            let system = WeightedMeanSystem::new(&weights, &boundary)?;
            Ok((weights, system))
        })?;
        let options = solve_options(settings);
        let map = context.stage("solve", &mut report, || Ok(system.solve(options)?))?;
        if weights.is_symmetric() {
            metrics.energy_history.push(spring_energy(&weights, &map));
        }
        let flipped = measure(mesh, None, &map, context, &mut report, &mut metrics)?;
        let negative = weights.negative_count(system.interior().iter().copied());
        if negative > 0 {
            report.notes.push(format!(
                "{negative} {} weights of interior vertices are negative{}",
                weight_name(kind),
                match kind {
                    Weights::Cotan => " (obtuse triangles); use tutte for a map that never flips",
                    _ => " (reflex quad corners); the bijectivity theorem needs positive weights",
                }
            ));
        }
        if flipped > 0 {
            report.notes.push(format!(
                "{flipped} of {} faces are flipped or collapsed (Jacobian <= 0)",
                mesh.face_count()
            ));
        }
        let collapsed = boundary::collapsed_faces(mesh, &boundary).len();
        if collapsed > 0 {
            report.notes.push(format!(
                "{collapsed} faces have all their vertices on one straight side of the boundary and collapse to segments: give corners at those vertices or map onto the circle"
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

/// `E = (1/2) sum_{edges ij} w_ij |x_i - x_j|^2 = (1/4) sum_i sum_j w_ij |x_i - x_j|^2`
/// for symmetric weights: the energy whose minimizer the weighted-mean map is (the
/// Dirichlet energy for cotangent weights).
fn spring_energy(weights: &EdgeWeights, map: &[Complex64]) -> f64 {
    let mut energy = 0.0;
    for (i, &xi) in map.iter().enumerate() {
        for (j, w) in weights.row(VertexId::from_usize(i)) {
            energy += w * (xi - map[j.idx()]).norm_sqr();
        }
    }
    energy / 4.0
}
