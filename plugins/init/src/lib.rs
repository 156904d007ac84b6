#![warn(missing_docs)]
//! # beltrami-init
//!
//! The first solvers of beltrami: linear parameterizations of disk-topology meshes
//! (triangles, quads or both) into the plane, and of closed genus-0 meshes onto the
//! sphere. They are ends in themselves and the initial maps of every iterative solver.
//!
//! - [`Tutte`] (`tutte`): the boundary goes onto a convex curve (circle, unit square,
//!   convex polygon; [`beltrami_fem::boundary`]) and every interior vertex is a weighted
//!   mean of its neighbours, `sum_j w_ij (x_i - x_j) = 0`, with uniform weights
//!   `w_ij = 1` (W. T. Tutte, "How to draw a graph", Proc. London Math. Soc. 13, 1963)
//!   or Floater's mean-value weights `w_ij = (tan(a/2) + tan(b/2)) / |p_i - p_j|`
//!   (M. S. Floater, "Mean value coordinates", CAGD 20, 2003). With a convex boundary
//!   and positive weights the map is bijective (Tutte's theorem, extended by Floater,
//!   "One-to-one piecewise linear mappings over triangulations", Math. Comp. 72, 2003).
//! - [`Harmonic`] (`harmonic`): the same boundaries, cotangent weights
//!   `w_ij = (cot a_ij + cot b_ij) / 2` (U. Pinkall and K. Polthier, "Computing discrete
//!   minimal surfaces and their conjugates", Experimental Math. 2, 1993), i.e. the
//!   minimizer of the Dirichlet energy `(1/2) integral |grad f|^2` of the P1/Q1 map. With
//!   the boundary fixed, `E_D = A + 2 integral |f_zbar|^2` (`A` the image area, fixed by
//!   the boundary), so it is also the most conformal map in the least-squares sense.
//!   Cotangent weights are negative on obtuse triangles, and then faces may flip.
//! - [`Lscm`] (`lscm`): the least-squares conformal map with a free boundary
//!   (B. Levy, S. Petitjean, N. Ray, J. Maillot, "Least squares conformal maps for
//!   automatic texture atlas generation", SIGGRAPH 2002): minimize
//!   `E_C(f) = sum_q w_q |f_zbar(q)|^2` over the quadrature points `q` of all faces (one
//!   per triangle, four per quad) in the face frames, with two vertices pinned (by
//!   default two boundary vertices far apart, at `(0, 0)` and `(1, 0)`).
//! - [`Sphere`] (`sphere`): a closed genus-0 mesh onto the unit sphere, nearly
//!   conformally: the cotangent-harmonic map of the mesh with one face's vertices held
//!   (P. T. Choi, K. C. Lam, L. M. Lui, "FLASH", SIAM J. Imaging Sci. 8, 2015), the
//!   inverse stereographic projection `s(z) = (2x, 2y, |z|^2 - 1) / (|z|^2 + 1)`,
//!   harmonic corrections alternating between the two stereographic charts, Moebius
//!   centering of the area (A. Baden, K. Crane, M. Kazhdan, "Moebius registration",
//!   SGP 2018) and local re-solves of flipped faces; or, with `start=tutte`, the Tutte
//!   embedding of the mesh minus one face (T. W. Wong and H. Zhao, SIAM J. Imaging
//!   Sci. 7, 2014, section 4.1).
//!
//! The first three need a single topological disk, [`Sphere`] a closed genus-0 surface;
//! a mesh of another topology gets [`beltrami_core::SolverError::Unsupported`] saying
//! what it is and what to do instead.
//! Their reports carry the timings of each stage, the per-face Beltrami coefficient and
//! its statistics (flipped faces included), and notes on flips.
//!
//! The numerics behind them that other solvers share are in `beltrami-fem`: the boundary
//! maps ([`beltrami_fem::boundary`]), the edge weights ([`beltrami_fem::weights`]) and
//! the weighted-mean system ([`beltrami_fem::weighted_mean`]). This crate holds the
//! solvers: their capability checks, the choice of boundary and weights from the
//! problem, and their reports.
//!
//! ```
//! use beltrami_core::{Context, PlanarBoundary, Problem, Solver, Target};
//! use beltrami_init::Tutte;
//! use beltrami_mesh::{Mesh, primitives::{grid, Cells}};
//!
//! let mesh = Mesh::from_soup(&grid(8, 8, Cells::Triangles)).unwrap();
//! let problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Circle));
//! let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
//! assert_eq!(solution.metrics.flipped(), Some(0));
//! ```

pub mod harmonic;
pub mod lscm;
pub mod sphere;
pub mod tutte;

pub use harmonic::Harmonic;
pub use lscm::Lscm;
pub use sphere::Sphere;
pub use tutte::Tutte;

