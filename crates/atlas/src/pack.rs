//! Packing flat charts into the unit square.
//!
//! Each chart is turned (a rotation, never a reflection) to its bounding rectangle of
//! least area, which has a side along an edge of the convex hull (Freeman and Shapira
//! 1975), and wrapped in a margin of half the gap. The rectangles are then placed
//! tallest first by the bottom-left skyline rule: each goes where its top ends lowest,
//! then leftmost, on the upper outline of those already placed. Several strip widths
//! are tried and the packing with the smallest enclosing square kept; one scale then
//! maps that square onto `[0, 1]^2`, so every chart keeps its shape and the charts keep
//! their sizes relative to each other. Rectangles do not overlap, so neither do charts,
//! and any two charts are at least the gap apart.

/// Strip widths tried, as multiples of the square root of the rectangles' total area.
const WIDTHS: [f64; 6] = [1.0, 1.1, 1.2, 1.3, 1.45, 1.6];

/// Moves the points of every chart (a rotation and a translation per chart, then one
/// common scale) so that all lie in `[0, 1]^2`, no two charts' bounding rectangles
/// overlap and any two charts are at least `gap` apart (a fraction of the square's side).
pub fn pack(charts: &mut [Vec<[f64; 2]>], gap: f64) {
    let boxes: Vec<[f64; 2]> = charts.iter_mut().map(|c| turn_to_least_box(c)).collect();
    if boxes.is_empty() {
        return;
    }
    let area: f64 = boxes.iter().map(|b| b[0] * b[1]).sum();
    let mut side = area.sqrt().max(f64::MIN_POSITIVE);
    let mut placed = Vec::new();
    let mut margin = 0.0;
    // The gap is a fraction of the final side, which the packing decides: repeat until
    // the side the margin was taken from is at least the side obtained.
    for _ in 0..8 {
        margin = gap * side;
        let (positions, obtained) = best_skyline(&boxes, margin);
        placed = positions;
        let enough = obtained <= side;
        side = obtained;
        if enough {
            break;
        }
    }
    let scale = 1.0 / side;
    for (chart, at) in charts.iter_mut().zip(&placed) {
        for p in chart.iter_mut() {
            p[0] = (p[0] + at[0] + margin / 2.0) * scale;
            p[1] = (p[1] + at[1] + margin / 2.0) * scale;
        }
    }
}

