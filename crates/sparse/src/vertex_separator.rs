//! Multilevel vertex separators (Karypis and Kumar 1998, "A fast and high quality
//! multilevel scheme for partitioning irregular graphs", SIAM J. Sci. Comput. 20(1)).
//!
//! A graph is coarsened by matching neighbours and merging each matched pair into one
//! vertex (vertex weights add up, so do the weights of parallel edges), down to a few
//! hundred vertices. There a separator is cheap to find: level sets of breadth-first
//! searches from a few vertices, each improved by refinement, the smallest kept. It is
//! then carried back level by level, each fine vertex taking its coarse vertex's
//! place, and refined at every level, where the finer graph leaves room for a finer
//! boundary.
//!
//! Refinement is Fiduccia and Mattheyses' (1982, "A linear-time heuristic for
//! improving network partitions") for vertex separators (Ashcraft and Liu 1998,
//! "Robust ordering of sparse matrices using multisection"): a separator vertex moves
//! into one side, and its neighbours in the other side move into the separator; the
//! gain of the move is the weight leaving the separator less the weight entering it.
//! The best move that keeps both sides within the balance limit is taken, even at a
//! loss, each vertex moving once a pass, and the pass ends after a run of moves with
//! no better separator; the moves after the best separator seen are undone.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Vertex count below which a graph is not coarsened further (Karypis and Kumar
/// coarsen to about 100 vertices; a few more leave the initial separators room).
const COARSEST: usize = 128;

/// A coarsening that keeps more than this share of the vertices (a star-like graph,
/// where few edges can be matched) ends the coarsening.
const SLOW_COARSENING: f64 = 0.95;

/// Levels coarsened once; below them each of [`TRIALS`] coarsenings goes on with its
/// own matchings and the smallest separator is kept. The separator a coarsening leads
/// to varies by 20-50% with the matchings on the scanned meshes; the trials run on a
/// graph 16 times smaller than the part, so they cost about a quarter more.
const SHARED_LEVELS: usize = 4;

/// Coarsenings tried below [`SHARED_LEVELS`].
const TRIALS: usize = 4;

/// Vertices shuffled among themselves for the matching order (see [`shuffled`]).
const SHUFFLE_BLOCK: usize = 1024;

/// Breadth-first searches tried for the coarsest graph's separator.
const INITIAL_TRIES: usize = 6;

/// Largest number of refinement passes at one level (passes stop early once one
/// finds no smaller separator).
const PASSES: usize = 6;

/// The seed of the pseudo-random order in which vertices are matched: fixed, so that
/// a graph always gets the same separator.
const SEED: u64 = 0x9e37_79b9_7f4a_7c15;

/// Where a vertex lies relative to a separator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Place {
    /// One side.
    A,
    /// The other side.
    B,
    /// The separator.
    S,
}

impl Place {
    /// The index of the place in per-place arrays.
    fn index(self) -> usize {
        match self {
            Place::A => 0,
            Place::B => 1,
            Place::S => 2,
        }
    }

    /// The other side (a side's only).
    fn other(self) -> Place {
        match self {
            Place::A => Place::B,
            Place::B => Place::A,
            Place::S => Place::S,
        }
    }
}

/// A graph with weighted vertices and edges, as adjacency lists.
struct Weighted {
    start: Vec<usize>,
    neighbours: Vec<u32>,
    /// The weight of the edge `neighbours[k]`.
    edge_weight: Vec<u32>,
    vertex_weight: Vec<u32>,
}

impl Weighted {
    /// The graph with adjacency lists `neighbours[start[v]..start[v + 1]]`, every weight
    /// one.
    fn unit(start: Vec<usize>, neighbours: Vec<u32>) -> Self {
        Self {
            edge_weight: vec![1; neighbours.len()],
            vertex_weight: vec![1; start.len() - 1],
            start,
            neighbours,
        }
    }

