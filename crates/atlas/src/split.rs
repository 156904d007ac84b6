//! Splitting a chart in two where it cannot be laid flat whole: its faces go to the
//! nearer of two far-apart seed vertices (a vertex farthest from the first vertex by
//! edge-path length, then the vertex farthest from that), each face judged by the mean
//! distance of its corners. The border is then straightened: a face most of whose
//! neighbours lie in the other half joins it (a few passes), so that no tooth of single
//! faces sticks out (a tooth is a hairpin of the flat boundary, where charts overlap).
//! Last, no half may touch itself at a vertex (a pinch: its flat boundary would pass
//! twice through one point): at a vertex where a half's faces form several separate
//! fans, all but the largest fan go to the other half.

use beltrami_mesh::{Mesh, VertexId};

use crate::shortest_paths::ShortestPaths;

/// For each face of `chart`, 0 or 1: the half it goes to (see the module docs).
pub fn split_in_two(chart: &Mesh) -> Vec<u8> {
    let first = farthest(chart, VertexId(0)).0;
    let (second, from_first) = farthest(chart, first);
    let from_second = farthest(chart, second).1;
    let mut half: Vec<u8> = chart
        .faces()
        .map(|f| {
            let (a, b) = chart.face_vertices(f).fold((0.0, 0.0), |(a, b), v| {
                (a + from_first[v.idx()], b + from_second[v.idx()])
            });
            u8::from(b < a)
        })
        .collect();
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
