#![warn(missing_docs)]
//! # beltrami-fem
//!
//! The numerical floor under every beltrami solver: P1 (triangles) and Q1 (quads)
//! elements on surfaces in R^3, assembled operators (stiffness / cotangent Laplacian,
//! mass, complex derivatives `D_z`, `D_zbar`), Beltrami coefficients of maps (planar,
//! surface to plane, surface to surface, quaternionic), sparse assembly into fixed
//! patterns, affine DOF maps for constraints, and constrained least-squares solves that
//! reuse their symbolic factorization ([`least_squares`], on the sparse Cholesky of
//! `beltrami-sparse`; the vertex graph's orders carried to the unknowns in
//! [`vertex_graph`]).
//!
//! The numerics the solver plugins share live here too: boundary maps of disk meshes
//! onto a circle, square or convex polygon ([`boundary`]), the edge weights of linear
//! maps (uniform, mean-value, cotangent; [`weights`]), the weighted-mean (Tutte) system
//! of a fixed boundary ([`weighted_mean`]), and Beltrami coefficients given as
//! expressions of `z` ([`expr`]).
//!
//! Conventions (see `docs/conventions.md`): `f_z = (f_x - i f_y) / 2`,
//! `f_zbar = (f_x + i f_y) / 2`, `mu = f_zbar / f_z`; derivatives are taken in the tangent
//! frame of each quadrature point ([`Frame`]).

pub mod assembly;
pub mod beltrami;
pub mod boundary;
pub mod conformal_energy;
pub mod distortion;
pub mod dof;
pub mod element;
mod error;
pub mod expr;
pub mod field;
pub mod least_squares;
pub mod mean_curvature;
pub mod operators;
pub mod quaternion;
pub mod quaternionic_lsqc;
pub mod vertex_graph;
pub mod weighted_mean;
pub mod weights;

pub use beltrami::ReferenceNormal;
pub use boundary::{BoundaryError, BoundaryMap};
pub use distortion::{Distortion, DistortionStats, Histogram, MuError};
pub use dof::{DofBuilder, DofConstraints, DofError, DofMap, DofScalar, DofTerm, NodeDof};
pub use element::{Elements, Frame, QuadraturePoint, TangentFrame};
pub use error::FemError;
pub use expr::{Expr, ExprError};
pub use field::{BeltramiField, FieldError};
pub use least_squares::LeastSquaresSolver;
pub use weighted_mean::WeightedMeanSystem;
pub use weights::{EdgeWeights, WeightError};
