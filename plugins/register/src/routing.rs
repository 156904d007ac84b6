//! The target's cut graph, drawn after the source's: the same nodes and arcs, numbered
//! alike, so that both meshes cut into disks that read the same word
//! ([`crate::skeleton`]).
//!
//! 1. **Placement.** Source positions are carried into the target's frame by a
//!    [`SpatialMatch`]: the similarity fitted to the landmarks when at least three (not
//!    on one line) are given, otherwise the rough match of centroids and sizes refined
//!    by closest points (an affine map, `crate::affine_alignment`: two shapes stretched
//!    differently along the axes overlap, so that the closest points below fall on the
//!    right handle), then warped ([`Warp`]) so that known correspondences land on their partners: the
//!    landmarks, points of the paired boundary loops and, on a closed surface without
//!    the landmarks' similarity, the closest points on the target of up to
//!    [`WARP_SURFACE_SAMPLES`] spread source vertices (two surfaces of different shapes
//!    then overlap where the arcs are drawn, and each arc's corridor follows the
//!    target's own handle; with boundary loops their points anchor the warp, and
//!    closest points there made the four-boundary faces' initial map worse).
//! 2. **Boundary loops** are paired by the landmarks whose source and target are both on
//!    a boundary loop (two landmarks pairing one loop with two others are refused, naming
//!    them), then the rest by the smallest sum of distances between the placed source
//!    loops and the target loops (the symmetric mean distance of their vertices, up to
//!    256 of each; all pairings tried up to eight loops, nearest first beyond).
//! 3. **Nodes** on a boundary loop keep their arc-length fractions along it, measured
//!    from anchors: the landmarks on the loop (linear in arc length between them), or
//!    else the best of 360 rotations of the placed loop moved onto its partner's
//!    centroid (a loop placed off its partner still finds its turn). So their cyclic
//!    order along the loop is kept, and landmarks on loops are made nodes. The
//!    other nodes go to the nearest free interior target vertex of their placed
//!    positions.
//! 4. **Arcs** along a boundary loop follow the paired target loop in the same sense.
//!    The other arcs, shortest first, are shortest paths on the target that avoid the
//!    boundary, every node but their own two ends and every arc drawn before, for the
//!    edge cost `|e| (1 + (d / s)^2)`: `d` the distance of the edge's far end from the
//!    placed source arc, `s` 2% of the target's bounding-box diagonal (at least twice its
//!    mean edge length). The penalty keeps a path in a corridor about the placed arc,
//!    so it goes around the same handles and holes. The path goes through waypoints,
//!    the target vertices nearest to the placed arc's vertices; a leg to a waypoint
//!    longer than [`DETOUR`] times the stretch of placed arc it stands for goes round a
//!    handle the placed arc does not (the waypoint lies across an arc drawn before):
//!    the waypoint is skipped, and a last leg into the arc's end that is such a detour
//!    (the legs before it reached the end from the wrong side) drops them from the end.
//!    An arc drawn round a tube that the source's arc runs along would make the map a
//!    twist about that tube, which no flow undoes.
//!
//! The word of the target's cut is then compared with the source's by the caller: a
//! geometry too different for the placement to find the same pattern is refused there,
//! with landmarks as the way out.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet, VecDeque};

use beltrami_mesh::{HalfedgeId, Mesh, Point3, VertexId};
use beltrami_spatial::SurfaceIndex;
use kiddo::SquaredEuclidean;
use kiddo::kd_tree::KdTree;
use kiddo::leaf_strategies::VecOfArenas;
use kiddo::stem_strategies::eytzinger::Eytzinger;

use crate::error::RegisterError;
use crate::landmarks::{Resolved, SpatialMatch};
use crate::param::arc_fractions;
use crate::skeleton::{Arc, Ordered, Skeleton, halfedge_between};

/// Rotations of a boundary loop tried when no landmark anchors it.
const LOOP_ROTATIONS: usize = 360;

/// Vertices of a loop compared when pairing loops, at most.
const LOOP_SAMPLES: usize = 256;

/// Loop pairings tried exhaustively up to this many loops.
const EXHAUSTIVE_LOOPS: usize = 8;

/// A landmark target this close to a target boundary loop (relative to the target's
/// diagonal) counts as on it.
const ON_LOOP: f64 = 1e-9;

/// The corridor width `s` of the arc cost, relative to the target's diagonal.
const CORRIDOR: f64 = 0.02;

/// The cost factor of a step through a node's 1-ring by an arc that does not end at
/// that node (or further on after a step into the ring of its end): such steps take
/// room the node's own arcs need, and are left for when there is no other way.
const RING_COST: f64 = 50.0;

/// A leg of a drawn arc longer than this many times the stretch of the placed arc it
/// stands for (plus two corridor widths) goes round a handle the placed arc does not.
const DETOUR: f64 = 3.0;

/// Points of every boundary loop that refine the placement ([`Warp`]), at most.
const WARP_LOOP_SAMPLES: usize = 32;

/// Vertices of the mesh with the cut graph whose closest points on the other one refine
/// a placement no landmarks fix ([`Warp`]), at most.
const WARP_SURFACE_SAMPLES: usize = 256;

/// Points per kd-tree leaf.
const BUCKET: usize = 16;

/// A kd-tree of the samples of a placed arc.
type Tree = KdTree<f64, u32, Eytzinger, VecOfArenas<f64, u32, 3, BUCKET>, 3, BUCKET>;

/// The boundary loops of a mesh: vertices in loop order and each boundary vertex's loop.
pub(crate) struct Loops {
    /// The loops' vertices, in `boundary_loop_list` order.
    pub vertices: Vec<Vec<VertexId>>,
    /// Per vertex, its loop (`usize::MAX` off the boundary).
    pub of_vertex: Vec<usize>,
}

impl Loops {
    /// The loops of `mesh`.
    pub fn of(mesh: &Mesh) -> Self {
        let vertices: Vec<Vec<VertexId>> = mesh
            .boundary_loop_list()
            .into_iter()
            .map(|l| l.vertices)
            .collect();
        let mut of_vertex = vec![usize::MAX; mesh.vertex_count()];
        for (k, l) in vertices.iter().enumerate() {
            for v in l {
                of_vertex[v.idx()] = k;
            }
        }
        Self {
            vertices,
            of_vertex,
        }
    }
}

/// The similarity that places positions of the mesh with the cut graph in the frame of
/// the other one, and whether the landmarks gave it: the similarity fitted to the
/// landmarks, or else the rough match of centroids and sizes.
fn placement(from: &Mesh, onto: &Mesh, pins: &[Pin]) -> (SpatialMatch, bool) {
    let a: Vec<Point3<f64>> = pins.iter().map(|p| p.from).collect();
    let b: Vec<Point3<f64>> = pins.iter().map(|p| p.onto).collect();
    match SpatialMatch::fitted(&a, &b) {
        Some(fit) => (fit, true),
        None => (SpatialMatch::new(from, onto), false),
    }
}

/// [`placement`], the rough match refined by closest points on `onto_index`'s mesh
/// (`crate::affine_alignment`) when no landmarks fix it (module docs, step 1).
///
/// # Errors
/// [`RegisterError::Spatial`] when a closest point cannot be found.
pub(crate) fn refined_placement(
    from: &Mesh,
    onto: &Mesh,
    onto_index: &SurfaceIndex<'_>,
    pins: &[Pin],
) -> Result<(SpatialMatch, bool), RegisterError> {
    match placement(from, onto, pins) {
        (rough, false) => Ok((rough.refined_by_closest_points(from, onto_index)?, false)),
        fitted => Ok(fitted),
    }
}

