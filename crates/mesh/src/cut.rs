//! Cutting a surface of genus g >= 1 (closed or with boundary) into a topological disk.
//!
//! # Cut graph: tree-cotree with a greedy shortest basis
//!
//! The cut graph comes from the tree-cotree decomposition (Eppstein 2003, "Dynamic
//! generators of topologically embedded graphs"), with the weights of Erickson &
//! Whittlesey 2005 ("Greedy optimal homotopy and homology generators"), which make the
//! generator loops a greedy shortest homotopy basis at the root vertex:
//!
//! 1. **Tree** `T`: a shortest-path tree of the vertices by edge length (Dijkstra, with
//!    predecessors kept), from one root vertex per component.
//! 2. **Cotree** `C`: a spanning tree of the dual graph (faces, joined across edges)
//!    that uses no edge of `T`, chosen as a *maximum* spanning tree for the weight
//!    `d(u) + |uw| + d(w)` of each dual edge `uw` (the length of the loop that edge closes
//!    through the root), with petgraph's `min_spanning_tree` on negated weights over an
//!    `EdgeFiltered` view of the dual graph that hides the edges of `T`.
//! 3. **Generators**: on a closed surface of genus g exactly `2g` edges are in neither
//!    `T` nor `C`; each closes a simple cycle in `T`. These loops are a basis of the
//!    first homology, and, in the order of their weights, the greedy shortest system of
//!    loops through the root.
//! 4. **Cut graph**: every edge not in `C`, pruned by removing degree-1 vertices until
//!    none is left (its 2-core). Cutting along all edges not in `C` leaves the faces glued
//!    along the tree `C` only, which is a disk; a pruned branch is a slit ending inside
//!    that disk, so gluing it back keeps a disk. The pruned graph contains every
//!    generator loop and the tree paths that join them.
//!
//! # Boundary
//!
//! Each boundary loop is closed up by a virtual face, giving a closed surface of the
//! same genus. The tree is grown so that it contains every edge of each boundary loop
//! but one (Dijkstra contracts each loop to a point: the first vertex of a loop to be
//! settled settles the whole loop at its distance, joined along the loop, and the loop
//! edge opposite to it is left out). A virtual face then has a single edge outside `T`,
//! so it is a leaf of every cotree: the cotree of the real faces is a spanning tree of
//! its own, the cut still leaves a disk, and every boundary edge is on the cut graph.
//! The `2g` edges outside both trees give the handle loops; the `b` boundary loops
//! (each a tree path closed by its left-out edge) add `b - 1` independent generators,
//! for `2g + b - 1` in all, the rank of the fundamental group of a surface with `b > 0`
//! boundary loops.
//!
//! # Cutting
//!
//! [`cut_to_disk`] duplicates every cut-graph vertex once per wedge of faces between
//! consecutive cut edges around it and rebuilds the mesh through [`PolygonSoup`] and
//! [`Mesh::build`]. Faces keep their ids, order and first vertex; the seam map gives the
//! original vertex of every new one.
//!
//! For a closed torus the tree-cotree cut graph may be a theta graph (two branch
//! vertices, a hexagonal disk) instead of two loops through one vertex, so
//! [`cut_to_disk`] cuts a torus along a figure-eight instead: the shortest generator
//! loop `a`, and the shortest loop `b` that leaves a vertex `p` of `a` on one side and
//! comes back on the other through vertices off `a` (a shortest path across the annulus
//! that `a` cuts out, tried from several `p`). The disk is then a square whose boundary
//! reads `a b a^-1 b^-1` ([`TorusSides`]).

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::ops::Range;

use petgraph::algo::min_spanning_tree;
use petgraph::data::Element;
use petgraph::graph::{NodeIndex, UnGraph};
use petgraph::visit::EdgeFiltered;
use thiserror::Error;

use crate::{
    BoundaryLoopId, BuildOptions, Component, ComponentId, EdgeId, FaceId, HalfedgeId, Mesh,
    MeshError, PolygonSoup, Repair, VertexId,
};

/// What kind of loop a [`Generator`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeneratorKind {
    /// A loop around or along a handle: a tree path closed by an edge in neither tree.
    Handle,
    /// A boundary loop (every boundary loop of a component but its first).
    Boundary(BoundaryLoopId),
}

/// One generator loop: a simple closed cycle of halfedges.
#[derive(Debug, Clone, PartialEq)]
pub struct Generator {
    /// The component the loop lies on.
    pub component: ComponentId,
    /// Handle or boundary loop.
    pub kind: GeneratorKind,
    /// The cycle: `target(halfedges[i]) == origin(halfedges[i + 1])`, and the last
    /// halfedge enters the origin of the first. No vertex is visited twice.
    pub halfedges: Vec<HalfedgeId>,
    /// Sum of the edge lengths.
    pub length: f64,
}

