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
//!
//! A point on the polyline moves along it by arc length ([`PolylineIndex::walk`]), and
//! one at a point where two segments meet at an angle has a tangent on either side
//! ([`PolylineIndex::corner`]): a move forward from there follows the segment ahead,
//! a move back the segment behind.

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

/// How near, relative to the length of its segment, a point of a polyline must be to
/// one of the segment's ends for [`PolylineIndex::corner`] to place it there. A point
/// that far before a corner and moved past it by `s` first covers the rest of its own
/// segment, a difference from the move along the segment ahead of at most `2e-3 l`:
/// small against the steps that cross the corner, while a point left closer than this
/// to a corner crosses it in nearly every step. On `disk_human_face` remeshed to 100K
/// faces onto `disk_hand`, the flow stalled at mean `|mu|` 0.050 with `1e-6` and
/// `1e-4`, its largest mover a boundary vertex between `1e-4` and `1e-3` of its
/// segment from a corner.
pub const CORNER_TOLERANCE: f64 = 1e-3;

/// A point of a polyline where two segments meet at an angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// The index of the point.
    pub point: usize,
    /// The unit direction of the segment that ends there.
    pub behind: Vector3<f64>,
    /// The unit direction of the segment that starts there.
    pub ahead: Vector3<f64>,
}

