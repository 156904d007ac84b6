//! The boundary loops of a multiply-connected mesh and the initial circle-domain map.
//!
//! Ho-Lui 2016 (Algorithm 2, steps 1-2, section 6.2) start from a circle domain `D_0`
//! approximating the boundary loops and a harmonic map onto it; the iteration tolerates
//! a start that is not a bijection. Here the start is a bijection up to the faces next
//! to the holes (step 3 can fold a few of them; 2 of 27,306 on `mc4_face_a`, none on
//! the other shared meshes):
//!
//! 1. every inner loop is closed by a fan of triangles around a new cone vertex, which
//!    makes the mesh a disk;
//! 2. Tutte's embedding of that disk (uniform weights) with the outer loop on the unit
//!    circle by arc length is a bijection onto the disk (Tutte 1963, Floater 2003): each
//!    hole becomes a polygon star-shaped about its cone vertex `c_j`;
//! 3. hole `j` gets the circle of centre `c_j` and radius `rho_j`, the distance from `c_j`
//!    to its polygon (the largest circle about `c_j` inside the hole), and the loop's
//!    vertices move radially onto it (their angular order about `c_j` is kept, since the
//!    polygon is star-shaped);
//! 4. the disk automorphism of [`DiskAutomorphism::centering`] moves the first inner
//!    circle to the centre and the outer loop's first vertex to `1` (the normalization
//!    the iteration keeps).

use beltrami_core::SolverError;
use beltrami_fem::boundary;
use beltrami_fem::{EdgeWeights, WeightedMeanSystem};
use beltrami_mesh::{Mesh, Point3, PolygonSoup, VertexId};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::NAME;
use crate::moebius::{DiskAutomorphism, PlaneCircle};

/// The boundary loops, the outer one first.
#[derive(Debug, Clone, PartialEq)]
pub struct Loops {
    /// Per loop, its index in the mesh's `boundary_loop_list` (outer first, then the
    /// others in list order).
    pub index: Vec<usize>,
    /// Per loop, its vertices in loop order (the outer loop starting at its first
    /// vertex in the list, the vertex the normalization sends to `1`).
    pub vertices: Vec<Vec<VertexId>>,
}

impl Loops {
    /// The loops of `mesh` with loop `outer` (an index into `boundary_loop_list`) outer,
    /// or the longest when `outer` is `None`. Error: `outer` is not a loop.
    pub fn new(mesh: &Mesh, outer: Option<usize>) -> Result<Self, SolverError> {
        let list = mesh.boundary_loop_list();
        let outer = match outer {
            Some(o) if o < list.len() => o,
            Some(o) => {
                return Err(SolverError::unsupported(
                    NAME,
                    format!(
                        "option `outer`: the mesh has {} boundary loops (0 to {}), there is no loop {o}",
                        list.len(),
                        list.len().saturating_sub(1)
                    ),
                ));
            }
            None => (0..list.len())
                .max_by(|&a, &b| list[a].length.total_cmp(&list[b].length))
                .unwrap_or(0),
        };
        let index: Vec<usize> = std::iter::once(outer)
            .chain((0..list.len()).filter(|&i| i != outer))
            .collect();
        let vertices = index.iter().map(|&i| list[i].vertices.clone()).collect();
        Ok(Self { index, vertices })
    }

    /// Number of loops (`k`).
    pub fn len(&self) -> usize {
        self.index.len()
    }

    /// Whether there is no loop.
    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }

    /// Per vertex, the loop (position in [`Loops::index`]) it lies on, if any.
    pub fn loop_of(&self, vertex_count: usize) -> Vec<Option<usize>> {
        let mut of = vec![None; vertex_count];
        for (j, vertices) in self.vertices.iter().enumerate() {
            for v in vertices {
                of[v.idx()] = Some(j);
            }
        }
        of
    }
}

/// A map onto a circle domain: the images of the vertices and the circles, per loop
/// of [`Loops`] (the outer one the unit circle).
#[derive(Debug, Clone, PartialEq)]
pub struct CircleMap {
    /// The image of every vertex.
    pub map: Vec<Complex64>,
    /// The circle of each loop, outer first.
    pub circles: Vec<PlaneCircle>,
}