/// The target loop paired with every source loop (module docs): the loops the
/// landmarks pair ([`pair_marked_loops`]), the others by their distance once `place`d.
///
/// # Errors
/// [`RegisterError::Landmark`] for a landmark with one end on a boundary loop and the
/// other not, or one that pairs a loop already paired otherwise.
pub(crate) fn pair_loops(
    source: &Mesh,
    target: &Mesh,
    source_loops: &Loops,
    target_loops: &Loops,
    marks: &[Resolved],
    place: &SpatialMatch,
) -> Result<Vec<usize>, RegisterError> {
    let k = source_loops.vertices.len();
    let pair = pair_marked_loops(target, source_loops, target_loops, marks)?;
    let mut taken = vec![false; k];
    for &(t, _) in pair.iter().flatten() {
        taken[t] = true;
    }
    let samples = |mesh: &Mesh, vertices: &[VertexId], moved: bool| -> Vec<Point3<f64>> {
        let step = vertices.len().div_ceil(LOOP_SAMPLES).max(1);
        vertices
            .iter()
            .step_by(step)
            .map(|&v| {
                let p = mesh.position(v);
                if moved { place.to_target(&p) } else { p }
            })
            .collect()
    };
    let free_sources: Vec<usize> = (0..k).filter(|&s| pair[s].is_none()).collect();
    let free_targets: Vec<usize> = (0..k).filter(|&t| !taken[t]).collect();
    let target_samples: Vec<Vec<Point3<f64>>> = free_targets
        .iter()
        .map(|&t| samples(target, &target_loops.vertices[t], false))
        .collect();
    let cost: Vec<Vec<f64>> = free_sources
        .iter()
        .map(|&s| {
            let a = samples(source, &source_loops.vertices[s], true);
            target_samples.iter().map(|b| chamfer(&a, b)).collect()
        })
        .collect();
    let chosen = cheapest_assignment(&cost);
    let mut out: Vec<usize> = pair.iter().map(|p| p.map_or(usize::MAX, |p| p.0)).collect();
    for (i, &s) in free_sources.iter().enumerate() {
        out[s] = free_targets[chosen[i]];
    }
    Ok(out)
}

/// Per source loop, the target loop a landmark pairs it with and the first such
/// landmark's index, if any.
///
/// # Errors
/// As [`pair_loops`].
fn pair_marked_loops(
    target: &Mesh,
    source_loops: &Loops,
    target_loops: &Loops,
    marks: &[Resolved],
) -> Result<Vec<Option<(usize, usize)>>, RegisterError> {
    let k = source_loops.vertices.len();
    let mut pair: Vec<Option<(usize, usize)>> = vec![None; k];
    let mut taken: Vec<Option<usize>> = vec![None; k];
    for mark in marks {
        let s = source_loops.of_vertex[mark.source.idx()];
        let t = target_loop_of(target, target_loops, mark);
        let fail = |reason: String| RegisterError::Landmark {
            index: mark.index,
            vertex: mark.source,
            reason,
        };
        match (s != usize::MAX, t) {
            (false, None) => continue,
            (true, None) => {
                return Err(fail(
                    "the source vertex is on a boundary loop but its target is not: boundary loops go onto boundary loops".to_string(),
                ));
            }
            (false, Some(_)) => {
                return Err(fail(
                    "the source vertex is off the boundary but its target is on a boundary loop: boundary loops go onto boundary loops".to_string(),
                ));
            }
            (true, Some(t)) => {
                if let Some((other, index)) = pair[s]
                    && other != t
                {
                    return Err(fail(format!(
                        "it puts source boundary loop {s} onto target loop {t}, landmark {index} onto target loop {other}"
                    )));
                }
                if let Some(index) = taken[t]
                    && pair[s].is_none()
                {
                    return Err(fail(format!(
                        "it puts source boundary loop {s} onto target loop {t}, which landmark {index} gives to another source loop"
                    )));
                }
                pair[s] = Some((t, mark.index));
                taken[t].get_or_insert(mark.index);
            }
        }
    }
    Ok(pair)
}

/// The symmetric mean distance between two point sets: the mean distance from each
/// point of one to the nearest of the other, both ways, added.
fn chamfer(a: &[Point3<f64>], b: &[Point3<f64>]) -> f64 {
    let one_way = |x: &[Point3<f64>], y: &[Point3<f64>]| {
        x.iter()
            .map(|p| {
                y.iter()
                    .map(|q| (p - q).norm())
                    .fold(f64::INFINITY, f64::min)
            })
            .sum::<f64>()
            / x.len().max(1) as f64
    };
    one_way(a, b) + one_way(b, a)
}

/// The target loop a landmark's target lies on, if any.
fn target_loop_of(target: &Mesh, loops: &Loops, mark: &Resolved) -> Option<usize> {
    if let Some(v) = mark.vertex {
        let l = loops.of_vertex[v.idx()];
        return (l != usize::MAX).then_some(l);
    }
    let (vertices, degree) = target.face_vertex_array(mark.target.face);
    let tolerance = ON_LOOP * target.bounding_box().diagonal();
    let p = mark.target.position(target);
    let at_vertex = vertices[..degree].iter().find(|&&u| {
        loops.of_vertex[u.idx()] != usize::MAX && (target.position(u) - p).norm() <= tolerance
    });
    if let Some(u) = at_vertex {
        return Some(loops.of_vertex[u.idx()]);
    }
    (0..degree).find_map(|k| {
        let (u, w) = (vertices[k], vertices[(k + 1) % degree]);
        let h = halfedge_between(target, u, w)?;
        if !target.is_boundary_edge(target.edge(h)) {
            return None;
        }
        let c = beltrami_spatial::closest_point::closest_on_segment(
            &p,
            &target.position(u),
            &target.position(w),
        );
        (c.distance() <= tolerance).then_some(loops.of_vertex[u.idx()])
    })
}

/// The assignment of rows to distinct columns with the smallest total cost: every
/// permutation up to [`EXHAUSTIVE_LOOPS`] rows, the cheapest remaining pair first beyond.
fn cheapest_assignment(cost: &[Vec<f64>]) -> Vec<usize> {
    let n = cost.len();
    if n <= EXHAUSTIVE_LOOPS {
        let mut best = (f64::INFINITY, (0..n).collect::<Vec<usize>>());
        let mut current: Vec<usize> = (0..n).collect();
        permute(&mut current, 0, cost, &mut best);
        return best.1;
    }
    let mut out = vec![usize::MAX; n];
    let mut used = vec![false; n];
    let mut pairs: Vec<(f64, usize, usize)> = (0..n)
        .flat_map(|r| (0..n).map(move |c| (r, c)))
        .map(|(r, c)| (cost[r][c], r, c))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, r, c) in pairs {
        if out[r] == usize::MAX && !used[c] {
            out[r] = c;
            used[c] = true;
        }
    }
    out
}

fn permute(current: &mut [usize], k: usize, cost: &[Vec<f64>], best: &mut (f64, Vec<usize>)) {
    if k == current.len() {
        let total: f64 = current.iter().enumerate().map(|(r, &c)| cost[r][c]).sum();
        if total < best.0 {
            *best = (total, current.to_vec());
        }
        return;
    }
    for i in k..current.len() {
        current.swap(k, i);
        permute(current, k + 1, cost, best);
        current.swap(k, i);
    }
}

