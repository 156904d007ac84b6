//! Unfolding a flipped face by untangling the patch around it at once (the last
//! resort of a flow on a target mesh, [`crate::untangle::untangle_patches`]).
//!
//! One vertex at a time cannot unfold a face whose fold runs through several stars: on
//! the genus-3 pair `slim64` onto `stout64` (docs/register.md) the kernel moves left
//! face 17517 inverted with three neighbours standing edge-on, where the target turns
//! by 44 degrees, and every corner's kernel empty. The patch of faces within `r` rings
//! of the flipped face is laid into the plane normal to the mean target normal at its
//! vertices' images (origin at their centroid, axes [`orthonormal_basis`]); its free
//! vertices whose whole star lies in the patch then move together, sweep after sweep,
//! down the untangling energy of Escobar, Rodriguez, Montenegro, Montero and
//! Gonzalez-Yuste ("Simultaneous untangling and smoothing of tetrahedral meshes",
//! CMAME 192, 2003; here its triangle form, [`untangle_in_plane`]), which is finite
//! while faces are inverted and whose minimizers have none. Each moved vertex keeps its
//! height over the plane and is projected back onto the target, and the descent goes on
//! there, each vertex in its own tangent plane ([`polish_on_surface`]). The result is kept
//! only when the patch has fewer flipped faces than before, so the count of flips never
//! grows. (Tutte's embedding of the patch with its boundary held, tried first, folded
//! 1-3 faces of its own: the projected boundary of a patch across a fold is not
//! convex.)

use beltrami_fem::Elements;
use beltrami_mesh::{FaceId, Point3, Vector2, Vector3};

use crate::measure::{ImageFace, image_face};
use crate::target::{Role, TargetGeometry, orthonormal_basis};
use crate::untangle::Stars;

/// Sweeps over the moving vertices of [`untangle_in_plane`] and of
/// [`polish_on_surface`].
const SWEEPS: usize = 60;

/// Backtracking halvings of one vertex's step in [`untangle_in_plane`].
const HALVINGS: usize = 30;

/// Moves the vertices `moving` (slots of `plane`) one at a time down the gradient of
/// the untangling energy of Escobar et al. (2003), summed over each one's star
/// (`stars[i]`: triples of slots, the vertex first):
///
/// ```text
/// F = sum_f l_f^2 / h(A_f),    h(A) = (A + sqrt(A^2 + 4 d^2)) / 2,
/// ```
///
/// `A_f` the face's signed area in the plane, `l_f^2` the sum of its squared edge
/// lengths and `d` a small share of the mean area: `h` is positive for every area, so
/// `F` is finite while faces are inverted and grows without bound as `d -> 0` on them,
/// and its minimizers have every face positive and well shaped.
fn untangle_in_plane(plane: &mut [Vector2<f64>], moving: &[usize], stars: &[Vec<[usize; 3]>]) {
    let Some(energy) = UntanglingEnergy::of(plane, stars.iter().flatten()) else {
        return;
    };
    for _ in 0..SWEEPS {
        for (i, &k) in moving.iter().enumerate() {
            energy.descend(plane, k, &stars[i]);
        }
    }
}

/// After the lift onto the target: [`SWEEPS`] more sweeps of the same descent, each
/// vertex of `moving` in the plane tangent to the target at its own image (its star's
/// images projected there), then projected back onto the target. Across a turn of the
/// target one plane for the whole patch misjudges the faces far from its centre (the
/// `slim64` patch: no flip in the plane, two after the lift).
fn polish_on_surface<G: TargetGeometry>(
    target: &G,
    moving: &[usize],
    (triangles, stars): (&[[usize; 3]], &Stars),
    mapped: &mut Mapped<'_>,
) {
    let (mut ids, mut points, mut star) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..SWEEPS {
        for &v in moving {
            let origin = mapped.image[v];
            let [u, w] = orthonormal_basis(&mapped.normals[v]);
            ids.clear();
            points.clear();
            star.clear();
            let local = |g: usize, ids: &mut Vec<usize>, points: &mut Vec<Vector2<f64>>| {
                ids.iter().position(|&k| k == g).unwrap_or_else(|| {
                    let d = mapped.image[g] - origin;
                    ids.push(g);
                    points.push(Vector2::new(d.dot(&u), d.dot(&w)));
                    ids.len() - 1
                })
            };
            local(v, &mut ids, &mut points);
            for &f in stars.of(v) {
                let t = triangles[f];
                let at = t.iter().position(|&k| k == v).unwrap_or(0);
                star.push(
                    [t[at], t[(at + 1) % 3], t[(at + 2) % 3]]
                        .map(|g| local(g, &mut ids, &mut points)),
                );
            }
            let Some(energy) = UntanglingEnergy::of(&points, star.iter()) else {
                continue;
            };
            if energy.descend(&mut points, 0, &star) {
                let moved =
                    target.project(Role::Free, &(origin + u * points[0].x + w * points[0].y));
                mapped.image[v] = moved;
                mapped.normals[v] = target.normal(&moved);
            }
        }
    }
}

