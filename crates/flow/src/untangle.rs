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

/// How [`untangle`] runs.
#[derive(Debug, Clone, Copy, Default)]
pub struct UntangleRounds<'a> {
    /// The most rounds.
    pub rounds: usize,
    /// The images before a trial step of the flow, when untangling that step: a vertex
    /// first tries its image there (the least move that can unfold a face the step
    /// folded).
    pub previous: Option<&'a [Point3<f64>]>,
}

/// Moves free vertices of flipped faces into the kernels of their stars (module docs),
/// for at most `how.rounds` rounds; `faces` and `normals` are updated with `image`.
/// With `how.previous` (the images before a trial step of the flow), a vertex first
/// tries its previous image: the least move that can unfold a face the step folded.
pub fn untangle<G: TargetGeometry>(
    elements: &Elements,
    target: &G,
    roles: &[Role],
    image: &mut [Point3<f64>],
    normals: &mut [Vector3<f64>],
    faces: &mut [ImageFace],
    how: UntangleRounds<'_>,
) -> Untangled {
    let (triangles, stars) = triangles_and_stars(elements, image.len());
    let star_moves = StarMoves {
        elements,
        target,
        triangles: &triangles,
        stars: &stars,
    };
    let count = |faces: &[ImageFace]| faces.iter().filter(|f| f.flipped()).count();
    let mut done = Untangled {
        before: count(faces),
        ..Untangled::default()
    };
    let mut kernel = KernelBuffers::default();
    let mut visit = vec![false; image.len()];
    let mut map = Mapped {
        image,
        normals,
        faces,
    };
    for round in 0..how.rounds {
        let queue = star_moves.queue(roles, map.faces, round, &mut visit);
        if queue.is_empty() {
            break;
        }
        for &v in &queue {
            visit[v] = false;
            let flips = star_moves.flips(v, map.faces);
            if flips == 0 && round == 0 {
                continue;
            }
            let Some(candidates) = star_moves.candidates(v, &map, how.previous, &mut kernel) else {
                continue;
            };
            if star_moves.try_candidates(v, candidates, flips, round, &mut map) {
                done.moves += 1;
            }
        }
        if count(map.faces) == 0 {
            break;
        }
    }
    done.after = count(map.faces);
    done
}

/// The polygons the kernel of a star is clipped in, kept between vertices.
#[derive(Default)]
struct KernelBuffers {
    polygon: Vec<Vector2<f64>>,
    clipped: Vec<Vector2<f64>>,
}

/// What moving a vertex within its star reads: the elements, the target, the faces'
/// triangles and the faces around each vertex.
struct StarMoves<'a, G> {
    elements: &'a Elements,
    target: &'a G,
    triangles: &'a [[usize; 3]],
    stars: &'a Stars,
}

