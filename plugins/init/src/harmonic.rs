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

use beltrami_core::{Context, Problem, Solution, Solver, SolverError, Weights};

use crate::tutte::FixedBoundary;

/// The harmonic map (module docs): a disk mesh onto a fixed boundary, cotangent weights
/// by default.
///
/// Reads what [`crate::Tutte`] reads; `params.weights` may choose `Cotan` (default),
/// `Uniform` or `MeanValue`. The report's energy is the Dirichlet energy
/// `(1/2) sum_{pairs ij} w_ij |x_i - x_j|^2` for the symmetric weights.
#[derive(Debug, Clone, Copy, Default)]
pub struct Harmonic;

const FIXED_HARMONIC: FixedBoundary = FixedBoundary {
    solver: "harmonic",
    default_weights: Weights::Cotan,
    accepted_weights: &[Weights::Cotan, Weights::Uniform, Weights::MeanValue],
};

impl Solver for Harmonic {
    fn name(&self) -> &'static str {
        "harmonic"
    }

    fn description(&self) -> &'static str {
        "harmonic map: disk onto a fixed boundary minimizing the Dirichlet energy (cotangent weights); may flip faces on obtuse meshes"
    }

    fn accepts(&self) -> &'static str {
        "disk meshes (triangles, quads); targets: circle, square, convex polygon, disk, keep, given boundary; weights: cotangent, uniform, mean-value; one boundary pin to choose the start"
    }

    fn check(&self, problem: &Problem<'_>) -> Result<(), SolverError> {
        FIXED_HARMONIC.check(problem)
    }

    fn solve(
        &self,
        problem: &Problem<'_>,
        context: &mut Context<'_>,
    ) -> Result<Solution, SolverError> {
        FIXED_HARMONIC.solve(problem, context)
    }
}
