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
//!
//! A curved surface of genus 0 with several boundary loops is made a disk first, as the
//! paper does: every loop but the longest is closed by a fan of triangles around a new
//! vertex at the loop's centroid, the filled disk is laid out by LSCM, and the fill is
//! removed (the source keeps its own faces, now at their planar images).

use beltrami_core::{Context, PlanarBoundary, Problem, Solver, SolverError, Target};
use beltrami_fem::beltrami::planar_map;
use beltrami_fem::{Elements, Frame};
use beltrami_init::Lscm;
use beltrami_mesh::{Mesh, Point3, PolygonSoup};
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

/// `mesh` with every boundary loop but the longest closed by a fan around a new vertex
/// at its centroid (the new vertices follow the mesh's own).
fn filled(mesh: &Mesh) -> Result<Mesh, SolverError> {
    let mut loops = mesh.boundary_loop_list();
    let longest = (0..loops.len())
        .max_by(|&a, &b| loops[a].length.total_cmp(&loops[b].length))
        .unwrap_or(0);
    loops.remove(longest);
    let mut soup = PolygonSoup::new(mesh.positions().to_vec());
    for f in mesh.faces() {
        let face: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        soup.push_face(&face);
    }
    for l in &loops {
        let centre = l
            .vertices
            .iter()
            .fold(Point3::origin(), |c, &v| c + mesh.position(v).coords)
            / l.vertices.len() as f64;
        let c = soup.positions.len() as u32;
        soup.positions.push(centre);
        // The surface is on the right of a boundary loop: the fan is on its left.
        for (k, &a) in l.vertices.iter().enumerate() {
            let b = l.vertices[(k + 1) % l.vertices.len()];
            soup.push_face(&[a.0, b.0, c]);
        }
    }
    Ok(Mesh::from_soup(&soup)?)
}

/// Lays `mesh` (a curved disk of triangles, or a curved genus-0 surface with several
/// boundary loops, filled first: module docs) out in the plane by LSCM; refuses a
/// layout with flipped faces of `mesh`. `context` is the caller's [`Context::inner`]:
/// a Ctrl-C stops the LSCM solve too.
pub fn flatten(mesh: &Mesh, context: &mut Context<'_>) -> Result<Flattening, SolverError> {
    let disk = if mesh.boundary_loop_count() > 1 {
        Some(filled(mesh)?)
    } else {
        None
    };
    let layout = disk.as_ref().unwrap_or(mesh);
    let problem = Problem::new(layout, Target::Plane(PlanarBoundary::Free));
    let solution = Lscm.solve(&problem, context)?;
    let uv = solution.planar().ok_or_else(|| {
        SolverError::unsupported(NAME, "the conformal flattening gave no planar map")
    })?;
    let uv = &uv[..mesh.vertex_count()];
    let elements = Elements::new(mesh, Frame::Face)?;
    let derivatives = planar_map(&elements, mesh.vertex_count(), uv)?;
    let flipped = derivatives
        .iter()
        .filter(|d| d.fz.norm_sqr() - d.fzbar.norm_sqr() <= 0.0)
        .count();
    if flipped > 0 {
        return Err(SolverError::unsupported(
            NAME,
            format!(
                "the conformal flattening of the surface (LSCM) flips {flipped} faces; flatten it with a bijective map first (e.g. `beltrami param --solver tutte`) and map the flat copy"
            ),
        ));
    }
    let mus: Vec<f64> = derivatives
        .iter()
        .map(|d| (d.fzbar / d.fz).norm())
        .collect();
    let derivative = derivatives.iter().map(|d| d.fz).collect();
    let flat = mesh.with_positions(uv.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect())?;
    Ok(Flattening {
        mesh: flat,
        derivative,
        mu_mean: mus.iter().sum::<f64>() / mus.len().max(1) as f64,
        mu_max: mus.iter().copied().fold(0.0, f64::max),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    #[test]
    fn the_flattening_stops_when_its_caller_is_cancelled() {
        let mut soup = primitives::disk(2);
        for p in &mut soup.positions {
            p.z = 0.5 * (p.x * p.x - p.y * p.y);
        }
        let mesh = Mesh::from_soup(&soup).unwrap();
        let cancelled = Context::new().with_cancel_flag(Arc::new(AtomicBool::new(true)));
        assert!(matches!(
            flatten(&mesh, &mut cancelled.inner()),
            Err(SolverError::Cancelled)
        ));
        assert!(flatten(&mesh, &mut Context::new()).is_ok());
    }
}
