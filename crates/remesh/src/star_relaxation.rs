//! Moving the vertices of the worst faces of the assembled surface.
//!
//! Refinement bounds angles in the parameter domain; on the surface a few faces still
//! come out with a small angle, mostly opposite an edge much shorter than the asked
//! length where two vertices ended close together (next to a feature vertex or across
//! a seam). A flip cannot help there (the short edge is the shared one); moving an end
//! of it can. Each vertex of a face whose smallest angle is below [`ANGLE_LIMIT`], and
//! not on the surface's boundary, tries the centroid of its neighbours projected onto
//! the input (the closest point of the input surface, exact on it); the move is kept
//! when it raises the smallest angle of the vertex's faces and turns none of them over
//! (each new face normal has a positive dot product with the old one), and when every
//! input vertex that the star held within the feature tolerance (`t h`, see
//! [`crate::RemeshOptions::feature_tolerance`]) stays within it: a move must not cut off
//! a crease that the refinement kept.

use beltrami_mesh::{Point3, SurfacePoint, Vector3};
use beltrami_spatial::SurfaceIndex;
use beltrami_spatial::closest_point::closest_on_triangle;

use crate::RemeshError;
use crate::refine::smallest_sine;

/// Smallest angle, in degrees, below which a face's vertices are moved. At 20 (the
/// refinement's limit) the eight shared meshes of the pymeshlab comparison ended at
/// 20.1-26.4 degrees; at 26 at 24.8-28.8, with fewer angles under 30 and the same
/// Hausdorff distances; at 28 and 30 the scanned face's Hausdorff distance grew from
/// 0.31% to 0.44% of the diagonal.
pub const ANGLE_LIMIT: f64 = 26.0;

/// Sweeps at most.
const SWEEPS: usize = 4;