impl Generator {
    /// The vertices of the cycle in order (the origin of every halfedge).
    pub fn vertices(&self, mesh: &Mesh) -> Vec<VertexId> {
        self.halfedges.iter().map(|&h| mesh.origin(h)).collect()
    }

    /// The edges of the cycle in order.
    pub fn edges(&self, mesh: &Mesh) -> Vec<EdgeId> {
        self.halfedges.iter().map(|&h| mesh.edge(h)).collect()
    }
}

/// Topology of one component and the root of its shortest-path tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CutComponent {
    /// The component.
    pub id: ComponentId,
    /// Its genus.
    pub genus: i64,
    /// Its number of boundary loops.
    pub boundary_loops: usize,
    /// The root of the vertex tree (the basepoint of the handle loops): on the first
    /// boundary loop when there is one.
    pub root: VertexId,
}

/// Generator loops and the cut graph of every component of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct CutGraph {
    /// Every component, in id order.
    pub components: Vec<CutComponent>,
    /// Per component `2g` handle loops (shortest first) and then `b - 1` boundary loops;
    /// the components follow one another in id order.
    pub generators: Vec<Generator>,
    /// The edges of the cut graph, sorted: every boundary edge, every generator loop and
    /// the tree paths joining them, with no vertex of degree 1. Cutting a component
    /// along it leaves a disk; it is empty on a closed genus-0 component.
    pub edges: Vec<EdgeId>,
}

impl CutGraph {
    /// Total length of the cut-graph edges.
    pub fn length(&self, mesh: &Mesh) -> f64 {
        self.edges.iter().map(|&e| mesh.edge_length(e)).sum()
    }
}

/// The four sides of the square that a cut torus becomes: ranges of indices into
/// [`CutMesh::boundary`], in boundary order, together the whole boundary. Side `a`
/// and side `a_inv` run over the same original vertices in opposite orders, and so do
/// `b` and `b_inv`; all four corners are copies of one original vertex.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TorusSides {
    /// Side `a` (along the first loop), starting at index 0.
    pub a: Range<usize>,
    /// Side `b` (along the second loop).
    pub b: Range<usize>,
    /// Side `a^-1`.
    pub a_inv: Range<usize>,
    /// Side `b^-1`, ending at the end of the boundary.
    pub b_inv: Range<usize>,
}

impl TorusSides {
    /// The sides in boundary order: `[a, b, a^-1, b^-1]`.
    pub fn sides(&self) -> [Range<usize>; 4] {
        [
            self.a.clone(),
            self.b.clone(),
            self.a_inv.clone(),
            self.b_inv.clone(),
        ]
    }
}

/// A mesh cut open into a disk, with the correspondence back to the original.
#[derive(Debug, Clone)]
pub struct CutMesh {
    /// The cut mesh: one topological disk. Face `f` is original face `f`, with the same
    /// first vertex and orientation; vertex `v < n` (`n` the original vertex count) is a
    /// copy of original vertex `v`, and the extra copies along the cut follow.
    pub mesh: Mesh,
    /// The seam map: the original vertex of every cut-mesh vertex.
    pub to_original: Vec<VertexId>,
    /// The cut graph that was cut along (original ids). On a closed torus it is the
    /// figure-eight of the two loops of [`TorusSides`].
    pub cut: CutGraph,
    /// The boundary of the cut mesh as one loop of its boundary halfedges (surface on
    /// the right), starting at the corner where side `a` starts on a torus.
    pub boundary: Vec<HalfedgeId>,
    /// On a closed torus, the four sides of the square; `None` otherwise, and on a torus
    /// whose edge graph has no loop crossing the first one exactly once (only very coarse
    /// meshes), which is then cut along the tree-cotree cut graph.
    pub torus_sides: Option<TorusSides>,
}

impl CutMesh {
    /// The original vertex of cut-mesh vertex `v`.
    pub fn original_vertex(&self, v: VertexId) -> VertexId {
        self.to_original[v.idx()]
    }

    /// The original face of cut-mesh face `f`: `f` itself (faces keep their ids).
    pub fn original_face(&self, f: FaceId) -> FaceId {
        f
    }

    /// The cut-mesh vertices along the boundary, in the order of [`CutMesh::boundary`].
    pub fn boundary_vertices(&self) -> Vec<VertexId> {
        self.boundary.iter().map(|&h| self.mesh.origin(h)).collect()
    }

    /// The length of the boundary of the cut mesh.
    pub fn boundary_length(&self) -> f64 {
        self.path_length(0..self.boundary.len())
    }