use beltrami_core::{
    Context, Goal, Metrics, OptionKind, OptionSpec, Problem, Report, Settings, SolverError,
};
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::distortion::{Distortion, measure_planar};
use beltrami_fem::{EdgeWeights, Elements, Frame, WeightError};
use beltrami_mesh::Mesh;
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

/// Adds [`Tutte`], [`Harmonic`], [`Lscm`] and [`Sphere`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(Tutte));
    registry.register(Box::new(Harmonic));
    registry.register(Box::new(Lscm));
    registry.register(Box::new(Sphere));
}

/// The advice of the topology check: what to do with a mesh that is not a disk.
const NOT_A_DISK: &str = "run `beltrami cut` first or use beltrami-flow";

/// Rejects goals other than least-squares conformality and curve constraints, which
/// none of these linear solvers can honour.
fn check_goal_and_curves(solver: &'static str, problem: &Problem<'_>) -> Result<(), SolverError> {
    let unsupported = |message: String| Err(SolverError::unsupported(solver, message));
    match &problem.goal {
        Goal::Conformal { p } if *p == 2.0 => {}
        Goal::Conformal { p } => {
            return unsupported(format!(
                "{solver} minimizes a least-squares (p = 2) energy, not the L^{p} norm of mu; use an iterative solver for p > 2"
            ));
        }
        Goal::Prescribed(_) => {
            return unsupported(format!(
                "{solver} computes a map of its own and cannot follow a prescribed Beltrami coefficient; use lsqc"
            ));
        }
        Goal::Features(_) => {
            return unsupported(format!(
                "{solver} matches no features; features are matched by register"
            ));
        }
        Goal::Extremal => {
            return unsupported(format!(
                "{solver} does not compute extremal (Teichmueller) maps; use teichmuller"
            ));
        }
    }
    if problem.constraints.curves().next().is_some() {
        return unsupported(format!(
            "{solver} cannot make vertices follow curves; use lsqc or beltrami-flow"
        ));
    }
    Ok(())
}

/// The edge weights of `kind` on `mesh`: [`EdgeWeights::uniform`],
/// [`EdgeWeights::mean_value`] or [`EdgeWeights::cotangent`].
fn edge_weights(mesh: &Mesh, kind: Weights) -> Result<EdgeWeights, WeightError> {
    match kind {
        Weights::Uniform => Ok(EdgeWeights::uniform(mesh)),
        Weights::MeanValue => EdgeWeights::mean_value(mesh),
        Weights::Cotan => EdgeWeights::cotangent(mesh),
    }
}

/// The solve options of the settings' `threads`.
fn solve_options(settings: &Settings) -> SolveOptions {
    SolveOptions {
        threads: settings.int("threads"),
        ..SolveOptions::default()
    }
}

/// The `weights` option of a linear map, with its default and choices.
const fn weights_option(
    default: &'static str,
    choices: &'static [&'static str],
    help: &'static str,
) -> OptionSpec {
    OptionSpec {
        name: "weights",
        kind: OptionKind::Choice { default, choices },
        help,
    }
}

/// Edge weights of the linear maps, as the `weights` option names them (`uniform`,
/// `mean-value`, `cotan`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weights {
    /// Every neighbour counts the same (Tutte's barycentric embedding).
    Uniform,
    /// Floater's mean-value weights (positive on any mesh).
    MeanValue,
    /// Cotangent weights (harmonic; may be negative on obtuse meshes).
    Cotan,
}

/// The edge weights named by the `weights` option.
fn weights_of(settings: &Settings) -> Weights {
    match settings.choice("weights") {
        "mean-value" => Weights::MeanValue,
        "cotan" => Weights::Cotan,
        _ => Weights::Uniform,
    }
}

/// Measures the distortion of a planar map in the face frames into `metrics.mu` and
/// `metrics.distortion` (a "distortion" stage timed in `report`), and returns the number
/// of flipped faces.
/// `elements` are the solver's own face-frame elements when it has them (reused), else
/// they are computed.
fn measure(
    mesh: &Mesh,
    elements: Option<&Elements>,
    map: &[Complex64],
    context: &mut Context<'_>,
    report: &mut Report,
    metrics: &mut Metrics,
) -> Result<usize, SolverError> {
    let distortion = context.stage("distortion", report, || match elements {
        Some(elements) => {
            let derivatives = planar_map(elements, mesh.vertex_count(), map)?;
            Ok(Distortion::from_derivatives(elements, &derivatives)?)
        }
        None => Ok(measure_planar(mesh, map, Frame::Face)?),
    })?;
    let flipped = distortion.stats.flipped;
    metrics.mu = Some(distortion.field);
    metrics.distortion = Some(distortion.stats);
    Ok(flipped)
}
