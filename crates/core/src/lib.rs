#![warn(missing_docs)]
//! # beltrami-core
//!
//! What every solver shares:
//!
//! - the [`Problem`]: source mesh, [`Target`], [`Goal`], typed [`Constraints`] (pins,
//!   landmarks, slides, curves, loop matches, normal and area constraints, reference
//!   angles), an initial [`Map`] and the [`Options`] a user set;
//! - the [`Solver`] trait: one [`SolverInfo`] record (a name, what it accepts as data
//!   ([`Accepts`]), its typed options ([`OptionSpec`]: type, default, range, help)), and
//!   one validation shared by [`Solver::check`] and [`Solver::solve`], before any work;
//! - the [`Solution`]: an [`Output`] (a [`Map`] of the source's vertices or a
//!   [`Remeshed`] mesh located on the source), typed [`Metrics`] (`|mu|` statistics,
//!   flips, `|mu - target|`, `k`, iterations and histories, why it stopped), typed
//!   [`Extras`] (an annulus radius, circle-domain circles, a quadratic differential,
//!   how a remeshing was made) and a [`Report`] of timings and prose notes;
//! - the solve [`Context`] (progress callback, cancellation), the [`Registry`] of
//!   solvers by name, and [`SolverError`], which keeps the errors of the crates below
//!   typed (`#[from]`/`source`).
//!
//! ```
//! use beltrami_core::{Accepts, Context, Element, GoalKind, Map, OptionKind, OptionSpec};
//! use beltrami_core::{Problem, Report, Settings, Solution, Solver, SolverError, SolverInfo};
//! use beltrami_core::{Target, TargetKind, Topology};
//! use beltrami_mesh::{Mesh, primitives::{grid, Cells}};
//! use num_complex::Complex64;
//!
//! /// Scales the source's own planar positions by the option `scale`.
//! struct Scale;
//!
//! const OPTIONS: &[OptionSpec] = &[OptionSpec {
//!     name: "scale",
//!     kind: OptionKind::Float { default: 1.0, min: 1e-6, max: 1e6 },
//!     help: "the factor",
//! }];
//!
//! const INFO: SolverInfo = SolverInfo {
//!     name: "scale",
//!     description: "scales a planar mesh",
//!     accepts: Accepts {
//!         elements: &[Element::Triangle, Element::Quad],
//!         topologies: &[Topology::Disk],
//!         targets: &[TargetKind::PlaneKeep],
//!         goals: &[GoalKind::Conformal],
//!         constraints: &[],
//!     },
//!     options: OPTIONS,
//! };
//!
//! impl Solver for Scale {
//!     fn info(&self) -> &'static SolverInfo { &INFO }
//!     fn check_problem(&self, _: &Problem<'_>, _: &Settings) -> Result<(), SolverError> {
//!         Ok(())
//!     }
//!     fn run(&self, problem: &Problem<'_>, settings: &Settings, _: &mut Context<'_>)
//!         -> Result<Solution, SolverError> {
//!         let s = settings.float("scale");
//!         let map = problem.source.positions().iter()
//!             .map(|p| Complex64::new(s * p.x, s * p.y)).collect();
//!         Ok(Solution::from_map(Map::Planar(map), Report::new("scale")))
//!     }
//! }
//!
//! let mesh = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
//! let mut problem = Problem::new(&mesh, Target::Plane(beltrami_core::PlanarBoundary::Keep));
//! problem.options.set_text("scale", "2");
//! let solution = Scale.solve(&problem, &mut Context::new()).unwrap();
//! assert_eq!(solution.planar().unwrap()[0], 2.0 * Complex64::new(mesh.positions()[0].x, mesh.positions()[0].y));
//! problem.options.set_text("scale", "-1");
//! assert!(Scale.check(&problem).unwrap_err().to_string().contains("`scale` must lie in"));
//! ```

mod accepts;
pub mod components;
mod constraint;
mod error;
mod features;
mod map;
mod options;
mod problem;
mod registry;
mod renumbered;
mod report;
mod solution;
mod solver;
pub mod topology;

pub use accepts::{Accepts, Element, GoalKind, TargetKind, Topology};
pub use constraint::{
    Constraint, ConstraintError, ConstraintKind, Constraints, Curve, Direction, Landmark,
    LoopMatch, MAX_NORMAL_WEIGHT, Pin, Slide,
};
pub use error::SolverError;
pub use features::Features;
pub use map::{Map, SurfacePoint};
pub use options::{OptionError, OptionKind, OptionSpec, OptionValue, Options, Settings, THREADS};
pub use problem::{Goal, PlanarBoundary, Position, Problem, Target};
pub use registry::Registry;
pub use renumbered::{Renumbered, SCATTERED_SPREAD, solve_renumbered};
pub use report::Report;
pub use solution::{
    AnnulusRadius, Circle, ComponentSummary, Extras, FeatureMismatch, InPlaceSummary,
    LandmarkResidual, Metrics, Output, ParamSummary, QuadraticDifferential, RemeshSummary,
    Remeshed, ShapeDistance, Solution, Stop,
};
pub use solver::{Context, Progress, Solver, SolverInfo};
