//! Sampling the boundary of the parameter domain once per surface curve.
//!
//! The boundary of a chart consists of the surface's own boundary loops and, after a
//! cut, of two copies of every cut curve. It splits at *nodes* (surface vertices where
//! the number of cut and boundary edges around them is not 2: ends and branch points of
//! the cut graph; a loop without one gets its smallest vertex id) into *runs*, each of
//! which is a copy of one surface *chain* (a path of surface edges between two nodes),
//! walked forwards or backwards. Every chain is divided into `n` pieces of equal length
//! on the surface, and every copy places its samples at the same arc lengths, so that
//! both copies of a seam point lift to the same surface point and become one vertex of
//! the result: the seam is sampled once and the result closes up.

use std::collections::HashMap;

use beltrami_mesh::{HalfedgeId, Mesh, VertexId};

use num_complex::Complex64;

/// A sample's identity on the surface, shared by all its copies on the boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum SeamPoint {
    /// A node: a surface vertex.
    Node(VertexId),
    /// Sample `k` (`0 < k < n`) of chain `chain`, counted in the chain's own direction.
    Chain { chain: usize, k: usize },
}

/// The boundary samples of the parameter domain and the constraint edges joining them.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundarySamples {
    /// The samples in the parameter domain, loop after loop, each loop in the order of
    /// its boundary halfedges.
    pub points: Vec<Complex64>,
    /// Per sample, its vertex of the result: copies of one surface point share it.
    pub vertex: Vec<u32>,
    /// Number of distinct result vertices among the samples.
    pub vertex_count: usize,
    /// Constraint edges between consecutive samples of each loop (indices into
    /// `points`).
    pub edges: Vec<[usize; 2]>,
}

/// Samples the boundary of `chart` (parameter positions `uv`, surface vertex of each
/// chart vertex `to_original`) with pieces of about `spacing(v)` on the surface near
/// surface vertex `v` (a chain takes the mean over its vertices). With a finite
/// `corner_tolerance` (the feature tolerance relative to the spacing), runs of the
/// surface's own boundary (edges with one copy in the chart) are split at their corners
/// (`split_at_corners`); a chart of part of a surface, whose boundary the surface goes
/// on across, passes `f64::INFINITY`.
pub fn sample(
    chart: &Mesh,
    uv: &[Complex64],
    to_original: &[VertexId],
    spacing: impl Fn(VertexId) -> f64,
    corner_tolerance: f64,
) -> BoundarySamples {
    let original = |v: VertexId| to_original[v.idx()];
    let edge_key = |h: HalfedgeId| {
        let (a, b) = (original(chart.origin(h)).0, original(chart.target(h)).0);
        (a.min(b), a.max(b))
    };
    // Cut and boundary edges of the surface around each surface vertex.
    let mut keys: Vec<(u32, u32)> = chart
        .boundary_loops()
        .flat_map(|b| chart.loop_halfedges(b).map(edge_key))
        .collect();
    keys.sort_unstable();
    // An edge of the surface's own boundary has one copy in the chart, a cut edge two.
    let single: std::collections::HashSet<(u32, u32)> = keys
        .chunk_by(|a, b| a == b)
        .filter(|copies| copies.len() == 1)
        .map(|copies| copies[0])
        .collect();
    keys.dedup();
    let mut degree: HashMap<u32, usize> = HashMap::new();
    for &(a, b) in &keys {
        *degree.entry(a).or_default() += 1;
        *degree.entry(b).or_default() += 1;
    }
    let is_node = |v: VertexId| degree.get(&original(v).0) != Some(&2);

    let mut sampling = Sampling {
        out: BoundarySamples {
            points: Vec::new(),
            vertex: Vec::new(),
            vertex_count: 0,
            edges: Vec::new(),
        },
        ids: HashMap::new(),
        chains: HashMap::new(),
    };
    for b in chart.boundary_loops() {
        let mut hs: Vec<HalfedgeId> = chart.loop_halfedges(b).collect();
        let start = hs
            .iter()
            .position(|&h| is_node(chart.origin(h)))
            .unwrap_or_else(|| {
                (0..hs.len())
                    .min_by_key(|&i| original(chart.origin(hs[i])).0)
                    .unwrap_or(0)
            });
        hs.rotate_left(start);
        let first = sampling.out.points.len();
        let mut run: Vec<HalfedgeId> = Vec::new();
        for (i, &h) in hs.iter().enumerate() {
            run.push(h);
            let last = i + 1 == hs.len();
            if last || is_node(chart.target(h)) {
                let mut pieces = Vec::new();
                if corner_tolerance.is_finite() && single.contains(&edge_key(run[0])) {
                    split_at_corners(
                        chart,
                        &original,
                        &run,
                        &spacing,
                        corner_tolerance,
                        &mut pieces,
                    );
                } else {
                    pieces.push(run.clone());
                }
                for piece in &pieces {
                    sample_run(chart, uv, &original, piece, &spacing, &mut sampling);
                }
                run.clear();
            }
        }
        let count = sampling.out.points.len() - first;
        sampling
            .out
            .edges
            .extend((0..count).map(|i| [first + i, first + (i + 1) % count]));
    }
    let mut out = sampling.out;
    out.vertex_count = sampling.ids.len();
    out
}