impl CircleMap {
    /// The mirror image `z -> conj(z)` of the map and its circles (the normalization is
    /// kept: the first inner circle stays centred and `1` stays at `1`).
    pub fn mirror(&mut self) {
        for z in &mut self.map {
            *z = z.conj();
        }
        for c in &mut self.circles {
            c.center = c.center.conj();
        }
    }
}

/// The unit circle.
pub const UNIT: PlaneCircle = PlaneCircle {
    center: Complex64::new(0.0, 0.0),
    radius: 1.0,
};

/// The initial map (module docs, steps 1-4).
pub fn initial_map(
    mesh: &Mesh,
    loops: &Loops,
    options: SolveOptions,
) -> Result<CircleMap, SolverError> {
    let n = mesh.vertex_count();
    let mut soup = PolygonSoup::new(mesh.positions().to_vec());
    for f in mesh.faces() {
        let face: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        soup.push_face(&face);
    }
    for (j, vertices) in loops.vertices.iter().enumerate().skip(1) {
        let sum = vertices
            .iter()
            .fold(Point3::origin().coords, |s, v| s + mesh.position(*v).coords);
        soup.positions
            .push(Point3::from(sum / vertices.len() as f64));
        let cone = (n + j - 1) as u32;
        // The loop runs along its boundary halfedges, opposite to its faces' edges:
        // (v_i, v_i+1, cone) uses each boundary edge the other way from its face.
        for (i, v) in vertices.iter().enumerate() {
            let w = vertices[(i + 1) % vertices.len()];
            soup.push_face(&[v.0, w.0, cone]);
        }
    }
    let filled = Mesh::from_soup(&soup)?;
    if filled.vertex_count() != soup.positions.len()
        || (0..filled.vertex_count())
            .any(|i| filled.vertex_map().to_input(VertexId::from_usize(i)) != i)
    {
        return Err(SolverError::invalid(
            NAME,
            "closing the holes renumbered the vertices (the mesh has unreferenced vertices); remove them first",
        ));
    }
    let start = loops.vertices[0][0];
    let outer = boundary::circle(&filled, Some(start)).map_err(|error| SolverError::Boundary {
        solver: NAME,
        error,
    })?;
    let tutte = WeightedMeanSystem::new(&EdgeWeights::uniform(&filled), &outer)?.solve(options)?;

    let mut map = tutte[..n].to_vec();
    let mut circles = vec![UNIT];
    for (j, vertices) in loops.vertices.iter().enumerate().skip(1) {
        let center = tutte[n + j - 1];
        let radius = vertices
            .iter()
            .zip(vertices.iter().cycle().skip(1))
            .map(|(a, b)| distance_to_segment(center, map[a.idx()], map[b.idx()]))
            .fold(f64::INFINITY, f64::min);
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the initial map closes boundary loop {} (starting at vertex {}) to a point",
                    loops.index[j],
                    mesh.vertex_map().to_input(vertices[0])
                ),
            ));
        }
        let circle = PlaneCircle { center, radius };
        for v in vertices {
            map[v.idx()] = circle.project(map[v.idx()]);
        }
        circles.push(circle);
    }
    if circles.len() > 1 {
        let phi = DiskAutomorphism::centering(&circles[1], map[start.idx()]);
        for z in &mut map {
            *z = phi.apply(*z);
        }
        for (j, circle) in circles.iter_mut().enumerate().skip(1) {
            *circle = phi.circle(circle).ok_or_else(|| {
                SolverError::invalid(
                    NAME,
                    format!(
                        "the initial circle of boundary loop {} degenerated",
                        loops.index[j]
                    ),
                )
            })?;
        }
        circles[1].center = Complex64::new(0.0, 0.0);
    }
    for (vertices, circle) in loops.vertices.iter().zip(&circles) {
        for v in vertices {
            map[v.idx()] = circle.project(map[v.idx()]);
        }
    }
    map[start.idx()] = Complex64::new(1.0, 0.0);
    Ok(CircleMap { map, circles })
}

/// The distance from `p` to the segment `[a, b]`.
fn distance_to_segment(p: Complex64, a: Complex64, b: Complex64) -> f64 {
    let d = b - a;
    let len2 = d.norm_sqr();
    let t = if len2 > 0.0 {
        ((p - a) * d.conj()).re / len2
    } else {
        0.0
    };
    (a + d * t.clamp(0.0, 1.0) - p).norm()
}
