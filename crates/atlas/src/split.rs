//! Splitting a chart in two where it cannot be laid flat whole, along a short border at
//! a waist of the chart.
//!
//! 1. **Fiedler vector**: the eigenvector of the smallest non-zero eigenvalue of
//!    `L x = lambda M x` (`L` the cotan Laplacian, `M` the barycentric vertex areas),
//!    found by inverse iteration on `L + eps M` from the difference of the geodesic
//!    distances to two far-apart vertices (a vertex farthest from the first, then the
//!    vertex farthest from that), each iterate kept `M`-orthogonal to the constants. It
//!    runs from one end of the chart to the other and is flat across its waists.
//! 2. **Sweep**: faces sorted by the mean of the vector at their corners; the split is
//!    the prefix, holding between [`SMALLEST_SHARE`] and `1 - SMALLEST_SHARE` of the
//!    area, whose border is shortest relative to the square root of the smaller side's
//!    area (a ratio cut: a short border around a small part is worth as much as a longer
//!    one across the middle).
//! 3. **Clean-up**: the border is straightened (a face most of whose neighbours lie in
//!    the other half joins it, a few passes), so that no tooth of single faces sticks
//!    out (a tooth is a hairpin of the flat boundary, where charts overlap); then no
//!    half may touch itself at a vertex (a pinch: its flat boundary would pass twice
//!    through one point): at a vertex where a half's faces form several separate fans,
//!    all but the largest fan go to the other half.

use beltrami_fem::operators::cotan_laplacian;
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::{SolveOptions, SpdSolver};
use faer::Mat;

use crate::AtlasError;
use crate::shortest_paths::ShortestPaths;

/// The smallest share of the chart's area either half may hold.
pub const SMALLEST_SHARE: f64 = 0.1;

/// Inverse iterations towards the Fiedler vector.
const ITERATIONS: usize = 20;

/// For each face of `chart`, 0 or 1: the half it goes to (see the module docs).
pub fn split_in_two(chart: &Mesh) -> Result<Vec<u8>, AtlasError> {
    let first = farthest(chart, VertexId(0)).0;
    let (second, from_first) = farthest(chart, first);
    let from_second = farthest(chart, second).1;
    let start: Vec<f64> = from_first
        .iter()
        .zip(&from_second)
        .map(|(a, b)| a - b)
        .collect();
    let fiedler = fiedler_vector(chart, start)?;
    let mut half = sweep(chart, &fiedler);
    for _ in 0..SMOOTHING_PASSES {
        let before = half.clone();
        for f in chart.faces() {
            let other = chart
                .face_halfedges(f)
                .filter_map(|h| chart.face(chart.twin(h)))
                .filter(|g| before[g.idx()] != before[f.idx()])
                .count();
            if other >= 2 {
                half[f.idx()] = 1 - before[f.idx()];
            }
        }
    }
    for _ in 0..PINCH_PASSES {
        if !separate_pinches(chart, &mut half) {
            break;
        }
    }
    Ok(half)
}

/// Inverse iteration towards the Fiedler vector from `x` (see the module docs).
fn fiedler_vector(chart: &Mesh, mut x: Vec<f64>) -> Result<Vec<f64>, AtlasError> {
    let area = chart.vertex_areas();
    let total: f64 = area.iter().sum();
    let mut matrix = cotan_laplacian(chart)?;
    let diagonal: Vec<Option<usize>> = {
        let symbolic = matrix.symbolic();
        let (col_ptr, rows) = (symbolic.col_ptr(), symbolic.row_idx());
        (0..area.len())
            .map(|j| (col_ptr[j]..col_ptr[j + 1]).find(|&k| rows[k] == j))
            .collect()
    };
    // A shift far below the Fiedler value keeps the matrix definite without changing
    // the iteration's limit.
    let scale = chart.edge_lengths().iter().map(|l| l * l).sum::<f64>() / chart.edge_count() as f64;
    let shift = 1e-8 / scale;
    let values = matrix.val_mut();
    for (k, &a) in diagonal.iter().zip(&area) {
        if let Some(k) = *k {
            values[k] += shift * a;
        }
    }
    let mut solver = SpdSolver::new(matrix.symbolic(), SolveOptions::default())?;
    solver.factorize(matrix.as_ref())?;
    let mut rhs = Mat::<f64>::zeros(x.len(), 1);
    for _ in 0..ITERATIONS {
        let mean = x.iter().zip(&area).map(|(x, a)| x * a).sum::<f64>() / total;
        let norm = x
            .iter()
            .zip(&area)
            .map(|(x, a)| (x - mean) * (x - mean) * a)
            .sum::<f64>()
            .sqrt();
        if norm <= 0.0 || !norm.is_finite() {
            break;
        }
        for i in 0..x.len() {
            rhs[(i, 0)] = area[i] * (x[i] - mean) / norm;
        }
        solver.solve_in_place(rhs.as_mut())?;
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = rhs[(i, 0)];
        }
    }
    Ok(x)
}