/// Relaxes the vertices of the faces `faces` (triangles, indices into `positions`)
/// whose smallest angle is below [`ANGLE_LIMIT`] (module docs); `on_source` follows
/// every move; `sizes[v]` is the asked edge length at vertex `v`, and `tolerance` times
/// it its feature tolerance (an infinite one guards nothing). Boundary vertices stay.
/// Returns the moves made.
pub fn relax_worst_stars(
    faces: &[[u32; 3]],
    positions: &mut [Point3<f64>],
    on_source: &mut [SurfacePoint],
    sizes: &[f64],
    tolerance: f64,
    surface: &SurfaceIndex<'_>,
) -> Result<usize, RemeshError> {
    let n = positions.len();
    let mut star: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut edge_faces = std::collections::HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (face[k] as usize, face[(k + 1) % 3] as usize);
            star[a].push(f);
            neighbours[a].push(b);
            *edge_faces.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
        }
    }
    let mut on_boundary = vec![false; n];
    for (&(a, b), &count) in &edge_faces {
        if count == 1 {
            on_boundary[a] = true;
            on_boundary[b] = true;
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let limit = ANGLE_LIMIT.to_radians().sin();
    let quality = |positions: &[Point3<f64>], f: usize| {
        let [a, b, c] = faces[f].map(|i| positions[i as usize]);
        smallest_sine(&[a, b, c])
    };
    let normal = |positions: &[Point3<f64>], f: usize| -> Vector3<f64> {
        let [a, b, c] = faces[f].map(|i| positions[i as usize]);
        (b - a).cross(&(c - a))
    };
    let mut moves = 0;
    for _ in 0..SWEEPS {
        let mut moved = 0;
        for (f, face) in faces.iter().enumerate() {
            if quality(positions, f) >= limit {
                continue;
            }
            for v in face.map(|i| i as usize) {
                if on_boundary[v] || neighbours[v].is_empty() {
                    continue;
                }
                let before = star[v]
                    .iter()
                    .map(|&g| quality(positions, g))
                    .fold(f64::INFINITY, f64::min);
                let normals: Vec<Vector3<f64>> =
                    star[v].iter().map(|&g| normal(positions, g)).collect();
                let centroid = neighbours[v]
                    .iter()
                    .fold(Vector3::zeros(), |s, &w| s + positions[w].coords)
                    / neighbours[v].len() as f64;
                let located = surface.locate(&Point3::from(centroid))?;
                let old = positions[v];
                positions[v] = located.position;
                let after = star[v]
                    .iter()
                    .map(|&g| quality(positions, g))
                    .fold(f64::INFINITY, f64::min);
                let keeps_turn = star[v]
                    .iter()
                    .zip(&normals)
                    .all(|(&g, n)| normal(positions, g).dot(n) > 0.0);
                if after > before * (1.0 + 1e-9)
                    && keeps_turn
                    && keeps_features(
                        faces,
                        &star[v],
                        positions,
                        (v, old),
                        tolerance * sizes[v],
                        surface,
                    )?
                {
                    on_source[v] = located.point;
                    moved += 1;
                } else {
                    positions[v] = old;
                }
            }
        }
        moves += moved;
        if moved == 0 {
            break;
        }
    }
    Ok(moves)
}

/// Whether every input vertex near the star `star` of vertex `v` (faces `faces`, `v`
/// now at `positions[v]`, before at `old`) that lay within `tolerance` of the star
/// before still does.
fn keeps_features(
    faces: &[[u32; 3]],
    star: &[usize],
    positions: &[Point3<f64>],
    (v, old): (usize, Point3<f64>),
    tolerance: f64,
    surface: &SurfaceIndex<'_>,
) -> Result<bool, RemeshError> {
    if !tolerance.is_finite() {
        return Ok(true);
    }
    let corners = |g: usize, moved: bool| {
        faces[g].map(|i| {
            let i = i as usize;
            if i == v && !moved { old } else { positions[i] }
        })
    };
    let distance = |x: &Point3<f64>, moved: bool| {
        star.iter()
            .map(|&g| closest_on_triangle(x, &corners(g, moved)).distance())
            .fold(f64::INFINITY, f64::min)
    };
    let reach = star
        .iter()
        .flat_map(|&g| corners(g, false).into_iter().chain(corners(g, true)))
        .map(|p| (p - old).norm())
        .fold(0.0, f64::max);
    let input = surface.mesh();
    let mut near: Vec<_> = surface
        .faces_within(&old, reach + tolerance)?
        .into_iter()
        .flat_map(|f| input.face_vertices(f))
        .collect();
    near.sort_unstable();
    near.dedup();
    Ok(near.into_iter().all(|w| {
        let x = input.position(w);
        distance(&x, false) > tolerance || distance(&x, true) <= tolerance
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::{Mesh, PolygonSoup};

    #[test]
    fn a_vertex_pushed_next_to_its_neighbour_goes_back_to_the_middle() {
        // A regular hexagon fanned around its centre, in the plane z = 1, with the
        // centre moved to 0.05 from the first corner: angles near 3 degrees there.
        let mut points: Vec<Point3<f64>> = (0..6)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 6.0;
                Point3::new(t.cos(), t.sin(), 1.0)
            })
            .collect();
        points.push(Point3::new(0.0, 0.0, 1.0));
        let faces: Vec<[u32; 3]> = (0..6).map(|k| [6, k, (k + 1) % 6]).collect();
        let input = Mesh::from_soup(&PolygonSoup::from_triangles(points.clone(), &faces)).unwrap();
        let index = SurfaceIndex::new(&input).unwrap();
        let mut positions = points.clone();
        positions[6] = Point3::new(0.95, 0.0, 1.0);
        let mut on_source: Vec<SurfacePoint> = positions
            .iter()
            .map(|p| index.locate(p).unwrap().point)
            .collect();
        let smallest = |p: &[Point3<f64>]| {
            faces
                .iter()
                .map(|f| smallest_sine(&f.map(|i| p[i as usize])))
                .fold(f64::INFINITY, f64::min)
        };
        assert!(smallest(&positions) < ANGLE_LIMIT.to_radians().sin());
        let moves = relax_worst_stars(
            &faces,
            &mut positions,
            &mut on_source,
            &[0.5; 7],
            0.2,
            &index,
        )
        .unwrap();
        assert!(moves >= 1);
        // The centroid of the ring is the centre: equilateral faces again, on the plane.
        assert!((positions[6] - Point3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
        assert!((smallest(&positions) - 60f64.to_radians().sin()).abs() < 1e-12);
        // The boundary ring did not move, and the surface point follows the vertex.
        assert_eq!(&positions[..6], &points[..6]);
        assert!((on_source[6].position(&input) - positions[6]).norm() < 1e-12);
    }
}
