//! Nested dissection: a fill-reducing elimination order for the sparse Cholesky
//! factorization of matrices whose graph is a surface mesh.
//!
//! A vertex separator `S` splits a graph into parts `A` and `B` with no edge between
//! them; eliminating `A`, then `B`, then `S` confines the fill of `A` and `B` to
//! themselves and to `S`, and the rule applied recursively to `A` and `B` (George 1973,
//! "Nested dissection of a regular finite element mesh") bounds the factor of a planar
//! mesh with `n` vertices by `O(n log n)` entries and `O(n^(3/2))` operations, the best
//! possible order (Lipton, Rose, Tarjan 1979). Minimum-degree orders such as AMD are
//! cheaper to compute and as good on many scanned meshes, but fall behind on large
//! regular ones (`fill_reducing_order` chooses; figures in docs/benchmarks.md).
//!
//! Separators come from breadth-first searches (George and Liu 1978, "An automatic
//! nested dissection algorithm for irregular finite element problems"): the edges of a
//! search join only equal or consecutive levels, so every level separates the levels
//! before it from those after. Here two searches start from the ends `u`, `v` of a
//! pseudo-diameter, and three kinds of band are candidates: a level of `d_u`, a level
//! of `d_v`, and two consecutive values of `d_u - d_v` (which an edge changes by at
//! most 2), whose level sets cross the part between `u` and `v` instead of circling
//! one of them. Among the bands that leave neither side more than [`BALANCE`] of the
//! part, the one with the fewest vertices after thinning is taken, and thinned: a band
//! vertex with no neighbour on one side moves to the other. Parts of at most [`LEAF`]
//! vertices are ordered by AMD.
//!
//! [`Depth::Multilevel`] takes multilevel separators instead ([`vertex_separator`]:
//! coarsening, a separator of the coarsest graph, refinement on the way back), smaller
//! and about 2.5 times as costly to compute; the flow, which factors one pattern at
//! every step, orders with them.
//!
//! The two sides of the first separator are dissected at once, one on a second thread
//! as a graph of its own: the order is the same as one thread's (the 1M-triangle disk's
//! in 0.9 s instead of 1.5 s on two cores, 2026-11-27).

use super::vertex_separator::{self, Place};

/// Largest part ordered by minimum degree instead of a further separator (256: the
/// factors of the 1M-triangle disk and of the subdivided hand were within 3% of each
/// other for leaves of 64 to 4096 vertices, and the order was quickest near 256).
const LEAF: usize = 256;

/// Largest share of a part's vertices one side of its separator may hold.
const BALANCE: f64 = 0.6;

/// [`BALANCE`] of the first split, whose two sides are factored at once on two cores
/// (`two_domains`): the factorization waits for the larger side.
const FIRST_BALANCE: f64 = 0.52;

/// Breadth-first sweeps spent looking for a pseudo-peripheral vertex.
const SWEEPS: usize = 4;

/// Marks a vertex that is already eliminated (in an order slot).
const DONE: u32 = u32::MAX;

/// The symmetric graph of a square pattern without its diagonal, as adjacency lists.
struct Graph {
    start: Vec<usize>,
    neighbours: Vec<u32>,
    /// Each vertex's degree in the whole pattern's graph, also in a subgraph cut from
    /// it ([`Graph::induced`]), so that a part's pseudo-peripheral vertex is the same
    /// whether the part is dissected inside the whole graph or on its own.
    whole_degree: Vec<u32>,
}

