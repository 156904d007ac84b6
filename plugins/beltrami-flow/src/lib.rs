#![warn(missing_docs)]
//! # beltrami-flow
//!
//! Discrete Beltrami flow (T. W. Wong and H. Zhao, "Computation of quasiconformal
//! surface maps using discrete Beltrami flow", SIAM J. Imaging Sci. 7, 2014, sections
//! 3-4): a map from a triangle mesh onto a fixed target — a planar polygon, the unit
//! disk, an annulus, the unit sphere — with a prescribed Beltrami coefficient, or as
//! conformal as the target allows (smallest `L^p` norm of `mu`), improved step by step by
//! composing it with homeomorphisms of the target that are flows of tangent vector fields.
//!
//! One step ([`flow`] has the formulas): measure `mu` of the current map per face
//! ([`measure`]); transport the needed change of `mu` to the target with the composition
//! formula (eq. 3.5, 3.17); solve the least-squares flow `V_zbar = rho` for a tangent
//! field on the image mesh, boundary vertices sliding along the target's boundary and
//! pinned vertices held ([`system`]; eq. 4.4, Appendix eq. 6.1-6.9); take the largest
//! step that flips no face and decreases the error; project back onto the target
//! ([`target`]). The flow is a tangent field on the target mesh, so target meshes
//! (registration) use the same machinery with another [`target::TargetGeometry`].
//!
//! Coefficients on the sphere are often given in the stereographic coordinate
//! ([`stereographic`]).

pub mod extension;
pub mod flow;
pub mod measure;
pub mod mesh_target;
pub mod paper;
mod setup;
mod solver;
pub mod stereographic;
pub mod system;
pub mod target;
mod validate;

pub use solver::{ACCEPTS, BeltramiFlow, OPTIONS};
pub use validate::annulus_inner_radius;

/// The solver's name.
pub const NAME: &str = "beltrami-flow";

/// Adds [`BeltramiFlow`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(BeltramiFlow));
}
