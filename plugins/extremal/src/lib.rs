#![warn(missing_docs)]
//! # beltrami-extremal
//!
//! Extremal quasiconformal maps of planar triangle meshes with prescribed boundary
//! values: among all maps with those boundary values (in the homotopy class of the
//! start), the one with the smallest largest dilatation. For the boundary data of
//! Proposition 2 of O. Weber, A. Myles, D. Zorin, "Computing extremal quasiconformal
//! maps" (Computer Graphics Forum 31(5), 2012), it is the unique Teichmueller map,
//!
//! ```text
//! mu = f_zbar / f_z = k conj(phi) / |phi|,   phi holomorphic,   0 <= k < 1 constant
//! ```
//!
//! (`f = h o A_k o g` locally, with `g`, `h` conformal, `A_k(w) = w + k conj(w)` and
//! `phi = g_z^2`, the paper's Lemma 1, eq. 4).
//!
//! # Discretization (section 4.1)
//!
//! - `f` is piecewise linear; `f_z`, `f_zbar` are constant per triangle (eq. 6).
//! - `phi` is represented by a discrete harmonic 1-form `h` (one real value per edge,
//!   closed and co-closed with cotangent weights, eq. 10), whose per-face value is
//!   eq. 8 ([`forms`]).
//! - The least-squares Beltrami energy (eq. 9)
//!   `E = sum_m A_m |f_zbar^m - k conj(phi_m) / |phi_m| f_z^m|^2`, with the auxiliary
//!   `s_m = 1/|phi_m|` (eq. 11) that makes `E` quadratic in `h` for fixed `s`.
//!
//! # Algorithm 1 (section 4.2)
//!
//! Start from a map with the prescribed boundary (harmonic by default; any start, also
//! a folded one), `h` minimizing `E` with `s = 1`, `k = 1`, then `k` by eq. 12. Each
//! outer iteration does up to `inner-iters` h-steps (solve for `h` with `f`, `k`, `s`
//! fixed; line search on `t` between the old and new `h` with `s` projected back to
//! `1/|phi(t)|`; `k` by eq. 12) and one f-step (the least-squares quasiconformal map for
//! `mu = k conj(phi)/|phi|` with the boundary fixed). Every step lowers `E`. Both linear
//! systems keep their patterns: the h-step's saddle-point LU
//! ([`beltrami_sparse::SaddlePointSolver`]) and the f-step's normal-equation
//! Cholesky ([`beltrami_fem::LeastSquaresSolver`]) are factored symbolically once.
//!
//! # Domains
//!
//! Planar meshes (z = 0) of genus 0 with one or several boundary loops, every boundary
//! vertex fixed (`PlanarBoundary::Keep` or `Given`). On a multiply connected domain the
//! harmonic forms include one non-exact generator per inner loop ([`forms`]). A curved
//! disk is laid out in the plane by LSCM first and `mu` is measured on the surface in
//! its face frames (distortion is conformally invariant, section 4.2 "Extension to
//! surfaces"); a curved surface with several boundary loops is refused with the way out
//! (flatten it first).
//!
//! The solution carries `metrics.k` (eq. 12 at the end), the energy history, the step
//! sizes of the line searches, the measured `mu` with its statistics and flips, the
//! start map's statistics, and `extras.quadratic_differential` (`phi` per face in the
//! global frame, scaled to an area-weighted mean `|phi|` of 1).

mod flatten;
pub mod forms;
mod quadrilateral;
mod solver;

pub use solver::Extremal;

/// Adds [`Extremal`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(Extremal));
}