impl Graph {
    /// The graph of the pattern's lower and upper triangles together (an entry `(i, j)`,
    /// `i != j`, read in either triangle, makes `i` and `j` neighbours; duplicates are
    /// harmless).
    fn of_pattern(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Self {
        let mut degree = vec![0usize; n];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if i != j {
                    degree[i] += 1;
                    degree[j] += 1;
                }
            }
        }
        let start = offsets(&degree);
        let whole_degree = degree.iter().map(|&d| d as u32).collect();
        let mut fill = start.clone();
        let mut neighbours = vec![0u32; start[n]];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if i != j {
                    neighbours[fill[i]] = j as u32;
                    fill[i] += 1;
                    neighbours[fill[j]] = i as u32;
                    fill[j] += 1;
                }
            }
        }
        Self {
            start,
            neighbours,
            whole_degree,
        }
    }

    /// The vertices in breadth-first order, component after component.
    fn breadth_first_order(&self) -> Vec<usize> {
        let n = self.start.len() - 1;
        let mut seen = vec![false; n];
        let mut order = Vec::with_capacity(n);
        for root in 0..n {
            if seen[root] {
                continue;
            }
            seen[root] = true;
            let mut head = order.len();
            order.push(root);
            while head < order.len() {
                let v = order[head];
                head += 1;
                for w in self.neighbours(v) {
                    if !seen[w] {
                        seen[w] = true;
                        order.push(w);
                    }
                }
            }
        }
        order
    }

    /// The same graph with vertex `order[k]` renumbered `k`.
    fn renumbered(&self, order: &[usize]) -> Self {
        let mut new_index = vec![0u32; order.len()];
        for (k, &v) in order.iter().enumerate() {
            new_index[v] = k as u32;
        }
        let degree: Vec<usize> = order
            .iter()
            .map(|&v| self.start[v + 1] - self.start[v])
            .collect();
        let start = offsets(&degree);
        let mut neighbours = Vec::with_capacity(self.neighbours.len());
        for &v in order {
            neighbours.extend(self.neighbours(v).map(|w| new_index[w]));
        }
        let whole_degree = order.iter().map(|&v| self.whole_degree[v]).collect();
        Self {
            start,
            neighbours,
            whole_degree,
        }
    }

    /// The subgraph induced by `vertices`, vertex `vertices[k]` numbered `k`; `local[v]`
    /// must hold that `k` for every `v` of `vertices`, and `inside(w)` must say whether
    /// `w` is one of them.
    fn induced(&self, vertices: &[usize], local: &[u32], inside: impl Fn(usize) -> bool) -> Self {
        let mut start = Vec::with_capacity(vertices.len() + 1);
        let mut neighbours = Vec::new();
        start.push(0);
        for &v in vertices {
            neighbours.extend(self.neighbours(v).filter(|&w| inside(w)).map(|w| local[w]));
            start.push(neighbours.len());
        }
        let whole_degree = vertices.iter().map(|&v| self.whole_degree[v]).collect();
        Self {
            start,
            neighbours,
            whole_degree,
        }
    }

    fn neighbours(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.neighbours[self.start[v]..self.start[v + 1]]
            .iter()
            .map(|&w| w as usize)
    }

    fn degree(&self, v: usize) -> u32 {
        self.whole_degree[v]
    }
}

/// Prefix sums: where each vertex's list starts, and the total at the end.
fn offsets(degree: &[usize]) -> Vec<usize> {
    let mut start = Vec::with_capacity(degree.len() + 1);
    let mut total = 0;
    for d in degree {
        start.push(total);
        total += d;
    }
    start.push(total);
    start
}

/// Which distance array a search fills.
#[derive(Debug, Clone, Copy)]
enum Distance {
    U,
    V,
}

/// The function of the distances whose values a separator band takes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Key {
    /// `d_u`.
    U,
    /// `d_v`.
    V,
    /// `d_u - d_v`, shifted by the given depth of the search from `v` to stay >= 0.
    Difference(u32),
}

/// Where a vertex falls relative to a separator band.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Side {
    A,
    S,
    B,
}

impl Key {
    /// The key's value at a vertex with distances `d_u`, `d_v`.
    fn value(self, d_u: u32, d_v: u32) -> u32 {
        match self {
            Key::U => d_u,
            Key::V => d_v,
            Key::Difference(shift) => d_u + shift - d_v,
        }
    }

    /// How many consecutive values of the key a separator band takes: enough that no
    /// edge jumps over the band.
    fn width(self) -> usize {
        match self {
            Key::U | Key::V => 1,
            Key::Difference(_) => 2,
        }
    }
}

/// A separator band: the vertices whose key lies in `start..start + key.width()`.
#[derive(Debug, Clone, Copy)]
struct Cut {
    key: Key,
    start: u32,
}