    /// The cut-mesh vertices of a stretch of the boundary given by halfedge indices into
    /// [`CutMesh::boundary`]: both end points included, so `range.len() + 1` vertices.
    pub fn path_vertices(&self, range: Range<usize>) -> Vec<VertexId> {
        let hs = &self.boundary[range];
        let mut out: Vec<VertexId> = hs.iter().map(|&h| self.mesh.origin(h)).collect();
        if let Some(&last) = hs.last() {
            out.push(self.mesh.target(last));
        }
        out
    }

    /// The length of a stretch of the boundary (halfedge indices into
    /// [`CutMesh::boundary`]).
    pub fn path_length(&self, range: Range<usize>) -> f64 {
        self.boundary[range]
            .iter()
            .map(|&h| self.mesh.halfedge_vector(h).norm())
            .sum()
    }
}

/// Why a mesh could not be cut into a disk.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CutError {
    /// The mesh has several connected components; a disk is one piece.
    #[error(
        "the mesh has {} connected components ({}); cutting into one disk needs one component: split the mesh and cut each part",
        components.len(),
        describe(components)
    )]
    MultipleComponents {
        /// Every component with its counts and genus.
        components: Vec<Component>,
    },
    /// A closed genus-0 surface (a topological sphere) has no cut graph.
    #[error(
        "the surface is closed with genus 0 (a topological sphere): it has no loops to cut along; remove a face to open it into a disk, or use a spherical method"
    )]
    ClosedGenusZero,
    /// The cut mesh failed validation (a bug: please report it with the mesh).
    #[error("building the cut mesh failed: {0}")]
    Build(#[from] MeshError),
}