/// The untangling energy of [`untangle_in_plane`] with its regularization `d`.
#[derive(Debug, Clone, Copy)]
struct UntanglingEnergy {
    d: f64,
}

/// The signed area of triangle `t` (slots of `p`).
fn signed_area(p: &[Vector2<f64>], t: [usize; 3]) -> f64 {
    let (ab, ac) = (p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]);
    0.5 * (ab.x * ac.y - ab.y * ac.x)
}

impl UntanglingEnergy {
    /// With `d` 1% of the mean absolute area of `triangles` (`None` when that is 0).
    fn of<'t>(p: &[Vector2<f64>], triangles: impl Iterator<Item = &'t [usize; 3]>) -> Option<Self> {
        let (mut sum, mut count) = (0.0, 0usize);
        for &t in triangles {
            sum += signed_area(p, t).abs();
            count += 1;
        }
        let mean = sum / count.max(1) as f64;
        (mean > 0.0 && mean.is_finite()).then_some(Self { d: 1e-2 * mean })
    }

    fn h(&self, a: f64) -> f64 {
        0.5 * (a + (a * a + 4.0 * self.d * self.d).sqrt())
    }

    /// The energy of the triangles `star`.
    fn of_star(&self, p: &[Vector2<f64>], star: &[[usize; 3]]) -> f64 {
        star.iter()
            .map(|&t| {
                let l2 = (p[t[1]] - p[t[0]]).norm_squared()
                    + (p[t[2]] - p[t[0]]).norm_squared()
                    + (p[t[2]] - p[t[1]]).norm_squared();
                l2 / self.h(signed_area(p, t))
            })
            .sum()
    }

    /// One gradient step of slot `k` on the energy of its `star` (triples with `k`
    /// first), the step halved until the energy falls; `false` when none does.
    fn descend(&self, p: &mut [Vector2<f64>], k: usize, star: &[[usize; 3]]) -> bool {
        let mut gradient = Vector2::zeros();
        for &t in star {
            let (x, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
            let a = signed_area(p, t);
            let l2 = (b - x).norm_squared() + (c - x).norm_squared() + (c - b).norm_squared();
            let dl2 = (x - b) * 2.0 + (x - c) * 2.0;
            let da = Vector2::new(b.y - c.y, c.x - b.x) * 0.5;
            let ha = self.h(a);
            let dh = 0.5 * (1.0 + a / (a * a + 4.0 * self.d * self.d).sqrt());
            gradient += (dl2 * ha - da * (l2 * dh)) / (ha * ha);
        }
        let norm = gradient.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            return false;
        }
        let reach = star
            .iter()
            .map(|t| (p[t[1]] - p[t[0]]).norm())
            .fold(0.0, f64::max);
        let (start, before) = (p[k], self.of_star(p, star));
        let mut step = 0.5 * reach / norm;
        for _ in 0..HALVINGS {
            p[k] = start - gradient * step;
            if self.of_star(p, star) < before {
                return true;
            }
            step *= 0.5;
        }
        p[k] = start;
        false
    }
}

/// The map being untangled: images of the source vertices, the target's normals there
/// and the image faces.
pub(crate) struct Mapped<'a> {
    pub(crate) image: &'a mut [Point3<f64>],
    pub(crate) normals: &'a mut [Vector3<f64>],
    pub(crate) faces: &'a mut [ImageFace],
}