/// A landmark as the drawing reads it: its point on the mesh whose cut graph is drawn
/// and its point on the mesh it is drawn onto (each a vertex when it is one).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pin {
    /// The point on the mesh with the cut graph.
    pub from: Point3<f64>,
    /// That point's vertex, when it is one.
    pub from_vertex: Option<VertexId>,
    /// The corresponding point on the other mesh.
    pub onto: Point3<f64>,
    /// That point's vertex, when it is one.
    pub onto_vertex: Option<VertexId>,
    /// The landmark's index, for messages.
    pub index: usize,
    /// The landmark's source vertex, for messages.
    pub vertex: VertexId,
}

/// Everything the drawing of a cut graph onto the other mesh reads. The cut graph is
/// the coarser mesh's, drawn onto the finer one, which has room for it (the caller
/// chooses; "source" and "target" below are the registration's).
pub(crate) struct Drawing<'a> {
    /// The mesh whose cut graph is drawn.
    pub from: &'a Mesh,
    /// Which mesh of the registration it is, for messages.
    pub from_side: crate::error::Side,
    /// Its cut skeleton.
    pub skeleton: &'a Skeleton,
    /// The mesh it is drawn onto.
    pub onto: &'a Mesh,
    /// Its closest-point index.
    pub onto_index: &'a SurfaceIndex<'a>,
    /// The landmarks.
    pub pins: &'a [Pin],
    /// Positions of `from` into the frame of `onto`.
    pub place: &'a SpatialMatch,
    /// The boundary loops of `from`.
    pub from_loops: &'a Loops,
    /// The boundary loops of `onto`.
    pub onto_loops: &'a Loops,
    /// The loop of `onto` paired with every loop of `from`.
    pub paired: &'a [usize],
}

