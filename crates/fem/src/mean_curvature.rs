//! The mean curvature per vertex of a triangle mesh, from the cotangent Laplacian:
//! `L x = 2 A H n` at each vertex (Meyer, Desbrun, Schroeder, Barr, "Discrete
//! differential-geometry operators for triangulated 2-manifolds", 2003, section 3.3),
//! with `L` the cotangent Laplacian ([`cotan_laplacian`]), `A` the mixed Voronoi area of
//! the vertex (Meyer et al., figure 4: the Voronoi region's part of each non-obtuse
//! incident triangle, half of an obtuse triangle at its obtuse corner, a quarter at its
//! other corners) and `n` the unit vertex normal.
//!
//! Conventions: `H = (k_1 + k_2) / 2`, positive where the surface bends away from its
//! normal (a sphere with outward normals has `H = 1 / r`); boundary vertices get the
//! same formula, which there measures the boundary's curvature as well.

use beltrami_mesh::Mesh;

use crate::error::FemError;
use crate::operators::cotan_laplacian;

/// The signed mean curvature `H_i = (L x)_i . n_i / (2 A_i)` of every vertex (module
/// docs).
///
/// # Errors
/// [`FemError`] for a mesh with a face that is not a triangle.
pub fn mean_curvature(mesh: &Mesh) -> Result<Vec<f64>, FemError> {
    let laplacian = cotan_laplacian(mesh)?;
    let n = mesh.vertex_count();
    let mut lx = vec![nalgebra::Vector3::zeros(); n];
    for j in 0..n {
        let xj = mesh.positions()[j].coords;
        let col = laplacian.as_ref().col_range(j);
        let rows = &laplacian.as_ref().symbolic().row_idx()[col.clone()];
        let values = &laplacian.as_ref().val()[col];
        for (&i, &w) in rows.iter().zip(values) {
            lx[i] += xj * w;
        }
    }
    let area = mixed_areas(mesh);
    Ok(mesh
        .vertices()
        .map(|v| {
            let i = v.idx();
            let a = area[i].max(f64::MIN_POSITIVE);
            lx[i].dot(&mesh.vertex_normal(v)) / (2.0 * a)
        })
        .collect())
}

/// The mixed Voronoi area of every vertex (module docs).
fn mixed_areas(mesh: &Mesh) -> Vec<f64> {
    let mut area = vec![0.0; mesh.vertex_count()];
    for f in mesh.faces() {
        let corners: Vec<_> = mesh.face_vertices(f).collect();
        let p: Vec<_> = corners.iter().map(|&v| mesh.position(v)).collect();
        let whole = mesh.face_area(f);
        // The angle at each corner through its cosine's sign and its cotangent.
        let cot = |k: usize| {
            let a = p[(k + 1) % 3] - p[k];
            let b = p[(k + 2) % 3] - p[k];
            a.dot(&b) / a.cross(&b).norm().max(f64::MIN_POSITIVE)
        };
        let obtuse = (0..3).find(|&k| cot(k) < 0.0);
        for k in 0..3 {
            area[corners[k].idx()] += match obtuse {
                None => {
                    // (|P Q|^2 cot R + |P R|^2 cot Q) / 8 for the corner P.
                    let (q, r) = ((k + 1) % 3, (k + 2) % 3);
                    ((p[q] - p[k]).norm_squared() * cot(r) + (p[r] - p[k]).norm_squared() * cot(q))
                        / 8.0
                }
                Some(o) if o == k => whole / 2.0,
                Some(_) => whole / 4.0,
            };
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid, icosphere};

    #[test]
    fn a_sphere_of_radius_two_has_mean_curvature_one_half_and_converges() {
        let error = |level: usize| {
            let mut soup = icosphere(level);
            for p in &mut soup.positions {
                *p = nalgebra::Point3::from(p.coords * 2.0);
            }
            let mesh = Mesh::from_soup(&soup).unwrap();
            let h = mean_curvature(&mesh).unwrap();
            h.iter().map(|h| (h - 0.5).abs()).fold(0.0, f64::max)
        };
        let (coarse, fine) = (error(3), error(4));
        assert!(fine < 0.01, "{fine}");
        assert!(fine < 0.5 * coarse, "{coarse} -> {fine}");
    }

    #[test]
    fn a_plane_is_flat_inside() {
        let mesh = Mesh::from_soup(&grid(6, 6, Cells::Triangles)).unwrap();
        let h = mean_curvature(&mesh).unwrap();
        for v in mesh.vertices().filter(|&v| !mesh.is_boundary_vertex(v)) {
            assert!(h[v.idx()].abs() < 1e-12, "{v}: {}", h[v.idx()]);
        }
    }
}
