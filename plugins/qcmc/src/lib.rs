#![warn(missing_docs)]
//! # beltrami-qcmc
//!
//! The solver `qcmc` ([`Qcmc`]): quasiconformal parameterization of a genus-0 mesh with
//! `k >= 2` boundary loops onto a circle domain, the unit disk minus `k - 1` disks whose
//! centres and radii (the conformal module) are unknowns fixed by `mu` itself (K. T. Ho,
//! L. M. Lui, "QCMC: Quasi-conformal parameterizations for multiply-connected domains",
//! Adv. Comput. Math. 42, 2016).
//!
//! Algorithm 2 of the paper: from an initial map onto a circle domain ([`initial`]),
//! repeat the least-squares step of eq. 19 ([`system`]), in which interior vertices move
//! freely, boundary vertices slide tangentially along their circles (eq. 13-14) and each
//! inner circle's centre and radius move with its vertices (eq. 17); put the boundary
//! back onto the moved circles (eq. 15-16); stop when nothing moves more than the
//! tolerance. Each step takes the largest of `1, 1/2, 1/4, ...` that lowers the energy,
//! keeps the circles apart and inside the unit disk and flips no more triangles than the
//! map had (the paper takes full steps; the least-squares optimum of a coarse loop can
//! fold two boundary vertices past each other, which this forbids: no iterate has more
//! flipped triangles than the start).
//!
//! Normalization of the Moebius freedom (the three real parameters of the disk's
//! automorphisms, [`moebius`]): the outer loop is the unit circle, the first inner
//! circle (the first loop after the outer one in the mesh's boundary-loop order) is
//! centred at 0, and the first vertex of the outer loop is at `1`. The report states the
//! loop and vertex. For `k = 2` the domain is the concentric annulus `r < |z| < 1`.
//!
//! Conventions: `mu = f_zbar / f_z` in the frame of the field (the face frames, or the
//! global frame `z = x + i y` of a mesh in the plane z = 0), and the map preserves the
//! orientation of that frame: in face frames each image triangle turns like its face
//! seen from the normal side; in the global frame like the face in the plane (a mesh
//! listed clockwise in the plane keeps its clockwise turn, and its start is mirrored).

pub mod initial;
pub mod moebius;
mod solver;
pub mod system;

pub use solver::{OPTIONS, Qcmc};

/// The solver's name.
pub const NAME: &str = "qcmc";

/// Adds [`Qcmc`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(Qcmc));
}
