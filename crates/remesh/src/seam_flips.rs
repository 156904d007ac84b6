//! Edge flips on the assembled surface, where seams are ordinary edges.
//!
//! Refinement and its flips ([`crate::refine`]) work in the parameter domain of one
//! chart, where every edge of a cut curve is a constraint with a face on one side only.
//! At a node of the cut graph (an end or a branch point) the chart has a corner whose
//! angle refinement cannot change, and the faces on the two copies of a seam were
//! triangulated apart. Once the copies are one curve of the result, its edges have a
//! face on each side, and a flip across one can raise the smallest angle where no flip
//! in the plane could (measured on `g2_eight`, whose genus-2 cut graph has branch
//! points: smallest angle 14.3 degrees before, see `docs/remesh.md`).
//!
//! An interior edge `ab` with faces `abc` and `bad` becomes `cd` when
//!
//! - that raises the smallest angle of the two faces (so each flip raises the sorted
//!   angle vector of the mesh and the sweeps end),
//! - `cd` is not an edge already, nor made by another flip of the same sweep (the result
//!   stays a manifold),
//! - both new faces turn the way the old pair did (their normals have a positive dot
//!   product with the sum of the old area vectors), so the flip does not fold the surface,
//! - the midpoint of `cd` is no farther from the input surface than the midpoint of `ab`
//!   or [`crate::refine::FLIP_DEVIATION`] `h` (a flip across a crease would cut it off).

use std::collections::{HashMap, HashSet};

use beltrami_mesh::{Point3, Vector3};
use beltrami_spatial::SurfaceIndex;

use crate::RemeshError;
use crate::refine::{FLIP_DEVIATION, smallest_sine};

/// Sweeps of flips at most.
const SWEEPS: usize = 8;

/// Flips edges of the triangles `faces` (counter-clockwise about the outward side,
/// indices into `positions`) for their smallest angles (module docs); `sizes` is the
/// asked edge length at each vertex and `surface` the input. Returns the flips made.
pub fn flip_for_angles(
    faces: &mut [[u32; 3]],
    positions: &[Point3<f64>],
    sizes: &[f64],
    surface: &SurfaceIndex<'_>,
) -> Result<usize, RemeshError> {
    let mut total = 0;
    for _ in 0..SWEEPS {
        let flips = sweep(faces, positions, sizes, surface)?;
        total += flips;
        if flips == 0 {
            break;
        }
    }
    Ok(total)
}