impl Cut {
    fn side(&self, d_u: u32, d_v: u32) -> Side {
        let key = self.key.value(d_u, d_v);
        if key < self.start {
            Side::A
        } else if key < self.start + self.key.width() as u32 {
            Side::S
        } else {
            Side::B
        }
    }
}

/// Working state of one dissection: which part each vertex belongs to, the search
/// buffers, and the order built so far.
struct Dissection<'g> {
    graph: &'g Graph,
    /// The part a vertex belongs to, or [`DONE`].
    part: Vec<u32>,
    /// Distances from the two ends of a pseudo-diameter of the part being split.
    distance_u: Vec<u32>,
    distance_v: Vec<u32>,
    next_part: u32,
    order: Vec<usize>,
    /// The sizes of the two sides of the first split (see [`Dissected::halves`]).
    halves: Option<[usize; 2]>,
    depth: Depth,
}

/// How far a dissection splits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Depth {
    /// Separators in every part down to parts of at most [`LEAF`] vertices.
    Full,
    /// Multilevel separators ([`vertex_separator`]) in every part down to parts of at
    /// most [`LEAF`] vertices: smaller separators than the level sets' at 2.5 times
    /// their cost, for orders computed once and factored many times (the flow's).
    Multilevel,
}

/// A breadth-first search inside one part: the vertices reached in search order and
/// where each level starts in that list.
struct Levels {
    queue: Vec<usize>,
    /// `queue[starts[l]..starts[l + 1]]` is level `l`.
    starts: Vec<usize>,
}

impl Levels {
    fn with_capacity(vertices: usize) -> Self {
        Self {
            queue: Vec::with_capacity(vertices),
            starts: Vec::new(),
        }
    }
}

impl<'g> Dissection<'g> {
    /// A dissection of all of `graph`'s vertices, none ordered yet; `halves` is the
    /// first split when `graph` is one of its sides.
    fn new(graph: &'g Graph, depth: Depth, halves: Option<[usize; 2]>) -> Self {
        let n = graph.whole_degree.len();
        Self {
            graph,
            part: vec![0; n],
            distance_u: vec![0; n],
            distance_v: vec![0; n],
            next_part: 0,
            order: Vec::with_capacity(n),
            halves,
            depth,
        }
    }

    /// Dissects all of the graph: its elimination order.
    fn run(mut self) -> Vec<usize> {
        let n = self.part.len();
        self.dissect((0..n).collect(), 0);
        self.order
    }

    /// The largest share of a part one side of its separator may hold:
    /// [`FIRST_BALANCE`] at the first split (before its sides are known), else
    /// [`BALANCE`].
    fn balance(&self) -> f64 {
        if self.halves.is_none() {
            FIRST_BALANCE
        } else {
            BALANCE
        }
    }

    fn fresh_part(&mut self) -> u32 {
        self.next_part += 1;
        self.next_part
    }

    /// Breadth-first search from `root` through vertices of part `id`, writing the
    /// distances from `root` into the array `into`.
    fn search(&mut self, root: usize, id: u32, levels: &mut Levels, into: Distance) {
        levels.queue.clear();
        levels.starts.clear();
        levels.queue.push(root);
        levels.starts.push(0);
        // Visited vertices are moved to a temporary part so each is queued once; the
        // caller gives them their real part afterwards.
        let visiting = self.fresh_part();
        let distance = match into {
            Distance::U => &mut self.distance_u,
            Distance::V => &mut self.distance_v,
        };
        self.part[root] = visiting;
        distance[root] = 0;
        let mut head = 0;
        while head < levels.queue.len() {
            let v = levels.queue[head];
            head += 1;
            let l = distance[v];
            for w in self.graph.neighbours(v) {
                if self.part[w] == id {
                    self.part[w] = visiting;
                    distance[w] = l + 1;
                    if levels.starts.len() == (l + 1) as usize {
                        levels.starts.push(levels.queue.len());
                    }
                    levels.queue.push(w);
                }
            }
        }
        levels.starts.push(levels.queue.len());
    }

