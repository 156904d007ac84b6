//! Conformal flattening of a curved disk before the extremal solve.
//!
//! Distortion is conformally invariant: for a conformal `c` from the surface onto a
//! planar region, `f` and `f o c^-1` have the same `|mu|` at corresponding points, and
//! `mu` itself changes by the phase `conj(c_z) / c_z` of `c` (Weber, Myles, Zorin 2012,
//! section 4.2, the extension to surfaces). So a curved disk is laid out by the
//! least-squares conformal map (`beltrami_init::Lscm`, free boundary), the extremal map
//! is computed on that planar copy with the same boundary values, and `mu` is measured
//! on the surface itself, in its face frames. A quadratic differential transforms as
//! `phi dz^2`: on a face with frame coordinate `w` and flattening `c`, the surface's
//! `phi_w = phi_c c_w^2`.

use beltrami_core::{Context, PlanarBoundary, Problem, Solver, SolverError, Target};
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::{Elements, Frame};
use beltrami_init::Lscm;
use beltrami_mesh::{Mesh, Point3};
use num_complex::Complex64;

use crate::solver::NAME;

/// A curved disk laid out in the plane.
#[derive(Debug)]
pub struct Flattening {
    /// The surface's connectivity with the vertices at their images in the plane z = 0.
    pub mesh: Mesh,
    /// `c_w` per face: the flattening's complex derivative in the face's own frame.
    pub derivative: Vec<Complex64>,
    /// Mean and largest `|mu|` of the flattening (its distance from conformal).
    pub mu_mean: f64,
    /// See `mu_mean`.
    pub mu_max: f64,
}

/// Lays `mesh` (a curved disk of triangles) out in the plane by LSCM; refuses a layout
/// with flipped faces.
pub fn flatten(mesh: &Mesh) -> Result<Flattening, SolverError> {
    let problem = Problem::new(mesh, Target::Plane(PlanarBoundary::Free));
    let solution = Lscm.solve(&problem, &mut Context::new())?;
    let uv = solution.planar().ok_or_else(|| SolverError::Unsupported {
        solver: NAME,
        message: "the conformal flattening gave no planar map".to_string(),
    })?;
    let stats = solution.metrics.distortion.as_ref();
    if let Some(s) = stats
        && s.flipped > 0
    {
        return Err(SolverError::Unsupported {
            solver: NAME,
            message: format!(
                "the conformal flattening of the surface (LSCM) flips {} faces; flatten it with a bijective map first (e.g. `beltrami param --solver tutte`) and map the flat copy",
                s.flipped
            ),
        });
    }
    let elements = Elements::new(mesh, Frame::Face)?;
    let derivative = planar_map(&elements, mesh.vertex_count(), uv)?
        .iter()
        .map(|d| d.fz)
        .collect();
    let flat = mesh.with_positions(uv.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect())?;
    Ok(Flattening {
        mesh: flat,
        derivative,
        mu_mean: stats.map_or(f64::NAN, |s| s.mu_mean),
        mu_max: stats.map_or(f64::NAN, |s| s.mu_max),
    })
}