impl Drawing<'_> {
    /// The target's skeleton (module docs).
    ///
    /// # Errors
    /// [`RegisterError::Seams`] when a node finds no free target vertex or an arc no path.
    pub fn draw(&self) -> Result<Skeleton, RegisterError> {
        let (nodes, warp) = self.nodes()?;
        let lengths: Vec<f64> = self
            .skeleton
            .arcs
            .iter()
            .map(|a| a.length(self.from))
            .collect();
        let on_boundary: Vec<bool> = self
            .skeleton
            .arcs
            .iter()
            .map(|a| a.on_boundary(self.from))
            .collect();
        let mut order: Vec<usize> = (0..self.skeleton.arcs.len()).collect();
        order.sort_by(|&a, &b| lengths[a].total_cmp(&lengths[b]));
        // Boundary arcs first: they are fixed by the nodes.
        order.sort_by_key(|&a| !on_boundary[a]);
        let interior = on_boundary.iter().filter(|&&b| !b).count();
        let mut failure = None;
        for _ in 0..interior.max(1) {
            match self.draw_in_order(&nodes, &warp, &order, &on_boundary)? {
                Ok(arcs) => return Ok(Skeleton { nodes, arcs }),
                Err((a, error)) => {
                    // Again, with the arc that found no way drawn before the others.
                    failure = Some(error);
                    let k = order.iter().position(|&x| x == a).unwrap_or(0);
                    let first_interior = order.len() - interior;
                    if k == first_interior {
                        break;
                    }
                    order.remove(k);
                    order.insert(first_interior, a);
                }
            }
        }
        Err(failure.unwrap_or_else(|| self.seams("no arc to draw".to_string())))
    }

    /// The arcs drawn in `order` (`on_boundary` telling the arcs along boundary loops),
    /// or the first arc that found no path and why.
    #[allow(clippy::type_complexity)]
    fn draw_in_order(
        &self,
        nodes: &[VertexId],
        warp: &Warp<'_>,
        order: &[usize],
        on_boundary: &[bool],
    ) -> Result<Result<Vec<Arc>, (usize, RegisterError)>, RegisterError> {
        let mut blocked = vec![false; self.onto.vertex_count()];
        for l in &self.onto_loops.vertices {
            for v in l {
                blocked[v.idx()] = true;
            }
        }
        for n in nodes {
            blocked[n.idx()] = true;
        }
        // The 1-rings of the nodes are kept for the arcs that end there.
        let mut rings: HashMap<VertexId, Vec<VertexId>> = HashMap::new();
        for &n in nodes {
            for w in self.onto.vertex_neighbors(n) {
                rings.entry(w).or_default().push(n);
            }
        }
        let mut used_edge = vec![false; self.onto.edge_count()];
        let mut drawn_ends: HashMap<(usize, usize), HalfedgeId> = HashMap::new();
        let mut arcs: Vec<Option<Arc>> = vec![None; self.skeleton.arcs.len()];
        for &a in order {
            let arc = &self.skeleton.arcs[a];
            let [from, to] = arc.ends.map(|n| nodes[n]);
            let vertices = if on_boundary[a] {
                self.along_loop(arc, from, to, nodes)?
            } else {
                let wedges = [0, 1].map(|end| self.wedge(a, end, nodes, &drawn_ends));
                match self.route(a, [from, to], warp, (&blocked, &rings), &used_edge, &wedges) {
                    Ok(path) => path,
                    Err(RegisterError::Seams { reason }) => {
                        return Ok(Err((a, RegisterError::Seams { reason })));
                    }
                    Err(other) => return Err(other),
                }
            };
            let n = vertices.len();
            if n < 2 {
                return Ok(Err((
                    a,
                    self.seams(format!(
                        "the cut graph's arc {a} was drawn as a single vertex"
                    )),
                )));
            }
            for (end, pair) in [
                (0, [vertices[0], vertices[1]]),
                (1, [vertices[n - 1], vertices[n - 2]]),
            ] {
                if let Some(h) = halfedge_between(self.onto, pair[0], pair[1]) {
                    drawn_ends.insert((a, end), h);
                }
            }
            for pair in vertices.windows(2) {
                if let Some(h) = halfedge_between(self.onto, pair[0], pair[1]) {
                    used_edge[self.onto.edge(h).idx()] = true;
                }
            }
            for v in &vertices {
                blocked[v.idx()] = true;
            }
            arcs[a] = Some(Arc {
                vertices,
                ends: arc.ends,
            });
        }
        Ok(Ok(arcs.into_iter().flatten().collect()))
    }

    /// The outgoing target halfedges at the node of end `end` (0 first, 1 last) of arc
    /// `a` through which it may leave so that the arcs around the node keep the
    /// source's cyclic order: those strictly between the drawn arcs that come before and
    /// after it around the source's node. `None` when no arc there is drawn yet.
    fn wedge(
        &self,
        a: usize,
        end: usize,
        nodes: &[VertexId],
        drawn_ends: &HashMap<(usize, usize), HalfedgeId>,
    ) -> Option<Vec<HalfedgeId>> {
        let node = self.skeleton.arcs[a].ends[end];
        let around = self.rotation_at(node);
        let k = around.iter().position(|&x| x == (a, end))?;
        let m = around.len();
        // The undrawn ends between the drawn ones before and after this one: room is
        // left for those before it and those after it.
        let ahead = (1..m).find(|&i| drawn_ends.contains_key(&around[(k + i) % m]))?;
        let behind = (1..m)
            .find(|&i| drawn_ends.contains_key(&around[(k + m - i) % m]))
            .unwrap_or(ahead);
        let after = drawn_ends[&around[(k + ahead) % m]];
        let before = drawn_ends[&around[(k + m - behind) % m]];
        let (room_before, room_after) = (behind - 1, ahead - 1);
        let target_around: Vec<HalfedgeId> = self.onto.outgoing_halfedges(nodes[node]).collect();
        let t = target_around.len();
        let start = target_around.iter().position(|&h| h == before)?;
        let gap: Vec<HalfedgeId> = (1..t)
            .map(|i| target_around[(start + i) % t])
            .take_while(|&h| h != after || before == after)
            .collect();
        Some(
            gap.iter()
                .skip(room_before)
                .take(gap.len().saturating_sub(room_before + room_after))
                .copied()
                .collect(),
        )
    }

    /// The arc ends at source node `node` in the order of its outgoing halfedges.
    fn rotation_at(&self, node: usize) -> Vec<(usize, usize)> {
        let v = self.skeleton.nodes[node];
        let mut out = Vec::new();
        for h in self.from.outgoing_halfedges(v) {
            let w = self.from.target(h);
            for (a, arc) in self.skeleton.arcs.iter().enumerate() {
                let n = arc.vertices.len();
                if arc.vertices[0] == v && arc.vertices[1] == w {
                    out.push((a, 0));
                }
                if arc.vertices[n - 1] == v && arc.vertices[n - 2] == w {
                    out.push((a, 1));
                }
            }
        }
        out
    }

    /// The target vertex of every source node (module docs, step 3).
    fn nodes(&self) -> Result<(Vec<VertexId>, Warp<'_>), RegisterError> {
        let mut out = vec![None; self.skeleton.nodes.len()];
        let mut taken = vec![false; self.onto.vertex_count()];
        let mut pairs: Vec<(Point3<f64>, Point3<f64>)> =
            self.pins.iter().map(|p| (p.from, p.onto)).collect();
        // Nodes on boundary loops, loop by loop.
        for s in 0..self.from_loops.vertices.len() {
            self.loop_nodes(s, &mut out, &mut taken, &mut pairs)?;
        }
        if self.pins.len() < 3 && self.from_loops.vertices.is_empty() {
            self.surface_pairs(&mut pairs)?;
        }
        let warp = Warp::new(self.place, &pairs, self.onto);
        self.landmark_nodes(&mut out, &mut taken);
        // Other interior nodes: the nearest free interior vertex, by rings around the
        // located face.
        for (n, &v) in self.skeleton.nodes.iter().enumerate() {
            if out[n].is_some() {
                continue;
            }
            let p = warp.to_target(&self.from.position(v));
            let face = self.onto_index.locate(&p)?.point.face;
            let chosen = self.nearest_free(&p, face, &taken).ok_or_else(|| {
                self.seams(format!(
                    "no free interior target vertex for the cut graph's node at source vertex {}",
                    self.from.vertex_map().to_input(v)
                ))
            })?;
            taken[chosen.idx()] = true;
            out[n] = Some(chosen);
        }
        Ok((out.into_iter().flatten().collect(), warp))
    }

    /// The target vertices of the nodes on boundary loop `s` (into `out`, marked in
    /// `taken`), at their anchored arc-length fractions along the paired loop, and
    /// spread points of the loop with their partners for the warp (into `pairs`).
    ///
    /// # Errors
    /// The errors of [`loop_anchors`]; [`RegisterError::Seams`] when the paired loop
    /// has fewer free vertices than the loop has nodes.
    fn loop_nodes(
        &self,
        s: usize,
        out: &mut [Option<VertexId>],
        taken: &mut [bool],
        pairs: &mut Vec<(Point3<f64>, Point3<f64>)>,
    ) -> Result<(), RegisterError> {
        let loop_vertices = &self.from_loops.vertices[s];
        let target_loop = &self.onto_loops.vertices[self.paired[s]];
        let sigma = arc_fractions(self.from, loop_vertices);
        let tau = arc_fractions(self.onto, target_loop);
        let anchors = loop_anchors(
            self.onto,
            self.pins,
            &LoopPair {
                indices: [s, self.paired[s]],
                vertices: [loop_vertices, target_loop],
                fractions: [&sigma, &tau],
            },
        )?;
        let shift = if anchors.is_empty() {
            self.best_rotation(loop_vertices, &sigma, target_loop, &tau)
        } else {
            0.0
        };
        let fraction = |position: usize| {
            if anchors.is_empty() {
                (sigma[position] + shift).rem_euclid(1.0)
            } else {
                along_anchors(&anchors, &sigma, &tau, sigma[position])
            }
        };
        let step = loop_vertices.len().div_ceil(WARP_LOOP_SAMPLES).max(1);
        for position in (0..loop_vertices.len()).step_by(step) {
            pairs.push((
                self.from.position(loop_vertices[position]),
                loop_point(self.onto, target_loop, &tau, fraction(position)),
            ));
        }
        let on_loop: Vec<(usize, usize)> = self
            .skeleton
            .nodes
            .iter()
            .enumerate()
            .filter_map(|(n, v)| {
                loop_vertices
                    .iter()
                    .position(|w| w == v)
                    .map(|position| (n, position))
            })
            .collect();
        for &(_, position) in &on_loop {
            if let Some(a) = anchors.iter().find(|a| a.position == position) {
                taken[target_loop[a.target].idx()] = true;
            }
        }
        for (n, position) in on_loop {
            if let Some(a) = anchors.iter().find(|a| a.position == position) {
                out[n] = Some(target_loop[a.target]);
                continue;
            }
            let want = fraction(position);
            let nearest = (0..target_loop.len())
                .filter(|&j| !taken[target_loop[j].idx()])
                .min_by(|&i, &j| circular(tau[i], want).total_cmp(&circular(tau[j], want)))
                .ok_or_else(|| self.seams(format!(
                    "target boundary loop {} has fewer vertices than the source's cut graph meets it",
                    self.paired[s]
                )))?;
            taken[target_loop[nearest].idx()] = true;
            out[n] = Some(target_loop[nearest]);
        }
        Ok(())
    }

    /// For a closed surface with no similarity from landmarks (nor boundary loops to
    /// anchor it): spread samples with their closest points on the other surface (into
    /// `pairs`), which pull the rough placement onto it.
    fn surface_pairs(
        &self,
        pairs: &mut Vec<(Point3<f64>, Point3<f64>)>,
    ) -> Result<(), RegisterError> {
        let step = self
            .from
            .vertex_count()
            .div_ceil(WARP_SURFACE_SAMPLES)
            .max(1);
        for v in self.from.vertices().step_by(step) {
            let p = self.from.position(v);
            let located = self.onto_index.locate(&self.place.to_target(&p))?;
            pairs.push((p, located.position));
        }
        Ok(())
    }

    /// The interior nodes at landmarks (into `out`, marked in `taken`): at their
    /// partners' vertices, or the interior vertex nearest to a partner point; a vertex
    /// already taken is left to the other interior nodes' search.
    fn landmark_nodes(&self, out: &mut [Option<VertexId>], taken: &mut [bool]) {
        for (n, &v) in self.skeleton.nodes.iter().enumerate() {
            if out[n].is_some() {
                continue;
            }
            if let Some(pin) = self.pins.iter().find(|p| p.from_vertex == Some(v)) {
                let vertex = pin.onto_vertex.unwrap_or_else(|| {
                    self.onto
                        .vertices()
                        .filter(|&w| !self.onto.is_boundary_vertex(w))
                        .min_by(|&a, &b| {
                            (self.onto.position(a) - pin.onto)
                                .norm_squared()
                                .total_cmp(&(self.onto.position(b) - pin.onto).norm_squared())
                        })
                        .unwrap_or(v)
                });
                if !std::mem::replace(&mut taken[vertex.idx()], true) {
                    out[n] = Some(vertex);
                }
            }
        }
    }

    /// The shift of arc-length fractions from a source loop onto its target loop that
    /// best matches the placed positions, of [`LOOP_ROTATIONS`] tried.
    fn best_rotation(
        &self,
        source_loop: &[VertexId],
        sigma: &[f64],
        target_loop: &[VertexId],
        tau: &[f64],
    ) -> f64 {
        // Each loop about its own centroid: a loop placed off its partner still finds
        // its rotation.
        let centroid = |points: &[Point3<f64>]| {
            Point3::from(
                points
                    .iter()
                    .map(|p| p.coords)
                    .sum::<nalgebra::Vector3<f64>>()
                    / points.len().max(1) as f64,
            )
        };
        let placed: Vec<Point3<f64>> = source_loop
            .iter()
            .map(|&v| self.place.to_target(&self.from.position(v)))
            .collect();
        let partner: Vec<Point3<f64>> =
            target_loop.iter().map(|&v| self.onto.position(v)).collect();
        let offset = centroid(&partner) - centroid(&placed);
        let moved: Vec<Point3<f64>> = placed.iter().map(|p| p + offset).collect();
        let point_at = |t: f64| loop_point(self.onto, target_loop, tau, t);
        (0..LOOP_ROTATIONS)
            .map(|k| k as f64 / LOOP_ROTATIONS as f64)
            .map(|d| {
                let cost: f64 = moved
                    .iter()
                    .zip(sigma)
                    .map(|(p, s)| (p - point_at(s + d)).norm_squared())
                    .sum();
                (d, cost)
            })
            .fold(
                (0.0, f64::INFINITY),
                |best, c| if c.1 < best.1 { c } else { best },
            )
            .0
    }

    /// The free interior target vertex nearest to `p`, searched ring by ring from the
    /// vertices of `face` until a ring has one.
    fn nearest_free(
        &self,
        p: &Point3<f64>,
        face: beltrami_mesh::FaceId,
        taken: &[bool],
    ) -> Option<VertexId> {
        let mesh = self.onto;
        let mut ring: Vec<VertexId> = mesh.face_vertices(face).collect();
        let mut seen: HashSet<VertexId> = ring.iter().copied().collect();
        let mut queue = VecDeque::new();
        while !ring.is_empty() {
            let best = ring
                .iter()
                .filter(|v| !taken[v.idx()] && !mesh.is_boundary_vertex(**v))
                .min_by(|a, b| {
                    (mesh.position(**a) - p)
                        .norm_squared()
                        .total_cmp(&(mesh.position(**b) - p).norm_squared())
                });
            if let Some(&v) = best {
                return Some(v);
            }
            queue.extend(ring.drain(..));
            while let Some(v) = queue.pop_front() {
                for w in mesh.vertex_neighbors(v) {
                    if seen.insert(w) {
                        ring.push(w);
                    }
                }
            }
        }
        None
    }

    /// The target path along the loop of `from` and `to` in the sense of the source arc.
    fn along_loop(
        &self,
        arc: &Arc,
        from: VertexId,
        to: VertexId,
        nodes: &[VertexId],
    ) -> Result<Vec<VertexId>, RegisterError> {
        let source_loop =
            &self.from_loops.vertices[self.from_loops.of_vertex[arc.vertices[0].idx()]];
        let n = source_loop.len();
        let i = source_loop
            .iter()
            .position(|&v| v == arc.vertices[0])
            .unwrap_or(0);
        let with_loop = source_loop[(i + 1) % n] == arc.vertices[1];
        let l = self.onto_loops.of_vertex[from.idx()];
        let target_loop = &self.onto_loops.vertices[l];
        let m = target_loop.len();
        let mut j = target_loop.iter().position(|&v| v == from).unwrap_or(0);
        let mut out = vec![from];
        for _ in 0..m {
            j = if with_loop {
                (j + 1) % m
            } else {
                (j + m - 1) % m
            };
            let v = target_loop[j];
            out.push(v);
            if v == to {
                return Ok(out);
            }
            if nodes.contains(&v) {
                break;
            }
        }
        Err(self.seams(format!(
            "the nodes of the cut graph on target boundary loop {l} are not in the source's order along it"
        )))
    }

    /// A path for arc `a` from `from` to `to` (module docs, step 4): through waypoints,
    /// the free target vertices nearest to the placed interior vertices of the arc in
    /// order, each leg the cheapest path in the arc's corridor that avoids what is drawn
    /// (the legs before it included). A waypoint no leg can reach is skipped.
    fn route(
        &self,
        a: usize,
        [from, to]: [VertexId; 2],
        warp: &Warp<'_>,
        (blocked, rings): (&[bool], &HashMap<VertexId, Vec<VertexId>>),
        used_edge: &[bool],
        wedges: &[Option<Vec<HalfedgeId>>; 2],
    ) -> Result<Vec<VertexId>, RegisterError> {
        let [first, last_wedge] = wedges.each_ref().map(Option::as_deref);
        let arc = &self.skeleton.arcs[a];
        // The placed arc: the waypoints, the corridor and the detours' yardstick.
        let placed: Vec<Point3<f64>> = arc
            .vertices
            .iter()
            .map(|&v| warp.to_target(&self.from.position(v)))
            .collect();
        let mut route = ArcRoute {
            drawing: self,
            arc,
            from,
            first,
            corridor: Corridor::new(&placed, warp.corridor_width),
            corridor_width: warp.corridor_width,
            along: lengths_along(&placed),
            placed,
            rings,
            blocked: blocked.to_vec(),
            used_edge: used_edge.to_vec(),
            legs: Vec::new(),
            ends: Vec::new(),
        };
        route.through_waypoints()?;
        route.last_leg(to, last_wedge)?;
        Ok(route.path())
    }

    /// Marks the vertices (but the first) and edges of `leg` as drawn, or, with
    /// `drawn` false, as free again.
    fn take(&self, leg: &[VertexId], blocked: &mut [bool], used_edge: &mut [bool], drawn: bool) {
        for pair in leg.windows(2) {
            if let Some(h) = halfedge_between(self.onto, pair[0], pair[1]) {
                used_edge[self.onto.edge(h).idx()] = drawn;
            }
            blocked[pair[1].idx()] = drawn;
        }
    }

    fn seams(&self, reason: String) -> RegisterError {
        RegisterError::Seams { reason }
    }
}

