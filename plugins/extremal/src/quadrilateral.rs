//! The four-point problem (Weber-Myles-Zorin 2012, section 5): a disk whose boundary
//! slides on the unit circle, four boundary vertices (the landmarks) sent to four given
//! points of the circle.
//!
//! A disk with four marked boundary points is a quadrilateral. Its extremal map onto
//! another is `f = g_2^{-1} o A_k o g_1`, with `g_i` the conformal maps onto rectangles
//! that send the marked points to the corners and `A_k` the affine stretch between the
//! rectangles (Teichmueller's theorem for quadrilaterals; Ahlfors, *Lectures on
//! quasiconformal mappings*, ch. I). Its quadratic differential is therefore fixed by
//! the source alone, `phi = (g_1')^2`, real on the four sides and with simple poles at
//! the corners: for the sliding problem the admissible quadratic differentials form a
//! one-dimensional space, and Algorithm 1's h-step has nothing left to choose. (Keeping
//! the free h-step of the Dirichlet problem would not do: every Teichmueller map of the
//! disk onto itself that meets the four points has zero least-squares energy, eq. 9,
//! whatever its `k`.)
//!
//! `g_1 = u + i v` is found from its real part: `u` is the discrete harmonic function
//! (cotangent weights) that is 0 on the side from the first landmark to the second, 1 on
//! the side from the third to the fourth, with the natural (zero-flux) condition on the
//! other two; then `g_1' = u_x - i u_y` per face, and `conj(phi) = (u_x + i u_y)^2`.
//! The map and `k` are then found by the f-step (the least-squares map of
//! `mu = k conj(phi)/|phi|` with the landmarks fixed and every other boundary vertex
//! sliding along the circle, projected back onto it) alternating with eq. 12 for `k`.

use beltrami_core::{Constraint, Position, Problem, SolverError};
use beltrami_fem::{BoundaryMap, EdgeWeights, Elements, WeightedMeanSystem, beltrami::planar_map};
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::solver::NAME;

/// How far from the unit circle a landmark's destination may be.
const ON_CIRCLE: f64 = 1e-9;

/// The four landmarks in the order of the boundary loop (counter-clockwise, the
/// domain on the left), each with its destination on the unit circle, and the loop.
#[derive(Debug, Clone)]
pub(crate) struct Quadrilateral {
    /// The boundary loop, starting at the first landmark.
    pub(crate) boundary: Vec<VertexId>,
    /// Position in `boundary` and destination of each landmark, in loop order.
    pub(crate) corners: [(usize, Complex64); 4],
}

/// The quadrilateral of a disk-target problem: exactly four landmarks, on boundary
/// vertices, with destinations on the unit circle in the same cyclic order as the
/// vertices along the boundary. Errors name the offending landmark.
pub(crate) fn quadrilateral(problem: &Problem<'_>) -> Result<Quadrilateral, SolverError> {
    let mesh = problem.source;
    let loops = mesh.boundary_loop_list();
    let [boundary] = loops.as_slice() else {
        return Err(SolverError::invalid(
            NAME,
            format!(
                "--target disk slides one boundary loop on the unit circle; this mesh has {}",
                loops.len()
            ),
        ));
    };
    // Boundary loops run with the surface on their right (docs/conventions.md): reversed,
    // the loop of a positively oriented disk turns counter-clockwise.
    let ccw: Vec<VertexId> = boundary.vertices.iter().rev().copied().collect();
    let mut marks = Vec::new();
    for c in problem.constraints.iter() {
        let Constraint::Landmark(l) = c else {
            continue;
        };
        let Position::Planar(w) = l.position else {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the landmark of vertex {} is a point of R^3; the disk target takes points x + i y of the unit circle",
                    l.vertex
                ),
            ));
        };
        if (w.norm() - 1.0).abs() > ON_CIRCLE {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the landmark of vertex {} goes to ({}, {}), which is not on the unit circle (|w| = {})",
                    l.vertex,
                    w.re,
                    w.im,
                    w.norm()
                ),
            ));
        }
        let Some(at) = ccw.iter().position(|&v| v == l.vertex) else {
            return Err(SolverError::invalid(
                NAME,
                format!(
                    "the landmark vertex {} is not on the boundary: the four-point problem moves boundary points",
                    l.vertex
                ),
            ));
        };
        marks.push((at, w / w.norm()));
    }
    if marks.len() != 4 {
        return Err(SolverError::invalid(
            NAME,
            format!(
                "the disk target with a sliding boundary is the four-point problem: give exactly four boundary landmarks (`p INDEX x y`), not {}",
                marks.len()
            ),
        ));
    }
    marks.sort_by_key(|&(at, _)| at);
    // Destinations must turn once around the circle, counter-clockwise, in loop order.
    let turn: f64 = (0..4).map(|j| arc(marks[j].1, marks[(j + 1) % 4].1)).sum();
    if (turn - std::f64::consts::TAU).abs() > 1e-6 {
        return Err(SolverError::invalid(
            NAME,
            "the landmarks' destinations are not in the order of their vertices along the boundary (counter-clockwise): no homeomorphism of the disk moves them there",
        ));
    }
    let start = marks[0].0;
    let n = ccw.len();
    let rotated: Vec<VertexId> = (0..n).map(|i| ccw[(start + i) % n]).collect();
    let corners = std::array::from_fn(|j| ((marks[j].0 + n - start) % n, marks[j].1));
    Ok(Quadrilateral {
        boundary: rotated,
        corners,
    })
}

