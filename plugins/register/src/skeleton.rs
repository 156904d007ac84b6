//! A cut graph as a graph of its own: branch *nodes* (cut-graph vertices whose degree in
//! the cut graph is not 2) joined by *arcs* (the chains of cut edges between them), and
//! the *word* of the disk it cuts out: the cyclic sequence of arcs, each with its
//! direction, met along the disk's boundary.
//!
//! Two cut graphs with arcs numbered alike whose disks read the same word (up to a
//! cyclic shift) cut their surfaces in the same pattern: gluing each disk back along its
//! arcs gives the surface, so maps of the two disks onto one polygon that agree on every
//! copy of every arc (same arc, same fraction of its length) glue to a homeomorphism of
//! the surfaces, and it preserves orientation because both boundaries are read with the
//! surface on the right.

use beltrami_mesh::{EdgeId, HalfedgeId, Mesh, VertexId};

/// One arc: a path of cut edges from one node to another (or back to itself), through
/// vertices of cut-graph degree 2.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Arc {
    /// Its vertices from the first node to the last, both included.
    pub vertices: Vec<VertexId>,
    /// Its two nodes (indices into [`Skeleton::nodes`]).
    pub ends: [usize; 2],
}

impl Arc {
    /// Whether every edge of the arc is a boundary edge of `mesh` (a piece of a boundary
    /// loop; a cut graph contains every boundary edge).
    pub fn on_boundary(&self, mesh: &Mesh) -> bool {
        self.vertices.windows(2).all(|pair| {
            halfedge_between(mesh, pair[0], pair[1])
                .is_some_and(|h| mesh.is_boundary_edge(mesh.edge(h)))
        })
    }

    /// The length of the arc.
    pub fn length(&self, mesh: &Mesh) -> f64 {
        self.vertices
            .windows(2)
            .map(|pair| (mesh.position(pair[1]) - mesh.position(pair[0])).norm())
            .sum()
    }
}

/// A cut graph split into nodes and arcs.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Skeleton {
    /// The branch nodes (a single vertex of the cycle when the graph is one cycle).
    pub nodes: Vec<VertexId>,
    /// The arcs between them.
    pub arcs: Vec<Arc>,
}

/// One side of the cut disk's boundary: a copy of an arc, read forwards (from its first
/// node to its last) or backwards.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Letter {
    /// The arc (index into [`Skeleton::arcs`]).
    pub arc: usize,
    /// Read from `ends[0]` to `ends[1]`.
    pub forward: bool,
}

/// The boundary of a cut disk split at the copies of the nodes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Word {
    /// The disk's boundary vertices in order (surface on the right), starting at a copy
    /// of a node.
    pub vertices: Vec<VertexId>,
    /// The letters in order.
    pub letters: Vec<Letter>,
    /// Where letter `k` starts in `vertices`; it ends where letter `k + 1` starts (the
    /// last one at `vertices.len()`, i.e. back at `vertices[0]`).
    pub starts: Vec<usize>,
}

impl Word {
    /// The boundary vertices of letter `k`, both node copies included.
    pub fn side(&self, k: usize) -> Vec<VertexId> {
        let end = self
            .starts
            .get(k + 1)
            .copied()
            .unwrap_or(self.vertices.len());
        let mut out = self.vertices[self.starts[k]..end].to_vec();
        out.push(self.vertices[end % self.vertices.len()]);
        out
    }

    /// The shift `r` with `other.letters[(k + r) % m] == self.letters[k]` for every `k`,
    /// if there is one.
    pub fn shift_onto(&self, other: &Word) -> Option<usize> {
        let m = self.letters.len();
        if other.letters.len() != m {
            return None;
        }
        (0..m).find(|&r| (0..m).all(|k| other.letters[(k + r) % m] == self.letters[k]))
    }
}