/// The length of a polyline from its start to each of its points: a leg is measured
/// against the stretch of the placed arc it stands for.
fn lengths_along(placed: &[Point3<f64>]) -> Vec<f64> {
    let mut along = Vec::with_capacity(placed.len());
    let mut length = 0.0;
    for (k, p) in placed.iter().enumerate() {
        length += k.checked_sub(1).map_or(0.0, |j| (p - placed[j]).norm());
        along.push(length);
    }
    along
}

/// One interior arc's path on the other mesh while it is drawn ([`Drawing::route`]):
/// the placed arc, its corridor, the legs drawn so far and what they and the arcs
/// drawn before block.
struct ArcRoute<'d, 'a> {
    /// The drawing the arc belongs to.
    drawing: &'d Drawing<'a>,
    /// The source arc.
    arc: &'d Arc,
    /// The target vertex the path starts at.
    from: VertexId,
    /// The outgoing halfedges at `from` the path may leave by, when restricted.
    first: Option<&'d [HalfedgeId]>,
    /// The placed arc: the waypoints, the corridor and the detours' yardstick.
    placed: Vec<Point3<f64>>,
    /// The placed arc's length from its start to each of its vertices.
    along: Vec<f64>,
    /// The corridor about the placed arc.
    corridor: Corridor,
    /// The corridor's width.
    corridor_width: f64,
    /// The target vertices in the 1-rings of nodes, with their nodes.
    rings: &'d HashMap<VertexId, Vec<VertexId>>,
    /// The target vertices drawn through, the legs' included.
    blocked: Vec<bool>,
    /// The target edges drawn along, the legs' included.
    used_edge: Vec<bool>,
    /// The legs drawn so far, each from the end of the one before.
    legs: Vec<Vec<VertexId>>,
    /// The index of the arc vertex each leg ends at.
    ends: Vec<usize>,
}