    fn len(&self) -> usize {
        self.vertex_weight.len()
    }

    fn neighbours(&self, v: usize) -> impl Iterator<Item = usize> + '_ {
        self.neighbours[self.start[v]..self.start[v + 1]]
            .iter()
            .map(|&w| w as usize)
    }

    /// `v`'s neighbours with the weights of the edges to them.
    fn edges(&self, v: usize) -> impl Iterator<Item = (usize, u32)> + '_ {
        let range = self.start[v]..self.start[v + 1];
        self.neighbours[range.clone()]
            .iter()
            .zip(&self.edge_weight[range])
            .map(|(&w, &weight)| (w as usize, weight))
    }

    fn total_weight(&self) -> u64 {
        self.vertex_weight.iter().map(|&w| u64::from(w)).sum()
    }
}

/// A separator of the graph with adjacency lists `neighbours[start[v]..start[v + 1]]`
/// (symmetric, without loops): the place of every vertex, each side holding at most
/// `balance` of the vertices where the graph allows. Multilevel (module docs); the same
/// graph always gets the same separator.
pub(super) fn separator(start: Vec<usize>, neighbours: Vec<u32>, balance: f64) -> Vec<Place> {
    let finest = Weighted::unit(start, neighbours);
    let limit = (balance * finest.len() as f64) as u64;
    let mut random = SEED;
    let (levels, middle) = hierarchy(finest, &mut random, SHARED_LEVELS);
    let mut best: Option<(Score, Vec<Place>)> = None;
    for _ in 0..TRIALS {
        let places = trial(&middle, limit, &mut random);
        let score = Score::of(&weights(&middle, &places), limit);
        if best.as_ref().is_none_or(|(b, _)| score < *b) {
            best = Some((score, places));
        }
        if middle.len() <= COARSEST {
            break;
        }
    }
    let places = best.map_or_else(Vec::new, |(_, places)| places);
    uncoarsened(levels, places, limit)
}

/// Coarsens `graph` at most `most` times, until it has at most [`COARSEST`] vertices
/// or coarsens slowly: each level's graph with the map from its vertices to the next
/// coarser level's, and the coarsest graph.
fn hierarchy(
    mut graph: Weighted,
    random: &mut u64,
    most: usize,
) -> (Vec<(Weighted, Vec<u32>)>, Weighted) {
    let mut levels = Vec::new();
    while levels.len() < most && graph.len() > COARSEST {
        let (coarse, map) = coarsened(&graph, random);
        if coarse.len() as f64 > SLOW_COARSENING * graph.len() as f64 {
            break;
        }
        levels.push((graph, map));
        graph = coarse;
    }
    (levels, graph)
}

/// Carries the separator `places` of the coarsest graph of `levels` back to the finest,
/// refining it at each level.
fn uncoarsened(
    mut levels: Vec<(Weighted, Vec<u32>)>,
    mut places: Vec<Place>,
    limit: u64,
) -> Vec<Place> {
    while let Some((fine, map)) = levels.pop() {
        places = map.iter().map(|&c| places[c as usize]).collect();
        refine(&fine, &mut places, limit);
    }
    places
}

/// One multilevel separator of `graph`: coarsened to the end, separated, carried back.
fn trial(graph: &Weighted, limit: u64, random: &mut u64) -> Vec<Place> {
    if graph.len() <= COARSEST {
        return initial_separator(graph, limit);
    }
    let (coarse, map) = coarsened(graph, random);
    if coarse.len() as f64 > SLOW_COARSENING * graph.len() as f64 {
        return initial_separator(graph, limit);
    }
    let (levels, coarsest) = hierarchy(coarse, random, usize::MAX);
    let coarse_places = uncoarsened(levels, initial_separator(&coarsest, limit), limit);
    let mut places = map
        .iter()
        .map(|&c| coarse_places[c as usize])
        .collect::<Vec<_>>();
    refine(graph, &mut places, limit);
    places
}