    /// The best of three separators of a part with searches `from_u` (distances `d_u`)
    /// and `from_v` (`d_v`) from the two ends of a pseudo-diameter: a level of `d_u`, a
    /// level of `d_v`, or two consecutive values of `d_u - d_v` (an edge changes it by
    /// at most 2, so those two values separate the smaller from the larger; its level
    /// sets run across the diameter instead of around one end, which suits elongated
    /// parts). The one with the fewest vertices after thinning is taken among those
    /// that leave neither side more than `balance` of the part.
    fn best_cut(
        &self,
        id: u32,
        from_u: &Levels,
        from_v: &Levels,
        total: usize,
        balance: f64,
    ) -> Cut {
        let depth_u = from_u.starts.len() - 2;
        let depth_v = from_v.starts.len() - 2;
        let keys = [Key::U, Key::V, Key::Difference(depth_v as u32)];
        let ranges = [depth_u + 1, depth_v + 1, depth_u + depth_v + 1];
        let key_of = |w: usize| keys.map(|key| key.value(self.distance_u[w], self.distance_v[w]));
        // Vertices per key value, then the band starts that leave neither side empty
        // nor larger than the limit.
        let mut counts: Vec<Vec<usize>> = ranges.iter().map(|&r| vec![0; r]).collect();
        for &v in &from_u.queue {
            for (count, k) in counts.iter_mut().zip(key_of(v)) {
                count[k as usize] += 1;
            }
        }
        let limit = (balance * total as f64) as usize;
        let balanced: Vec<Vec<bool>> = keys
            .iter()
            .zip(&counts)
            .map(|(key, count)| {
                let width = key.width();
                let mut before = 0;
                (0..count.len())
                    .map(|start| {
                        let band: usize =
                            count[start..(start + width).min(count.len())].iter().sum();
                        let after = total - before - band;
                        let ok = before > 0 && after > 0 && before <= limit && after <= limit;
                        before += count[start];
                        ok
                    })
                    .collect()
            })
            .collect();
        // Per balanced band start, the band's vertices that keep a neighbour on each
        // side (those thinning leaves in the separator); only vertices in some
        // balanced band are looked at.
        let mut kept: Vec<Vec<usize>> = ranges.iter().map(|&r| vec![0; r]).collect();
        for &v in &from_u.queue {
            let own = key_of(v);
            let in_band = |i: usize| {
                let k = own[i] as usize;
                (k.saturating_sub(keys[i].width() - 1)..=k).any(|start| balanced[i][start])
            };
            if !(0..3).any(in_band) {
                continue;
            }
            let (mut low, mut high) = (own, own);
            for w in self.graph.neighbours(v) {
                if self.part[w] != id {
                    continue;
                }
                for (i, k) in key_of(w).into_iter().enumerate() {
                    low[i] = low[i].min(k);
                    high[i] = high[i].max(k);
                }
            }
            for (i, key) in keys.iter().enumerate() {
                let k = own[i] as usize;
                let width = key.width();
                let first = k.saturating_sub(width - 1);
                for (start, kept) in kept[i][first..=k].iter_mut().enumerate() {
                    let start = first + start;
                    if (low[i] as usize) < start && high[i] as usize >= start + width {
                        *kept += 1;
                    }
                }
            }
        }
        let mut best: Option<(Cut, usize)> = None;
        for (i, &key) in keys.iter().enumerate() {
            for (start, &size) in kept[i].iter().enumerate() {
                if balanced[i][start] && best.is_none_or(|(_, s)| size < s) {
                    best = Some((
                        Cut {
                            key,
                            start: start as u32,
                        },
                        size,
                    ));
                }
            }
        }
        best.map_or_else(
            || {
                // No balanced band (a star-like part): the level of `d_u` holding the
                // median vertex.
                let median = (0..from_u.starts.len() - 1)
                    .find(|&l| from_u.starts[l + 1] * 2 >= total)
                    .unwrap_or(0);
                Cut {
                    key: Key::U,
                    start: median as u32,
                }
            },
            |(cut, _)| cut,
        )
    }

