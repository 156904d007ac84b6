//! The cut that opens a chart with cones into a disk: its cut graph (boundary loops and
//! the loops around its handles, [`beltrami_mesh::cut_graph`]) joined to every cone by
//! shortest paths, grown like Prim's tree (each cone in turn is reached from the cut
//! made so far by the shortest path, one search from every vertex of the cut at once,
//! every joined path becoming a source). A closed genus-0 chart has no cut graph: the
//! tree starts at its first cone.
//!
//! Cutting along the result ([`beltrami_mesh::cut_along`]) leaves a disk whose boundary
//! passes through every cone, so the flattening can give each cone its angle.

use beltrami_mesh::{EdgeId, Mesh, VertexId, cut_graph};

use crate::shortest_paths::ShortestPaths;

/// The edges to cut `mesh` along so that it becomes a disk with every one of `cones`
/// on its boundary (see the module docs). Empty for a disk without cones.
pub fn cone_cut(mesh: &Mesh, cones: &[VertexId]) -> Vec<EdgeId> {
    let mut in_cut = vec![false; mesh.edge_count()];
    let mut on_cut = vec![false; mesh.vertex_count()];
    for e in cut_graph(mesh).edges {
        in_cut[e.idx()] = true;
        for v in mesh.edge_vertices(e) {
            on_cut[v.idx()] = true;
        }
    }
    if !on_cut.iter().any(|&c| c)
        && let Some(&first) = cones.first()
    {
        on_cut[first.idx()] = true;
    }
    let mut search = ShortestPaths::new(mesh);
    for v in mesh.vertices().filter(|v| on_cut[v.idx()]) {
        search.seed(v);
    }
    let mut waiting = vec![false; mesh.vertex_count()];
    let mut left = 0;
    for &c in cones {
        if !on_cut[c.idx()] && !waiting[c.idx()] {
            waiting[c.idx()] = true;
            left += 1;
        }
    }
    while left > 0 {
        let Some(v) = search.settle_next() else { break };
        if !waiting[v.idx()] {
            continue;
        }
        waiting[v.idx()] = false;
        left -= 1;
        let mut w = v;
        while !on_cut[w.idx()] {
            let Some(h) = search.reached_by[w.idx()] else {
                break;
            };
            in_cut[mesh.edge(h).idx()] = true;
            on_cut[w.idx()] = true;
            search.seed(w);
            w = mesh.origin(h);
        }
    }
    mesh.edges().filter(|e| in_cut[e.idx()]).collect()
}
