#![warn(missing_docs)]
//! # beltrami-lsqc
//!
//! The least-squares quasiconformal (LSQC) map of a disk mesh into the plane for a
//! prescribed Beltrami coefficient `mu`, in one linear solve.
//!
//! A map `f` given by its vertex images `x` (complex, `f = sum_i x_i N_i` on every P1
//! triangle or Q1 quad) has the Beltrami coefficient `mu` where it solves the Beltrami
//! equation `f_zbar = mu f_z`, with `f_z = (f_x - i f_y) / 2` and
//! `f_zbar = (f_x + i f_y) / 2`. [`Lsqc`] minimizes the residual of that equation,
//!
//! ```text
//! E_mu(x) = sum_q w_q |f_zbar(q) - mu_q f_z(q)|^2 = | W^(1/2) (D_zbar - diag(mu_q) D_z) x |^2
//! ```
//!
//! over the quadrature points `q` of all faces (one per triangle, the 2x2 Gauss points of
//! a quad), `w_q` the quadrature weights and `mu_q = mu_f` the prescribed value of the
//! face `f` of `q` (T. W. Wong and H. Zhao, "Computation of quasi-conformal surface maps
//! using discrete Beltrami flow", SIAM J. Imaging Sci. 7, 2014, section 4; the
//! least-squares formulation of the Beltrami equation as in L. M. Lui, K. C. Lam,
//! T. W. Wong, X. Gu, "Texture map and video compression using Beltrami representation",
//! SIAM J. Imaging Sci. 6, 2013). `f_z` and `f_zbar` are complex-linear in `x`, so
//! `E_mu` is a Hermitian form in `N` complex unknowns, solved through its normal
//! equations with sparse Cholesky ([`beltrami_fem::LeastSquaresSolver`]). With `mu = 0`
//! it is the least-squares conformal map (lscm of `beltrami-init`).
//!
//! Frames: the derivatives are taken in the frame of the prescribed field — the global
//! coordinate `z = x + i y` ([`beltrami_fem::Frame::Global`], a mesh in the plane
//! z = 0) or each face's own frame ([`beltrami_fem::Frame::Face`], any surface).
//!
//! Boundary conditions (all complex-linear: fixed vertex values):
//!
//! - Dirichlet: the source's own boundary positions (`PlanarBoundary::Keep`) or the
//!   boundary of a given map (`PlanarBoundary::Given`). A Beltrami coefficient fixes a
//!   map up to a conformal map only, so fixed boundary values generally cannot be met
//!   together with `mu`: the result is the least-squares compromise.
//! - Free, with pins: `E_mu` is invariant under `f -> a f + b`, so two pins fix the map
//!   on a disk; the free-boundary map then has exactly the prescribed `mu` when such a
//!   map exists (any constant `mu = k`: `f = z + k conj(z)` up to `a f + b`).
//!
//! Faces with `|mu| >= 1` are rejected before any work, naming the face. The report has
//! the stage timings, the measured per-face `mu` and its statistics (flipped faces
//! included) in the field's frame, the final `E_mu`, and a note with `|mu - target|`
//! (area-weighted RMS and sup, [`beltrami_fem::MuError`]).
//!
//! Coefficients given as expressions of `z` (`0.6*z`, `0.3+0.3i`) are parsed and
//! evaluated at face centroids by [`beltrami_fem::Expr`].
//!
//! ```
//! use beltrami_core::{Context, Goal, PlanarBoundary, Problem, Solver, Target};
//! use beltrami_fem::{BeltramiField, Frame};
//! use beltrami_lsqc::Lsqc;
//! use beltrami_mesh::{Mesh, primitives::{grid, Cells}};
//! use num_complex::Complex64;
//!
//! let mesh = Mesh::from_soup(&grid(8, 8, Cells::Triangles)).unwrap();
//! let mu = vec![Complex64::new(0.3, 0.1); mesh.face_count()];
//! let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Free));
//! problem.goal = Goal::Prescribed(BeltramiField::new(Frame::Global, mu));
//! let solution = Lsqc.solve(&problem, &mut Context::new()).unwrap();
//! assert_eq!(solution.metrics.flipped(), Some(0));
//! ```

mod lsqc;
pub mod space;

pub use beltrami_fem::operators::beltrami_operator;
pub use lsqc::Lsqc;

/// Adds [`Lsqc`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(Lsqc));
}
