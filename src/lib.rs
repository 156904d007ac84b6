//! # beltrami
//!
//! Quasiconformal maps of triangle and quad meshes: parameterizations, surface-to-surface
//! registration and remeshing, finite-element style. This facade re-exports the crates
//! of the workspace:
//!
//! - [`mesh`]: the halfedge mesh (triangles and quads), validation, topology, geometry
//!   and IO.
//!
//! The `beltrami` binary built from this package is the command-line front end; see the
//! README for its commands.

pub use beltrami_mesh as mesh;
