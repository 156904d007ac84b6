//! What a remeshing achieved: element angles, edge lengths and the distance between the
//! result and the input.

use beltrami_mesh::{Mesh, Point3, Vector3};
use beltrami_spatial::SurfaceIndex;

use crate::RemeshError;

/// Statistics of a remeshed surface against its input. Angles in degrees, lengths in the
/// mesh's units.
#[derive(Debug, Clone, PartialEq)]
pub struct Quality {
    /// Vertices of the result.
    pub vertices: usize,
    /// Faces of the result.
    pub faces: usize,
    /// Smallest corner angle.
    pub min_angle: f64,
    /// Mean corner angle (60 for triangles: reported as a check).
    pub mean_angle: f64,
    /// Share of corner angles below 30 degrees, in `[0, 1]`.
    pub share_below_30: f64,
    /// Edge lengths: shortest, mean, longest, and the spread `std / mean`.
    pub edge_min: f64,
    /// Mean edge length.
    pub edge_mean: f64,
    /// Longest edge.
    pub edge_max: f64,
    /// Standard deviation of the edge lengths over their mean.
    pub edge_spread: f64,
    /// Two-sided Hausdorff distance between the result and the input, sampled: the
    /// largest distance from a sample of either surface to the other surface.
    pub hausdorff: f64,
    /// Mean of the two one-sided mean distances.
    pub mean_distance: f64,
    /// Bounding-box diagonal of the input (distances are often quoted relative to it).
    pub diagonal: f64,
}

/// Measures `output` against `input`. Distances are exact closest-point distances
/// ([`SurfaceIndex`]) from samples: from the output, its vertices, edge midpoints and
/// the centroid of each face and the midpoints between it and the corners (barycentric
/// `(4,1,1)/6` on a triangle); from the input, its vertices
/// and face centroids.
pub fn measure(input: &Mesh, output: &Mesh) -> Result<Quality, RemeshError> {
    let on_output: Vec<Point3<f64>> = output
        .faces()
        .flat_map(|f| {
            let (v, k) = output.face_vertex_array(f);
            let p: Vec<Point3<f64>> = v[..k].iter().map(|&v| output.position(v)).collect();
            let c = p.iter().fold(Vector3::zeros(), |s, q| s + q.coords) / k as f64;
            let mut s = vec![Point3::from(c)];
            for i in 0..k {
                s.push(Point3::from((p[i].coords + p[(i + 1) % k].coords) / 2.0));
                s.push(Point3::from((p[i].coords + c) / 2.0));
            }
            s
        })
        .chain(output.positions().iter().copied())
        .collect();
    let on_input: Vec<Point3<f64>> = input
        .faces()
        .map(|f| input.face_centroid(f))
        .chain(input.positions().iter().copied())
        .collect();
    let to_input = SurfaceIndex::new(input)?.locate_all(&on_output)?;
    let to_output = SurfaceIndex::new(output)?.locate_all(&on_input)?;
    let (max_a, mean_a) = max_mean(to_input.iter().map(|l| l.distance));
    let (max_b, mean_b) = max_mean(to_output.iter().map(|l| l.distance));
    Ok(Quality {
        hausdorff: max_a.max(max_b),
        mean_distance: (mean_a + mean_b) / 2.0,
        diagonal: input.bounding_box().diagonal(),
        ..shape(output)
    })
}

/// The angles and edge lengths of `mesh` alone ([`Quality`] with zero distances and the
/// mesh's own diagonal): the "before" of a remeshing.
pub fn shape(mesh: &Mesh) -> Quality {
    let mut angles = Vec::with_capacity(3 * mesh.face_count());
    for f in mesh.faces() {
        for h in mesh.face_halfedges(f) {
            angles.push(mesh.corner_angle(h).to_degrees());
        }
    }
    let min_angle = angles.iter().copied().fold(f64::INFINITY, f64::min);
    let mean_angle = angles.iter().sum::<f64>() / angles.len().max(1) as f64;
    let share_below_30 =
        angles.iter().filter(|&&a| a < 30.0).count() as f64 / angles.len().max(1) as f64;
    let lengths = mesh.edge_lengths();
    let n = lengths.len().max(1) as f64;
    let edge_mean = lengths.iter().sum::<f64>() / n;
    let variance = lengths.iter().map(|l| (l - edge_mean).powi(2)).sum::<f64>() / n;
    Quality {
        vertices: mesh.vertex_count(),
        faces: mesh.face_count(),
        min_angle,
        mean_angle,
        share_below_30,
        edge_min: lengths.iter().copied().fold(f64::INFINITY, f64::min),
        edge_mean,
        edge_max: lengths.iter().copied().fold(0.0, f64::max),
        edge_spread: variance.sqrt() / edge_mean,
        hausdorff: 0.0,
        mean_distance: 0.0,
        diagonal: mesh.bounding_box().diagonal(),
    }
}

fn max_mean(d: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0usize);
    for x in d {
        max = max.max(x);
        sum += x;
        n += 1;
    }
    (max, sum / n.max(1) as f64)
}
