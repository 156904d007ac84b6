//! Exact closest points on a polyline in R^3 (a boundary loop or a feature curve of a
//! target mesh), by a kd-tree of pieces of its segments.
//!
//! Each segment of length `l` is cut into `ceil(l / h)` equal pieces (at most
//! [`MAX_PIECES`]), `h` twice the median segment length (so that one long segment does
//! not widen every search), and
//! the pieces' midpoints go into a kiddo kd-tree. For a query point `p`, the nearest
//! midpoint names a segment whose exact closest point lies at distance `r` from `p`: an
//! upper bound of the distance to the polyline. The closest point `c` of the polyline
//! lies on a piece with midpoint `m` and half-length at most `rho` (the largest
//! half-length of a piece), so
//! ```text
//! |p - m| <= |p - c| + |c - m| <= r + rho,
//! ```
//! and measuring exactly the segments of every piece within `r + rho` of `p` finds `c`.
//! Ties go to the lowest segment index, as a scan of the segments in order would give.
//! Segments of zero length are left out (they have no direction).

use beltrami_mesh::{Point3, Vector3};
use kiddo::SquaredEuclidean;

use crate::SpatialError;
use crate::closest_point::closest_on_segment;
use crate::index::Tree;

/// The most pieces a segment is cut into: a segment a million times the median then
/// widens the searches instead of filling the memory.
pub const MAX_PIECES: usize = 64;

/// The closest point of a polyline to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnPolyline {
    /// The closest point.
    pub position: Point3<f64>,
    /// Its segment: from point `segment` to point `segment + 1` (to point 0 for the
    /// closing segment of a closed polyline).
    pub segment: usize,
    /// The unit direction of that segment.
    pub direction: Vector3<f64>,
    /// The squared distance from the query point.
    pub distance_squared: f64,
}

/// A polyline with a kd-tree for exact closest-point queries (module docs).
pub struct PolylineIndex {
    points: Vec<Point3<f64>>,
    /// `None` when every segment has zero length.
    tree: Option<Tree>,
    /// The segment of each piece, in the tree's item order.
    pieces: Vec<u32>,
    /// The largest half-length of a piece (`rho` in the module docs).
    reach: f64,
}

impl std::fmt::Debug for PolylineIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PolylineIndex")
            .field("points", &self.points.len())
            .field("pieces", &self.pieces.len())
            .finish_non_exhaustive()
    }
}

impl PolylineIndex {
    /// The index of the polyline through `points`, closed (the last point joined to the
    /// first) when `closed`. Fails with [`SpatialError::TooLarge`] beyond `u32` segments
    /// or pieces.
    pub fn new(points: Vec<Point3<f64>>, closed: bool) -> Result<Self, SpatialError> {
        let n = points.len();
        let count = if closed { n } else { n.saturating_sub(1) };
        let lengths: Vec<f64> = (0..count)
            .map(|s| (points[(s + 1) % n] - points[s]).norm())
            .collect();
        let mut positive: Vec<f64> = lengths.iter().copied().filter(|&l| l > 0.0).collect();
        let (mut centers, mut pieces, mut reach) = (Vec::new(), Vec::new(), 0.0f64);
        if !positive.is_empty() {
            let middle = positive.len() / 2;
            let (_, &mut median, _) = positive.select_nth_unstable_by(middle, f64::total_cmp);
            let h = 2.0 * median;
            for (s, &l) in lengths.iter().enumerate().filter(|(_, l)| **l > 0.0) {
                let (a, b) = (points[s], points[(s + 1) % n]);
                let k = (l / h).ceil().clamp(1.0, MAX_PIECES as f64);
                reach = reach.max(0.5 * l / k);
                for i in 0..k as usize {
                    let m = a + (b - a) * ((i as f64 + 0.5) / k);
                    centers.push([m.x, m.y, m.z]);
                    pieces.push(s as u32);
                }
            }
        }
        let too_large = SpatialError::TooLarge {
            samples: centers.len(),
        };
        if u32::try_from(count.max(centers.len())).is_err() {
            return Err(too_large);
        }
        let tree = if centers.is_empty() {
            None
        } else {
            Some(Tree::new_from_slice(&centers).map_err(|_| too_large)?)
        };
        Ok(Self {
            points,
            tree,
            pieces,
            reach,
        })
    }

    /// The polyline's points.
    pub fn points(&self) -> &[Point3<f64>] {
        &self.points
    }

    /// The ends of segment `s`.
    fn segment(&self, s: usize) -> (Point3<f64>, Point3<f64>) {
        let n = self.points.len();
        (self.points[s], self.points[(s + 1) % n])
    }