/// The ratio-cut sweep over the faces sorted by `value` (see the module docs).
fn sweep(chart: &Mesh, value: &[f64]) -> Vec<u8> {
    let face_value: Vec<f64> = chart
        .faces()
        .map(|f| chart.face_vertices(f).map(|v| value[v.idx()]).sum::<f64>())
        .collect();
    let mut order: Vec<usize> = (0..chart.face_count()).collect();
    order.sort_by(|&a, &b| face_value[a].total_cmp(&face_value[b]));
    let area: Vec<f64> = chart.faces().map(|f| chart.face_area(f)).collect();
    let total: f64 = area.iter().sum();
    let mut inside = vec![false; chart.face_count()];
    let (mut border, mut taken) = (0.0, 0.0);
    let mut best = (f64::INFINITY, order.len() / 2);
    for (k, &f) in order.iter().enumerate() {
        inside[f] = true;
        taken += area[f];
        for h in chart.face_halfedges(beltrami_mesh::FaceId::from_usize(f)) {
            let length = chart.edge_length(chart.edge(h));
            match chart.face(chart.twin(h)) {
                Some(g) if inside[g.idx()] => border -= length,
                Some(_) => border += length,
                None => {}
            }
        }
        let smaller = taken.min(total - taken);
        if smaller >= SMALLEST_SHARE * total {
            let ratio = border / smaller.sqrt();
            if ratio < best.0 {
                best = (ratio, k + 1);
            }
        }
    }
    let mut half = vec![1u8; chart.face_count()];
    for &f in &order[..best.1] {
        half[f] = 0;
    }
    half
}

/// Gives every fan of a half but the largest at each vertex to the other half; whether
/// any face moved.
fn separate_pinches(chart: &Mesh, half: &mut [u8]) -> bool {
    let mut moved = false;
    for v in chart.vertices() {
        let mut fans: Vec<(u8, Vec<usize>)> = Vec::new();
        let around: Vec<Option<usize>> = chart
            .outgoing_halfedges(v)
            .map(|h| chart.face(h).map(|f| f.idx()))
            .collect();
        // Start after a gap (a boundary) or a change of half, so no fan wraps around.
        let n = around.len();
        let start = (0..n)
            .find(|&i| {
                let prev = around[(i + n - 1) % n];
                match (prev, around[i]) {
                    (None, Some(_)) => true,
                    (Some(p), Some(f)) => half[p] != half[f],
                    _ => false,
                }
            })
            .unwrap_or(0);
        let mut last: Option<u8> = None;
        for k in 0..n {
            match around[(start + k) % n] {
                Some(f) if last == Some(half[f]) => {
                    if let Some(fan) = fans.last_mut() {
                        fan.1.push(f);
                    }
                }
                Some(f) => {
                    fans.push((half[f], vec![f]));
                    last = Some(half[f]);
                }
                None => last = None,
            }
        }
        for side in 0..2u8 {
            let largest = fans
                .iter()
                .enumerate()
                .filter(|(_, fan)| fan.0 == side)
                .max_by_key(|(_, fan)| fan.1.len())
                .map(|(k, _)| k);
            for (k, fan) in fans.iter().enumerate() {
                if fan.0 == side && Some(k) != largest {
                    for &f in &fan.1 {
                        half[f] = 1 - side;
                    }
                    moved = true;
                }
            }
        }
    }
    moved
}

/// How often pinches are looked for (moving faces may make new ones).
const PINCH_PASSES: usize = 10;

/// How often the border between the halves is straightened.
const SMOOTHING_PASSES: usize = 3;

/// The vertex farthest from `from` and every vertex's distance from `from`.
fn farthest(chart: &Mesh, from: VertexId) -> (VertexId, Vec<f64>) {
    let mut search = ShortestPaths::new(chart);
    search.seed(from);
    search.run();
    let far = (0..chart.vertex_count())
        .filter(|&i| search.dist[i].is_finite())
        .max_by(|&a, &b| search.dist[a].total_cmp(&search.dist[b]))
        .map_or(from, VertexId::from_usize);
    (far, search.dist)
}