/// The counter-clockwise angle from `a` to `b` on the circle, in `(0, 2 pi]`.
fn arc(a: Complex64, b: Complex64) -> f64 {
    let t = (b / a).arg();
    if t <= 0.0 {
        t + std::f64::consts::TAU
    } else {
        t
    }
}

impl Quadrilateral {
    /// Side `j` (from corner `j` to corner `j + 1`) as positions in `boundary`, the end
    /// excluded and not yet reduced modulo the loop's length (the last side wraps).
    fn side(&self, j: usize) -> std::ops::Range<usize> {
        let (from, to) = (self.corners[j].0, self.corners[(j + 1) % 4].0);
        from..if to <= from {
            to + self.boundary.len()
        } else {
            to
        }
    }

    /// The boundary's start positions: landmarks at their destinations, the vertices of
    /// each side spread over the arc between its corners' destinations in proportion to
    /// their arc length on the source.
    pub(crate) fn start_boundary(&self, mesh: &Mesh) -> Vec<(VertexId, Complex64)> {
        let n = self.boundary.len();
        let mut out = Vec::with_capacity(n);
        for j in 0..4 {
            let (a, b) = (self.corners[j].1, self.corners[(j + 1) % 4].1);
            let side = self.side(j);
            let length = |i: usize| {
                let p = mesh.position(self.boundary[i % n]);
                let q = mesh.position(self.boundary[(i + 1) % n]);
                (q - p).norm()
            };
            let total: f64 = side.clone().map(length).sum();
            let angle = arc(a, b);
            let mut walked = 0.0;
            for i in side {
                let t = if total > 0.0 { walked / total } else { 0.0 };
                out.push((
                    self.boundary[i % n],
                    a * Complex64::from_polar(1.0, t * angle),
                ));
                walked += length(i);
            }
        }
        out
    }

    /// The boundary vertices other than the four landmarks (they slide).
    pub(crate) fn sliding(&self) -> Vec<VertexId> {
        let corners: Vec<usize> = self.corners.iter().map(|c| c.0).collect();
        (0..self.boundary.len())
            .filter(|i| !corners.contains(i))
            .map(|i| self.boundary[i])
            .collect()
    }

    /// The landmarks with their destinations.
    pub(crate) fn landmarks(&self) -> Vec<(VertexId, Complex64)> {
        self.corners
            .iter()
            .map(|&(at, w)| (self.boundary[at], w))
            .collect()
    }

    /// `conj(phi)` per face of the source's rectangle map (module docs): `(u_x + i u_y)^2`
    /// of the harmonic `u` that is 0 on the first side, 1 on the third and has zero flux
    /// through the other two.
    pub(crate) fn quadratic_differential(
        &self,
        mesh: &Mesh,
        elements: &Elements,
        options: SolveOptions,
    ) -> Result<Vec<Complex64>, SolverError> {
        let n = self.boundary.len();
        let mut vertices = Vec::new();
        let mut positions = Vec::new();
        for (j, value) in [(0, 0.0), (2, 1.0)] {
            let side = self.side(j);
            for i in side.start..=side.end {
                vertices.push(self.boundary[i % n]);
                positions.push(Complex64::new(value, 0.0));
            }
        }
        let weights = EdgeWeights::cotangent(mesh).map_err(|error| SolverError::Weights {
            solver: NAME,
            error,
        })?;
        let u = WeightedMeanSystem::new(
            &weights,
            &BoundaryMap {
                vertices,
                positions,
            },
        )?
        .solve(options)?;
        let d = planar_map(elements, mesh.vertex_count(), &u)?;
        // For the real map u, f_z = (u_x - i u_y)/2 and conj(f_z) = (u_x + i u_y)/2.
        Ok(d.iter().map(|d| (2.0 * d.fz.conj()).powi(2)).collect())
    }
}