/// One sweep; faces changed in it wait for the next.
fn sweep(
    faces: &mut [[u32; 3]],
    positions: &[Point3<f64>],
    sizes: &[f64],
    surface: &SurfaceIndex<'_>,
) -> Result<usize, RemeshError> {
    let mut across: HashMap<(u32, u32), (usize, u32)> = HashMap::with_capacity(3 * faces.len());
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            across.insert((face[k], face[(k + 1) % 3]), (f, face[(k + 2) % 3]));
        }
    }
    let p = |i: u32| positions[i as usize];
    let quality = |a: u32, b: u32, c: u32| smallest_sine(&[p(a), p(b), p(c)]);
    let area_vector = |a: u32, b: u32, c: u32| (p(b) - p(a)).cross(&(p(c) - p(a)));
    let gap = |a: u32, b: u32| -> Result<f64, RemeshError> {
        let mid = Point3::from((p(a).coords + p(b).coords) / 2.0);
        Ok(surface.locate(&mid)?.distance)
    };
    let mut changed = vec![false; faces.len()];
    let mut made: HashSet<(u32, u32)> = HashSet::new();
    let mut flips = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b, c) = (face[k], face[(k + 1) % 3], face[(k + 2) % 3]);
            let Some(&(g, d)) = across.get(&(b, a)) else {
                continue;
            };
            if g < f || changed[f] || changed[g] || c == d {
                continue;
            }
            // Nor one that a flip of this sweep makes (the edge map is the sweep's
            // start): two flips that both made `cd` would leave it with four faces.
            if across.contains_key(&(c, d))
                || across.contains_key(&(d, c))
                || made.contains(&(c.min(d), c.max(d)))
            {
                continue;
            }
            let before = quality(a, b, c).min(quality(b, a, d));
            let after = quality(a, d, c).min(quality(d, b, c));
            if after <= before * (1.0 + 1e-9) {
                continue;
            }
            let turn: Vector3<f64> = area_vector(a, b, c) + area_vector(b, a, d);
            if area_vector(a, d, c).dot(&turn) <= 0.0 || area_vector(d, b, c).dot(&turn) <= 0.0 {
                continue;
            }
            let h = (sizes[a as usize] + sizes[b as usize]) / 2.0;
            if gap(c, d)? > gap(a, b)?.max(FLIP_DEVIATION * h) {
                continue;
            }
            changed[f] = true;
            changed[g] = true;
            made.insert((c.min(d), c.max(d)));
            flips.push((f, g, [a, d, c], [d, b, c]));
        }
    }
    for &(f, g, first, second) in &flips {
        faces[f] = first;
        faces[g] = second;
    }
    Ok(flips.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::{Mesh, PolygonSoup};

    /// The flat quad a b c d with its long diagonal ab and its short one cd, as the
    /// two faces on ab.
    fn flat_quad() -> Mesh {
        let points = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [2.0, 0.5, 0.0],
            [2.0, -0.5, 0.0],
        ];
        surface(&points, &[[0, 1, 2], [1, 0, 3]])
    }

    fn surface(points: &[[f64; 3]], faces: &[[u32; 3]]) -> Mesh {
        let positions = points
            .iter()
            .map(|p| Point3::new(p[0], p[1], p[2]))
            .collect();
        Mesh::from_soup(&PolygonSoup::from_triangles(positions, faces)).unwrap()
    }

    #[test]
    fn a_long_diagonal_of_a_flat_quad_is_flipped() {
        let input = flat_quad();
        let index = SurfaceIndex::new(&input).unwrap();
        let positions: Vec<_> = input.positions().to_vec();
        let mut faces = [[0, 1, 2], [1, 0, 3]];
        let flips = flip_for_angles(&mut faces, &positions, &[1.0; 4], &index).unwrap();
        assert_eq!(flips, 1);
        assert_eq!(faces, [[0, 3, 2], [3, 1, 2]]);
        // Flipped back it would lower the smallest angle: nothing more to do.
        assert_eq!(
            flip_for_angles(&mut faces, &positions, &[1.0; 4], &index).unwrap(),
            0
        );
    }

    #[test]
    fn two_flips_of_one_sweep_never_make_the_same_edge() {
        // Two copies of the quad of the test above (vertices a, b and a2, b2 at the same
        // places) sharing c and d: either flip alone makes cd; both would give cd four
        // faces (a remesh of a face with a hole ended "face 3051 duplicates face 3050").
        let input = flat_quad();
        let index = SurfaceIndex::new(&input).unwrap();
        let mut positions: Vec<_> = input.positions().to_vec();
        positions.extend([positions[0], positions[1]]);
        let mut faces = [[0, 1, 2], [1, 0, 3], [4, 5, 2], [5, 4, 3]];
        let flips = flip_for_angles(&mut faces, &positions, &[1.0; 6], &index).unwrap();
        assert_eq!(flips, 1);
        let on_cd = faces
            .iter()
            .filter(|f| f.contains(&2) && f.contains(&3))
            .count();
        assert_eq!(on_cd, 2, "{faces:?}");
    }

    #[test]
    fn a_flip_across_a_crease_or_into_a_fold_is_refused() {
        // The same quad folded along ab into a valley: cd would cut across the crease.
        let points = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [2.0, 0.5, 1.0],
            [2.0, -0.5, 1.0],
        ];
        let input = surface(&points, &[[0, 1, 2], [1, 0, 3]]);
        let index = SurfaceIndex::new(&input).unwrap();
        let mut faces = [[0, 1, 2], [1, 0, 3]];
        let positions: Vec<_> = input.positions().to_vec();
        assert_eq!(
            flip_for_angles(&mut faces, &positions, &[1.0; 4], &index).unwrap(),
            0
        );
        // A flat quad that is not convex at b: cd would turn one face over.
        let points = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [3.0, 0.5, 0.0],
            [3.0, -0.5, 0.0],
        ];
        let input = surface(&points, &[[0, 1, 2], [1, 0, 3]]);
        let index = SurfaceIndex::new(&input).unwrap();
        let positions: Vec<_> = input.positions().to_vec();
        let mut faces = [[0, 1, 2], [1, 0, 3]];
        assert_eq!(
            flip_for_angles(&mut faces, &positions, &[1.0; 4], &index).unwrap(),
            0
        );
    }
}