/// A step of a small pseudo-random generator (splitmix64, Steele, Lea and Flood 2014):
/// fixed-seed noise for the matching order.
fn next_random(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The vertices `0..n` in a pseudo-random order (Fisher-Yates inside blocks of
/// [`SHUFFLE_BLOCK`]): matching in index order pairs vertices along the numbering's
/// sweeps into long thin coarse vertices (measured: 40% more factor operations on the
/// 1M-triangle disk), while a shuffle of the whole graph visits its memory at random.
fn shuffled(n: usize, random: &mut u64) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n as u32).collect();
    for chunk in order.chunks_mut(SHUFFLE_BLOCK) {
        for i in (1..chunk.len()).rev() {
            let j = ((u128::from(next_random(random)) * (i as u128 + 1)) >> 64) as usize;
            chunk.swap(i, j);
        }
    }
    order
}

/// Marks a vertex not matched yet.
const UNMATCHED: u32 = u32::MAX;

/// Heavy-edge matching (Karypis and Kumar 1998, section 3.1): each vertex, in a
/// pseudo-random order, is matched with the unmatched neighbour joined by the heaviest
/// edge (ties to the lightest neighbour, keeping the coarse weights even), or with
/// itself. Heavy edges inside coarse vertices leave light ones between them, and pairs
/// heavier than `cap` are not formed, so that no coarse vertex outweighs a balanced
/// side's slack. `mate[v]` is `v`'s partner.
fn heavy_edge_matching(graph: &Weighted, random: &mut u64, cap: u64) -> Vec<u32> {
    let n = graph.len();
    let mut mate = vec![UNMATCHED; n];
    let salt = next_random(random) as u32;
    for v in shuffled(n, random) {
        let v = v as usize;
        if mate[v] != UNMATCHED {
            continue;
        }
        let own = u64::from(graph.vertex_weight[v]);
        let mut best: Option<(u32, Reverse<u32>, u32, usize)> = None;
        for (w, weight) in graph.edges(v) {
            let other = graph.vertex_weight[w];
            if mate[w] != UNMATCHED || own + u64::from(other) > cap {
                continue;
            }
            let noise = (w as u32).wrapping_mul(0x9e37_79b1) ^ salt;
            let key = (weight, Reverse(other), noise, w);
            if best.is_none_or(|(b, o, h, _)| (key.0, key.1, key.2) > (b, o, h)) {
                best = Some(key);
            }
        }
        let partner = best.map_or(v, |(_, _, _, w)| w);
        mate[v] = partner as u32;
        mate[partner] = v as u32;
    }
    mate
}

/// The graph with every matched pair of `graph` merged into one vertex, and the map
/// from `graph`'s vertices to the merged ones (numbered in the order of their first
/// fine vertex, which keeps neighbours close in memory).
fn coarsened(graph: &Weighted, random: &mut u64) -> (Weighted, Vec<u32>) {
    let n = graph.len();
    let cap = (3 * graph.total_weight() / (2 * COARSEST as u64)).max(2);
    let mate = heavy_edge_matching(graph, random, cap);
    let mut map = vec![UNMATCHED; n];
    let mut representatives = Vec::with_capacity(n / 2 + 1);
    for v in 0..n {
        if map[v] == UNMATCHED {
            let c = representatives.len() as u32;
            map[v] = c;
            map[mate[v] as usize] = c;
            representatives.push(v);
        }
    }
    let coarse_n = representatives.len();
    // `slot[c]` is where coarse neighbour `c` sits in the list being built, if it is
    // there (a position at or past the list's start).
    let mut slot = vec![usize::MAX; coarse_n];
    let mut start = Vec::with_capacity(coarse_n + 1);
    let mut neighbours = Vec::with_capacity(graph.neighbours.len() / 2);
    let mut edge_weight = Vec::with_capacity(graph.neighbours.len() / 2);
    let mut vertex_weight = Vec::with_capacity(coarse_n);
    for (c, &v) in representatives.iter().enumerate() {
        let list_start = neighbours.len();
        start.push(list_start);
        let partner = mate[v] as usize;
        let pair: &[usize] = if partner == v { &[v] } else { &[v, partner] };
        let mut weight = 0;
        for &u in pair {
            weight += graph.vertex_weight[u];
            for (w, edge) in graph.edges(u) {
                let d = map[w] as usize;
                if d == c {
                    continue;
                }
                let s = slot[d];
                if s != usize::MAX && s >= list_start {
                    edge_weight[s] += edge;
                } else {
                    slot[d] = neighbours.len();
                    neighbours.push(d as u32);
                    edge_weight.push(edge);
                }
            }
        }
        vertex_weight.push(weight);
    }
    start.push(neighbours.len());
    let coarse = Weighted {
        start,
        neighbours,
        edge_weight,
        vertex_weight,
    };
    (coarse, map)
}