impl<G: TargetGeometry> StarMoves<'_, G> {
    /// The flipped faces around vertex `v`.
    fn flips(&self, v: usize, faces: &[ImageFace]) -> usize {
        self.stars
            .of(v)
            .iter()
            .filter(|&&f| faces[f].flipped())
            .count()
    }

    /// The free vertices a round visits, in face order: those of every flipped face, and
    /// from the second round on also those of the faces around them. `visit` marks the
    /// vertices queued (all false on entry; the caller clears each as it visits it).
    fn queue(
        &self,
        roles: &[Role],
        faces: &[ImageFace],
        round: usize,
        visit: &mut [bool],
    ) -> Vec<usize> {
        let mut queue = Vec::new();
        for (f, t) in self.triangles.iter().enumerate() {
            if !faces[f].flipped() {
                continue;
            }
            for &v in t {
                let ring: &[usize] = if round == 0 { &[] } else { self.stars.of(v) };
                let near = ring.iter().flat_map(|&g| self.triangles[g]);
                for u in std::iter::once(v).chain(near) {
                    if roles[u] == Role::Free && !visit[u] {
                        visit[u] = true;
                        queue.push(u);
                    }
                }
            }
        }
        queue
    }

    /// Where vertex `v` may move, in the order tried: its previous image (when given),
    /// the centroid of its star's kernel in the tangent plane at its image (module
    /// docs), then the mean of its link's images (across a fold of the target the
    /// tangent plane at one corner says little about the others); a candidate that does
    /// not exist is `None`. `None` altogether when the star has no extent in the plane.
    fn candidates(
        &self,
        v: usize,
        map: &Mapped<'_>,
        previous: Option<&[Point3<f64>]>,
        kernel: &mut KernelBuffers,
    ) -> Option<[Option<Point3<f64>>; 3]> {
        let (image, star) = (&*map.image, self.stars.of(v));
        let origin = image[v];
        let [u, w] = orthonormal_basis(&map.normals[v]);
        let plane = |p: &Point3<f64>| {
            let d = p - origin;
            Vector2::new(d.dot(&u), d.dot(&w))
        };
        let mut reach: f64 = 0.0;
        for &f in star {
            for &k in &self.triangles[f] {
                reach = reach.max(plane(&image[k]).norm());
            }
        }
        if reach == 0.0 {
            return None;
        }
        let KernelBuffers { polygon, clipped } = kernel;
        polygon.clear();
        polygon.extend(
            [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, y)| Vector2::new(x, y) * (2.0 * reach)),
        );
        for &f in star {
            let t = self.triangles[f];
            let at = t.iter().position(|&k| k == v).unwrap_or(0);
            let (a, b) = (t[(at + 1) % 3], t[(at + 2) % 3]);
            clip(polygon, plane(&image[a]), plane(&image[b]), clipped);
            std::mem::swap(polygon, clipped);
            if polygon.is_empty() {
                break;
            }
        }
        let kernel = centroid(polygon).map(|p| origin + u * p.x + w * p.y);
        let mut link = Vector3::zeros();
        let mut links = 0usize;
        for &f in star {
            for &k in &self.triangles[f] {
                if k != v {
                    link += image[k].coords;
                    links += 1;
                }
            }
        }
        let mean = (links > 0).then(|| Point3::from(link / links as f64));
        let back = previous.and_then(|p| p.get(v).copied());
        Some([back, kernel, mean])
    }

    /// Tries the candidates of vertex `v` in order, each projected onto the target, and
    /// keeps the first that leaves its star fewer flips than `flips` (from the second
    /// round, as many; with none before, none after); undoes the others. True if a move
    /// was kept.
    fn try_candidates(
        &self,
        v: usize,
        candidates: [Option<Point3<f64>>; 3],
        flips: usize,
        round: usize,
        map: &mut Mapped<'_>,
    ) -> bool {
        let star = self.stars.of(v);
        let origin = map.image[v];
        for candidate in candidates.into_iter().flatten() {
            let moved = self.target.project(Role::Free, &candidate);
            let (old_normal, old_faces): (Vector3<f64>, Vec<ImageFace>) =
                (map.normals[v], star.iter().map(|&f| map.faces[f]).collect());
            map.image[v] = moved;
            map.normals[v] = self.target.normal(&moved);
            for &f in star {
                map.faces[f] = image_face(self.elements, map.normals, map.image, FaceId(f as u32));
            }
            let after = star.iter().filter(|&&f| map.faces[f].flipped()).count();
            // From the second round a move that keeps the star's count is kept as
            // well: across a fold narrower than the star, a flip only passes between
            // two faces of one vertex, and the neighbour visited next can remove it
            // from the other face (hemisphere onto the human face: 1 flip -> 0).
            let sideways = round > 0 && after == flips;
            if after < flips || sideways || (flips == 0 && after == 0) {
                return true;
            }
            map.image[v] = origin;
            map.normals[v] = old_normal;
            for (&f, face) in star.iter().zip(old_faces) {
                map.faces[f] = face;
            }
        }
        false
    }
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