/// The faces within `rings` rings of face `face` (ring 0: the face itself).
fn patch_faces(triangles: &[[usize; 3]], stars: &Stars, face: usize, rings: usize) -> Vec<usize> {
    let mut faces = vec![face];
    let mut inside = vec![false; triangles.len()];
    inside[face] = true;
    for _ in 0..rings {
        let mut grown = faces.clone();
        for &f in &faces {
            for &v in &triangles[f] {
                for &g in stars.of(v) {
                    if !inside[g] {
                        inside[g] = true;
                        grown.push(g);
                    }
                }
            }
        }
        faces = grown;
    }
    faces
}

/// Untangles the patch of `rings` rings around flipped face `face` (module docs);
/// returns how many vertices moved: none unless the patch ended with fewer flipped
/// faces (and then nothing changed).
pub(crate) fn reembed_patch<G: TargetGeometry>(
    elements: &Elements,
    target: &G,
    roles: &[Role],
    (triangles, stars): (&[[usize; 3]], &Stars),
    mapped: &mut Mapped<'_>,
    face: usize,
    rings: usize,
) -> usize {
    let faces = patch_faces(triangles, stars, face, rings);
    let mut in_patch = vec![false; triangles.len()];
    for &f in &faces {
        in_patch[f] = true;
    }
    let mut vertices: Vec<usize> = faces.iter().flat_map(|&f| triangles[f]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    let moving: Vec<usize> = vertices
        .iter()
        .copied()
        .filter(|&v| roles[v] == Role::Free && stars.of(v).iter().all(|&f| in_patch[f]))
        .collect();
    if moving.is_empty() {
        return 0;
    }
    let normal: Vector3<f64> = vertices.iter().map(|&v| mapped.normals[v]).sum();
    if normal.norm() == 0.0 || !normal.norm().is_finite() {
        return 0;
    }
    let normal = normal.normalize();
    let centre = Point3::from(
        vertices
            .iter()
            .map(|&v| mapped.image[v].coords)
            .sum::<Vector3<f64>>()
            / vertices.len() as f64,
    );
    let [u, w] = orthonormal_basis(&normal);
    // Planar positions of every vertex met, indexed through `slot`.
    let mut slot = std::collections::HashMap::with_capacity(vertices.len());
    let mut plane: Vec<Vector2<f64>> = Vec::with_capacity(vertices.len());
    for (k, &v) in vertices.iter().enumerate() {
        slot.insert(v, k);
        let d = mapped.image[v] - centre;
        plane.push(Vector2::new(d.dot(&u), d.dot(&w)));
    }
    // Each moving vertex's star as triples of slots, the vertex first (its orientation
    // is the source's).
    let stars_of: Vec<Vec<[usize; 3]>> = moving
        .iter()
        .map(|&v| {
            stars
                .of(v)
                .iter()
                .map(|&f| {
                    let t = triangles[f];
                    let at = t.iter().position(|&k| k == v).unwrap_or(0);
                    [t[at], t[(at + 1) % 3], t[(at + 2) % 3]].map(|k| slot[&k])
                })
                .collect()
        })
        .collect();
    let moving_slots: Vec<usize> = moving.iter().map(|v| slot[v]).collect();
    untangle_in_plane(&mut plane, &moving_slots, &stars_of);
    let flipped =
        |mapped: &Mapped<'_>| faces.iter().filter(|&&f| mapped.faces[f].flipped()).count();
    let before = flipped(mapped);
    let old: Vec<(Point3<f64>, Vector3<f64>)> = moving
        .iter()
        .map(|&v| (mapped.image[v], mapped.normals[v]))
        .collect();
    let old_faces: Vec<ImageFace> = faces.iter().map(|&f| mapped.faces[f]).collect();
    for &v in &moving {
        let p = plane[slot[&v]];
        let height = (mapped.image[v] - centre).dot(&normal);
        let moved = target.project(Role::Free, &(centre + u * p.x + w * p.y + normal * height));
        mapped.image[v] = moved;
        mapped.normals[v] = target.normal(&moved);
    }
    polish_on_surface(target, &moving, (triangles, stars), mapped);
    for &f in &faces {
        mapped.faces[f] = image_face(elements, mapped.normals, mapped.image, FaceId(f as u32));
    }
    if flipped(mapped) < before {
        return moving.len();
    }
    for (&v, (p, n)) in moving.iter().zip(old) {
        mapped.image[v] = p;
        mapped.normals[v] = n;
    }
    for (&f, face) in faces.iter().zip(old_faces) {
        mapped.faces[f] = face;
    }
    0
}

#[cfg(test)]
mod tests {
    use beltrami_fem::Frame;
    use beltrami_mesh::Mesh;
    use beltrami_mesh::primitives::{Cells, grid};

    use super::*;
    use crate::measure::image_faces;
    use crate::target::PlaneRegion;

    /// On a regular grid every interior star is centrally symmetric, so the grid is a
    /// stationary point of the untangling energy: a fold made by pushing two
    /// neighbouring vertices across each other is undone, the vertices back where they
    /// were (to 1e-9 of the 0.25 edge after the sweeps' gradient steps).
    #[test]
    fn a_folded_patch_of_a_regular_grid_is_laid_back_as_it_was() {
        let mesh = Mesh::from_soup(&grid(8, 8, Cells::Triangles)).unwrap();
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let flat = mesh.positions().to_vec();
        let roles: Vec<Role> = mesh
            .vertices()
            .map(|v| {
                if mesh.is_boundary_vertex(v) {
                    Role::Fixed
                } else {
                    Role::Free
                }
            })
            .collect();
        let triangles = crate::system::triangles(&elements);
        let stars = Stars::new(&triangles, flat.len());
        // The interior vertex nearest the grid's centroid and its neighbour of largest x
        // swap places (and a little more): their faces fold.
        let middle = flat.iter().map(|p| p.coords).sum::<Vector3<f64>>() / flat.len() as f64;
        let centre = (0..flat.len())
            .min_by(|&a, &b| {
                (flat[a].coords - middle)
                    .norm()
                    .total_cmp(&(flat[b].coords - middle).norm())
            })
            .unwrap();
        let right = stars
            .of(centre)
            .iter()
            .flat_map(|&f| triangles[f])
            .filter(|&v| v != centre && roles[v] == Role::Free)
            .max_by(|&a, &b| flat[a].x.total_cmp(&flat[b].x))
            .unwrap();
        let mut image = flat.clone();
        let step = flat[right] - flat[centre];
        image[centre] = flat[right] + step * 0.3;
        image[right] = flat[centre] - step * 0.3;
        let mut normals = vec![Vector3::z(); image.len()];
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let folded = faces.iter().filter(|f| f.flipped()).count();
        assert!(folded > 0);
        let first = (0..faces.len()).find(|&f| faces[f].flipped()).unwrap();
        let target = PlaneRegion { sides: Vec::new() };
        let mut mapped = Mapped {
            image: &mut image,
            normals: &mut normals,
            faces: &mut faces,
        };
        let laid = (1..=3).any(|rings| {
            0 < reembed_patch(
                &elements,
                &target,
                &roles,
                (&triangles, &stars),
                &mut mapped,
                first,
                rings,
            )
        });
        assert!(laid);
        assert_eq!(faces.iter().filter(|f| f.flipped()).count(), 0);
        let off = image
            .iter()
            .zip(&flat)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max);
        assert!(off < 1e-7, "{off}");
    }

    /// Nothing moves, and the answer is no, when the patch would not have fewer flips:
    /// a patch whose every vertex is held.
    #[test]
    fn a_patch_without_free_vertices_is_left_alone() {
        let mesh = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let mut image = mesh.positions().to_vec();
        image.swap(0, 1);
        let before = image.clone();
        let roles = vec![Role::Fixed; image.len()];
        let triangles = crate::system::triangles(&elements);
        let stars = Stars::new(&triangles, image.len());
        let mut normals = vec![Vector3::z(); image.len()];
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let target = PlaneRegion { sides: Vec::new() };
        let mut mapped = Mapped {
            image: &mut image,
            normals: &mut normals,
            faces: &mut faces,
        };
        let moved = reembed_patch(
            &elements,
            &target,
            &roles,
            (&triangles, &stars),
            &mut mapped,
            0,
            2,
        );
        assert_eq!(moved, 0);
        assert_eq!(image, before);
    }
}
