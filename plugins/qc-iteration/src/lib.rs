#![warn(missing_docs)]
//! # beltrami-qc-iteration
//!
//! The QC iteration (L. M. Lui, K. C. Lam, S.-T. Yau, X. Gu, "Teichmueller mapping
//! (T-map) and its applications to landmark matching registration", SIAM J. Imaging
//! Sci. 7, 2014; the planar case `N = (0, 0, 1)` of Gruber-Aulisa 2022, section 5,
//! Algorithms 2-4): a fixed-point iteration on the Beltrami coefficient whose limit is
//! the Teichmueller map of a Dirichlet boundary condition, `|mu| = k` constant.
//!
//! From `mu_0 = 0`, repeat:
//!
//! 1. `f_n` = the least-squares QC map of `mu_n` with the boundary held
//!    (`|| D_zbar f - mu_n D_z f ||^2` over the interior vertices, one complex solve on a
//!    fixed pattern);
//! 2. `nu` = the measured coefficient of `f_n` per face;
//! 3. smooth `nu` once (one Jacobi step of the face graph: the mean of a face and its
//!    edge neighbours; Gruber-Aulisa, Remark 5.3: more smoothing makes the limit worse);
//! 4. project `|nu|` to its area-weighted mean `k`: `mu_(n+1) = k nu / |nu|`;
//!
//! until no face's `mu` moves by more than `tolerance`. The result carries `k`, the
//! spread of `|mu|` per iteration as the energy history, and `|mu|` statistics and
//! flips. Planar triangle meshes (z = 0) of genus 0, every boundary vertex held.

mod solver;

pub use solver::QcIteration;

/// Adds [`QcIteration`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(QcIteration));
}