/// A polyline with a kd-tree for exact closest-point queries (module docs).
pub struct PolylineIndex {
    points: Vec<Point3<f64>>,
    /// Whether the last point is joined to the first.
    closed: bool,
    /// The total length of the segments.
    length: f64,
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
            closed,
            length: lengths.iter().sum(),
            tree,
            pieces,
            reach,
        })
    }

    /// The number of segments.
    fn segment_count(&self) -> usize {
        let n = self.points.len();
        if self.closed { n } else { n.saturating_sub(1) }
    }

    /// The nearest segment of positive length after segment `s` (`ahead`) or before it,
    /// `None` past an end of an open polyline.
    fn neighbour(&self, s: usize, ahead: bool) -> Option<usize> {
        let count = self.segment_count();
        let mut at = s;
        for _ in 1..count {
            at = match (ahead, self.closed) {
                (true, _) if at + 1 < count => at + 1,
                (true, true) => 0,
                (false, _) if at > 0 => at - 1,
                (false, true) => count - 1,
                _ => return None,
            };
            let (a, b) = self.segment(at);
            if a != b {
                return Some(at);
            }
        }
        None
    }

    /// The corner at `on` (a point of the polyline, as [`PolylineIndex::closest`] or
    /// [`PolylineIndex::walk`] gives it) when it lies within [`CORNER_TOLERANCE`] of
    /// its segment's length from an end of its segment where the next segment of
    /// positive length turns; `None` inside a segment, at an end of an open polyline
    /// and where the segments meet straight.
    pub fn corner(&self, on: &OnPolyline) -> Option<Corner> {
        let (a, b) = self.segment(on.segment);
        let tolerance = CORNER_TOLERANCE * (b - a).norm();
        let at_end = if (on.position - b).norm() <= tolerance {
            true
        } else if (on.position - a).norm() <= tolerance {
            false
        } else {
            return None;
        };
        let other = self.neighbour(on.segment, at_end)?;
        let (c, d) = self.segment(other);
        let turn = (d - c).normalize();
        let corner = if at_end {
            Corner {
                point: (on.segment + 1) % self.points.len(),
                behind: on.direction,
                ahead: turn,
            }
        } else {
            Corner {
                point: on.segment,
                behind: turn,
                ahead: on.direction,
            }
        };
        (corner.behind != corner.ahead).then_some(corner)
    }

    /// The point `arc` away from `on` (a point of the polyline) along the polyline by
    /// arc length: towards higher point indices for `arc > 0`, lower ones for `arc < 0`;
    /// it stops at the ends of an open polyline, and goes round a closed one as often
    /// as `arc` asks. Its `distance_squared` is zero.
    pub fn walk(&self, on: &OnPolyline, arc: f64) -> OnPolyline {
        let ahead = arc > 0.0;
        let mut left = arc.abs();
        if self.closed && self.length > 0.0 {
            left %= self.length;
        }
        let (mut s, mut at) = (on.segment, on.position);
        loop {
            let (a, b) = self.segment(s);
            let end = if ahead { b } else { a };
            let room = (end - at).norm();
            let next = if left <= room {
                None
            } else {
                self.neighbour(s, ahead)
            };
            let Some(next) = next else {
                let position = if room > left {
                    at + (end - at) * (left / room)
                } else {
                    end
                };
                return OnPolyline {
                    position,
                    segment: s,
                    direction: (b - a).normalize(),
                    distance_squared: 0.0,
                };
            };
            left -= room;
            (s, at) = (next, end);
        }
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

    /// An L of two unit segments and a unit segment back down, open: (0,0) (1,0)
    /// (1,1) and a repeated point, then (0,1).
    fn hook() -> PolylineIndex {
        let points = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        PolylineIndex::new(points, false).unwrap()
    }

    #[test]
    fn a_walk_goes_by_arc_length_round_corners_and_stops_at_the_ends() {
        let index = hook();
        let start = index.closest(&Point3::new(0.25, -0.5, 0.0)).unwrap();
        let cases = [
            (0.5, Point3::new(0.75, 0.0, 0.0), 0),
            (1.25, Point3::new(1.0, 0.5, 0.0), 1),
            // Over the repeated point: the segment of zero length is skipped.
            (2.0, Point3::new(0.75, 1.0, 0.0), 3),
            (9.0, Point3::new(0.0, 1.0, 0.0), 3),
            (-0.125, Point3::new(0.125, 0.0, 0.0), 0),
            (-9.0, Point3::new(0.0, 0.0, 0.0), 0),
            (0.0, Point3::new(0.25, 0.0, 0.0), 0),
        ];
        for (arc, position, segment) in cases {
            let got = index.walk(&start, arc);
            assert!((got.position - position).norm() < 1e-15, "{arc}: {got:?}");
            assert_eq!(got.segment, segment, "{arc}");
            assert_eq!(got.distance_squared, 0.0);
        }
        // Back from the last segment round both corners.
        let end = index.closest(&Point3::new(0.5, 1.5, 0.0)).unwrap();
        let got = index.walk(&end, -2.0);
        assert!((got.position - Point3::new(0.5, 0.0, 0.0)).norm() < 1e-15);
        assert_eq!(got.segment, 0);
        // A closed square goes round as often as asked.
        let square = PolylineIndex::new(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            true,
        )
        .unwrap();
        let start = square.closest(&Point3::new(0.5, -1.0, 0.0)).unwrap();
        for (arc, position) in [
            (4.25, Point3::new(0.75, 0.0, 0.0)),
            (-0.75, Point3::new(0.0, 0.25, 0.0)),
            (-8.75, Point3::new(0.0, 0.25, 0.0)),
        ] {
            let got = square.walk(&start, arc);
            assert!((got.position - position).norm() < 1e-12, "{arc}: {got:?}");
        }
    }

    #[test]
    fn corners_have_a_tangent_on_either_side_within_the_tolerance() {
        let index = hook();
        let (x, y) = (Vector3::x(), Vector3::y());
        // Past the convex corner (1, 0): the closest point is the corner itself.
        let at = index.closest(&Point3::new(2.0, -1.0, 0.0)).unwrap();
        assert_eq!(at.position, Point3::new(1.0, 0.0, 0.0));
        let corner = index.corner(&at).unwrap();
        assert_eq!((corner.point, corner.behind, corner.ahead), (1, x, y));
        // Just inside the tolerance on either segment, and just outside it.
        let near = 0.5 * CORNER_TOLERANCE;
        for p in [
            Point3::new(1.0 - near, 0.0, 0.0),
            Point3::new(1.0, near, 0.0),
        ] {
            let on = index.closest(&p).unwrap();
            assert_eq!(index.corner(&on).map(|c| c.point), Some(1), "{p}");
        }
        let far = index
            .closest(&Point3::new(1.0 - 2.0 * CORNER_TOLERANCE, 0.0, 0.0))
            .unwrap();
        assert_eq!(index.corner(&far), None);
        // The corner (1, 1) across the repeated point turns from y to -x.
        let on = index.closest(&Point3::new(2.0, 2.0, 0.0)).unwrap();
        let corner = index.corner(&on).unwrap();
        assert_eq!((corner.behind, corner.ahead), (y, -x));
        // The ends of an open polyline and a straight joint are not corners.
        for p in [Point3::new(-1.0, 0.0, 0.0), Point3::new(-1.0, 1.0, 0.0)] {
            assert_eq!(index.corner(&index.closest(&p).unwrap()), None, "{p}");
        }
        let straight = PolylineIndex::new(
            vec![
                Point3::origin(),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(3.0, 0.0, 0.0),
            ],
            false,
        )
        .unwrap();
        let on = straight.closest(&Point3::new(1.0, 1.0, 0.0)).unwrap();
        assert_eq!(straight.corner(&on), None);
    }
}
