//! Removing the flipped faces the flow leaves: each free vertex of a flipped face moves
//! into the kernel of its star.
//!
//! The flow accepts no step that adds a flip, and it cannot always remove one: a face
//! inverted across a sharp fold of the target (a coarse source face spanning a nostril
//! of a fine target) has `|mu| > 1`, and the linearized composition of
//! [`crate::flow`] points the wrong way there. Flips are a combinatorial property of a
//! vertex's star, and so is their cure. In the plane tangent to the target at the image
//! `y_v` of a free vertex `v` (normal `n`, basis `(u, w)` with `u x w = n`), the faces
//! `(v, a, b)` of its star (in the source's orientation) are positively oriented exactly
//! when `y_v` lies left of every link edge `a -> b`:
//!
//! ```text
//! (b - a) x (p - a) . n > 0    for every face (v, a, b) around v.
//! ```
//!
//! These half-planes meet in the kernel of the star polygon. When it is not empty, the
//! vertex moves to the kernel's centroid (an interior point, away from every link edge)
//! projected back onto the target, and the move is kept if its star has fewer flipped
//! faces than before; otherwise (or when the kernel is empty) the mean of its link's
//! images, projected, is tried the same way: across a fold of the target, the tangent
//! plane at one image says little about where the others are. A round visits the free
//! vertices of every flipped face; a later round also their free neighbours, whose
//! moves can open an empty kernel, and keeps moves that leave the star's count of flips
//! unchanged too (a flip that passes to another face of the star can be removed there
//! by the next vertex; the count of flips never grows, and the rounds are bounded). Boundary,
//! curve and fixed vertices never move. The flow runs again afterwards to restore
//! conformality, from a map with fewer flips, and keeps them at most as many. Faces the
//! flow still leaves flipped get their surrounding patches untangled at once
//! ([`untangle_patches`], `patch_embedding.rs`).

use beltrami_fem::Elements;
use beltrami_mesh::{FaceId, Point3, Vector2, Vector3};

use crate::measure::{ImageFace, image_face};
use crate::patch_embedding::{Mapped, reembed_patch};
use crate::target::{Role, TargetGeometry, orthonormal_basis};

/// What [`untangle`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Untangled {
    /// Flipped faces before.
    pub before: usize,
    /// Flipped faces after.
    pub after: usize,
    /// Vertex moves kept.
    pub moves: usize,
}

/// The faces around each vertex (compressed rows).
pub(crate) struct Stars {
    start: Vec<usize>,
    faces: Vec<usize>,
}

