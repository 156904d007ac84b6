//! Shortest paths along the edges of a mesh from a set of sources that may grow while
//! the search runs (Dijkstra with lazy deletion: a vertex whose distance drops is pushed
//! again and its stale entries are skipped).

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use beltrami_mesh::{HalfedgeId, Mesh, VertexId};

/// A running shortest-path search by edge length.
pub struct ShortestPaths<'a> {
    mesh: &'a Mesh,
    length: Vec<f64>,
    /// The distance of every vertex from the nearest source found so far.
    pub dist: Vec<f64>,
    /// The halfedge each vertex was last reached by (pointing to it); `None` at sources
    /// and unreached vertices.
    pub reached_by: Vec<Option<HalfedgeId>>,
    heap: BinaryHeap<Reverse<(Distance, VertexId)>>,
}

impl<'a> ShortestPaths<'a> {
    /// A search on `mesh` with no source yet.
    pub fn new(mesh: &'a Mesh) -> Self {
        Self {
            mesh,
            length: mesh.edge_lengths(),
            dist: vec![f64::INFINITY; mesh.vertex_count()],
            reached_by: vec![None; mesh.vertex_count()],
            heap: BinaryHeap::new(),
        }
    }

    /// Makes `v` a source (distance 0).
    pub fn seed(&mut self, v: VertexId) {
        self.dist[v.idx()] = 0.0;
        self.reached_by[v.idx()] = None;
        self.heap.push(Reverse((Distance(0.0), v)));
    }

    /// Settles the nearest vertex not settled at its current distance, relaxes its
    /// edges and returns it; `None` when every reachable vertex is settled.
    pub fn settle_next(&mut self) -> Option<VertexId> {
        while let Some(Reverse((Distance(d), v))) = self.heap.pop() {
            if d > self.dist[v.idx()] {
                continue;
            }
            for h in self.mesh.outgoing_halfedges(v) {
                let w = self.mesh.target(h);
                let next = d + self.length[self.mesh.edge(h).idx()];
                if next < self.dist[w.idx()] {
                    self.dist[w.idx()] = next;
                    self.reached_by[w.idx()] = Some(h);
                    self.heap.push(Reverse((Distance(next), w)));
                }
            }
            return Some(v);
        }
        None
    }

    /// Settles every reachable vertex.
    pub fn run(&mut self) {
        while self.settle_next().is_some() {}
    }
}

/// A distance ordered totally (distances are finite and non-negative).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Distance(f64);

impl Eq for Distance {}

impl PartialOrd for Distance {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Distance {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0)
    }
}
