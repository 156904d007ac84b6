//! # beltrami
//!
//! Quasiconformal maps of triangle and quad meshes: parameterizations, surface-to-surface
//! registration and remeshing, finite-element style. This facade re-exports the crates
//! of the workspace:
//!
//! - [`mesh`]: the halfedge mesh (triangles and quads), validation, topology, geometry
//!   and IO.
//! - [`fem`]: P1/Q1 elements, assembled operators, Beltrami coefficients of maps,
//!   Beltrami fields (per-face `mu` in a stated frame, with their file format) and
//!   distortion statistics.
//!
//! The `beltrami` binary built from this package is the command-line front end; see the
//! README for its commands.

pub use beltrami_fem as fem;
pub use beltrami_mesh as mesh;
