#![warn(missing_docs)]
//! # beltrami-flow
//!
//! The solver `beltrami-flow` ([`BeltramiFlow`]): discrete Beltrami flow (T. W. Wong and
//! H. Zhao, "Computation of quasiconformal surface maps using discrete Beltrami flow",
//! SIAM J. Imaging Sci. 7, 2014) onto a planar polygon, the unit disk, an annulus, the
//! unit sphere or a target mesh. It builds the initial map (with the `init` solvers) and
//! runs the flow engine of `beltrami-flow-engine`, which registration and later solvers
//! compose as well.
//!
//! Coefficients on the sphere are often given in the stereographic coordinate
//! ([`stereographic`]); [`paper`] holds the reference tables of the paper.

pub mod paper;
mod solver;
pub mod stereographic;

pub use beltrami_flow_engine::{ACCEPTS, NAME, OPTIONS};
pub use solver::BeltramiFlow;

/// Adds [`BeltramiFlow`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(BeltramiFlow));
}