impl<'d> ArcRoute<'d, '_> {
    /// Where the next leg starts, and the wedge it must leave by (only at `from`).
    fn leg_start(&self) -> (VertexId, Option<&'d [HalfedgeId]>) {
        match self.legs.last().and_then(|l| l.last()) {
            Some(&end) => (end, None),
            None => (self.from, self.first),
        }
    }

    /// Whether `leg`, standing for the placed arc from its vertex `from` to `to`, is
    /// longer than [`DETOUR`] times that stretch (plus two corridor widths): it goes
    /// round a handle the placed arc does not.
    fn detour(&self, leg: &[VertexId], from: usize, to: usize) -> bool {
        let onto = self.drawing.onto;
        let drawn: f64 = leg
            .windows(2)
            .map(|pair| (onto.position(pair[1]) - onto.position(pair[0])).norm())
            .sum();
        drawn > DETOUR * (self.along[to] - self.along[from]) + 2.0 * self.corridor_width
    }

    /// The cheapest leg from `start` to `end` in the corridor that avoids what is
    /// drawn, leaving and entering through `wedges` when given ([`Corridor::shortest`]).
    fn shortest(
        &self,
        [start, end]: [VertexId; 2],
        wedges: [Option<&[HalfedgeId]>; 2],
    ) -> Option<Vec<VertexId>> {
        self.corridor.shortest(
            self.drawing.onto,
            [start, end],
            (&self.blocked, self.rings),
            &self.used_edge,
            wedges,
        )
    }

    /// Draws `leg`, which ends at arc vertex `end`, after the legs before.
    fn push(&mut self, leg: Vec<VertexId>, end: usize) {
        let drawing = self.drawing;
        drawing.take(&leg, &mut self.blocked, &mut self.used_edge, true);
        self.legs.push(leg);
        self.ends.push(end);
    }

    /// The legs through the waypoints, the free target vertices nearest to the placed
    /// interior vertices of the arc in order; a waypoint by a node, unreachable, or
    /// reached only by a detour is skipped.
    fn through_waypoints(&mut self) -> Result<(), RegisterError> {
        let last = self.arc.vertices.len().saturating_sub(1);
        for i in 1..last {
            let p = self.placed[i];
            let face = self.drawing.onto_index.locate(&p)?.point.face;
            // A waypoint by a node is left out: the corridor leads past it.
            let Some(via) = self.drawing.nearest_free(&p, face, &self.blocked) else {
                continue;
            };
            if self.rings.contains_key(&via) {
                continue;
            }
            let (start, leaving) = self.leg_start();
            if via == start {
                continue;
            }
            if let Some(leg) = self.shortest([start, via], [leaving, None]) {
                // A waypoint reached only round a handle lies across an arc drawn
                // before (or this one): skipped, the arc would wind where the placed
                // one does not, a twist of the map that no flow undoes.
                if self.detour(&leg, self.ends.last().copied().unwrap_or(0), i) {
                    continue;
                }
                self.push(leg, i);
            }
        }
        Ok(())
    }

    /// The last leg, into `to` through `last_wedge` when given; when the legs before
    /// wall `to` off, or leave it to be reached only round a handle (from the wrong
    /// side of its wedge), they are dropped from the end.
    ///
    /// # Errors
    /// [`RegisterError::Seams`] when no leg is left and `to` still cannot be reached.
    fn last_leg(
        &mut self,
        to: VertexId,
        last_wedge: Option<&[HalfedgeId]>,
    ) -> Result<(), RegisterError> {
        let last = self.arc.vertices.len().saturating_sub(1);
        let mut through_middle = false;
        let mut walled = 1;
        loop {
            let (start, leaving) = self.leg_start();
            // A loop at its node with no leg left: first through the placed arc's
            // middle, so that the path goes round what the arc goes round.
            if start == to && !through_middle {
                through_middle = true;
                if self.through_middle(start, leaving, last / 2)? {
                    continue;
                }
            }
            let leg = (start != to)
                .then(|| self.shortest([start, to], [leaving, last_wedge]))
                .flatten();
            // A detour drops one leg; no path at all drops 1, 2, 4, .. legs (each search
            // that finds nothing explores all the mesh it can reach).
            let drop = if let Some(leg) = leg {
                // Nothing to drop before it: the leg is the arc's only way.
                let only = self.legs.is_empty() || through_middle && self.legs.len() == 1;
                if only || !self.detour(&leg, self.ends.last().copied().unwrap_or(0), last) {
                    self.legs.push(leg);
                    return Ok(());
                }
                1
            } else {
                walled *= 2;
                walled / 2
            };
            if self.legs.is_empty() {
                return Err(self.no_path());
            }
            for _ in 0..drop.min(self.legs.len()) {
                if let Some(dropped) = self.legs.pop() {
                    self.ends.pop();
                    let drawing = self.drawing;
                    drawing.take(&dropped, &mut self.blocked, &mut self.used_edge, false);
                }
            }
        }
    }

    /// For an arc that is a loop at its node: a leg from `start` (leaving by
    /// `leaving`) to the free target vertex nearest to the placed arc's vertex
    /// `middle`, drawn when there is one; whether it was.
    fn through_middle(
        &mut self,
        start: VertexId,
        leaving: Option<&[HalfedgeId]>,
        middle: usize,
    ) -> Result<bool, RegisterError> {
        let p = self.placed[middle];
        let face = self.drawing.onto_index.locate(&p)?.point.face;
        let leg = self
            .drawing
            .nearest_free(&p, face, &self.blocked)
            .and_then(|via| self.shortest([start, via], [leaving, None]));
        let Some(leg) = leg else {
            return Ok(false);
        };
        self.push(leg, middle);
        Ok(true)
    }

    /// Why the arc has no path: it goes round a handle or a hole the placement did
    /// not pair, with the landmark that ties it down.
    fn no_path(&self) -> RegisterError {
        let arc = self.arc;
        let from = self.drawing.from;
        let side = self.drawing.from_side;
        let middle = arc.vertices[arc.vertices.len() / 2];
        self.drawing.seams(format!(
            "no path on the other mesh for the cut graph's arc from vertex {} to vertex {} of the {} that avoids the arcs drawn before it (the arc goes round a handle or a hole the placement did not pair: a landmark at {} vertex {}, the arc's middle, with its partner on the other mesh ties that handle down)",
            from.vertex_map().to_input(arc.vertices[0]),
            from.vertex_map()
                .to_input(*arc.vertices.last().unwrap_or(&arc.vertices[0])),
            side,
            side,
            from.vertex_map().to_input(middle),
        ))
    }

    /// The whole path: the legs joined, from `from`.
    fn path(self) -> Vec<VertexId> {
        let mut path = vec![self.from];
        for leg in self.legs {
            path.extend_from_slice(&leg[1..]);
        }
        path
    }
}

