#![warn(missing_docs)]
//! # beltrami-core
//!
//! What every solver shares: the [`Solver`] trait with its capability check, the
//! [`Problem`] (source, [`Target`], [`Goal`], [`Constraints`], initial [`Map`],
//! [`Params`]), the [`Solution`] with its [`Report`], the solve [`Context`] (progress
//! callback, cancellation) and the [`Registry`] of solvers by name.
//!
//! A solver is used as
//!
//! ```ignore
//! solver.check(&problem)?;          // a typed error a user understands, before any work
//! let solution = solver.solve(&problem, &mut Context::new())?;
//! ```

mod error;
mod map;
mod problem;
mod registry;
mod solver;
pub mod topology;

pub use error::SolverError;
pub use map::{Map, SurfacePoint};
pub use problem::{
    Constraints, Curve, Goal, Params, Pin, PlanarBoundary, Position, Problem, Target, Weights,
};
pub use registry::Registry;
pub use solver::{Context, Progress, Report, Solution, Solver};
