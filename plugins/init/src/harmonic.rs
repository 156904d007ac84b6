//! The discrete harmonic map of a disk mesh with a fixed boundary.
//!
//! It minimizes the Dirichlet energy of the P1/Q1 map `f` given by the vertex images,
//!
//! ```text
//! E_D(f) = (1/2) integral |grad f|^2 = (1/2) (x^T K x + y^T K y),
//! ```
//!
//! `K` the stiffness matrix, over the interior vertices with the boundary fixed. Its
//! stationarity condition is the weighted-mean system ([`beltrami_fem::weighted_mean`])
//! with the cotangent weights `w_ij = -K_ij` (Pinkall-Polthier 1993; on triangles
//! `(cot a_ij + cot b_ij) / 2`), solved by sparse Cholesky; the solver is
//! [`crate::tutte`]'s with other weights.
//!
//! Since `E_D = A + 2 integral |f_zbar|^2` with `A` the image area, which the boundary
//! fixes, the harmonic map is also the least-squares conformal map for that boundary.
//! Cotangent weights reproduce linear maps exactly (a planar mesh with its own boundary
//! gives the identity). They are negative where the angles opposite an edge add up to
//! more than `pi`, and then faces may flip even on a convex boundary; the report counts
//! the flipped faces and the negative weights in its notes.

use beltrami_core::{
    Context, OptionSpec, Problem, Settings, Solution, Solver, SolverError, SolverInfo, THREADS,
};

use crate::tutte::{ACCEPTS, FixedBoundary};
use crate::weights_option;

/// The harmonic map (module docs): a disk mesh onto a fixed boundary, cotangent weights
/// by default.
///
/// Reads what [`crate::Tutte`] reads; the option `weights` may choose `cotan` (default),
/// `uniform` or `mean-value`. The report's energy is the Dirichlet energy
/// `(1/2) sum_{pairs ij} w_ij |x_i - x_j|^2` for the symmetric weights.
#[derive(Debug, Clone, Copy, Default)]
pub struct Harmonic;

const FIXED_HARMONIC: FixedBoundary = FixedBoundary { solver: "harmonic" };

const OPTIONS: &[OptionSpec] = &[
    weights_option(
        "cotan",
        &["cotan", "uniform", "mean-value"],
        "edge weights: cotan (Pinkall-Polthier, the Dirichlet energy), uniform or mean-value",
    ),
    THREADS,
];

/// What [`Harmonic`] is: its name, one line on what it computes, what it accepts and
/// its options.
const INFO: SolverInfo = SolverInfo {
    name: "harmonic",
    description: "harmonic map: disk onto a fixed boundary minimizing the Dirichlet energy (cotangent weights); may flip faces on obtuse meshes",
    accepts: ACCEPTS,
    options: OPTIONS,
};

impl Solver for Harmonic {
    fn info(&self) -> &'static SolverInfo {
        &INFO
    }

    fn check_problem(
        &self,
        problem: &Problem<'_>,
        _settings: &Settings,
    ) -> Result<(), SolverError> {
        FIXED_HARMONIC.check(problem)
    }

    fn run(
        &self,
        problem: &Problem<'_>,
        settings: &Settings,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        FIXED_HARMONIC.run(problem, settings, context)
    }
}