/// The coarsest graph's separator: the level set holding the median weight of a
/// breadth-first search from each of a few evenly spaced vertices (George and Liu
/// 1978), refined; the best after refinement.
fn initial_separator(graph: &Weighted, limit: u64) -> Vec<Place> {
    let n = graph.len();
    let tries = INITIAL_TRIES.min(n);
    let mut best: Option<(Score, Vec<Place>)> = None;
    for t in 0..tries {
        let mut places = median_level(graph, t * n / tries);
        refine(graph, &mut places, limit);
        let score = Score::of(&weights(graph, &places), limit);
        if best.as_ref().is_none_or(|(b, _)| score < *b) {
            best = Some((score, places));
        }
    }
    best.map_or_else(Vec::new, |(_, places)| places)
}

/// The places given by a breadth-first search from `root`: the level where the
/// searched weight reaches half the total is the separator, the levels before it side
/// `A`, the rest (and anything the search does not reach) side `B`.
fn median_level(graph: &Weighted, root: usize) -> Vec<Place> {
    let n = graph.len();
    let half = graph.total_weight().div_ceil(2);
    let mut level = vec![u32::MAX; n];
    let mut queue = Vec::with_capacity(n);
    level[root] = 0;
    queue.push(root);
    let mut head = 0;
    let mut searched = 0u64;
    let mut median = None;
    while head < queue.len() {
        let v = queue[head];
        head += 1;
        if median.is_some_and(|m| level[v] > m) {
            break;
        }
        searched += u64::from(graph.vertex_weight[v]);
        if median.is_none() && searched >= half {
            median = Some(level[v]);
        }
        for w in graph.neighbours(v) {
            if level[w] == u32::MAX {
                level[w] = level[v] + 1;
                queue.push(w);
            }
        }
    }
    let median = median.unwrap_or(u32::MAX);
    level
        .iter()
        .map(|&l| {
            if l == u32::MAX {
                Place::B
            } else if l < median {
                Place::A
            } else if l == median {
                Place::S
            } else {
                Place::B
            }
        })
        .collect()
}

/// The total vertex weight of each place, indexed by [`Place::index`].
fn weights(graph: &Weighted, places: &[Place]) -> [u64; 3] {
    let mut total = [0u64; 3];
    for (v, place) in places.iter().enumerate() {
        total[place.index()] += u64::from(graph.vertex_weight[v]);
    }
    total
}

/// How good a separator is, smaller better: first how far the heavier side exceeds the
/// balance limit, then the separator's weight, then the difference of the sides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Score {
    excess: u64,
    separator: u64,
    imbalance: u64,
}

impl Score {
    fn of(weights: &[u64; 3], limit: u64) -> Self {
        let [a, b, s] = *weights;
        Self {
            excess: a.max(b).saturating_sub(limit),
            separator: s,
            imbalance: a.abs_diff(b),
        }
    }
}

