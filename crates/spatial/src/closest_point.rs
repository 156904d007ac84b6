//! Exact closest points on segments, triangles and bilinear quads.
//!
//! # Triangles
//!
//! The orthogonal projection of `p` onto the plane of `(a, b, c)` has the barycentric
//! coordinates `l_b = n . ((p - a) x (c - a)) / |n|^2`, `l_c = n . ((b - a) x (p - a)) /
//! |n|^2`, `l_a = 1 - l_b - l_c`, with `n = (b - a) x (c - a)`: ratios of signed areas,
//! which stay accurate for any triangle that is not a sliver. If all three are
//! non-negative the projection is the closest point. Otherwise the closest point lies on
//! the boundary, and convexity says where: with one negative coordinate it is on the
//! opposite edge (the segment from `p`'s projection to any other point of the triangle
//! crosses that edge), with two it is on one of the two edges meeting at the vertex with
//! the positive coordinate. Each edge is an exact clamped segment projection.
//!
//! A *sliver* (smallest height below `1e-4` of the longest edge, `|n|^2 <= 1e-8 l^4`) or a
//! degenerate triangle (zero area) has an ill-conditioned projection, so there the
//! answer is the best of the three edges and, when it is inside, the projection: every
//! candidate is an actual point of the triangle and the one nearest to `p` wins.
//!
//! # Quads
//!
//! A quad `(p0, p1, p2, p3)` is the bilinear patch
//! `X(u, v) = (1-u)(1-v) p0 + u(1-v) p1 + u v p2 + (1-u) v p3` on `[0, 1]^2` (the
//! convention of [`beltrami_mesh::surface_point`]), handled bilinearly rather than split
//! into two triangles, so that the returned weights reproduce the returned point and
//! [`SurfacePoint::position`](beltrami_mesh::SurfacePoint::position) agrees. The patch
//! boundary is the four straight edges, solved exactly as segments. For the interior,
//! the closest point of the two triangles `(p0, p1, p2)` and `(p0, p2, p3)` gives a start
//! `(u, v)` (exact for a parallelogram, where the patch is affine), and Newton's method
//! on `f(u, v) = |X(u, v) - p|^2 / 2` (falling back to Gauss-Newton when the Hessian is
//! not positive definite, each step kept in the square and accepted only if it decreases
//! `f`) refines it. The answer is the best of the refined point and the four edges.
//! This is exact for planar quads (where the patch is the polygon, so the triangles
//! already contain the closest point and Newton only inverts the bilinear map) and finds
//! the closest interior point of a warped quad whenever `f` has a single minimum near
//! the start, which holds for points closer to the patch than its curvature radius.

use beltrami_mesh::surface_point::bilinear_weights;
use beltrami_mesh::{FaceId, Mesh};
use nalgebra::{Point3, Vector3};

/// A sliver has `|n|^2 <= SLIVER * l^4` (`n` twice the vector area, `l` the longest
/// edge): its smallest height is below `1e-4 l`.
const SLIVER: f64 = 1e-8;

/// Newton iterations on a quad's patch, at most.
const QUAD_NEWTON_STEPS: usize = 16;

/// The closest point of a face (or segment) to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    /// Coordinates of the point in the face's convention: barycentric `(l0, l1, l2, 0)`
    /// for a triangle, bilinear weights `((1-u)(1-v), u(1-v), u v, (1-u) v)` for a quad,
    /// `(1 - t, t, 0, 0)` for a segment.
    pub coords: [f64; 4],
    /// The point: `sum_i coords[i] p_i`, summed in vertex order (bit for bit what
    /// [`SurfacePoint::position`](beltrami_mesh::SurfacePoint::position) returns).
    pub position: Point3<f64>,
    /// Squared distance from the query point to `position`.
    pub distance_squared: f64,
}

impl ClosestPoint {
    fn new(p: &Point3<f64>, corners: &[Point3<f64>], coords: [f64; 4]) -> Self {
        let position = weighted_sum(corners, &coords);
        Self {
            coords,
            position,
            distance_squared: (p - position).norm_squared(),
        }
    }

