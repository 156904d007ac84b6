//! Corner angles for the reference shapes of in-place remeshing (Gruber-Aulisa 2022,
//! section 6.2): the conformal structure the QC iteration maps from, one angle per face
//! corner stored at the halfedge that leaves the corner's vertex inside the face (the
//! layout of `Constraint::ReferenceAngles`).

use std::f64::consts::{PI, TAU};

use beltrami_mesh::Mesh;

/// Which reference shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// Every triangle equilateral (`pi / 3`), every quad a square (`pi / 2`).
    Equiangular,
    /// Algorithm 5: angles adapted to the vertex valences.
    Optimized,
}

impl Reference {
    /// `equiangular` or `optimized`.
    pub fn name(self) -> &'static str {
        match self {
            Reference::Equiangular => "equiangular",
            Reference::Optimized => "optimized",
        }
    }
}

/// The corner angles of `reference` for every face of `mesh` (boundary halfedges get 0,
/// which is never read).
///
/// [`Reference::Optimized`] is Algorithm 5: a corner at a vertex with `m` faces around it
/// would like `alpha = 2 pi / m` (the vertex's own angle sum over `m` at a boundary
/// vertex, so that corners of the boundary keep their shape); in each face the
/// largest wish, when it is the only largest, is kept and the rest of the angle sum
/// (`pi` for a triangle, `2 pi` for a quad) is shared by the other corners in
/// proportion to their wishes; otherwise the whole sum is shared in proportion. A kept
/// largest wish leaves at least 15 degrees to each other corner (else the sum is shared
/// in proportion), so that every reference polygon exists.
pub fn reference_angles(mesh: &Mesh, reference: Reference) -> Vec<f64> {
    let mut angles = vec![0.0; mesh.halfedge_count()];
    let wish = match reference {
        Reference::Equiangular => None,
        Reference::Optimized => Some(vertex_wishes(mesh)),
    };
    for f in mesh.faces() {
        let corners: Vec<_> = mesh.face_halfedges(f).collect();
        let n = corners.len();
        let full = if n == 3 { PI } else { TAU };
        let Some(wish) = &wish else {
            for h in corners {
                angles[h.idx()] = full / n as f64;
            }
            continue;
        };
        let alpha: Vec<f64> = corners
            .iter()
            .map(|&h| wish[mesh.origin(h).idx()])
            .collect();
        let largest = alpha.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let leaders = alpha.iter().filter(|&&a| a == largest).count();
        let room = (n - 1) as f64 * 15f64.to_radians();
        let lead = (leaders == 1 && largest < full - room)
            .then(|| alpha.iter().position(|&a| a == largest).unwrap_or_default());
        let beta: Vec<f64> = match lead {
            Some(i) => {
                let rest = alpha.iter().sum::<f64>() - largest;
                alpha
                    .iter()
                    .enumerate()
                    .map(|(j, &a)| {
                        if j == i {
                            a
                        } else {
                            a * (full - largest) / rest
                        }
                    })
                    .collect()
            }
            None => {
                let sum: f64 = alpha.iter().sum();
                alpha.iter().map(|a| a * full / sum).collect()
            }
        };
        for (h, b) in corners.into_iter().zip(beta) {
            angles[h.idx()] = b;
        }
    }
    angles
}

/// Per vertex, the angle a corner there would like: `2 pi / m` inside, the vertex's
/// angle sum over `m` on the boundary (`m` its faces).
fn vertex_wishes(mesh: &Mesh) -> Vec<f64> {
    let mut faces = vec![0usize; mesh.vertex_count()];
    let mut sums = vec![0.0; mesh.vertex_count()];
    for f in mesh.faces() {
        for h in mesh.face_halfedges(f) {
            let v = mesh.origin(h).idx();
            faces[v] += 1;
            sums[v] += mesh.corner_angle(h);
        }
    }
    mesh.vertices()
        .map(|v| {
            let m = faces[v.idx()].max(1) as f64;
            if mesh.is_boundary_vertex(v) {
                sums[v.idx()] / m
            } else {
                TAU / m
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid, icosphere};

    #[test]
    fn regular_connectivity_asks_for_regular_shapes() {
        // Every vertex of a subdivided icosahedron has 6 faces but the 12 original ones,
        // which have 5 and are never in one face: a corner there wishes 72 degrees and
        // leads its triangle (the two others share 108), every other triangle is
        // equilateral.
        let mesh = Mesh::from_soup(&icosphere(2)).unwrap();
        let angles = reference_angles(&mesh, Reference::Optimized);
        let five = |h| mesh.outgoing_halfedges(mesh.origin(h)).count() == 5;
        for f in mesh.faces() {
            let led = mesh.face_halfedges(f).any(five);
            for h in mesh.face_halfedges(f) {
                let expected = match (led, five(h)) {
                    (false, _) => 60.0,
                    (true, true) => 72.0,
                    (true, false) => 54.0,
                };
                let got = angles[h.idx()].to_degrees();
                assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
            }
        }
    }

    #[test]
    fn boundary_corners_keep_their_angle_and_quads_sum_to_two_pi() {
        // A grid of quads: inner vertices have 4 faces (90 degrees), boundary vertices
        // 2 (180 / 2) and the corners 1 (90 / 1): every cell is asked to be a square.
        let mesh = Mesh::from_soup(&grid(4, 3, Cells::Quads)).unwrap();
        let angles = reference_angles(&mesh, Reference::Optimized);
        for f in mesh.faces() {
            for h in mesh.face_halfedges(f) {
                assert!((angles[h.idx()] - PI / 2.0).abs() < 1e-12);
            }
        }
        let equiangular = reference_angles(&mesh, Reference::Equiangular);
        assert!(
            mesh.faces()
                .flat_map(|f| mesh.face_halfedges(f))
                .all(|h| equiangular[h.idx()] == PI / 2.0)
        );
    }
}
