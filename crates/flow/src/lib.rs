#![warn(missing_docs)]
//! # beltrami-flow-engine
//!
//! The discrete Beltrami flow as an engine that solvers compose (T. W. Wong and H. Zhao,
//! "Computation of quasiconformal surface maps using discrete Beltrami flow", SIAM J.
//! Imaging Sci. 7, 2014, sections 3-4): a map from a triangle mesh onto a fixed target —
//! a planar polygon, the unit disk, an annulus, the unit sphere, a target mesh — with a
//! prescribed Beltrami coefficient, or as conformal as the target allows (smallest `L^p`
//! norm of `mu`), improved step by step by composing it with homeomorphisms of the
//! target that are flows of tangent vector fields.
//!
//! One step ([`flow`] has the formulas): measure `mu` of the current map per face
//! ([`measure`], with the orientation rule of `beltrami_fem::beltrami`); transport the
//! needed change of `mu` to the target with the composition formula (eq. 3.5, 3.17);
//! solve the least-squares flow `V_zbar = rho` for a tangent field on the image mesh,
//! boundary vertices sliding along the target's boundary and pinned vertices held
//! ([`system`]; eq. 4.4, Appendix eq. 6.1-6.9); take the largest step that flips no face
//! and decreases the error; project back onto the target ([`target`]). The flow is a
//! tangent field on the target, so target meshes (registration, [`mesh_target`]) use the
//! same machinery with another [`target::TargetGeometry`].
//!
//! [`solve`] runs it on a [`beltrami_core::Problem`] from a given initial map; the
//! `beltrami-flow` solver builds that map first, `register` builds a bijection onto the
//! target mesh. [`validate()`] is the check both run before any work.

pub mod extension;
pub mod flow;
pub mod measure;
pub mod mesh_target;
mod patch_embedding;
mod run;
mod setup;
pub mod system;
pub mod target;
pub mod untangle;
mod validate;

pub use run::{ACCEPTS, OPTIONS, solve};
pub use setup::given_initial;
pub use validate::{ON_TARGET, annulus_inner_radius, annulus_of};

/// The name errors and reports of the flow carry (the solver `beltrami-flow`).
pub const NAME: &str = "beltrami-flow";

/// Everything the flow checks before any work: the mesh, the target's topology, the
/// goal, the constraints, the initial map.
pub fn validate(problem: &beltrami_core::Problem<'_>) -> Result<(), beltrami_core::SolverError> {
    validate::validate(problem).map(|_| ())
}