/// What sampling the runs builds up, run after run.
struct Sampling {
    /// The samples so far (their vertex count is set at the end).
    out: BoundarySamples,
    /// The result vertex of each seam point sampled so far.
    ids: HashMap<SeamPoint, u32>,
    /// The chains met so far, keyed by their surface vertex sequence in their own
    /// direction (the lexicographically smaller of the two): their index and number of
    /// pieces, which every later copy reuses.
    chains: HashMap<Vec<u32>, (usize, usize)>,
}

/// The lengths of the edges of `run`, their sum and the number of pieces the run is
/// sampled with: its length over the mean spacing at its surface vertices (at least 1,
/// or 3 for a run that closes on the surface).
fn pieces_of(
    chart: &Mesh,
    original: &impl Fn(VertexId) -> VertexId,
    run: &[HalfedgeId],
    spacing: &impl Fn(VertexId) -> f64,
) -> (Vec<f64>, f64, usize) {
    let lengths: Vec<f64> = run
        .iter()
        .map(|&h| chart.halfedge_vector(h).norm())
        .collect();
    let total: f64 = lengths.iter().sum();
    let closed = original(chart.origin(run[0])) == original(chart.target(run[run.len() - 1]));
    let vertices = run
        .iter()
        .map(|&h| chart.origin(h))
        .chain(std::iter::once(chart.target(run[run.len() - 1])));
    let mean_spacing = vertices.map(|v| spacing(original(v))).sum::<f64>() / (run.len() + 1) as f64;
    let n = (total / mean_spacing).round() as usize;
    (lengths, total, n.max(if closed { 3 } else { 1 }))
}

/// Splits a run of the surface's own boundary at its vertices until every vertex lies
/// within `tolerance` times the spacing of the chord between the samples around it
/// (Douglas-Peucker with equal-length samples): the boundary keeps its corners as the
/// interior keeps its creases.
fn split_at_corners(
    chart: &Mesh,
    original: &impl Fn(VertexId) -> VertexId,
    run: &[HalfedgeId],
    spacing: &impl Fn(VertexId) -> f64,
    tolerance: f64,
    pieces: &mut Vec<Vec<HalfedgeId>>,
) {
    let (lengths, total, n) = pieces_of(chart, original, run, spacing);
    let step = total / n as f64;
    // The samples, in one sweep along the run.
    let mut samples = Vec::with_capacity(n + 1);
    let (mut edge, mut before) = (0, 0.0);
    for k in 0..=n {
        let s = step * k as f64;
        while edge + 1 < run.len() && before + lengths[edge] < s {
            before += lengths[edge];
            edge += 1;
        }
        let t = if lengths[edge] > 0.0 {
            ((s - before) / lengths[edge]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let h = run[edge];
        let (a, b) = (
            chart.position(chart.origin(h)),
            chart.position(chart.target(h)),
        );
        samples.push(a + (b - a) * t);
    }
    let mut worst = (0.0, 0);
    let mut arc = 0.0;
    for j in 1..run.len() {
        arc += lengths[j - 1];
        let k = ((arc / step).floor() as usize).min(n - 1);
        let (a, b) = (samples[k], samples[k + 1]);
        let p = chart.position(chart.origin(run[j]));
        let ab = b - a;
        let t = if ab.norm_squared() > 0.0 {
            ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let gap = (p - (a + ab * t)).norm() / spacing(original(chart.origin(run[j])));
        if gap > worst.0 {
            worst = (gap, j);
        }
    }
    if worst.0 > tolerance {
        split_at_corners(chart, original, &run[..worst.1], spacing, tolerance, pieces);
        split_at_corners(chart, original, &run[worst.1..], spacing, tolerance, pieces);
    } else {
        pieces.push(run.to_vec());
    }
}

/// Adds the samples of one run (all but its last point, which starts the next run).
fn sample_run(
    chart: &Mesh,
    uv: &[Complex64],
    original: &impl Fn(VertexId) -> VertexId,
    run: &[HalfedgeId],
    spacing: &impl Fn(VertexId) -> f64,
    sampling: &mut Sampling,
) {
    let Sampling { out, ids, chains } = sampling;
    let mut sequence: Vec<u32> = run.iter().map(|&h| original(chart.origin(h)).0).collect();
    sequence.push(original(chart.target(run[run.len() - 1])).0);
    let reversed: Vec<u32> = sequence.iter().rev().copied().collect();
    let forward = sequence <= reversed;
    let (lengths, total, pieces) = pieces_of(chart, original, run, spacing);
    let next_chain = chains.len();
    let (chain, n) = *chains
        .entry(if forward { sequence.clone() } else { reversed })
        .or_insert((next_chain, pieces));
    let mut edge = 0;
    let mut before = 0.0;
    for k in 0..n {
        let s = total * k as f64 / n as f64;
        while edge + 1 < run.len() && before + lengths[edge] < s {
            before += lengths[edge];
            edge += 1;
        }
        let h = run[edge];
        let t = if lengths[edge] > 0.0 {
            ((s - before) / lengths[edge]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (a, b) = (uv[chart.origin(h).idx()], uv[chart.target(h).idx()]);
        let key = if k == 0 {
            SeamPoint::Node(original(chart.origin(run[0])))
        } else {
            SeamPoint::Chain {
                chain,
                k: if forward { k } else { n - k },
            }
        };
        let next = ids.len() as u32;
        out.vertex.push(*ids.entry(key).or_insert(next));
        out.points.push(a + (b - a) * t);
    }
}