/// Improves the separator `places` of `graph` in place by vertex-separator
/// Fiduccia-Mattheyses passes (module docs), each side kept within `limit` weight
/// (or, where it starts beyond, not made heavier).
fn refine(graph: &Weighted, places: &mut [Place], limit: u64) {
    let mut separator: Vec<u32> = (0..graph.len() as u32)
        .filter(|&v| places[v as usize] == Place::S)
        .collect();
    let mut weight = weights(graph, places);
    let mut pass = Pass::new(graph.len());
    for _ in 0..PASSES {
        if !pass.run(graph, places, &mut separator, &mut weight, limit) {
            break;
        }
    }
}

/// The buffers of refinement passes over one graph.
struct Pass {
    /// `gain[side][v]`: the separator weight removed by moving separator vertex `v`
    /// into `side` (its weight) less the weight pulled in (its neighbours in the other
    /// side).
    gain: [Vec<i64>; 2],
    /// Whether a vertex has moved into a side in this pass (each moves once).
    moved: Vec<bool>,
    /// Every change of place in this pass, with the place before, to undo.
    log: Vec<(u32, Place)>,
    /// Candidate moves into each side, best gain first; an entry whose gain is no
    /// longer the vertex's (or whose vertex left the separator) is skipped.
    queue: [BinaryHeap<(i64, u32)>; 2],
}

impl Pass {
    fn new(n: usize) -> Self {
        Self {
            gain: [vec![0; n], vec![0; n]],
            moved: vec![false; n],
            log: Vec::new(),
            queue: [BinaryHeap::new(), BinaryHeap::new()],
        }
    }

    /// One pass over the separator `separator` (its vertices; updated) whose places
    /// weigh `weight` (updated); whether it found a better separator (then kept).
    fn run(
        &mut self,
        graph: &Weighted,
        places: &mut [Place],
        separator: &mut Vec<u32>,
        weight: &mut [u64; 3],
        limit: u64,
    ) -> bool {
        self.log.clear();
        self.queue.iter_mut().for_each(BinaryHeap::clear);
        for &v in separator.iter() {
            for side in [Place::A, Place::B] {
                self.set_gain(graph, places, v as usize, side);
            }
        }
        let start = Score::of(weight, limit);
        let (mut best, mut best_len) = (start, 0);
        // Moves past the best separator before the pass gives up: enough to cross a
        // plateau of a fine graph's separator, few on small graphs.
        let patience = (graph.len() / 100).clamp(15, 100);
        let mut since_best = 0;
        while since_best < patience {
            let Some((v, side)) = self.next_move(graph, places, weight, limit) else {
                break;
            };
            self.apply(graph, places, weight, v, side);
            let score = Score::of(weight, limit);
            if score < best {
                best = score;
                best_len = self.log.len();
                since_best = 0;
            } else {
                since_best += 1;
            }
        }
        for &(v, before) in self.log[best_len..].iter().rev() {
            let v = v as usize;
            let own = u64::from(graph.vertex_weight[v]);
            weight[places[v].index()] -= own;
            weight[before.index()] += own;
            places[v] = before;
        }
        // The separator now: the vertices it had and those that moved, where in it.
        separator.extend(self.log.iter().map(|&(v, _)| v));
        separator.sort_unstable();
        separator.dedup();
        separator.retain(|&v| places[v as usize] == Place::S);
        for &(v, _) in &self.log {
            self.moved[v as usize] = false;
        }
        best < start
    }

    /// Computes the gain of moving separator vertex `v` into `side` and queues it.
    fn set_gain(&mut self, graph: &Weighted, places: &[Place], v: usize, side: Place) {
        let other = side.other();
        let pulled: i64 = graph
            .neighbours(v)
            .filter(|&w| places[w] == other)
            .map(|w| i64::from(graph.vertex_weight[w]))
            .sum();
        let gain = i64::from(graph.vertex_weight[v]) - pulled;
        self.gain[side.index()][v] = gain;
        self.queue[side.index()].push((gain, v as u32));
    }

