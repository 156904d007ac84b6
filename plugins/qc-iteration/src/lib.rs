#![warn(missing_docs)]
//! # beltrami-qc-iteration
//!
//! The QC iteration (L. M. Lui, K. C. Lam, S.-T. Yau, X. Gu, "Teichmueller mapping
//! (T-map) and its applications to landmark matching registration", SIAM J. Imaging
//! Sci. 7, 2014), in the plane and, quaternionic, from surfaces into R^3 (A. Gruber,
//! E. Aulisa, "Quasiconformal mappings with surface domains", ACM TOG 2022, section 5,
//! Algorithms 2-4): a fixed-point iteration on the Beltrami coefficient whose limit is
//! close to the Teichmueller map of a Dirichlet boundary condition, `|mu| = k`
//! constant.
//!
//! From `mu_0 = 0`, repeat:
//!
//! 1. `f_n` = the least-squares QC map of `mu_n` with the held vertices (in the plane
//!    `|| f_zbar - mu_n f_z ||^2`, one complex solve; into R^3
//!    `|| df^- - mu_n df^+ ||^2` with the normal penalty and the area equality of
//!    sections 4.1-4.2 when asked; the symbolic factorization is built once);
//! 2. `nu` = the coefficient of `f_n` per face (Lemma 5.2 into R^3), in the faces'
//!    frames, and `k` its area-weighted mean modulus;
//! 3. `nu` smoothed once with frame transport (module `transport`: Algorithm 4; one Jacobi
//!    step, Remark 5.3: more smoothing makes the limit worse) and its modulus set to `k`;
//! 4. the line search of section 5.4 (module `line_search`): the best coefficient for `f_n`
//!    between `mu_n` and the smoothed one is `mu_(n+1)`;
//!
//! until no face's `mu` moves by more than `tolerance`. The result carries `k`, the
//! spread of `|nu|` around `k` per iteration as the energy history, the line-search
//! steps, and `|mu|` statistics and flips.
//!
//! In the plane: triangle meshes in z = 0, every boundary vertex held (`Plane(Keep)` or
//! `Plane(Given)`). Into R^3 (`Target::Surface`): triangle and quad meshes of any
//! topology, the pins' vertices held at their points; with `ReferenceAngles` the
//! elements are reference polygons with those corner angles in the faces' planes
//! (section 6.2: the map goes from the reference metric to the surface, which remeshes
//! it in place).

mod line_search;
mod solver;
mod system;
mod transport;

pub use solver::QcIteration;

/// Adds [`QcIteration`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(QcIteration));
}