/// The placed source arc and the cost of target edges about it (module docs, step 4).
struct Corridor {
    tree: Option<Tree>,
    width: f64,
}

impl Corridor {
    /// The corridor of width `width` about the placed arc `placed`, sampled at most
    /// `width / 4` apart.
    fn new(placed: &[Point3<f64>], width: f64) -> Self {
        let mut samples: Vec<[f64; 3]> = Vec::new();
        for pair in placed.windows(2) {
            let (p, q) = (pair[0], pair[1]);
            let pieces = ((q - p).norm() / (0.25 * width)).ceil().max(1.0) as usize;
            for k in 0..pieces {
                let x = p + (q - p) * (k as f64 / pieces as f64);
                samples.push([x.x, x.y, x.z]);
            }
        }
        if let Some(x) = placed.last() {
            samples.push([x.x, x.y, x.z]);
        }
        Self {
            tree: Tree::new_from_slice(&samples).ok(),
            width,
        }
    }

    /// The cost factor `1 + (d / s)^2` at `p`.
    fn penalty(&self, p: &Point3<f64>) -> f64 {
        let d2 = self.tree.as_ref().map_or(0.0, |tree| {
            tree.query(&[p.x, p.y, p.z])
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute()
                .distance
        });
        1.0 + d2 / (self.width * self.width)
    }

    /// The cheapest path from `from` to `to` through unblocked vertices (a vertex of a
    /// node's 1-ring, other than as the first step from that node or the last one into
    /// it, at [`RING_COST`] times the cost) and unused interior edges, each edge costing
    /// its length times the mean of the penalties at its middle and far end; leaving
    /// `from` only through the halfedges of `wedges[0]` and entering `to` only against
    /// those of `wedges[1]` (outgoing halfedges of `to`), when given; `from != to` (an
    /// arc that is a loop at its node is drawn through a waypoint).
    fn shortest(
        &self,
        mesh: &Mesh,
        [from, to]: [VertexId; 2],
        (blocked, rings): (&[bool], &HashMap<VertexId, Vec<VertexId>>),
        used_edge: &[bool],
        wedges: [Option<&[HalfedgeId]>; 2],
    ) -> Option<Vec<VertexId>> {
        // Per reached vertex: cost, predecessor, settled. A leg explores a neighbourhood
        // of its corridor, so a map keeps the work proportional to it.
        let mut state: HashMap<VertexId, (f64, Option<VertexId>, bool)> = HashMap::new();
        let mut heap = BinaryHeap::new();
        state.insert(from, (0.0, None, false));
        heap.push(Reverse((Ordered(0.0), from)));
        while let Some(Reverse((Ordered(d), x))) = heap.pop() {
            let entry = state.entry(x).or_insert((d, None, false));
            if std::mem::replace(&mut entry.2, true) {
                continue;
            }
            if x == to {
                break;
            }
            if x != from && blocked[x.idx()] {
                continue;
            }
            // In a node's ring after the first step: only on into `to`.
            let cornered = x != from
                && rings.contains_key(&x)
                && state.get(&x).and_then(|s| s.1) != Some(from);
            for h in mesh.outgoing_halfedges(x) {
                let w = mesh.target(h);
                let e = mesh.edge(h);
                if used_edge[e.idx()]
                    || mesh.is_boundary_edge(e)
                    || (blocked[w.idx()] && w != to)
                    || (x == from && wedges[0].is_some_and(|allowed| !allowed.contains(&h)))
                    || (w == to
                        && wedges[1].is_some_and(|allowed| !allowed.contains(&mesh.twin(h))))
                {
                    continue;
                }
                let (pw, px) = (mesh.position(w), mesh.position(x));
                let middle = Point3::from((pw.coords + px.coords) * 0.5);
                let mut cost = 0.5 * (self.penalty(&middle) + self.penalty(&pw));
                // Passing by a node through its ring takes room its own arcs need.
                let intrudes = rings.get(&w).is_some_and(|owners| {
                    !(owners.contains(&to) || x == from && owners.contains(&from))
                });
                if intrudes || (cornered && w != to) {
                    cost *= RING_COST;
                }
                let dw = d + mesh.edge_length(e) * cost;
                let slot = state.entry(w).or_insert((f64::INFINITY, None, false));
                if !slot.2 && dw < slot.0 {
                    *slot = (dw, Some(x), false);
                    heap.push(Reverse((Ordered(dw), w)));
                }
            }
        }
        if !state.get(&to).is_some_and(|s| s.2) {
            return None;
        }
        let mut path = vec![to];
        let mut x = to;
        while x != from {
            x = state.get(&x)?.1?;
            path.push(x);
        }
        path.reverse();
        Some(path)
    }
}

/// A landmark on a boundary loop: its source vertex's position in the source loop and
/// its target's in the target loop.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    position: usize,
    target: usize,
    index: usize,
    vertex: VertexId,
}

/// The target loop fraction of source loop fraction `f`: linear in arc length between
/// the two anchors about it (`anchors` in loop order, at least one).
fn along_anchors(anchors: &[Anchor], sigma: &[f64], tau: &[f64], f: f64) -> f64 {
    let n = anchors.len();
    let first = sigma[anchors[0].position];
    let offset = |x: f64| (x - first).rem_euclid(1.0);
    let k = anchors
        .partition_point(|a| offset(sigma[a.position]) <= offset(f))
        .saturating_sub(1);
    let (a, b) = (anchors[k], anchors[(k + 1) % n]);
    let span_s = if n == 1 {
        1.0
    } else {
        (sigma[b.position] - sigma[a.position]).rem_euclid(1.0)
    };
    let span_t = if n == 1 {
        1.0
    } else {
        (tau[b.target] - tau[a.target]).rem_euclid(1.0)
    };
    let part = if span_s > 0.0 {
        (f - sigma[a.position]).rem_euclid(1.0) / span_s
    } else {
        0.0
    };
    (tau[a.target] + part * span_t).rem_euclid(1.0)
}