    /// Adds `change` to the gain of moving `v` into `side`, requeueing it.
    fn add_gain(&mut self, v: usize, side: Place, change: i64) {
        let gain = &mut self.gain[side.index()][v];
        *gain += change;
        let gain = *gain;
        if !self.moved[v] {
            self.queue[side.index()].push((gain, v as u32));
        }
    }

    /// The best queued move that keeps its side within `limit` (or, while the other side
    /// is heavier and beyond it, relieves that side), ties to the lighter side.
    fn next_move(
        &mut self,
        graph: &Weighted,
        places: &[Place],
        weight: &[u64; 3],
        limit: u64,
    ) -> Option<(usize, Place)> {
        let mut best: Option<(i64, usize, Place)> = None;
        for side in [Place::A, Place::B] {
            let Some((gain, v)) = self.top(places, side) else {
                continue;
            };
            let after = weight[side.index()] + u64::from(graph.vertex_weight[v]);
            // Beyond the limit only to relieve a heavier side beyond it too.
            let relieves = weight[side.other().index()] > limit.max(weight[side.index()]);
            if after > limit && !relieves {
                continue;
            }
            let better = best.is_none_or(|(g, _, s)| {
                gain > g || (gain == g && weight[side.index()] < weight[s.index()])
            });
            if better {
                best = Some((gain, v, side));
            }
        }
        best.map(|(_, v, side)| (v, side))
    }

    /// The best current entry of `side`'s queue, stale entries dropped.
    fn top(&mut self, places: &[Place], side: Place) -> Option<(i64, usize)> {
        let queue = &mut self.queue[side.index()];
        while let Some(&(gain, v)) = queue.peek() {
            let v = v as usize;
            if places[v] == Place::S && !self.moved[v] && self.gain[side.index()][v] == gain {
                return Some((gain, v));
            }
            queue.pop();
        }
        None
    }

    /// Moves separator vertex `v` into `side`, pulling its neighbours in the other side
    /// into the separator, and updates the gains that change.
    fn apply(
        &mut self,
        graph: &Weighted,
        places: &mut [Place],
        weight: &mut [u64; 3],
        v: usize,
        side: Place,
    ) {
        let other = side.other();
        let own = graph.vertex_weight[v];
        self.relocate(places, weight, own, v, side);
        self.moved[v] = true;
        for u in graph.neighbours(v) {
            if places[u] == Place::S {
                // `v` joined `side`: moving `u` into the other side would pull it back.
                self.add_gain(u, other, -i64::from(own));
            } else if places[u] == other {
                self.pull(graph, places, weight, u, side);
            }
        }
    }

    /// Moves `u` from the side opposite `side` into the separator (a vertex moved into
    /// `side` pulled it), and updates its gains and its separator neighbours'.
    fn pull(
        &mut self,
        graph: &Weighted,
        places: &mut [Place],
        weight: &mut [u64; 3],
        u: usize,
        side: Place,
    ) {
        let other = side.other();
        let own = graph.vertex_weight[u];
        self.relocate(places, weight, own, u, Place::S);
        // Sums of `u`'s neighbours' weights in each side: what moving `u` into the
        // opposite side would pull.
        let (mut in_side, mut in_other) = (0i64, 0i64);
        for z in graph.neighbours(u) {
            let w = i64::from(graph.vertex_weight[z]);
            match places[z] {
                // `u` left `other`: moving `z` into `side` no longer pulls it.
                Place::S => self.add_gain(z, side, i64::from(own)),
                p if p == other => in_other += w,
                _ => in_side += w,
            }
        }
        self.gain[side.index()][u] = i64::from(own) - in_other;
        self.gain[other.index()][u] = i64::from(own) - in_side;
        if !self.moved[u] {
            for s in [side, other] {
                self.queue[s.index()].push((self.gain[s.index()][u], u as u32));
            }
        }
    }