    /// Distance from the query point to `position`.
    pub fn distance(&self) -> f64 {
        self.distance_squared.sqrt()
    }
}

/// `sum_i coords[i] corners[i]`, accumulated in the same order as
/// [`SurfacePoint::position`](beltrami_mesh::SurfacePoint::position).
pub(crate) fn weighted_sum(corners: &[Point3<f64>], coords: &[f64; 4]) -> Point3<f64> {
    let mut sum = Vector3::zeros();
    for (c, p) in coords.iter().zip(corners) {
        sum += *c * p.coords;
    }
    Point3::from(sum)
}

/// The closest point to `p` of the segment `a b`: parameter `t` in `[0, 1]` of the
/// clamped projection (`t = 0` for a zero-length segment), as coordinates
/// `(1 - t, t, 0, 0)`.
pub fn closest_on_segment(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> ClosestPoint {
    let t = segment_parameter(p, a, b);
    ClosestPoint::new(p, &[*a, *b], [1.0 - t, t, 0.0, 0.0])
}

/// Parameter in `[0, 1]` of the point of segment `a b` closest to `p`.
fn segment_parameter(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The closest point to `p` of triangle `t = (a, b, c)`, with barycentric coordinates
/// `(l_a, l_b, l_c, 0)`. Exact Voronoi-region classification; see the module docs for the
/// formulas and the treatment of slivers and degenerate triangles.
pub fn closest_on_triangle(p: &Point3<f64>, t: &[Point3<f64>; 3]) -> ClosestPoint {
    let [a, b, c] = t;
    let (ab, ac) = (b - a, c - a);
    let n = ab.cross(&ac);
    let nn = n.norm_squared();
    let longest = ab
        .norm_squared()
        .max(ac.norm_squared())
        .max((c - b).norm_squared());
    let well_shaped = nn > SLIVER * longest * longest;

    // On an edge of the triangle: edge `k` is opposite corner `k`.
    let on_edge = |k: usize| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let s = segment_parameter(p, &t[i], &t[j]);
        let mut coords = [0.0; 4];
        coords[i] = 1.0 - s;
        coords[j] = s;
        ClosestPoint::new(p, t, coords)
    };
    let nearer = |x: ClosestPoint, y: ClosestPoint| {
        if y.distance_squared < x.distance_squared {
            y
        } else {
            x
        }
    };

    let mut interior = None;
    if nn > 0.0 {
        let ap = p - a;
        let lb = n.dot(&ap.cross(&ac)) / nn;
        let lc = n.dot(&ab.cross(&ap)) / nn;
        let la = 1.0 - lb - lc;
        let l = [la, lb, lc];
        if l.iter().all(|&x| x >= 0.0) {
            let candidate = ClosestPoint::new(p, t, [la, lb, lc, 0.0]);
            if well_shaped {
                return candidate;
            }
            interior = Some(candidate);
        } else if well_shaped {
            // One negative coordinate: the opposite edge. Two: the edges through the
            // remaining positive corner, which are those opposite the negative ones.
            let mut result: Option<ClosestPoint> = None;
            for k in (0..3).filter(|&k| l[k] < 0.0) {
                let candidate = on_edge(k);
                result = Some(match result {
                    Some(best) => nearer(best, candidate),
                    None => candidate,
                });
            }
            if let Some(result) = result {
                return result;
            }
        }
    }
    let edges = nearer(nearer(on_edge(0), on_edge(1)), on_edge(2));
    match interior {
        Some(candidate) => nearer(edges, candidate),
        None => edges,
    }
}

/// The point `X(u, v)` of the bilinear patch of `q`.
fn patch_point(q: &[Point3<f64>; 4], u: f64, v: f64) -> Point3<f64> {
    weighted_sum(q, &bilinear_weights(u, v))
}

/// The closest point to `p` of the bilinear patch of quad `q = (p0, p1, p2, p3)`, with
/// the bilinear weights of its parameter as coordinates. See the module docs for the
/// method and when it is exact.
pub fn closest_on_quad(p: &Point3<f64>, q: &[Point3<f64>; 4]) -> ClosestPoint {
    // Start: the closest point of the two triangles of the diagonal p0 p2, mapped to the
    // parameter square by the affine maps of the two halves.
    let lower = closest_on_triangle(p, &[q[0], q[1], q[2]]);
    let upper = closest_on_triangle(p, &[q[0], q[2], q[3]]);
    let (u, v) = if lower.distance_squared <= upper.distance_squared {
        (lower.coords[1] + lower.coords[2], lower.coords[2])
    } else {
        (upper.coords[1], upper.coords[1] + upper.coords[2])
    };
    let (u, v) = refine_on_quad(p, q, u, v);
    let mut best = ClosestPoint::new(p, q, bilinear_weights(u, v));
    for k in 0..4 {
        let s = segment_parameter(p, &q[k], &q[(k + 1) % 4]);
        let (u, v) = quad_edge_parameter(k, s);
        let candidate = ClosestPoint::new(p, q, bilinear_weights(u, v));
        if candidate.distance_squared < best.distance_squared {
            best = candidate;
        }
    }
    best
}

/// The parameter `(u, v)` of the point at fraction `s` along edge `k` of a quad (edge `k`
/// runs from corner `k` to corner `k + 1`).
pub(crate) fn quad_edge_parameter(k: usize, s: f64) -> (f64, f64) {
    match k {
        0 => (s, 0.0),
        1 => (1.0, s),
        2 => (1.0 - s, 1.0),
        _ => (0.0, 1.0 - s),
    }
}

/// Newton's method for `min |X(u, v) - p|^2` on the square, from `(u, v)`: a local
/// minimum (or a point of the square's boundary).
pub(crate) fn refine_on_quad(p: &Point3<f64>, q: &[Point3<f64>; 4], u: f64, v: f64) -> (f64, f64) {
    let (mut u, mut v) = (u, v);
    let xuv = (q[0] - q[1]) + (q[2] - q[3]);
    let mut r = patch_point(q, u, v) - p;
    let mut f = r.norm_squared();
    for _ in 0..QUAD_NEWTON_STEPS {
        let xu = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
        let xv = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
        let (gu, gv) = (r.dot(&xu), r.dot(&xv));
        let (huu, hvv, huv_gn) = (xu.norm_squared(), xv.norm_squared(), xu.dot(&xv));
        let huv = huv_gn + r.dot(&xuv);
        let mut accepted = false;
        // Newton first, then Gauss-Newton (its Hessian |X_u x X_v|^2 >= 0 drops the
        // curvature term).
        for off_diagonal in [huv, huv_gn] {
            let det = huu * hvv - off_diagonal * off_diagonal;
            if !(det > 0.0 && huu > 0.0) {
                continue;
            }
            let du = -(hvv * gu - off_diagonal * gv) / det;
            let dv = -(huu * gv - off_diagonal * gu) / det;
            let (nu, nv) = ((u + du).clamp(0.0, 1.0), (v + dv).clamp(0.0, 1.0));
            let nr = patch_point(q, nu, nv) - p;
            let nf = nr.norm_squared();
            if nf <= f {
                let step = (nu - u).abs().max((nv - v).abs());
                (u, v, r, f) = (nu, nv, nr, nf);
                accepted = step > 1e-15;
                break;
            }
        }
        if !accepted {
            break;
        }
    }
    (u, v)
}

/// The closest point to `p` of face `f` of `mesh` (triangle or bilinear quad), in the
/// face's coordinate convention. Panics if `f` is not a face of `mesh`.
pub fn closest_on_face(mesh: &Mesh, f: FaceId, p: &Point3<f64>) -> ClosestPoint {
    let (vertices, n) = mesh.face_vertex_array(f);
    let x = |k: usize| mesh.position(vertices[k]);
    if n == 3 {
        closest_on_triangle(p, &[x(0), x(1), x(2)])
    } else {
        closest_on_quad(p, &[x(0), x(1), x(2), x(3)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    /// Brute force over a fine barycentric grid (plus the exact vertices and edges).
    fn sampled_min(p: &Point3<f64>, t: &[Point3<f64>; 3], n: usize) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (b, c) = (i as f64 / n as f64, j as f64 / n as f64);
                let x = t[0] + b * (t[1] - t[0]) + c * (t[2] - t[0]);
                best = best.min((p - x).norm_squared());
            }
        }
        best
    }

    fn check(p: Point3<f64>, t: &[Point3<f64>; 3], coords: [f64; 3]) {
        let r = closest_on_triangle(&p, t);
        for (c, e) in r.coords.iter().zip(&coords) {
            assert!(
                (c - e).abs() < 1e-14,
                "p {p:?}: coords {:?}, expected {coords:?}",
                r.coords
            );
        }
        assert_eq!(r.coords[3], 0.0);
        let x = weighted_sum(t, &r.coords);
        assert_eq!(x, r.position);
        assert!(((p - x).norm_squared() - r.distance_squared).abs() < 1e-15);
        assert!(r.distance_squared <= sampled_min(&p, t, 64) + 1e-14);
    }

    #[test]
    fn every_voronoi_region_of_a_triangle() {
        let t = [pt(0.0, 0.0, 0.0), pt(2.0, 0.0, 0.0), pt(0.0, 1.0, 0.0)];
        // Interior: the projection, at any height.
        check(pt(0.5, 0.25, 3.0), &t, [0.5, 0.25, 0.25]);
        check(pt(0.5, 0.25, -0.1), &t, [0.5, 0.25, 0.25]);
        // Vertex regions.
        check(pt(-1.0, -1.0, 0.5), &t, [1.0, 0.0, 0.0]);
        check(pt(3.0, -0.5, 0.2), &t, [0.0, 1.0, 0.0]);
        check(pt(-0.1, 2.0, -0.3), &t, [0.0, 0.0, 1.0]);
        // Edge regions: a-b (y < 0), a-c (x < 0), b-c (beyond the hypotenuse).
        check(pt(0.5, -1.0, 1.0), &t, [0.75, 0.25, 0.0]);
        check(pt(-2.0, 0.4, 0.0), &t, [0.6, 0.0, 0.4]);
        // Hypotenuse b-c: foot of the perpendicular from (1.5, 1.5).
        let (b, c) = (t[1], t[2]);
        let p = pt(1.5, 1.5, 0.7);
        let s = ((p - b).dot(&(c - b)) / (c - b).norm_squared()).clamp(0.0, 1.0);
        check(p, &t, [0.0, 1.0 - s, s]);
        // One negative coordinate, far out: the foot on the opposite edge.
        check(pt(1.0, -3.0, 0.0), &t, [0.5, 0.5, 0.0]);
        // Two negative coordinates (behind an obtuse corner a) with the closest point
        // inside edge a-b, not at the vertex.
        let obtuse = [pt(0.0, 0.0, 0.0), pt(2.0, 0.5, 0.0), pt(-2.0, 0.5, 0.0)];
        let s = 3.325 / 4.25;
        check(pt(1.8, -0.55, 0.0), &obtuse, [1.0 - s, s, 0.0]);
        // On the triangle: itself.
        check(pt(1.0, 0.2, 0.0), &t, [0.3, 0.5, 0.2]);
    }

    #[test]
    fn random_points_against_a_sampled_minimum() {
        let mut state = 7u64;
        let mut rand = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..300 {
            let t = [
                pt(rand(), rand(), rand()),
                pt(rand(), rand(), rand()),
                pt(rand(), rand(), rand()),
            ];
            let p = pt(rand(), rand(), rand());
            let r = closest_on_triangle(&p, &t);
            let sampled = sampled_min(&p, &t, 200);
            assert!(r.distance_squared <= sampled + 1e-12);
            // The sampled minimum is within a grid cell of the true one.
            assert!(sampled.sqrt() - r.distance() < 0.05);
            assert!(r.coords.iter().all(|&c| (0.0..=1.0).contains(&c)));
            assert!((r.coords.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn slivers_and_degenerate_triangles() {
        // Collinear: the closest point of the segment hull.
        let t = [pt(0.0, 0.0, 0.0), pt(1.0, 0.0, 0.0), pt(3.0, 0.0, 0.0)];
        let r = closest_on_triangle(&pt(2.0, 1.0, 0.0), &t);
        assert!((r.distance() - 1.0).abs() < 1e-15);
        assert!((r.position - pt(2.0, 0.0, 0.0)).norm() < 1e-15);
        // All three corners equal.
        let t = [pt(1.0, 1.0, 1.0); 3];
        let r = closest_on_triangle(&pt(1.0, 1.0, 2.0), &t);
        assert!((r.distance() - 1.0).abs() < 1e-15);
        assert!((r.coords.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        // A sliver of height 1e-9 under a point above its middle.
        let t = [pt(0.0, 0.0, 0.0), pt(1.0, 0.0, 0.0), pt(0.5, 1e-9, 0.0)];
        let r = closest_on_triangle(&pt(0.5, 0.5e-9, 2.0), &t);
        assert!((r.distance() - 2.0).abs() < 1e-15);
        let r = closest_on_triangle(&pt(0.25, -3.0, 0.0), &t);
        assert!((r.distance() - 3.0).abs() < 1e-15);
        assert!((r.position - pt(0.25, 0.0, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn segments() {
        let (a, b) = (pt(0.0, 0.0, 0.0), pt(2.0, 0.0, 0.0));
        let r = closest_on_segment(&pt(0.5, 1.0, 0.0), &a, &b);
        assert_eq!(r.coords, [0.75, 0.25, 0.0, 0.0]);
        assert_eq!(
            closest_on_segment(&pt(-1.0, 0.0, 0.0), &a, &b).coords[0],
            1.0
        );
        assert_eq!(
            closest_on_segment(&pt(5.0, 0.0, 0.0), &a, &b).coords[1],
            1.0
        );
        let r = closest_on_segment(&pt(5.0, 0.0, 0.0), &a, &a);
        assert_eq!(r.distance(), 5.0);
    }

    #[test]
    fn planar_quad_inverts_the_bilinear_map() {
        // A planar, non-parallelogram quad: the patch is the polygon.
        let q = [
            pt(0.0, 0.0, 0.0),
            pt(2.0, 0.0, 0.0),
            pt(1.5, 1.0, 0.0),
            pt(0.0, 1.5, 0.0),
        ];
        for &(u, v) in &[(0.3, 0.6), (0.9, 0.1), (0.5, 0.5), (0.0, 0.7), (1.0, 1.0)] {
            let x = patch_point(&q, u, v);
            for h in [0.0, 0.8, -2.0] {
                let p = x + Vector3::new(0.0, 0.0, h);
                let r = closest_on_quad(&p, &q);
                assert!((r.position - x).norm() < 1e-14, "{u} {v} {h}");
                assert!((r.distance() - h.abs()).abs() < 1e-14);
                let expected = bilinear_weights(u, v);
                for (c, e) in r.coords.iter().zip(&expected) {
                    assert!((c - e).abs() < 1e-13);
                }
            }
        }
        // Outside: the nearest edge point.
        let r = closest_on_quad(&pt(1.0, -1.0, 0.0), &q);
        assert!((r.position - pt(1.0, 0.0, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn warped_quad_against_a_sampled_minimum() {
        let q = [
            pt(0.0, 0.0, 0.0),
            pt(1.0, 0.0, 0.3),
            pt(1.0, 1.0, 0.0),
            pt(0.0, 1.0, 0.3),
        ];
        let n = 400;
        for p in [
            pt(0.3, 0.4, 0.5),
            pt(0.7, 0.2, -0.4),
            pt(0.5, 0.5, 0.05),
            pt(1.3, 0.5, 0.2),
            pt(-0.2, -0.3, 0.0),
        ] {
            let r = closest_on_quad(&p, &q);
            let mut sampled = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    let x = patch_point(&q, i as f64 / n as f64, j as f64 / n as f64);
                    sampled = sampled.min((p - x).norm_squared());
                }
            }
            assert!(r.distance_squared <= sampled + 1e-14, "{p:?}");
            assert!(sampled.sqrt() - r.distance() < 1e-4, "{p:?}");
            let (u, v) = (r.coords[1] + r.coords[2], r.coords[2] + r.coords[3]);
            assert!((patch_point(&q, u, v) - r.position).norm() < 1e-15);
        }
    }
}