impl Stars {
    pub(crate) fn new(triangles: &[[usize; 3]], vertices: usize) -> Self {
        let mut start = vec![0; vertices + 1];
        for t in triangles {
            for &v in t {
                start[v + 1] += 1;
            }
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        let mut next = start.clone();
        let mut faces = vec![0; start[vertices]];
        for (f, t) in triangles.iter().enumerate() {
            for &v in t {
                faces[next[v]] = f;
                next[v] += 1;
            }
        }
        Self { start, faces }
    }

    pub(crate) fn of(&self, v: usize) -> &[usize] {
        &self.faces[self.start[v]..self.start[v + 1]]
    }
}

/// The elements' triangles (vertex indices) and the faces around each of `vertices`.
fn triangles_and_stars(elements: &Elements, vertices: usize) -> (Vec<[usize; 3]>, Stars) {
    let triangles = crate::system::triangles(elements);
    let stars = Stars::new(&triangles, vertices);
    (triangles, stars)
}

/// The part of convex polygon `polygon` left of the directed line `a -> b` (closed
/// half-plane), Sutherland-Hodgman, into `out`.
fn clip(polygon: &[Vector2<f64>], a: Vector2<f64>, b: Vector2<f64>, out: &mut Vec<Vector2<f64>>) {
    out.clear();
    let d = b - a;
    let side = |p: &Vector2<f64>| d.x * (p.y - a.y) - d.y * (p.x - a.x);
    for (i, p) in polygon.iter().enumerate() {
        let q = &polygon[(i + 1) % polygon.len()];
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(*p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let t = sp / (sp - sq);
            out.push(p + (q - p) * t);
        }
    }
}

/// The area centroid of a convex polygon, `None` when its area is not positive.
fn centroid(polygon: &[Vector2<f64>]) -> Option<Vector2<f64>> {
    let (mut area, mut sum) = (0.0, Vector2::zeros());
    for (i, p) in polygon.iter().enumerate() {
        let q = &polygon[(i + 1) % polygon.len()];
        let cross = p.x * q.y - p.y * q.x;
        area += cross;
        sum += (p + q) * cross;
    }
    (area > 0.0).then(|| sum / (3.0 * area))
}

/// Moves free vertices of flipped faces into the kernels of their stars (module docs),
/// for at most `rounds` rounds; `faces` and `normals` are updated with `image`. With
/// `previous` (the images before a trial step of the flow), a vertex first tries its
/// previous image: the least move that can unfold a face the step folded.
#[allow(clippy::too_many_arguments)]
pub fn untangle<G: TargetGeometry>(
    elements: &Elements,
    target: &G,
    roles: &[Role],
    image: &mut [Point3<f64>],
    normals: &mut [Vector3<f64>],
    faces: &mut [ImageFace],
    rounds: usize,
    previous: Option<&[Point3<f64>]>,
) -> Untangled {
    let (triangles, stars) = triangles_and_stars(elements, image.len());
    let count = |faces: &[ImageFace]| faces.iter().filter(|f| f.flipped()).count();
    let mut done = Untangled {
        before: count(faces),
        ..Untangled::default()
    };
    let (mut polygon, mut clipped) = (Vec::new(), Vec::new());
    let mut visit = vec![false; image.len()];
    for round in 0..rounds {
        let mut queue = Vec::new();
        for (f, t) in triangles.iter().enumerate() {
            if !faces[f].flipped() {
                continue;
            }
            for &v in t {
                let ring: &[usize] = if round == 0 { &[] } else { stars.of(v) };
                let near = ring.iter().flat_map(|&g| triangles[g]);
                for u in std::iter::once(v).chain(near) {
                    if roles[u] == Role::Free && !visit[u] {
                        visit[u] = true;
                        queue.push(u);
                    }
                }
            }
        }
        if queue.is_empty() {
            break;
        }
        for &v in &queue {
            visit[v] = false;
            let star = stars.of(v);
            let flips = star.iter().filter(|&&f| faces[f].flipped()).count();
            if flips == 0 && round == 0 {
                continue;
            }
            let origin = image[v];
            let [u, w] = orthonormal_basis(&normals[v]);
            let plane = |p: &Point3<f64>| {
                let d = p - origin;
                Vector2::new(d.dot(&u), d.dot(&w))
            };
            let mut reach: f64 = 0.0;
            for &f in star {
                for &k in &triangles[f] {
                    reach = reach.max(plane(&image[k]).norm());
                }
            }
            if reach == 0.0 {
                continue;
            }
            polygon.clear();
            polygon.extend(
                [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .map(|(x, y)| Vector2::new(x, y) * (2.0 * reach)),
            );
            for &f in star {
                let t = triangles[f];
                let at = t.iter().position(|&k| k == v).unwrap_or(0);
                let (a, b) = (t[(at + 1) % 3], t[(at + 2) % 3]);
                clip(&polygon, plane(&image[a]), plane(&image[b]), &mut clipped);
                std::mem::swap(&mut polygon, &mut clipped);
                if polygon.is_empty() {
                    break;
                }
            }
            // Candidates: the previous image (when given), the kernel's centroid in the
            // tangent plane at the image, then the mean of the link's images (across a
            // fold of the target the tangent plane at one corner says little about the
            // others).
            let kernel = centroid(&polygon).map(|p| origin + u * p.x + w * p.y);
            let mut link = Vector3::zeros();
            let mut links = 0usize;
            for &f in star {
                for &k in &triangles[f] {
                    if k != v {
                        link += image[k].coords;
                        links += 1;
                    }
                }
            }
            let mean = (links > 0).then(|| Point3::from(link / links as f64));
            let back = previous.and_then(|p| p.get(v).copied());
            for candidate in [back, kernel, mean].into_iter().flatten() {
                let moved = target.project(Role::Free, &candidate);
                let (old_normal, old_faces): (Vector3<f64>, Vec<ImageFace>) =
                    (normals[v], star.iter().map(|&f| faces[f]).collect());
                image[v] = moved;
                normals[v] = target.normal(&moved);
                for &f in star {
                    faces[f] = image_face(elements, normals, image, FaceId(f as u32));
                }
                let after = star.iter().filter(|&&f| faces[f].flipped()).count();
                // From the second round a move that keeps the star's count is kept as
                // well: across a fold narrower than the star, a flip only passes between
                // two faces of one vertex, and the neighbour visited next can remove it
                // from the other face (hemisphere onto the human face: 1 flip -> 0).
                let sideways = round > 0 && after == flips;
                if after < flips || sideways || (flips == 0 && after == 0) {
                    done.moves += 1;
                    break;
                }
                image[v] = origin;
                normals[v] = old_normal;
                for (&f, face) in star.iter().zip(old_faces) {
                    faces[f] = face;
                }
            }
        }
        if count(faces) == 0 {
            break;
        }
    }
    done.after = count(faces);
    done
}

/// The last resort after [`untangle`] and the flow: the patch around each flipped face
/// untangled at once (`patch_embedding.rs`), from one to `PATCH_RINGS` (3) rings;
/// `faces` and `normals` are updated with `image`. The patches are not conformal: the
/// flow has to run again from the result. Kept for the faces the flow and the
/// vertex-by-vertex untangling leave: used on every flip, it left the genus-3 maps of
/// docs/register.md 5-40% higher in mean `|mu|` where they had none anyway.
pub fn untangle_patches<G: TargetGeometry>(
    elements: &Elements,
    target: &G,
    roles: &[Role],
    image: &mut [Point3<f64>],
    normals: &mut [Vector3<f64>],
    faces: &mut [ImageFace],
) -> Untangled {
    let (triangles, stars) = triangles_and_stars(elements, image.len());
    let count = |faces: &[ImageFace]| faces.iter().filter(|f| f.flipped()).count();
    let mut done = Untangled {
        before: count(faces),
        ..Untangled::default()
    };
    let mut mapped = Mapped {
        image,
        normals,
        faces,
    };
    for f in 0..triangles.len() {
        if !mapped.faces[f].flipped() {
            continue;
        }
        let laid = (&triangles[..], &stars);
        done.moves += (1..=PATCH_RINGS)
            .map(|rings| reembed_patch(elements, target, roles, laid, &mut mapped, f, rings))
            .find(|&moved| moved > 0)
            .unwrap_or(0);
    }
    done.after = count(mapped.faces);
    done
}

/// Rings of faces around a face still flipped that [`reembed_patch`] tries, from one.
const PATCH_RINGS: usize = 3;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_of_a_square_star_is_the_square() {
        let square =
            [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| Vector2::new(x, y));
        let mut polygon: Vec<Vector2<f64>> = [(-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)]
            .map(|(x, y)| Vector2::new(x, y))
            .to_vec();
        let mut out = Vec::new();
        for i in 0..4 {
            clip(&polygon, square[i], square[(i + 1) % 4], &mut out);
            std::mem::swap(&mut polygon, &mut out);
        }
        let c = centroid(&polygon).expect("a square kernel");
        assert!(c.norm() < 1e-12, "{c}");
        let area: f64 = (0..polygon.len())
            .map(|i| {
                let (p, q) = (polygon[i], polygon[(i + 1) % polygon.len()]);
                p.x * q.y - p.y * q.x
            })
            .sum::<f64>()
            / 2.0;
        assert!((area - 4.0).abs() < 1e-12, "{area}");
    }

    #[test]
    fn an_empty_kernel_has_no_centroid() {
        let mut polygon: Vec<Vector2<f64>> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, y)| Vector2::new(x, y))
            .to_vec();
        let mut out = Vec::new();
        // Left of y = 2 going +x, and left of y = -2 going -x: nothing of the square.
        clip(
            &polygon,
            Vector2::new(0.0, 2.0),
            Vector2::new(1.0, 2.0),
            &mut out,
        );
        std::mem::swap(&mut polygon, &mut out);
        assert!(centroid(&polygon).is_none());
    }
}