    /// Appends the minimum-degree order (faer's AMD) of the subgraph of part `id`.
    fn eliminate_leaf(&mut self, vertices: Vec<usize>, id: u32) {
        use faer::sparse::SymbolicSparseColMatRef;
        let n = vertices.len();
        // The distances are not needed any more in a leaf: they hold the local index.
        for (k, &v) in vertices.iter().enumerate() {
            self.distance_u[v] = k as u32;
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for &v in &vertices {
            for w in self.graph.neighbours(v) {
                if self.part[w] == id {
                    row_idx.push(self.distance_u[w] as usize);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let pattern = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &col_ptr, None, &row_idx);
        let order = crate::amd_order(pattern);
        for &v in &vertices {
            self.part[v] = DONE;
        }
        match order {
            Ok(order) => self.order.extend(order.iter().map(|&k| vertices[k])),
            // Only an allocation failure stops AMD: the part as it is, still an order.
            Err(_) => self.order.extend(vertices),
        }
    }

    /// Whether `v` has a neighbour in the part `id`.
    fn touches(&self, v: usize, id: u32) -> bool {
        self.graph.neighbours(v).any(|w| self.part[w] == id)
    }

    /// Gives every vertex of `vertices` the part `id`.
    fn assign(&mut self, vertices: &[usize], id: u32) {
        for &v in vertices {
            self.part[v] = id;
        }
    }

    /// Appends the elimination order of the part `id`, whose vertices are `vertices`.
    fn dissect(&mut self, vertices: Vec<usize>, id: u32) {
        if vertices.len() <= LEAF {
            self.eliminate_leaf(vertices, id);
            return;
        }
        let mut levels = Levels::with_capacity(vertices.len());
        self.search(vertices[0], id, &mut levels, Distance::U);
        if levels.queue.len() < vertices.len() {
            // The part is not connected: the component of `root` and the rest are
            // independent, so each is ordered on its own and nothing separates them.
            let component = std::mem::take(&mut levels.queue);
            let component_id = self.fresh_part();
            self.assign(&component, component_id);
            let rest: Vec<usize> = vertices
                .into_iter()
                .filter(|&v| self.part[v] == id)
                .collect();
            self.dissect_sides(component, component_id, rest, id);
            return;
        }
        self.assign(&levels.queue, id);
        if self.depth == Depth::Multilevel {
            self.split_multilevel(levels.queue, id);
            return;
        }
        // Pseudo-peripheral pair (u, v): v is a vertex of least degree in the last level
        // of the search from u; u moves to v while that search gets deeper.
        let mut far = Levels::with_capacity(vertices.len());
        for _ in 0..SWEEPS {
            let last = &levels.queue[levels.starts[levels.starts.len() - 2]..];
            let v = last
                .iter()
                .copied()
                .min_by_key(|&v| self.graph.degree(v))
                .unwrap_or(vertices[0]);
            self.search(v, id, &mut far, Distance::V);
            self.assign(&far.queue, id);
            if far.starts.len() <= levels.starts.len() {
                break;
            }
            std::mem::swap(&mut levels, &mut far);
            std::mem::swap(&mut self.distance_u, &mut self.distance_v);
        }
        let total = levels.queue.len();
        let cut = self.best_cut(id, &levels, &far, total, self.balance());
        let (a_id, b_id, s_id) = (self.fresh_part(), self.fresh_part(), self.fresh_part());
        let mut a = Vec::new();
        let mut b = Vec::new();
        let mut band = Vec::new();
        for &v in &levels.queue {
            match cut.side(self.distance_u[v], self.distance_v[v]) {
                Side::A => {
                    self.part[v] = a_id;
                    a.push(v);
                }
                Side::B => {
                    self.part[v] = b_id;
                    b.push(v);
                }
                Side::S => {
                    self.part[v] = s_id;
                    band.push(v);
                }
            }
        }
        // Thinning: a separator vertex with no neighbour in B is not needed to keep A
        // from B (and the reverse).
        let mut separator = Vec::with_capacity(band.len());
        for &s in &band {
            if !self.touches(s, b_id) {
                self.part[s] = a_id;
                a.push(s);
            } else if !self.touches(s, a_id) {
                self.part[s] = b_id;
                b.push(s);
            } else {
                separator.push(s);
            }
        }
        self.split([a, b], [a_id, b_id], separator, levels.queue);
    }

    /// Splits the connected part `id` of a [`Depth::Multilevel`] dissection (its
    /// vertices `reached`, in breadth-first order), cut out as a graph of its own, by the
    /// multilevel method ([`vertex_separator`]), each side at most [`FIRST_BALANCE`] of
    /// it at the first split and [`BALANCE`] below. On the scan `g0_koala` the first
    /// separator has 182 vertices where the level sets of [`Dissection::dissect`] had
    /// 352, on 50K-vertex remeshes 4-24% fewer; on the flow's 50K-vertex graphs the
    /// whole order factors with 16-45% fewer multiply-subtracts than AMD inside the
    /// first split's sides (docs/benchmarks.md, "Fill-reducing orders against METIS").
    fn split_multilevel(&mut self, reached: Vec<usize>, id: u32) {
        // No level set is computed here: the distances hold the local index.
        for (k, &v) in reached.iter().enumerate() {
            self.distance_u[v] = k as u32;
        }
        let part_graph = self
            .graph
            .induced(&reached, &self.distance_u, |w| self.part[w] == id);
        let places =
            vertex_separator::separator(part_graph.start, part_graph.neighbours, self.balance());
        let (a_id, b_id) = (self.fresh_part(), self.fresh_part());
        let (mut a, mut b, mut separator) = (Vec::new(), Vec::new(), Vec::new());
        for (&v, place) in reached.iter().zip(places) {
            match place {
                Place::A => {
                    self.part[v] = a_id;
                    a.push(v);
                }
                Place::B => {
                    self.part[v] = b_id;
                    b.push(v);
                }
                Place::S => separator.push(v),
            }
        }
        self.split([a, b], [a_id, b_id], separator, reached);
    }

    /// Orders a part split into sides `a`, `b` (parts `ids`) by `separator`: the sides,
    /// then the separator; `all` (the part's vertices) as they are when a side is empty
    /// (a clique-like part that nothing splits).
    fn split(
        &mut self,
        [a, b]: [Vec<usize>; 2],
        [a_id, b_id]: [u32; 2],
        separator: Vec<usize>,
        all: Vec<usize>,
    ) {
        if a.is_empty() || b.is_empty() {
            for &v in &all {
                self.part[v] = DONE;
            }
            self.order.extend(all);
            return;
        }
        for &s in &separator {
            self.part[s] = DONE;
        }
        self.dissect_sides(a, a_id, b, b_id);
        self.order.extend(separator);
    }

    /// Appends the orders of two parts with no edge between them, `a` (part `a_id`)
    /// first. When they are the sides of the first split, the side `b` is cut out as a
    /// graph of its own and dissected on a second thread meanwhile: after the first
    /// separator the two sides share no vertex and no search, so the order is the same
    /// as one thread's.
    fn dissect_sides(&mut self, a: Vec<usize>, a_id: u32, b: Vec<usize>, b_id: u32) {
        if self.halves.is_some() {
            self.dissect(a, a_id);
            self.dissect(b, b_id);
            return;
        }
        let halves = [a.len(), b.len()];
        self.halves = Some(halves);
        // The distances of `b`'s vertices are not needed here any more: they hold the
        // vertices' numbers in the cut-out graph.
        for (k, &v) in b.iter().enumerate() {
            self.distance_u[v] = k as u32;
        }
        let side = self
            .graph
            .induced(&b, &self.distance_u, |w| self.part[w] == b_id);
        for &v in &b {
            self.part[v] = DONE;
        }
        let depth = self.depth;
        let b_order = std::thread::scope(|scope| {
            let other = scope.spawn(move || {
                let order = Dissection::new(&side, depth, Some(halves)).run();
                order.into_iter().map(|k| b[k]).collect::<Vec<_>>()
            });
            self.dissect(a, a_id);
            // A panic in the other thread is a bug; pass it on as one.
            other
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        });
        self.order.extend(b_order);
    }
}

/// A nested-dissection order and its first split.
pub(super) struct Dissected {
    /// `order[k]` is the row eliminated `k`-th.
    pub(super) order: Vec<usize>,
    /// `[a, b]` when the first split divides the rows into two sides with no entry
    /// between them: `order[..a]` orders one side, `order[a..a + b]` the other, and the
    /// rest (possibly nothing, between two components) is their separator. `None` when
    /// nothing was split (a part of at most [`LEAF`] rows, or one no level splits).
    pub(super) halves: Option<[usize; 2]>,
}

/// The nested-dissection elimination order of a square pattern (module docs), split as
/// deep as `depth` says. Only the off-diagonal entries matter, read from either
/// triangle.
///
/// `col_ptr` has `n + 1` entries and `row_idx[col_ptr[j]..col_ptr[j + 1]]` are the rows
/// of column `j`, all below `n`.
pub(super) fn nested_dissection(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    depth: Depth,
) -> Dissected {
    // Renumbered in breadth-first order, a part's vertices and their neighbours lie
    // close together in memory, which the many searches of the dissection reward
    // (measured: the order of the twice-subdivided hand in 1.6 s instead of 2.1 s, of
    // the twice-subdivided bunny in 0.9 s instead of 1.9 s).
    let pattern_graph = Graph::of_pattern(n, col_ptr, row_idx);
    let original = pattern_graph.breadth_first_order();
    let graph = pattern_graph.renumbered(&original);
    drop(pattern_graph);
    let mut dissection = Dissection::new(&graph, depth, None);
    dissection.dissect((0..n).collect(), 0);
    Dissected {
        order: dissection.order.into_iter().map(|k| original[k]).collect(),
        halves: dissection.halves,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower-triangle pattern (`col_ptr`, `row_idx`, diagonal included) of `copies`
    /// disjoint `k x k` triangulated grids, copy `c` numbered `c k^2 ..`.
    fn grids(k: usize, copies: usize) -> (Vec<usize>, Vec<usize>) {
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for c in 0..copies {
            for j in 0..k {
                for i in 0..k {
                    let v = c * k * k + i + k * j;
                    row_idx.push(v);
                    if i + 1 < k {
                        row_idx.push(v + 1);
                    }
                    if j + 1 < k {
                        row_idx.push(v + k);
                    }
                    if i + 1 < k && j + 1 < k {
                        row_idx.push(v + k + 1);
                    }
                    col_ptr.push(row_idx.len());
                }
            }
        }
        (col_ptr, row_idx)
    }

    #[test]
    fn a_side_dissected_on_its_own_thread_is_ordered_as_in_place() {
        // Two equal components: the first split puts one on each side; the first is
        // dissected in the whole graph, the second cut out on the other thread. Both
        // must get the same order (shifted by the first's size).
        let k = 50;
        let m = k * k;
        let (col_ptr, row_idx) = grids(k, 2);
        let dissected = nested_dissection(2 * m, &col_ptr, &row_idx, Depth::Full);
        assert_eq!(dissected.halves, Some([m, m]));
        let (first, second) = dissected.order.split_at(m);
        let shifted: Vec<usize> = second.iter().map(|&v| v - m).collect();
        assert!(first.iter().all(|&v| v < m));
        assert_eq!(first, shifted.as_slice());
    }
    /// The first split of a [`Depth::Multilevel`] order is the multilevel separator:
    /// on a 150 x 150 grid with diagonals at random 152 vertices (the level sets used
    /// before: 201), within the balance.
    #[test]
    fn the_first_split_of_an_irregular_grid_is_about_one_line() {
        let k = 150;
        // Adjacency lists are a pattern of both triangles without the diagonal.
        let (col_ptr, neighbours) = crate::vertex_separator::tests::grid(k, true);
        let row_idx: Vec<usize> = neighbours.iter().map(|&w| w as usize).collect();
        let dissected = nested_dissection(k * k, &col_ptr, &row_idx, Depth::Multilevel);
        let [a, b] = dissected.halves.expect("a split");
        let separator = k * k - a - b;
        assert!(
            a.max(b) as f64 <= FIRST_BALANCE * (k * k) as f64,
            "sides {a}, {b}"
        );
        assert!(separator <= k + k / 5, "separator {separator}");
        // No edge between the sides: A's vertices never meet B's in a column.
        let mut side = vec![2u8; k * k];
        dissected.order[..a].iter().for_each(|&v| side[v] = 0);
        dissected.order[a..a + b].iter().for_each(|&v| side[v] = 1);
        for j in 0..k * k {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                assert!(
                    side[i] == 2 || side[j] == 2 || side[i] == side[j],
                    "edge {i}-{j}"
                );
            }
        }
    }
}