fn describe(components: &[Component]) -> String {
    components
        .iter()
        .map(|c| {
            format!(
                "{}: {} faces, genus {}, {} boundary loops",
                c.id, c.faces, c.genus, c.boundary_loops
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

// ---------------------------------------------------------------------------------------
// Shortest paths
// ---------------------------------------------------------------------------------------

/// A heap entry ordered so that `BinaryHeap` pops the smallest distance first.
#[derive(Clone, Copy)]
struct Entry {
    dist: f64,
    vertex: VertexId,
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .dist
            .total_cmp(&self.dist)
            .then_with(|| other.vertex.cmp(&self.vertex))
    }
}

/// Shortest paths by edge length from `root` over the whole mesh (Dijkstra; on a mesh
/// with boundary, every boundary loop is settled as a whole when its first vertex is,
/// as in the cut graph's tree): per vertex its distance (infinite off `root`'s
/// component) and the halfedge it was reached by, pointing towards it (`None` at the
/// root and off the component).
pub fn shortest_path_tree(mesh: &Mesh, root: VertexId) -> (Vec<f64>, Vec<Option<HalfedgeId>>) {
    let tree = VertexTree::shortest_paths(mesh, &[root], &mesh.edge_lengths());
    let reached = tree.up.iter().map(|up| up.map(|h| mesh.twin(h))).collect();
    (tree.dist, reached)
}

/// The spanning tree of the vertices: for each vertex the halfedge to its parent.
struct VertexTree {
    /// Distance from the root, with every boundary loop contracted to a point.
    dist: Vec<f64>,
    /// Halfedge from `v` to its parent; `None` at the roots.
    up: Vec<Option<HalfedgeId>>,
    /// Number of tree edges between `v` and its root.
    depth: Vec<u32>,
    /// Edges of the tree.
    in_tree: Vec<bool>,
}

impl VertexTree {
    /// Dijkstra from `roots` (one per component) by `length`, settling each boundary
    /// loop as a whole when its first vertex is settled (see the module docs).
    fn shortest_paths(mesh: &Mesh, roots: &[VertexId], length: &[f64]) -> Self {
        let nv = mesh.vertex_count();
        let mut tree = VertexTree {
            dist: vec![f64::INFINITY; nv],
            up: vec![None; nv],
            depth: vec![0; nv],
            in_tree: vec![false; mesh.edge_count()],
        };
        let mut settled = vec![false; nv];
        let mut heap = BinaryHeap::new();
        for &r in roots {
            tree.dist[r.idx()] = 0.0;
            heap.push(Entry {
                dist: 0.0,
                vertex: r,
            });
        }
        let mut batch = Vec::new();
        while let Some(Entry { dist, vertex }) = heap.pop() {
            if settled[vertex.idx()] {
                continue;
            }
            batch.clear();
            batch.push(vertex);
            settled[vertex.idx()] = true;
            if mesh.is_boundary_vertex(vertex) {
                tree.settle_loop(mesh, vertex, length, &mut settled, &mut batch);
            }
            for &x in &batch {
                for h in mesh.outgoing_halfedges(x) {
                    let w = mesh.target(h);
                    let d = dist + length[mesh.edge(h).idx()];
                    if !settled[w.idx()] && d < tree.dist[w.idx()] {
                        tree.dist[w.idx()] = d;
                        tree.up[w.idx()] = Some(mesh.twin(h));
                        tree.depth[w.idx()] = tree.depth[x.idx()] + 1;
                        heap.push(Entry { dist: d, vertex: w });
                    }
                }
            }
        }
        for v in mesh.vertices() {
            if let Some(h) = tree.up[v.idx()] {
                tree.in_tree[mesh.edge(h).idx()] = true;
            }
        }
        tree
    }

    /// Settles the boundary loop through the boundary vertex `v` (settled first among its
    /// vertices) at the distance of `v`: the vertices up to half the loop's length
    /// forward from `v` hang from their predecessor, the others from their successor, so
    /// that only the loop edge where the two halves meet stays out of the tree.
    fn settle_loop(
        &mut self,
        mesh: &Mesh,
        v: VertexId,
        length: &[f64],
        settled: &mut [bool],
        batch: &mut Vec<VertexId>,
    ) {
        // Halfedges g_0 .. g_{k-1} from v around the loop; vertex x_j = origin(g_j).
        let start = mesh.vertex_halfedge(v);
        let mut hs = vec![start];
        let mut h = mesh.next(start);
        while h != start {
            hs.push(h);
            h = mesh.next(h);
        }
        let total: f64 = hs.iter().map(|&h| length[mesh.edge(h).idx()]).sum();
        let dist = self.dist[v.idx()];
        let mut forward_end = 0; // last j hanging from its predecessor
        let mut along = 0.0;
        for j in 1..hs.len() {
            along += length[mesh.edge(hs[j - 1]).idx()];
            if along > 0.5 * total {
                break;
            }
            forward_end = j;
            let x = mesh.origin(hs[j]);
            self.hang(x, mesh.twin(hs[j - 1]), mesh.origin(hs[j - 1]), dist);
            settled[x.idx()] = true;
            batch.push(x);
        }
        for j in (forward_end + 1..hs.len()).rev() {
            let x = mesh.origin(hs[j]);
            self.hang(x, hs[j], mesh.target(hs[j]), dist);
            settled[x.idx()] = true;
            batch.push(x);
        }
    }

    fn hang(&mut self, x: VertexId, up: HalfedgeId, parent: VertexId, dist: f64) {
        self.dist[x.idx()] = dist;
        self.up[x.idx()] = Some(up);
        self.depth[x.idx()] = self.depth[parent.idx()] + 1;
    }

    /// The simple cycle that `h` (from `u` to `w`, not a tree edge) closes in the tree:
    /// `h`, then from `w` up to the lowest common ancestor, then down to `u`.
    fn cycle(&self, mesh: &Mesh, h: HalfedgeId) -> Vec<HalfedgeId> {
        let (mut a, mut b) = (mesh.target(h), mesh.origin(h));
        let mut up_part = Vec::new();
        let mut down_part = Vec::new();
        while a != b {
            if self.depth[a.idx()] >= self.depth[b.idx()] {
                let g = self.up[a.idx()].expect("a vertex deeper than another has a parent");
                up_part.push(g);
                a = mesh.target(g);
            } else {
                let g = self.up[b.idx()].expect("a vertex deeper than another has a parent");
                down_part.push(mesh.twin(g));
                b = mesh.target(g);
            }
        }
        let mut out = Vec::with_capacity(1 + up_part.len() + down_part.len());
        out.push(h);
        out.extend(up_part);
        out.extend(down_part.into_iter().rev());
        out
    }
}

fn cycle_length(mesh: &Mesh, halfedges: &[HalfedgeId], length: &[f64]) -> f64 {
    halfedges.iter().map(|&h| length[mesh.edge(h).idx()]).sum()
}

/// The component of vertex `v` (through a face halfedge at it).
fn vertex_component(mesh: &Mesh, v: VertexId) -> ComponentId {
    let h = mesh.vertex_halfedge(v);
    let face = mesh
        .face(h)
        .or_else(|| mesh.face(mesh.twin(h)))
        .expect("every mesh vertex has a face");
    mesh.face_component(face)
}

// ---------------------------------------------------------------------------------------
// Cut graph
// ---------------------------------------------------------------------------------------

/// Generator loops and cut graph of every component of `mesh` by tree-cotree with the
/// greedy shortest-loop weights (see the module docs).
pub fn cut_graph(mesh: &Mesh) -> CutGraph {
    let length = mesh.edge_lengths();
    let topology = mesh.components();

    // One root per component: on its first boundary loop, else its lowest vertex.
    let mut root: Vec<Option<VertexId>> = vec![None; topology.len()];
    for b in mesh.boundary_loops() {
        let v = mesh.origin(mesh.loop_halfedge(b));
        root[vertex_component(mesh, v).idx()].get_or_insert(v);
    }
    for v in mesh.vertices() {
        root[vertex_component(mesh, v).idx()].get_or_insert(v);
    }
    let components: Vec<CutComponent> = topology
        .iter()
        .zip(&root)
        .map(|(c, r)| CutComponent {
            id: c.id,
            genus: c.genus,
            boundary_loops: c.boundary_loops,
            root: r.expect("every component has a vertex"),
        })
        .collect();
    let roots: Vec<VertexId> = components.iter().map(|c| c.root).collect();
    let tree = VertexTree::shortest_paths(mesh, &roots, &length);

    // Dual graph over interior edges, weighted by the negated length of the loop each
    // edge closes through the root, so that the minimum spanning tree is the maximum one.
    let mut dual: UnGraph<(), (f64, EdgeId)> =
        UnGraph::with_capacity(mesh.face_count(), mesh.edge_count());
    for _ in mesh.faces() {
        dual.add_node(());
    }
    for e in mesh.edges() {
        if let [Some(f), Some(g)] = mesh.edge_faces(e) {
            let [u, w] = mesh.edge_vertices(e);
            let weight = tree.dist[u.idx()] + length[e.idx()] + tree.dist[w.idx()];
            dual.add_edge(
                NodeIndex::new(f.idx()),
                NodeIndex::new(g.idx()),
                (-weight, e),
            );
        }
    }
    let off_tree = EdgeFiltered::from_fn(&dual, |r| !tree.in_tree[r.weight().1.idx()]);
    let mut in_cotree = vec![false; mesh.edge_count()];
    for element in min_spanning_tree(&off_tree) {
        if let Element::Edge { weight: (_, e), .. } = element {
            in_cotree[e.idx()] = true;
        }
    }

    // Leftover interior edges: the handle generators.
    let mut generators: Vec<Generator> = Vec::new();
    for e in mesh.edges() {
        if tree.in_tree[e.idx()] || in_cotree[e.idx()] || mesh.is_boundary_edge(e) {
            continue;
        }
        let h = mesh.edge_halfedge(e);
        let halfedges = tree.cycle(mesh, h);
        generators.push(Generator {
            component: vertex_component(mesh, mesh.origin(h)),
            kind: GeneratorKind::Handle,
            length: cycle_length(mesh, &halfedges, &length),
            halfedges,
        });
    }
    generators.sort_by(|a, b| {
        a.component
            .cmp(&b.component)
            .then(a.length.total_cmp(&b.length))
    });
    // Boundary generators: every loop of a component but its first.
    let mut seen = vec![false; components.len()];
    for b in mesh.boundary_loops() {
        let halfedges: Vec<HalfedgeId> = mesh.loop_halfedges(b).collect();
        let c = vertex_component(mesh, mesh.origin(halfedges[0]));
        if std::mem::replace(&mut seen[c.idx()], true) {
            generators.push(Generator {
                component: c,
                kind: GeneratorKind::Boundary(b),
                length: cycle_length(mesh, &halfedges, &length),
                halfedges,
            });
        }
    }
    generators.sort_by_key(|g| g.component);

    // The cut graph: the edges outside the cotree, pruned to their 2-core.
    let mut in_cut: Vec<bool> = in_cotree.iter().map(|&c| !c).collect();
    prune(mesh, &mut in_cut);
    CutGraph {
        components,
        generators,
        edges: mesh.edges().filter(|e| in_cut[e.idx()]).collect(),
    }
}

/// Removes edges with an end of degree 1 (within the set) until there are none.
fn prune(mesh: &Mesh, in_cut: &mut [bool]) {
    let mut degree = vec![0u32; mesh.vertex_count()];
    for e in mesh.edges().filter(|e| in_cut[e.idx()]) {
        for v in mesh.edge_vertices(e) {
            degree[v.idx()] += 1;
        }
    }
    let mut leaves: Vec<VertexId> = mesh.vertices().filter(|v| degree[v.idx()] == 1).collect();
    while let Some(v) = leaves.pop() {
        if degree[v.idx()] != 1 {
            continue;
        }
        let Some(h) = mesh
            .outgoing_halfedges(v)
            .find(|&h| in_cut[mesh.edge(h).idx()])
        else {
            continue;
        };
        in_cut[mesh.edge(h).idx()] = false;
        degree[v.idx()] = 0;
        let w = mesh.target(h);
        degree[w.idx()] -= 1;
        if degree[w.idx()] == 1 {
            leaves.push(w);
        }
    }
}

// ---------------------------------------------------------------------------------------
// Torus: a figure-eight cut
// ---------------------------------------------------------------------------------------

/// The shortest loop that leaves `a[k]`'s origin `p` on the left of `a`, comes back from
/// the right and visits no other vertex of `a`, for a few `p` along `a` (all of them if
/// those few fail). Returns the loop starting at `p`.
fn crossing_loop(mesh: &Mesh, a: &[HalfedgeId], length: &[f64]) -> Option<Vec<HalfedgeId>> {
    let mut on_a = vec![false; mesh.vertex_count()];
    for &h in a {
        on_a[mesh.origin(h).idx()] = true;
    }
    const FIRST_TRIES: usize = 8;
    let step = a.len().div_ceil(FIRST_TRIES).max(1);
    let first: Vec<usize> = (0..a.len()).step_by(step).collect();
    let best = |ks: &mut dyn Iterator<Item = usize>| {
        ks.filter_map(|k| crossing_at(mesh, a, k, &on_a, length))
            .min_by(|x, y| x.0.total_cmp(&y.0))
    };
    best(&mut first.iter().copied())
        .or_else(|| best(&mut (0..a.len()).filter(|k| k % step != 0)))
        .map(|(_, path)| path)
}

/// The shortest crossing loop through `p = origin(a[k])` (see [`crossing_loop`]) and its
/// length.
fn crossing_at(
    mesh: &Mesh,
    a: &[HalfedgeId],
    k: usize,
    on_a: &[bool],
    length: &[f64],
) -> Option<(f64, Vec<HalfedgeId>)> {
    let out = a[k];
    let back = mesh.twin(a[(k + a.len() - 1) % a.len()]);
    let p = mesh.origin(out);
    // Outgoing halfedges of p counter-clockwise from `out`: left of a until `back`,
    // right of a after it.
    let mut left = Vec::new();
    let mut right = Vec::new();
    let mut past_back = false;
    for h in mesh
        .outgoing_halfedges(p)
        .cycle()
        .skip_while(|&h| h != out)
        .skip(1)
    {
        if h == out {
            break;
        }
        if h == back {
            past_back = true;
        } else if !on_a[mesh.target(h).idx()] {
            if past_back {
                right.push(h);
            } else {
                left.push(h);
            }
        }
    }
    if left.is_empty() || right.is_empty() {
        return None;
    }
    let nv = mesh.vertex_count();
    let mut dist = vec![f64::INFINITY; nv];
    let mut pred: Vec<Option<HalfedgeId>> = vec![None; nv];
    let mut done = vec![false; nv];
    let mut heap = BinaryHeap::new();
    for &h in &left {
        let w = mesh.target(h);
        dist[w.idx()] = length[mesh.edge(h).idx()];
        pred[w.idx()] = Some(h);
        heap.push(Entry {
            dist: dist[w.idx()],
            vertex: w,
        });
    }
    let mut is_right = vec![false; nv];
    for &h in &right {
        is_right[mesh.target(h).idx()] = true;
    }
    let mut best: Option<(f64, VertexId)> = None;
    while let Some(Entry { dist: d, vertex: x }) = heap.pop() {
        if done[x.idx()] {
            continue;
        }
        if best.is_some_and(|(b, _)| d >= b) {
            break;
        }
        done[x.idx()] = true;
        if is_right[x.idx()] {
            // The right halfedges leave p, so the closing edge has the same length.
            let closing = mesh
                .outgoing_halfedges(x)
                .find(|&h| mesh.target(h) == p)
                .map_or(f64::INFINITY, |h| length[mesh.edge(h).idx()]);
            if best.is_none_or(|(b, _)| d + closing < b) {
                best = Some((d + closing, x));
            }
        }
        for h in mesh.outgoing_halfedges(x) {
            let w = mesh.target(h);
            let dw = d + length[mesh.edge(h).idx()];
            if !on_a[w.idx()] && !done[w.idx()] && dw < dist[w.idx()] {
                dist[w.idx()] = dw;
                pred[w.idx()] = Some(h);
                heap.push(Entry {
                    dist: dw,
                    vertex: w,
                });
            }
        }
    }
    let (total, end) = best?;
    let mut path = Vec::new();
    let mut x = end;
    while x != p {
        let h = pred[x.idx()].expect("a reached vertex has a predecessor");
        path.push(h);
        x = mesh.origin(h);
    }
    path.reverse();
    path.push(
        mesh.outgoing_halfedges(end)
            .find(|&h| mesh.target(h) == p)?,
    );
    Some((total, path))
}

/// The figure-eight cut graph of a closed torus: the shortest generator and a loop
/// crossing it once. `None` when no crossing loop exists in the edge graph.
fn figure_eight(mesh: &Mesh, graph: &CutGraph) -> Option<CutGraph> {
    let length = mesh.edge_lengths();
    let a = graph.generators.first()?;
    let b = crossing_loop(mesh, &a.halfedges, &length)?;
    let b = Generator {
        component: a.component,
        kind: GeneratorKind::Handle,
        length: cycle_length(mesh, &b, &length),
        halfedges: b,
    };
    let mut edges: Vec<EdgeId> = a.edges(mesh);
    edges.extend(b.edges(mesh));
    edges.sort_unstable();
    edges.dedup();
    Some(CutGraph {
        components: graph.components.clone(),
        generators: vec![a.clone(), b],
        edges,
    })
}

// ---------------------------------------------------------------------------------------
// Cutting
// ---------------------------------------------------------------------------------------

/// Cuts a one-component mesh along its cut graph into a topological disk (see the
/// module docs). A disk comes back unchanged; a genus-0 surface with several boundary
/// loops is cut along paths joining them; a closed torus is cut along a figure-eight and
/// its four sides are reported.
///
/// # Errors
/// [`CutError::MultipleComponents`] for more than one component,
/// [`CutError::ClosedGenusZero`] for a topological sphere, [`CutError::Build`] if the
/// cut mesh fails validation.
pub fn cut_to_disk(mesh: &Mesh) -> Result<CutMesh, CutError> {
    let components = mesh.components();
    if components.len() != 1 {
        return Err(CutError::MultipleComponents { components });
    }
    let topology = components[0];
    if topology.is_closed() && topology.genus == 0 {
        return Err(CutError::ClosedGenusZero);
    }
    let graph = cut_graph(mesh);
    let torus = topology.is_closed() && topology.genus == 1;
    let eight = if torus {
        figure_eight(mesh, &graph)
    } else {
        None
    };
    let is_eight = eight.is_some();
    let cut = eight.unwrap_or(graph);

    let (cut_mesh, to_original) = cut_along(mesh, &cut.edges)?;
    let boundary: Vec<HalfedgeId> = cut_mesh
        .boundary_loops()
        .next()
        .map(|b| cut_mesh.loop_halfedges(b).collect())
        .unwrap_or_default();
    let mut out = CutMesh {
        mesh: cut_mesh,
        to_original,
        cut,
        boundary,
        torus_sides: None,
    };
    if is_eight {
        out.torus_sides = torus_sides(mesh, &mut out);
    }
    Ok(out)
}

/// Cuts `mesh` open along the given edges (any set, e.g. a path that slits a closed
/// genus-0 surface into a disk): every vertex is split into one copy per wedge of faces
/// between consecutive cut or boundary edges around it, as in [`cut_to_disk`]. Faces
/// keep their ids, order and first vertex; the returned seam map gives the original
/// vertex of every vertex of the cut mesh (vertex `v < n` is a copy of `v`).
///
/// # Errors
/// [`CutError::Build`] if the cut mesh fails validation.
pub fn cut_along(mesh: &Mesh, edges: &[EdgeId]) -> Result<(Mesh, Vec<VertexId>), CutError> {
    let mut in_cut = vec![false; mesh.edge_count()];
    for &e in edges {
        in_cut[e.idx()] = true;
    }
    let (soup, to_original) = split_along(mesh, &in_cut);
    // The faces are the original's, already validated: accept every area, whatever
    // tolerance the original was built with.
    let options = BuildOptions {
        degenerate_area_tolerance: -1.0,
        repair: Repair::NONE,
    };
    let (cut_mesh, _) = Mesh::build(&soup, &options)?;
    Ok((cut_mesh, to_original))
}

/// Splits the vertices of `mesh` by a class given per face corner (`class[h]` for the
/// face halfedge `h` leaving the corner's vertex; e.g. the index of its texture
/// coordinate): corners of one vertex with equal classes share a vertex of the result,
/// corners with different classes get different ones. Faces keep their ids, order and
/// first vertex. Returns the split mesh and, per vertex of it, the original vertex and
/// the class.
///
/// # Errors
/// [`MeshError`] if the split is not a valid mesh (corners of one class at a vertex
/// that are not one fan: the vertex would be pinched).
pub fn split_corners(
    mesh: &Mesh,
    class: &[u32],
) -> Result<(Mesh, Vec<(VertexId, u32)>), MeshError> {
    let mut vertex_of: std::collections::HashMap<(VertexId, u32), u32> =
        std::collections::HashMap::new();
    let mut origin: Vec<(VertexId, u32)> = Vec::new();
    let mut positions = Vec::new();
    let mut faces: Vec<u32> = Vec::with_capacity(4 * mesh.face_count());
    let mut sizes = Vec::with_capacity(mesh.face_count());
    for f in mesh.faces() {
        let mut size = 0;
        for h in mesh.face_halfedges(f) {
            let key = (mesh.origin(h), class[h.idx()]);
            let v = *vertex_of.entry(key).or_insert_with(|| {
                positions.push(mesh.position(key.0));
                origin.push(key);
                (positions.len() - 1) as u32
            });
            faces.push(v);
            size += 1;
        }
        sizes.push(size);
    }
    let mut soup = PolygonSoup::new(positions);
    let mut at = 0;
    for size in sizes {
        soup.push_face(&faces[at..at + size]);
        at += size;
    }
    let options = BuildOptions {
        degenerate_area_tolerance: -1.0,
        repair: Repair::NONE,
    };
    let (split, _) = Mesh::build(&soup, &options)?;
    Ok((split, origin))
}

/// The polygon soup of `mesh` with every vertex split into one copy per wedge of faces
/// between consecutive cut edges around it (boundary edges always separate), and the
/// original vertex of every copy. Copy 0 of vertex `v` keeps the id `v`.
fn split_along(mesh: &Mesh, in_cut: &[bool]) -> (PolygonSoup, Vec<VertexId>) {
    let mut positions = mesh.positions().to_vec();
    let mut to_original: Vec<VertexId> = mesh.vertices().collect();
    // The cut-mesh vertex of every face corner, by the face halfedge leaving it.
    let mut corner = vec![0u32; mesh.halfedge_count()];
    let separates =
        |h: HalfedgeId| in_cut[mesh.edge(h).idx()] || mesh.is_boundary_edge(mesh.edge(h));
    for v in mesh.vertices() {
        let around: Vec<HalfedgeId> = mesh.outgoing_halfedges(v).collect();
        let start = around.iter().position(|&h| separates(h)).unwrap_or(0);
        let mut current = v.0;
        let mut wedges = 0usize;
        let mut new_wedge = true;
        for &h in around[start..].iter().chain(&around[..start]) {
            new_wedge |= separates(h);
            if mesh.face(h).is_none() {
                continue;
            }
            if new_wedge {
                new_wedge = false;
                if wedges > 0 {
                    positions.push(mesh.position(v));
                    to_original.push(v);
                    current = (positions.len() - 1) as u32;
                }
                wedges += 1;
            }
            corner[h.idx()] = current;
        }
    }
    let mut soup = PolygonSoup::new(positions);
    soup.reserve(mesh.face_count(), 4 * mesh.face_count());
    let mut buf = Vec::with_capacity(4);
    for f in mesh.faces() {
        buf.clear();
        buf.extend(mesh.face_halfedges(f).map(|h| corner[h.idx()]));
        soup.push_face(&buf);
    }
    (soup, to_original)
}

/// Rotates `cut.boundary` to start where side `a` starts and splits it into the four
/// sides at the copies of the crossing vertex of the figure-eight.
fn torus_sides(original: &Mesh, cut: &mut CutMesh) -> Option<TorusSides> {
    let a = &cut.cut.generators[0];
    let b = &cut.cut.generators[1];
    let p = original.origin(b.halfedges[0]);
    let mut on_a = vec![false; original.edge_count()];
    for e in a.edges(original) {
        on_a[e.idx()] = true;
    }
    let m = &cut.mesh;
    let original_edge = |h: HalfedgeId| {
        let (u, w) = (
            cut.to_original[m.origin(h).idx()],
            cut.to_original[m.target(h).idx()],
        );
        original
            .outgoing_halfedges(u)
            .find(|&g| original.target(g) == w)
            .map(|g| original.edge(g))
    };
    let corners: Vec<usize> = (0..cut.boundary.len())
        .filter(|&i| cut.to_original[m.origin(cut.boundary[i]).idx()] == p)
        .collect();
    if corners.len() != 4 {
        return None;
    }
    let start = *corners
        .iter()
        .find(|&&i| original_edge(cut.boundary[i]).is_some_and(|e| on_a[e.idx()]))?;
    cut.boundary.rotate_left(start);
    let n = cut.boundary.len();
    let mut at: Vec<usize> = corners.iter().map(|&i| (i + n - start) % n).collect();
    at.sort_unstable();
    Some(TorusSides {
        a: at[0]..at[1],
        b: at[1]..at[2],
        a_inv: at[2]..at[3],
        b_inv: at[3]..n,
    })
}
