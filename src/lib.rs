//! # beltrami
//!
//! Quasiconformal maps of triangle and quad meshes: parameterizations, surface-to-surface
//! registration and remeshing, finite-element style. This facade re-exports the crates
//! of the workspace:
//!
//! - [`mesh`]: the halfedge mesh (triangles and quads), validation, topology, geometry,
//!   cutting and IO.
//! - [`fem`]: P1/Q1 elements, assembled operators, Beltrami coefficients of maps,
//!   Beltrami fields (per-face `mu` in a stated frame, with their file format),
//!   distortion statistics, DOF maps and least-squares solves under them.
//! - [`sparse`]: the sparse direct solvers (Cholesky with kept symbolic factorizations,
//!   fill-reducing orders, the two-core split, saddle-point systems).
//! - [`spatial`]: exact closest points on a target mesh through a kd-tree, tangent
//!   frames, and moving surface points along the surface.
//! - [`core`]: the `Solver` trait (what a solver accepts as data, its typed options, one
//!   validation shared by `check` and `solve`), problems with typed constraints,
//!   solutions (a map or a new mesh, typed metrics and extras), the registry.
//! - [`init`]: the initialization solvers (tutte, harmonic, lscm, sphere).
//! - [`lsqc`]: the least-squares quasiconformal map for a prescribed Beltrami
//!   coefficient (lsqc).
//! - [`flow_engine`]: the discrete Beltrami flow as an engine that solvers compose
//!   (target geometries, the flow system, the step search, image-frame measurement).
//! - [`flow`]: the solver beltrami-flow (initial map, then the engine) onto planar
//!   regions, the disk, annuli and the sphere.
//! - [`register`]: surface registration (register): initial bijections by topology,
//!   then the flow on the target mesh.
//! - [`qcmc`]: circle-domain maps of multiply-connected meshes (qcmc, Ho-Lui 2016): the
//!   unit disk minus disks whose centres and radii are found with the map.
//! - [`extremal`]: extremal (Teichmueller) maps with prescribed boundary values or
//!   the four-point problem (extremal).
//! - [`qc_iteration`]: the QC iteration towards the Teichmueller map of a boundary
//!   condition, in the plane and from surfaces into R^3 (qc-iteration).
//! - [`remesh`]: remeshing through a parameterization (spade's constrained Delaunay
//!   refinement of the parameter domain with a size field measured on the surface).
//! - [`remesh_solver`]: the remeshing as the registered solver `remesh` (through any
//!   registered parameterizer, or in place by reference angles).
//! - [`atlas`]: texture atlases of any triangle mesh (cones, cuts, boundary first
//!   flattening, charts split where they overlap, packing) and texture stretch.
//! - [`render`]: pictures of maps (uv and 3D views, |mu| colors, checkerboards) and
//!   |mu| histograms as PNG.
//!
//! [`registry`] returns every solver shipped with this package; [`catalog`] describes
//! each as data (accepts and options), for `beltrami solvers --json` and scripts.
//! `docs/adding-a-solver.md` walks through writing one.
//!
//! The files and reports around a solve, for every front end:
//!
//! - [`landmarks`]: the landmarks file of registration (`v`, `p` and `c` lines), parsed
//!   with errors naming the line, and turned into constraints.
//! - [`correspondence`]: the correspondence file of registration (`face b0 b1 b2` per
//!   source vertex), written atomically and read back.
//! - [`map_file`]: a solution's map as a mesh file on the source's connectivity
//!   (texture coordinates or positions; glTF with `|mu|` colors).
//! - [`report`]: a solution as a JSON object (the `--report` of the mapping commands).
//! - [`mapped`]: maps given as mesh files, read back (connectivity check, texture
//!   seams, a target surface's normals at the image).
//! - [`problem_spec`]: a problem in a front end's words (solver, target and boundary by
//!   name, goal, constraints, options), turned into a core `Problem` in one place for
//!   the command line, batch jobs and the Python package.
//!
//! The `beltrami` binary built from this package is the command-line front end (it
//! parses arguments, calls this library and prints); see the README for its commands.
#![warn(missing_docs)]

pub mod batch_job;
pub mod catalog;
pub mod correspondence;
pub mod landmarks;
pub mod map_file;
pub mod mapped;
pub mod problem_spec;
pub mod report;
pub mod vertex_field;

pub use beltrami_atlas as atlas;
pub use beltrami_core as core;
pub use beltrami_extremal as extremal;
pub use beltrami_fem as fem;
pub use beltrami_flow as flow;
pub use beltrami_flow_engine as flow_engine;
pub use beltrami_init as init;
pub use beltrami_lsqc as lsqc;
pub use beltrami_mesh as mesh;
pub use beltrami_qc_iteration as qc_iteration;
pub use beltrami_qcmc as qcmc;
pub use beltrami_register as register;
pub use beltrami_remesh as remesh;
pub use beltrami_remesh_solver as remesh_solver;
pub use beltrami_render as render;
pub use beltrami_sparse as sparse;
pub use beltrami_spatial as spatial;

/// Every solver shipped with beltrami, by name.
pub fn registry() -> beltrami_core::Registry {
    let mut registry = beltrami_core::Registry::new();
    beltrami_init::register(&mut registry);
    beltrami_lsqc::register(&mut registry);
    beltrami_flow::register(&mut registry);
    beltrami_register::register(&mut registry);
    beltrami_qcmc::register(&mut registry);
    beltrami_extremal::register(&mut registry);
    beltrami_qc_iteration::register(&mut registry);
    beltrami_affine::register(&mut registry);
    beltrami_remesh_solver::register(&mut registry, crate::registry);
    registry
}