/// The cut graph `edges` of `mesh` with a slit to every vertex of `tips` off it: the
/// shortest path (by edge length) from the tip to the graph as it stands, tip by tip.
/// Cutting along a slit keeps a disk a disk: the slit opens into two sides meeting at
/// the tip.
pub(crate) fn with_slits(mesh: &Mesh, edges: &[EdgeId], tips: &[VertexId]) -> Vec<EdgeId> {
    let mut out = edges.to_vec();
    let mut on_graph = vec![false; mesh.vertex_count()];
    for &e in edges {
        for v in mesh.edge_vertices(e) {
            on_graph[v.idx()] = true;
        }
    }
    for &tip in tips {
        if on_graph[tip.idx()] {
            continue;
        }
        // Dijkstra from the tip until a vertex of the graph is settled.
        let mut dist = std::collections::HashMap::new();
        let mut pred: std::collections::HashMap<VertexId, HalfedgeId> =
            std::collections::HashMap::new();
        let mut heap = std::collections::BinaryHeap::new();
        dist.insert(tip, 0.0);
        heap.push(std::cmp::Reverse((Ordered(0.0), tip)));
        let mut reached = None;
        while let Some(std::cmp::Reverse((Ordered(d), x))) = heap.pop() {
            if dist.get(&x).is_some_and(|&best| d > best) {
                continue;
            }
            if on_graph[x.idx()] {
                reached = Some(x);
                break;
            }
            for h in mesh.outgoing_halfedges(x) {
                let w = mesh.target(h);
                let dw = d + mesh.edge_length(mesh.edge(h));
                if dist.get(&w).is_none_or(|&best| dw < best) {
                    dist.insert(w, dw);
                    pred.insert(w, h);
                    heap.push(std::cmp::Reverse((Ordered(dw), w)));
                }
            }
        }
        let Some(mut x) = reached else {
            continue;
        };
        while x != tip {
            let h = pred[&x];
            out.push(mesh.edge(h));
            on_graph[x.idx()] = true;
            x = mesh.origin(h);
        }
        on_graph[tip.idx()] = true;
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// A float ordered by `total_cmp`, for the shortest-path heaps of the cut graphs
/// (`std::cmp::Reverse` of it pops the smallest first).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ordered(pub f64);
impl Eq for Ordered {}
impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The halfedge from `u` to `w`, if they are joined by an edge.
pub(crate) fn halfedge_between(mesh: &Mesh, u: VertexId, w: VertexId) -> Option<HalfedgeId> {
    mesh.outgoing_halfedges(u).find(|&h| mesh.target(h) == w)
}

impl Skeleton {
    /// The nodes and arcs of the cut graph made of `edges` of `mesh` (a connected graph
    /// with no vertex of degree 1, such as [`beltrami_mesh::cut_graph`]'s), with the
    /// cut-graph vertices of `extra` made nodes as well (splitting their arcs).
    pub fn of(mesh: &Mesh, edges: &[EdgeId], extra: &[VertexId]) -> Self {
        let mut in_cut = vec![false; mesh.edge_count()];
        let mut degree = vec![0u32; mesh.vertex_count()];
        for &e in edges {
            in_cut[e.idx()] = true;
            for v in mesh.edge_vertices(e) {
                degree[v.idx()] += 1;
            }
        }
        let mut is_extra = vec![false; mesh.vertex_count()];
        for v in extra {
            is_extra[v.idx()] = true;
        }
        let mut nodes: Vec<VertexId> = mesh
            .vertices()
            .filter(|v| degree[v.idx()] != 0 && (degree[v.idx()] != 2 || is_extra[v.idx()]))
            .collect();
        if nodes.is_empty()
            && let Some(&e) = edges.first()
        {
            nodes.push(mesh.edge_vertices(e)[0]);
        }
        let mut node_of = vec![usize::MAX; mesh.vertex_count()];
        for (k, v) in nodes.iter().enumerate() {
            node_of[v.idx()] = k;
        }
        let mut used = vec![false; mesh.edge_count()];
        let mut arcs = Vec::new();
        for (start, &n) in nodes.iter().enumerate() {
            let leaving: Vec<HalfedgeId> = mesh.outgoing_halfedges(n).collect();
            for h in leaving {
                if !in_cut[mesh.edge(h).idx()] || used[mesh.edge(h).idx()] {
                    continue;
                }
                let mut vertices = vec![n];
                let mut current = h;
                loop {
                    used[mesh.edge(current).idx()] = true;
                    let w = mesh.target(current);
                    vertices.push(w);
                    if node_of[w.idx()] != usize::MAX {
                        break;
                    }
                    match mesh
                        .outgoing_halfedges(w)
                        .find(|&g| in_cut[mesh.edge(g).idx()] && !used[mesh.edge(g).idx()])
                    {
                        Some(g) => current = g,
                        None => break,
                    }
                }
                let last = *vertices.last().unwrap_or(&n);
                arcs.push(Arc {
                    ends: [start, node_of[last.idx()]],
                    vertices,
                });
            }
        }
        Self { nodes, arcs }
    }

    /// Every edge of every arc.
    pub fn edges(&self, mesh: &Mesh) -> Vec<EdgeId> {
        let mut out: Vec<EdgeId> = self
            .arcs
            .iter()
            .flat_map(|arc| arc.vertices.windows(2))
            .filter_map(|pair| halfedge_between(mesh, pair[0], pair[1]).map(|h| mesh.edge(h)))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The word of the disk `cut` obtained by cutting `mesh` along this skeleton
    /// (`to_original` the seam map), or `None` when `cut` is not one disk whose boundary
    /// splits into whole copies of the arcs.
    pub fn word(&self, mesh: &Mesh, cut: &Mesh, to_original: &[VertexId]) -> Option<Word> {
        if cut.component_count() != 1 || cut.boundary_loop_count() != 1 || !cut.is_disk() {
            return None;
        }
        // Arc and position of every cut edge of `mesh`.
        let mut place = vec![None; mesh.edge_count()];
        for (a, arc) in self.arcs.iter().enumerate() {
            for (k, pair) in arc.vertices.windows(2).enumerate() {
                let h = halfedge_between(mesh, pair[0], pair[1])?;
                place[mesh.edge(h).idx()] = Some((a, k));
            }
        }
        let mut is_node = vec![false; mesh.vertex_count()];
        for n in &self.nodes {
            is_node[n.idx()] = true;
        }
        let loop_id = cut.boundary_loops().next()?;
        let halfedges: Vec<HalfedgeId> = cut.loop_halfedges(loop_id).collect();
        let original = |v: VertexId| to_original[v.idx()];
        let first = halfedges
            .iter()
            .position(|&h| is_node[original(cut.origin(h)).idx()])?;
        let halfedges: Vec<HalfedgeId> = halfedges[first..]
            .iter()
            .chain(&halfedges[..first])
            .copied()
            .collect();
        let mut word = Word {
            vertices: halfedges.iter().map(|&h| cut.origin(h)).collect(),
            letters: Vec::new(),
            starts: Vec::new(),
        };
        // The original edge of each boundary halfedge, from its face's side: cut faces
        // keep the ids, order and first vertex of the original faces.
        let mut expected: Option<(Letter, usize)> = None;
        for (i, &h) in halfedges.iter().enumerate() {
            let inner = cut.twin(h);
            let face = cut.face(inner)?;
            let k = cut.face_halfedges(face).position(|g| g == inner)?;
            let g = mesh.face_halfedges(face).nth(k)?;
            let (a, pos) = place[mesh.edge(g).idx()]?;
            let arc = &self.arcs[a];
            let (from, to) = (original(cut.origin(h)), original(cut.target(h)));
            let forward = arc.vertices[pos] == from && arc.vertices[pos + 1] == to;
            if !(forward || arc.vertices[pos] == to && arc.vertices[pos + 1] == from) {
                return None;
            }
            let letter = Letter { arc: a, forward };
            let edges = arc.vertices.len() - 1;
            let step = if forward { pos } else { edges - 1 - pos };
            if is_node[from.idx()] && step == 0 {
                word.letters.push(letter);
                word.starts.push(i);
                expected = Some((letter, 1));
            } else {
                match expected {
                    Some((l, next)) if l == letter && next == step => {
                        expected = Some((l, next + 1));
                    }
                    _ => return None,
                }
            }
        }
        Some(word)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{self, Cells};
    use beltrami_mesh::{cut_along, cut_graph};

    #[test]
    fn a_torus_cut_graph_reads_a_word_with_every_interior_arc_twice() {
        let mesh = Mesh::from_soup(&primitives::torus(12, 8, 2.0, 0.6, Cells::Triangles)).unwrap();
        let graph = cut_graph(&mesh);
        let skeleton = Skeleton::of(&mesh, &graph.edges, &[]);
        let edges = skeleton.edges(&mesh);
        assert_eq!(edges, graph.edges);
        let (cut, to_original) = cut_along(&mesh, &edges).unwrap();
        let word = skeleton.word(&mesh, &cut, &to_original).unwrap();
        // Each arc appears once forwards and once backwards.
        for a in 0..skeleton.arcs.len() {
            let copies: Vec<bool> = word
                .letters
                .iter()
                .filter(|l| l.arc == a)
                .map(|l| l.forward)
                .collect();
            assert_eq!(copies.len(), 2, "arc {a}");
            assert_ne!(copies[0], copies[1], "arc {a}");
        }
        assert_eq!(word.shift_onto(&word), Some(0));
    }

    #[test]
    fn boundary_arcs_appear_once() {
        let mesh = Mesh::from_soup(&primitives::annulus(0.4, 4, 24)).unwrap();
        let graph = cut_graph(&mesh);
        let skeleton = Skeleton::of(&mesh, &graph.edges, &[]);
        let (cut, to_original) = cut_along(&mesh, &skeleton.edges(&mesh)).unwrap();
        let word = skeleton.word(&mesh, &cut, &to_original).unwrap();
        for (a, arc) in skeleton.arcs.iter().enumerate() {
            let copies = word.letters.iter().filter(|l| l.arc == a).count();
            assert_eq!(
                copies,
                if arc.on_boundary(&mesh) { 1 } else { 2 },
                "arc {a}"
            );
        }
        // The sides together are the whole boundary.
        let total: usize = (0..word.letters.len())
            .map(|k| word.side(k).len() - 1)
            .sum();
        assert_eq!(total, word.vertices.len());
    }
}