    /// Puts `v` (weight `own`) in `to`, logging its place before and moving its weight.
    fn relocate(
        &mut self,
        places: &mut [Place],
        weight: &mut [u64; 3],
        own: u32,
        v: usize,
        to: Place,
    ) {
        let from = places[v];
        self.log.push((v as u32, from));
        weight[from.index()] -= u64::from(own);
        weight[to.index()] += u64::from(own);
        places[v] = to;
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Adjacency lists of a `k x k` grid of squares, vertex `i + k j` at column `i`,
    /// row `j`, each square split by a diagonal: always the same one, or, with
    /// `irregular`, one a fixed pseudo-random bit picks (degrees 2 to 8).
    pub(crate) fn grid(k: usize, irregular: bool) -> (Vec<usize>, Vec<u32>) {
        let mut lists = vec![Vec::new(); k * k];
        let mut edge = |a: usize, b: usize| {
            lists[a].push(b as u32);
            lists[b].push(a as u32);
        };
        let mut random = SEED;
        for j in 0..k {
            for i in 0..k {
                let v = i + k * j;
                if i + 1 < k {
                    edge(v, v + 1);
                }
                if j + 1 < k {
                    edge(v, v + k);
                }
                if i + 1 < k && j + 1 < k {
                    if irregular && next_random(&mut random) & 1 == 1 {
                        edge(v + 1, v + k);
                    } else {
                        edge(v, v + k + 1);
                    }
                }
            }
        }
        let mut start = vec![0];
        let mut neighbours = Vec::new();
        for list in lists {
            neighbours.extend(list);
            start.push(neighbours.len());
        }
        (start, neighbours)
    }

    /// The sizes of `A`, `B` and `S`, after checking that no edge joins `A` and `B`.
    fn checked_sizes(start: &[usize], neighbours: &[u32], places: &[Place]) -> [usize; 3] {
        let mut sizes = [0; 3];
        for (v, &place) in places.iter().enumerate() {
            sizes[place.index()] += 1;
            for &w in &neighbours[start[v]..start[v + 1]] {
                let other = places[w as usize];
                assert!(
                    place == Place::S || other == Place::S || other == place,
                    "edge {v}-{w} joins the sides"
                );
            }
        }
        sizes
    }

    #[test]
    fn a_grid_is_split_by_about_one_line() {
        // The 100 x 100 grid: a straight line of 100 vertices splits it in halves.
        let k = 100;
        let (start, neighbours) = grid(k, false);
        let places = separator(start.clone(), neighbours.clone(), 0.6);
        let [a, b, s] = checked_sizes(&start, &neighbours, &places);
        assert!(a > 0 && b > 0, "sides {a}, {b}");
        assert!(a.max(b) <= 6 * k * k / 10, "sides {a}, {b}");
        assert!(s <= k + k / 10, "separator {s}");
    }

    #[test]
    fn separators_separate_within_the_balance() {
        for (k, balance) in [(20, 0.52), (60, 0.52), (60, 0.6), (200, 0.55)] {
            let (start, neighbours) = grid(k, true);
            let n = k * k;
            let places = separator(start.clone(), neighbours.clone(), balance);
            let [a, b, s] = checked_sizes(&start, &neighbours, &places);
            assert!(a > 0 && b > 0, "k {k}: sides {a}, {b}");
            assert!(
                a.max(b) as f64 <= balance * n as f64,
                "k {k}, balance {balance}: sides {a}, {b}"
            );
            // A line across the grid, give or take its zigzags.
            assert!(s <= 2 * k, "k {k}: separator {s}");
        }
    }

    #[test]
    fn the_same_graph_gets_the_same_separator() {
        let (start, neighbours) = grid(80, true);
        let first = separator(start.clone(), neighbours.clone(), 0.6);
        assert_eq!(first, separator(start, neighbours, 0.6));
    }
}