    /// The exact closest point of the polyline to `p` (module docs); `None` when every
    /// segment has zero length.
    pub fn closest(&self, p: &Point3<f64>) -> Option<OnPolyline> {
        let tree = self.tree.as_ref()?;
        let q = [p.x, p.y, p.z];
        let nearest = tree
            .query(&q)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        let on = |s: usize| {
            let (a, b) = self.segment(s);
            let c = closest_on_segment(p, &a, &b);
            OnPolyline {
                position: c.position,
                segment: s,
                direction: (b - a).normalize(),
                distance_squared: c.distance_squared,
            }
        };
        let mut best = on(self.pieces[nearest.item as usize] as usize);
        // Padded so that rounding of the squared distances cannot drop a piece on the
        // sphere.
        let radius = (best.distance_squared.sqrt() + self.reach) * (1.0 + 1e-12)
            + 16.0 * f64::EPSILON * p.coords.amax();
        for item in tree
            .query(&q)
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .unsorted()
            .execute()
        {
            let s = self.pieces[item.item as usize] as usize;
            if s == best.segment {
                continue;
            }
            let candidate = on(s);
            let closer = candidate.distance_squared < best.distance_squared;
            let tie = candidate.distance_squared == best.distance_squared && s < best.segment;
            if closer || tie {
                best = candidate;
            }
        }
        Some(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closest point by a scan of every segment, ties to the lowest index.
    fn scan(points: &[Point3<f64>], closed: bool, p: &Point3<f64>) -> Option<(usize, f64)> {
        let n = points.len();
        let count = if closed { n } else { n.saturating_sub(1) };
        let mut best: Option<(usize, f64)> = None;
        for s in 0..count {
            let (a, b) = (points[s], points[(s + 1) % n]);
            if a == b {
                continue;
            }
            let d = closest_on_segment(p, &a, &b).distance_squared;
            if best.is_none_or(|(_, e)| d < e) {
                best = Some((s, d));
            }
        }
        best
    }

    /// A deterministic sequence in `[0, 1)`.
    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn agrees_with_a_scan_of_every_segment() {
        let mut state = 7;
        // A wavy closed loop with segments from 0.001 to 2 long, one of length 0 and
        // one 40 times the median, and an open spiral.
        let mut looped: Vec<Point3<f64>> = (0..400)
            .map(|i| {
                let t = std::f64::consts::TAU * f64::from(i) / 400.0;
                let r = 10.0 + (7.0 * t).sin();
                Point3::new(r * t.cos(), r * t.sin(), (3.0 * t).cos())
            })
            .collect();
        looped[17] = looped[16];
        looped.drain(200..240);
        let spiral: Vec<Point3<f64>> = (0..300)
            .map(|i| {
                let t = f64::from(i) * 0.05;
                Point3::new(t.cos() * (1.0 + t), t.sin() * (1.0 + t), 0.1 * t)
            })
            .collect();
        for (points, closed) in [(looped, true), (spiral, false)] {
            let index = PolylineIndex::new(points.clone(), closed).unwrap();
            for _ in 0..2000 {
                let p = Point3::new(
                    30.0 * lcg(&mut state) - 15.0,
                    30.0 * lcg(&mut state) - 15.0,
                    4.0 * lcg(&mut state) - 2.0,
                );
                let got = index.closest(&p).unwrap();
                let (segment, d) = scan(&points, closed, &p).unwrap();
                assert_eq!((got.segment, got.distance_squared), (segment, d), "{p}");
                let (a, b) = (points[segment], points[(segment + 1) % points.len()]);
                assert!((got.direction - (b - a).normalize()).norm() < 1e-15);
                assert!(((got.position - p).norm_squared() - d).abs() <= 1e-12 * d.max(1.0));
            }
        }
    }

    #[test]
    fn ties_go_to_the_lowest_segment_and_degenerate_polylines_have_no_closest_point() {
        // The centre of a square loop is equally far from its four sides.
        let square = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        let index = PolylineIndex::new(square, true).unwrap();
        let got = index.closest(&Point3::new(0.5, 0.5, 0.0)).unwrap();
        assert_eq!(got.segment, 0);
        assert_eq!(got.position, Point3::new(0.5, 0.0, 0.0));
        let point = Point3::new(1.0, 2.0, 3.0);
        for points in [vec![], vec![point], vec![point, point]] {
            let index = PolylineIndex::new(points, false).unwrap();
            assert_eq!(index.closest(&Point3::origin()), None);
        }
    }
}
