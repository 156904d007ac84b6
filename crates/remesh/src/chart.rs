//! Opening a surface into a chart the plane can hold: a disk (cut along a cut graph or,
//! for a closed genus-0 surface, slit along one path), or the surface itself when it is
//! already a disk or the parameterizer maps several boundary loops (a circle domain).

use beltrami_mesh::{EdgeId, Mesh, VertexId, cut_along, cut_to_disk, shortest_path_tree};

use crate::RemeshError;

/// How the surface was opened.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Opening {
    /// Not at all: the surface is a disk, or the parameterizer maps its boundary loops
    /// as they are.
    Uncut,
    /// Not at all, but parameterized with its holes closed: a genus-0 surface with
    /// several boundary loops mapped by a parameterizer of disks, with every loop but
    /// the longest closed by scaffold faces ([`crate::scaffold`]); `holes` loops closed.
    Filled {
        /// Number of loops closed for the parameterization.
        holes: usize,
    },
    /// Along the cut graph of [`beltrami_mesh::cut_to_disk`] (genus >= 1, or several
    /// boundary loops): `edges` mesh edges.
    CutGraph {
        /// Number of cut edges.
        edges: usize,
    },
    /// A closed genus-0 surface split into two disks along a loop of edges near the
    /// equator of its spherical map, each mapped by the stereographic projection from the
    /// opposite pole ([`crate::two_charts`]); the loop is sampled once for both.
    TwoCharts,
    /// A closed genus-0 surface slit along the shortest path between two far apart
    /// vertices (a tree, so the surface minus the slit is a disk): `edges` mesh edges.
    Slit {
        /// Number of slit edges.
        edges: usize,
    },
}

impl Opening {
    /// The stable name in reports: `uncut`, `filled`, `two-charts`, `cut-graph` or `slit`.
    pub fn name(&self) -> &'static str {
        match self {
            Opening::Uncut => "uncut",
            Opening::Filled { .. } => "filled",
            Opening::TwoCharts => "two-charts",
            Opening::CutGraph { .. } => "cut-graph",
            Opening::Slit { .. } => "slit",
        }
    }
}

/// The surface opened for the parameterization. Face `f` of the chart is face `f` of
/// the surface, with the same first vertex and orientation, so a surface point of the
/// chart is the same surface point of the surface.
#[derive(Debug, Clone)]
pub struct Chart {
    /// The opened mesh.
    pub mesh: Mesh,
    /// The surface's vertex of every chart vertex (the seam map).
    pub to_original: Vec<VertexId>,
    /// How it was opened.
    pub opening: Opening,
}

/// Opens `mesh` into a chart: a disk as it is; a closed genus-0 surface along a slit;
/// a genus-0 surface with several boundary loops as it is (when not `keep_loops`, its
/// parameterization closes the holes: [`Opening::Filled`]); every surface of genus >= 1
/// along its cut graph.
pub fn open(mesh: &Mesh, keep_loops: bool) -> Result<Chart, RemeshError> {
    let components = mesh.components();
    if components.len() != 1 {
        return Err(RemeshError::Components {
            components: components.len(),
        });
    }
    let c = components[0];
    let uncut = || Chart {
        mesh: mesh.clone(),
        to_original: mesh.vertices().collect(),
        opening: Opening::Uncut,
    };
    if c.is_disk() || (keep_loops && c.genus == 0 && c.boundary_loops > 1) {
        return Ok(uncut());
    }
    if c.genus == 0 && c.boundary_loops > 1 {
        return Ok(Chart {
            opening: Opening::Filled {
                holes: c.boundary_loops - 1,
            },
            ..uncut()
        });
    }
    if c.is_closed() && c.genus == 0 {
        let slit = slit_path(mesh);
        let (cut, to_original) = cut_along(mesh, &slit).map_err(|e| match e {
            beltrami_mesh::CutError::Build(error) => RemeshError::Build {
                what: "slit mesh",
                error,
            },
            other => RemeshError::Cut(other),
        })?;
        return Ok(Chart {
            mesh: cut,
            to_original,
            opening: Opening::Slit { edges: slit.len() },
        });
    }
    let cut = cut_to_disk(mesh)?;
    Ok(Chart {
        opening: Opening::CutGraph {
            edges: cut.cut.edges.len(),
        },
        mesh: cut.mesh,
        to_original: cut.to_original,
    })
}

/// The edges of the shortest path between two far apart vertices: the farthest vertex
/// `a` from vertex 0 and the farthest vertex `b` from `a` (a double sweep, which on a
/// round sphere finds a near-antipodal pair), joined by a shortest path. Slitting along
/// half a great circle keeps the conformal factor of the opened sphere bounded away from
/// 0 and infinity except near the two ends, where the slit angle `2 pi` opens to `pi`.
fn slit_path(mesh: &Mesh) -> Vec<EdgeId> {
    let (far, _) = shortest_path_tree(mesh, VertexId(0));
    let a = farthest(&far);
    let (dist, pred) = shortest_path_tree(mesh, a);
    let mut v = farthest(&dist);
    let mut edges = Vec::new();
    while let Some(h) = pred[v.idx()] {
        edges.push(mesh.edge(h));
        v = mesh.origin(h);
    }
    edges
}

fn farthest(dist: &[f64]) -> VertexId {
    let (i, _) = dist.iter().enumerate().filter(|(_, d)| d.is_finite()).fold(
        (0, f64::NEG_INFINITY),
        |best, (i, &d)| {
            if d > best.1 { (i, d) } else { best }
        },
    );
    VertexId(i as u32)
}
