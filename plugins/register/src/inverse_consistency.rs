//! How far a registration and the registration the other way are from inverses: for
//! each source vertex `x_i` with image `y_i` on the target, `y_i` carried back by the
//! reverse map (the reverse images of the target face's corners, weighted by `y_i`'s
//! coordinates there) lands at `z_i`; `|z_i - x_i|` is zero for a pair of exact
//! inverses. Symmetric registration methods report it (Christensen and Johnson, IEEE
//! TMI 20, 2001, inverse consistency error).

use beltrami_mesh::{Mesh, Point3, SurfacePoint};

/// The distances `|z_i - x_i|` of a round trip (module docs), in the source's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InverseConsistency {
    /// Their mean over the source's vertices.
    pub mean: f64,
    /// Their largest.
    pub max: f64,
    /// The source vertex where it is largest.
    pub worst: usize,
}

/// The inverse consistency of `forward` (the image of every source vertex on `target`)
/// and `backward` (the image of every target vertex, a position near the source).
/// `None` when `forward` and `backward` do not fit the meshes (lengths, a face out of
/// range) or the source has no vertex.
pub fn inverse_consistency(
    source: &Mesh,
    target: &Mesh,
    forward: &[SurfacePoint],
    backward: &[Point3<f64>],
) -> Option<InverseConsistency> {
    if forward.len() != source.vertex_count()
        || backward.len() != target.vertex_count()
        || source.vertex_count() == 0
    {
        return None;
    }
    let mut sum = 0.0;
    let mut worst = (0, 0.0f64);
    for (i, y) in forward.iter().enumerate() {
        if y.face.idx() >= target.face_count() {
            return None;
        }
        let (corners, degree) = target.face_vertex_array(y.face);
        let back = (0..degree).fold(nalgebra::Vector3::zeros(), |acc, k| {
            acc + backward[corners[k].idx()].coords * y.coords[k]
        });
        let d = (back - source.positions()[i].coords).norm();
        sum += d;
        if d > worst.1 {
            worst = (i, d);
        }
    }
    Some(InverseConsistency {
        mean: sum / source.vertex_count() as f64,
        max: worst.1,
        worst: worst.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    #[test]
    fn a_map_and_its_inverse_make_no_round_trip_error_and_a_shift_does() {
        // The identity of a grid both ways: zero. The same with the way back shifted by
        // (0.01, 0, 0): every round trip ends 0.01 off.
        let mesh = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).unwrap();
        let forward: Vec<SurfacePoint> = mesh
            .vertices()
            .map(|v| SurfacePoint::at_vertex(&mesh, v))
            .collect();
        let back: Vec<Point3<f64>> = mesh.positions().to_vec();
        let exact = inverse_consistency(&mesh, &mesh, &forward, &back).unwrap();
        assert!(exact.max < 1e-15, "{exact:?}");
        let shifted: Vec<Point3<f64>> = back
            .iter()
            .map(|p| p + nalgebra::Vector3::new(0.01, 0.0, 0.0))
            .collect();
        let off = inverse_consistency(&mesh, &mesh, &forward, &shifted).unwrap();
        assert!(
            (off.mean - 0.01).abs() < 1e-12 && (off.max - 0.01).abs() < 1e-12,
            "{off:?}"
        );
        assert_eq!(
            inverse_consistency(&mesh, &mesh, &forward[1..], &back),
            None
        );
    }
}