/// The skyline packing of the boxes (each grown by `margin`) of smallest enclosing
/// square over the tried widths: the lower-left corner of each box and the square's side.
fn best_skyline(boxes: &[[f64; 2]], margin: f64) -> (Vec<[f64; 2]>, f64) {
    let grown: Vec<[f64; 2]> = boxes
        .iter()
        .map(|b| [b[0] + margin, b[1] + margin])
        .collect();
    let area: f64 = grown.iter().map(|b| b[0] * b[1]).sum();
    let widest = grown.iter().map(|b| b[0]).fold(0.0, f64::max);
    let mut order: Vec<usize> = (0..grown.len()).collect();
    order.sort_by(|&a, &b| grown[b][1].total_cmp(&grown[a][1]));
    WIDTHS
        .iter()
        .map(|f| skyline(&grown, &order, (f * area.sqrt()).max(widest)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or_default()
}

/// Bottom-left skyline packing of `boxes` in `order` into a strip of width `width`: the
/// lower-left corner of each box and the side of the enclosing square.
fn skyline(boxes: &[[f64; 2]], order: &[usize], width: f64) -> (Vec<[f64; 2]>, f64) {
    // The outline: segments (x, y) with the next segment's x as the end.
    let mut outline: Vec<[f64; 2]> = vec![[0.0, 0.0]];
    let mut at = vec![[0.0; 2]; boxes.len()];
    let mut top: f64 = 0.0;
    for &k in order {
        let [w, h] = boxes[k];
        let mut best: Option<(f64, f64)> = None;
        for start in 0..outline.len() {
            let x = outline[start][0];
            if x + w > width * (1.0 + 1e-12) && start > 0 {
                break;
            }
            let y = outline[start..]
                .iter()
                .take_while(|s| s[0] < x + w)
                .map(|s| s[1])
                .fold(0.0, f64::max);
            if best.is_none_or(|(bx, by)| y < by || (y == by && x < bx)) {
                best = Some((x, y));
            }
        }
        let (x, y) = best.unwrap_or((0.0, top));
        at[k] = [x, y];
        top = top.max(y + h);
        raise(&mut outline, x, x + w, y + h);
    }
    let right = order
        .iter()
        .map(|&k| at[k][0] + boxes[k][0])
        .fold(0.0, f64::max);
    (at, right.max(top))
}

/// Sets the outline to height `y` over `[x0, x1)`.
fn raise(outline: &mut Vec<[f64; 2]>, x0: f64, x1: f64, y: f64) {
    let height_at = |outline: &[[f64; 2]], x: f64| {
        outline
            .iter()
            .take_while(|s| s[0] <= x)
            .last()
            .map_or(0.0, |s| s[1])
    };
    let after = height_at(outline, x1);
    outline.retain(|s| s[0] < x0 || s[0] > x1);
    let insert = outline
        .iter()
        .position(|s| s[0] > x0)
        .unwrap_or(outline.len());
    outline.insert(insert, [x0, y]);
    if !outline.iter().any(|s| s[0] == x1) {
        outline.insert(insert + 1, [x1, after]);
    }
}

/// Rotates `points` so that their bounding rectangle has the least area and is at least
/// as wide as tall, and moves that rectangle's lower-left corner to the origin; returns
/// its width and height.
fn turn_to_least_box(points: &mut [[f64; 2]]) -> [f64; 2] {
    let hull = convex_hull(points);
    let mut best = (f64::INFINITY, 1.0, 0.0);
    for i in 0..hull.len() {
        let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        if len == 0.0 {
            continue;
        }
        let (c, s) = (dx / len, dy / len);
        let [w, h] = extent(&hull, c, s);
        if w * h < best.0 {
            // Lying down (wider than tall) keeps the skyline low: a quarter turn more
            // when the box stands.
            best = if h > w { (w * h, -s, c) } else { (w * h, c, s) };
        }
    }
    let (_, c, s) = best;
    let mut lo = [f64::INFINITY; 2];
    for p in points.iter_mut() {
        // Rotate by minus the edge's angle, so the edge lies along u.
        *p = [c * p[0] + s * p[1], -s * p[0] + c * p[1]];
        lo = [lo[0].min(p[0]), lo[1].min(p[1])];
    }
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points.iter_mut() {
        *p = [p[0] - lo[0], p[1] - lo[1]];
        hi = [hi[0].max(p[0]), hi[1].max(p[1])];
    }
    hi
}

/// The width and height of `points` rotated by the angle with cosine `c` and sine `s`
/// (backwards).
fn extent(points: &[[f64; 2]], c: f64, s: f64) -> [f64; 2] {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        let q = [c * p[0] + s * p[1], -s * p[0] + c * p[1]];
        lo = [lo[0].min(q[0]), lo[1].min(q[1])];
        hi = [hi[0].max(q[0]), hi[1].max(q[1])];
    }
    [hi[0] - lo[0], hi[1] - lo[1]]
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain).
fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    sorted.dedup();
    if sorted.len() < 3 {
        return sorted;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * sorted.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(sorted.iter())
        } else {
            Box::new(sorted.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether two axis-aligned boxes (corner, size) share interior points.
    fn overlap(a: [f64; 2], sa: [f64; 2], b: [f64; 2], sb: [f64; 2]) -> bool {
        a[0] < b[0] + sb[0] && b[0] < a[0] + sa[0] && a[1] < b[1] + sb[1] && b[1] < a[1] + sa[1]
    }

    #[test]
    fn skyline_boxes_never_overlap_and_fit_the_square() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        let boxes: Vec<[f64; 2]> = (0..200)
            .map(|_| [0.05 + next(), 0.05 + next() * 2.0])
            .collect();
        let (at, side) = best_skyline(&boxes, 0.0);
        let area: f64 = boxes.iter().map(|b| b[0] * b[1]).sum();
        for i in 0..boxes.len() {
            assert!(at[i][0] >= 0.0 && at[i][1] >= 0.0);
            assert!(at[i][0] + boxes[i][0] <= side * (1.0 + 1e-12));
            assert!(at[i][1] + boxes[i][1] <= side * (1.0 + 1e-12));
            for j in 0..i {
                assert!(
                    !overlap(at[i], boxes[i], at[j], boxes[j]),
                    "boxes {i} and {j}"
                );
            }
        }
        // The packing wastes less than half of the square.
        assert!(
            area / (side * side) > 0.5,
            "filled {}",
            area / (side * side)
        );
    }

    #[test]
    fn a_rotated_rectangle_is_turned_to_lie_along_u() {
        // Turned by 0.3 past standing (1 wide, 4 tall): it comes back lying, 4 x 1.
        let angle: f64 = 0.3 + std::f64::consts::FRAC_PI_2;
        let (c, s) = (angle.cos(), angle.sin());
        let mut points: Vec<[f64; 2]> =
            [[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0], [2.0, 0.5]]
                .iter()
                .map(|p| [c * p[0] - s * p[1] + 7.0, s * p[0] + c * p[1] - 3.0])
                .collect();
        let [w, h] = turn_to_least_box(&mut points);
        assert!(
            (w - 4.0).abs() < 1e-12 && (h - 1.0).abs() < 1e-12,
            "{w} x {h}"
        );
        // A rotation keeps orientation: the triangle of the first three corners stays
        // counter-clockwise.
        let [a, b, d] = [points[0], points[1], points[2]];
        assert!((b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]) > 0.0);
    }

    #[test]
    fn packed_charts_lie_in_the_unit_square_with_the_gap_between_them() {
        let square = |x: f64, y: f64, s: f64| vec![[x, y], [x + s, y], [x + s, y + s], [x, y + s]];
        let mut charts = vec![
            square(0.0, 0.0, 1.0),
            square(5.0, 5.0, 2.0),
            square(-3.0, 1.0, 0.5),
        ];
        pack(&mut charts, 0.01);
        let boxes: Vec<([f64; 2], [f64; 2])> = charts
            .iter()
            .map(|c| {
                let lo = [
                    c.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min),
                    c.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min),
                ];
                let hi = [
                    c.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max),
                    c.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max),
                ];
                (lo, hi)
            })
            .collect();
        for (lo, hi) in &boxes {
            assert!(lo[0] >= 0.0 && lo[1] >= 0.0 && hi[0] <= 1.0 && hi[1] <= 1.0);
        }
        for i in 0..boxes.len() {
            for j in 0..i {
                let (a, b) = (boxes[i], boxes[j]);
                let apart_x = (b.0[0] - a.1[0]).max(a.0[0] - b.1[0]);
                let apart_y = (b.0[1] - a.1[1]).max(a.0[1] - b.1[1]);
                assert!(apart_x.max(apart_y) >= 0.01 - 1e-12, "charts {i} and {j}");
            }
        }
        // Sizes relative to each other are kept: the big square is 4 times the first.
        let side = |k: usize| boxes[k].1[0] - boxes[k].0[0];
        assert!((side(1) / side(0) - 2.0).abs() < 1e-9);
    }
}
