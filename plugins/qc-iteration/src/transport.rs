//! Smoothing a Beltrami coefficient across faces with frame transport (Gruber-Aulisa
//! 2022, section 5.3, Algorithm 4).
//!
//! `mu` is stored per face in the face's own frame (real axis `e1`), so neighbouring
//! values are not comparable as numbers. By Lemma 3.4, the value in the frame whose
//! real axis is `e1` turned by `theta` is `mu e^{-2 i theta}`, and turning by `pi`
//! changes nothing: the value of a face in the frame of one of its sides is
//! well-defined whichever way the side runs. One smoothing step averages the values
//! of the faces that share each edge in that edge's frame, then brings the edge values
//! back into each face (`e^{+2 i theta}`) and averages over its sides. In the plane
//! (one global frame) this is the plain mean over a face and its neighbours with
//! weights `1/2` for the face, `1/(2 n)` for each of its `n` sides' neighbours.

use beltrami_fem::Elements;
use beltrami_mesh::Mesh;
use num_complex::Complex64;

/// The per-side rotations of every face (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Transport {
    /// Per face and side: the edge and `e^{-2 i theta}` of the side's direction.
    sides: Vec<Vec<(usize, Complex64)>>,
    /// Per edge: the faces on it (1 or 2).
    faces_on_edge: Vec<f64>,
}

impl Transport {
    /// The rotations of the sides of `elements` (built on `mesh`).
    pub(crate) fn new(mesh: &Mesh, elements: &Elements) -> Self {
        let mut faces_on_edge = vec![0.0; mesh.edge_count()];
        let sides = mesh
            .faces()
            .map(|f| {
                mesh.face_halfedges(f)
                    .zip(elements.sides(f))
                    .map(|(h, side)| {
                        let e = mesh.edge(h).idx();
                        faces_on_edge[e] += 1.0;
                        let theta = side.y.atan2(side.x);
                        (e, Complex64::from_polar(1.0, -2.0 * theta))
                    })
                    .collect()
            })
            .collect();
        Self {
            sides,
            faces_on_edge,
        }
    }

    /// One smoothing step of `mu` (one value per face, in the face frames).
    pub(crate) fn smooth(&self, mu: &[Complex64]) -> Vec<Complex64> {
        let mut on_edge = vec![Complex64::new(0.0, 0.0); self.faces_on_edge.len()];
        for (sides, &m) in self.sides.iter().zip(mu) {
            for &(e, turn) in sides {
                on_edge[e] += turn * m;
            }
        }
        for (value, &count) in on_edge.iter_mut().zip(&self.faces_on_edge) {
            if count > 0.0 {
                *value /= count;
            }
        }
        self.sides
            .iter()
            .map(|sides| {
                sides
                    .iter()
                    .map(|&(e, turn)| turn.conj() * on_edge[e])
                    .sum::<Complex64>()
                    / sides.len() as f64
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_fem::Frame;
    use beltrami_fem::beltrami::rotate_frame;
    use beltrami_mesh::primitives::{Cells, grid, jittered_grid};
    use beltrami_mesh::{Mesh, Point3};

    /// A constant coefficient of the plane, written in the frames of a curved irregular
    /// mesh's faces through the frame rule, is a fixed point of the smoothing in the
    /// plane; on a surface the same holds for a field that is constant in the frames of
    /// a developed (flat) surface.
    #[test]
    fn a_constant_field_is_kept_in_every_frame() {
        let soup = jittered_grid(7, 5, Cells::Triangles, 0.3, 5);
        let mesh = Mesh::from_soup(&soup).unwrap();
        let face = Elements::new(&mesh, Frame::Face).unwrap();
        let global = Complex64::new(0.3, -0.2);
        let mu: Vec<Complex64> = mesh
            .faces()
            .map(|f| {
                let e1 = mesh.halfedge_vector(mesh.face_halfedge(f));
                rotate_frame(global, e1.y.atan2(e1.x))
            })
            .collect();
        let smoothed = Transport::new(&mesh, &face).smooth(&mu);
        for (a, b) in smoothed.iter().zip(&mu) {
            assert!((a - b).norm() < 1e-12, "{a} != {b}");
        }
        // The same field in the global frame is also kept (the plain average).
        let plane = Elements::new(&mesh, Frame::Global).unwrap();
        let constant = vec![global; mesh.face_count()];
        for a in Transport::new(&mesh, &plane).smooth(&constant) {
            assert!((a - global).norm() < 1e-12);
        }
        // Rolled onto a cylinder, the faces' frames are the developed ones: the
        // transported field stays fixed.
        let rolled: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::new(p.x.sin(), p.y, 1.0 - p.x.cos()))
            .collect();
        let cylinder = mesh.with_positions(rolled).unwrap();
        let on_cylinder = Elements::new(&cylinder, Frame::Face).unwrap();
        let smoothed = Transport::new(&cylinder, &on_cylinder).smooth(&mu);
        let worst = smoothed
            .iter()
            .zip(&mu)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(worst < 0.02, "{worst}");
    }

    /// A field with a kink is smoothed: the step moves it towards the mean of the
    /// neighbours, and the values on one side of a single interior edge of two faces
    /// average to their mean.
    #[test]
    fn two_faces_meet_halfway() {
        let soup = grid(1, 1, Cells::Triangles);
        let mesh = Mesh::from_soup(&soup).unwrap();
        let plane = Elements::new(&mesh, Frame::Global).unwrap();
        assert_eq!(mesh.face_count(), 2);
        let mu = [Complex64::new(0.4, 0.0), Complex64::new(0.0, 0.2)];
        let s = Transport::new(&mesh, &plane).smooth(&mu);
        // Each face: 2 of 3 sides on the boundary keep its value, the shared side holds
        // the mean.
        let mean = (mu[0] + mu[1]) / 2.0;
        for (a, m) in s.iter().zip(&mu) {
            let expected = (m * 2.0 + mean) / 3.0;
            assert!((a - expected).norm() < 1e-15, "{a} vs {expected}");
        }
    }
}