/// The point of the closed loop `vertices` of `mesh` at arc-length fraction `t`, the
/// vertices being at the increasing fractions `tau`.
fn loop_point(mesh: &Mesh, vertices: &[VertexId], tau: &[f64], t: f64) -> Point3<f64> {
    let t = t.rem_euclid(1.0);
    let j = tau.partition_point(|&x| x <= t).saturating_sub(1);
    let next = (j + 1) % tau.len();
    let end = if next == 0 { 1.0 } else { tau[next] };
    let span = end - tau[j];
    let lambda = if span > 0.0 {
        ((t - tau[j]) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (a, b) = (mesh.position(vertices[j]), mesh.position(vertices[next]));
    a + (b - a) * lambda
}

/// The placement refined by the correspondences known before any arc is drawn (the
/// landmarks and points of every paired boundary loop, matched by the loop's anchors or
/// rotation): the similarity's image moved by Shepard's interpolation of the residual
/// displacements, `sum_i w_i d_i / sum_i w_i` with `w_i = 1 / |q - a_i|^2` (`q` the
/// similarity's image, `a_i` those of the corresponding points, `d_i` their residuals),
/// so that the corresponding points land exactly on their partners. With no
/// correspondence it is the similarity.
pub(crate) struct Warp<'a> {
    similarity: &'a SpatialMatch,
    residuals: Vec<(Point3<f64>, nalgebra::Vector3<f64>)>,
    /// The corridor width `s` of the arcs drawn with it (module docs, step 4): 2% of the
    /// other mesh's diagonal, at least twice its mean edge length.
    corridor_width: f64,
}

impl<'a> Warp<'a> {
    fn new(
        similarity: &'a SpatialMatch,
        pairs: &[(Point3<f64>, Point3<f64>)],
        onto: &Mesh,
    ) -> Self {
        let mean_edge = onto.edge_lengths().iter().sum::<f64>() / onto.edge_count().max(1) as f64;
        Self {
            corridor_width: (CORRIDOR * onto.bounding_box().diagonal()).max(2.0 * mean_edge),
            similarity,
            residuals: pairs
                .iter()
                .map(|(a, b)| {
                    let q = similarity.to_target(a);
                    (q, b - q)
                })
                .collect(),
        }
    }

    /// A position of the mesh with the cut graph in the frame of the other one.
    pub(crate) fn to_target(&self, p: &Point3<f64>) -> Point3<f64> {
        let q = self.similarity.to_target(p);
        let mut sum = nalgebra::Vector3::zeros();
        let mut weight = 0.0;
        for (a, d) in &self.residuals {
            let r2 = (q - a).norm_squared();
            if r2 == 0.0 {
                return q + d;
            }
            sum += d / r2;
            weight += 1.0 / r2;
        }
        if weight > 0.0 { q + sum / weight } else { q }
    }
}

/// One paired boundary loop as the anchors read it: the loop of the mesh with the cut
/// graph (`from`, its index `s`) and its partner on the other mesh (`onto`, index `t`),
/// each with its vertices and their arc-length fractions.
pub(crate) struct LoopPair<'a> {
    /// The loop's index on `from` and its partner's on `onto`.
    pub indices: [usize; 2],
    /// The vertices of both loops.
    pub vertices: [&'a [VertexId]; 2],
    /// Their arc-length fractions.
    pub fractions: [&'a [f64]; 2],
}

/// The landmarks on a loop of `from` (`pair`) with their vertices on the partner loop
/// of `onto`, in loop order from the first one.
///
/// # Errors
/// [`RegisterError::Landmark`] when two of them are in a different order along the
/// partner loop, or share a vertex there.
fn loop_anchors(
    onto: &Mesh,
    pins: &[Pin],
    pair: &LoopPair<'_>,
) -> Result<Vec<Anchor>, RegisterError> {
    let [source_loop, target_loop] = pair.vertices;
    let [sigma, tau] = pair.fractions;
    let [s, t] = pair.indices;
    let mut anchors: Vec<Anchor> = Vec::new();
    for pin in pins {
        let Some(position) = pin
            .from_vertex
            .and_then(|v| source_loop.iter().position(|&w| w == v))
        else {
            continue;
        };
        let p = pin.onto;
        let target = match pin
            .onto_vertex
            .and_then(|v| target_loop.iter().position(|&w| w == v))
        {
            Some(j) => j,
            None => (0..target_loop.len())
                .min_by(|&i, &j| {
                    (onto.position(target_loop[i]) - p)
                        .norm_squared()
                        .total_cmp(&(onto.position(target_loop[j]) - p).norm_squared())
                })
                .unwrap_or(0),
        };
        anchors.push(Anchor {
            position,
            target,
            index: pin.index,
            vertex: pin.vertex,
        });
    }
    let Some(first) = anchors.first().copied() else {
        return Ok(anchors);
    };
    let from_first = |a: &Anchor| (sigma[a.position] - sigma[first.position]).rem_euclid(1.0);
    anchors.sort_by(|a, b| from_first(a).total_cmp(&from_first(b)));
    let first = anchors[0];
    let mut previous = 0.0;
    for pair in anchors.windows(2) {
        let turn = (tau[pair[1].target] - tau[first.target]).rem_euclid(1.0);
        if turn <= previous {
            return Err(RegisterError::Landmark {
                index: pair[1].index,
                vertex: pair[1].vertex,
                reason: format!(
                    "it and landmark {} are in one order along a boundary loop of one mesh and in the other (or at one vertex) along the paired loop of the other (loop {s} and loop {t})",
                    pair[0].index
                ),
            });
        }
        previous = turn;
    }
    Ok(anchors)
}

/// Checks the landmarks on boundary loops before any work: boundary onto boundary,
/// each source loop onto one target loop, and the same cyclic order along paired loops
/// (see [`pair_loops`]).
///
/// # Errors
/// [`RegisterError::Landmark`] naming the landmark that breaks one of these.
pub(crate) fn check_boundary_landmarks(
    source: &Mesh,
    target: &Mesh,
    marks: &[Resolved],
) -> Result<(), RegisterError> {
    let pins = forward_pins(source, target, marks);
    let source_loops = Loops::of(source);
    let target_loops = Loops::of(target);
    // Only loops with landmarks have anchors to check: those the landmarks pair.
    let paired = pair_marked_loops(target, &source_loops, &target_loops, marks)?;
    for (s, t) in paired
        .iter()
        .enumerate()
        .filter_map(|(s, pair)| pair.map(|(t, _)| (s, t)))
    {
        let (a, b) = (&source_loops.vertices[s], &target_loops.vertices[t]);
        let fractions = [arc_fractions(source, a), arc_fractions(target, b)];
        loop_anchors(
            target,
            &pins,
            &LoopPair {
                indices: [s, t],
                vertices: [a, b],
                fractions: [&fractions[0], &fractions[1]],
            },
        )?;
    }
    Ok(())
}

/// The landmarks as pins from the source onto the target.
pub(crate) fn forward_pins(source: &Mesh, target: &Mesh, marks: &[Resolved]) -> Vec<Pin> {
    marks
        .iter()
        .map(|m| Pin {
            from: source.position(m.source),
            from_vertex: Some(m.source),
            onto: m.target.position(target),
            onto_vertex: m.vertex.or_else(|| vertex_at(target, &m.target)),
            index: m.index,
            vertex: m.source,
        })
        .collect()
}

/// The vertex a surface point sits on, if it is within rounding of one.
pub(crate) fn vertex_at(mesh: &Mesh, point: &beltrami_mesh::SurfacePoint) -> Option<VertexId> {
    let (vertices, degree) = mesh.face_vertex_array(point.face);
    (0..degree)
        .find(|&k| point.coords[k] >= 1.0 - 1e-9)
        .map(|k| vertices[k])
}

/// The distance between two fractions of a loop, going either way round.
fn circular(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(1.0);
    d.min(1.0 - d)
}
