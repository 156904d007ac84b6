//! Closed polygonal curves in the plane: orientation, signed area and whether a curve
//! meets itself.
//!
//! A map of a disk whose faces all keep their orientation is one-to-one exactly when its
//! boundary curve is simple (the degree of the map at a point is the winding number of
//! the boundary about it), and it keeps the orientation of the surface exactly when its
//! boundary turns the way the surface's does. Self-crossing is found by bucketing the
//! segments in a uniform grid of cells about as large as the mean segment; touching
//! counts as meeting.

use std::collections::HashMap;

/// Whether the closed polygon through `points` (in order, closing back to the first)
/// meets itself anywhere other than between consecutive segments.
pub fn crosses_itself(points: &[[f64; 2]]) -> bool {
    let n = points.len();
    if n < 4 {
        return false;
    }
    let segment = |i: usize| (points[i], points[(i + 1) % n]);
    let mean = (0..n)
        .map(|i| {
            let (a, b) = segment(i);
            (b[0] - a[0]).hypot(b[1] - a[1])
        })
        .sum::<f64>()
        / n as f64;
    if mean <= 0.0 || !mean.is_finite() {
        return true;
    }
    let cell = |x: f64| (x / mean).floor() as i64;
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for i in 0..n {
        let (a, b) = segment(i);
        for cx in cell(a[0].min(b[0]))..=cell(a[0].max(b[0])) {
            for cy in cell(a[1].min(b[1]))..=cell(a[1].max(b[1])) {
                grid.entry((cx, cy)).or_default().push(i);
            }
        }
    }
    grid.values().any(|bucket| {
        bucket.iter().enumerate().any(|(k, &i)| {
            bucket[k + 1..].iter().any(|&j| {
                let neighbours = (i + 1) % n == j || (j + 1) % n == i;
                !neighbours && segments_meet(segment(i), segment(j))
            })
        })
    })
}

/// Twice the signed area of the triangle `a b c` (positive when counter-clockwise).
pub fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// The signed area of the closed polygon through `points` (shoelace formula; positive
/// when it turns counter-clockwise).
pub fn signed_area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
}

/// Whether `p`, known to be on the line through `a b`, lies within the segment.
fn within(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    p[0] >= a[0].min(b[0])
        && p[0] <= a[0].max(b[0])
        && p[1] >= a[1].min(b[1])
        && p[1] <= a[1].max(b[1])
}

/// Whether two closed segments share a point.
fn segments_meet((a, b): ([f64; 2], [f64; 2]), (c, d): ([f64; 2], [f64; 2])) -> bool {
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && within(c, d, a))
        || (d2 == 0.0 && within(c, d, b))
        || (d3 == 0.0 && within(a, b, c))
        || (d4 == 0.0 && within(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::{crosses_itself, signed_area};

    #[test]
    fn a_counter_clockwise_square_has_its_area_and_the_reverse_its_negative() {
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]];
        assert_eq!(signed_area(&square), 2.0);
        let mut reversed = square;
        reversed.reverse();
        assert_eq!(signed_area(&reversed), -2.0);
    }

    #[test]
    fn a_square_is_simple_and_a_bow_tie_is_not() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!(!crosses_itself(&square));
        let bow_tie = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        assert!(crosses_itself(&bow_tie));
    }

    #[test]
    fn a_curve_that_touches_itself_at_a_point_crosses() {
        // Two squares sharing the corner (1, 1), walked as one curve.
        let pinched = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [2.0, 1.0],
            [2.0, 2.0],
            [1.0, 2.0],
            [1.0, 1.0],
            [0.0, 1.0],
        ];
        assert!(crosses_itself(&pinched));
    }
}
