//! A conformal map of a disk onto the unit disk by boundary first flattening (Sawhney
//! and Crane 2017, section 5.3 "Uniformization": a disk's conformal map onto the
//! circle is the flattening whose boundary curvature is that of a circle).
//!
//! A circle of length `S` turns by `2 pi l / S` along an arc of length `l`, so the target
//! turning angle at boundary vertex `i` is `k~_i = pi (l~_{i-1} + l~_i) / S` (its dual
//! arc), with `l~` the flattened edge lengths `e^{(u_a + u_b)/2} l`. The scale `u` then
//! solves the Neumann problem `L u = -Omega` inside, `L u = k~ - k` on the boundary
//! (the Neumann-to-Dirichlet step of BFF; the right-hand side sums to zero by
//! Gauss-Bonnet, and one vertex is held to fix the constant), which changes `l~`; a few
//! rounds settle it (one factorization serves them all). The boundary vertices are then
//! put on the unit circle at the angles `2 pi` times their share of the arc length, so
//! the boundary lies exactly on the circle, and the interior is the harmonic extension
//! (cotan weights) of the boundary, solved on the Neumann problem's symbolic
//! factorization with the boundary held by a penalty.

use std::f64::consts::{PI, TAU};

use beltrami_fem::operators::cotan_laplacian;
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::{SolveOptions, SpdSolver};
use faer::Mat;
use faer::sparse::SparseColMat;

use crate::AtlasError;
use crate::boundary_first::{FlattenFailure, counter_clockwise_ring, is_disk};
use crate::held::{PENALTY, diagonal_slots};
use crate::overlap::folded_faces;

/// Rounds of the boundary lengths and the Neumann problem.
const ROUNDS: usize = 4;

/// The positions on the unit disk of the vertices of `disk` (see the module docs), or
/// why there are none (not a disk, a non-positive length, a folded face).
pub fn map_to_unit_disk(disk: &Mesh) -> Result<Result<Vec<[f64; 2]>, FlattenFailure>, AtlasError> {
    if !is_disk(disk) {
        return Ok(Err(FlattenFailure::NotADisk));
    }
    let laplacian = cotan_laplacian(disk)?;
    let slots = diagonal_slots(&laplacian);
    let ring = counter_clockwise_ring(disk);
    let n = ring.len();
    let rest: Vec<f64> = (0..n)
        .map(|i| (disk.position(ring[(i + 1) % n]) - disk.position(ring[i])).norm())
        .collect();
    // Hold the first interior vertex (or the first boundary one) at u = 0 by a penalty.
    let held = disk
        .vertices()
        .find(|&v| !disk.is_boundary_vertex(v))
        .unwrap_or(ring[0]);
    let mut matrix = laplacian.clone();
    hold(&mut matrix, &slots, &[held]);
    let mut solver = SpdSolver::new(matrix.symbolic(), SolveOptions::default())?;
    solver.factorize(matrix.as_ref())?;
    let defect: Vec<f64> = disk.vertices().map(|v| disk.angle_defect(v)).collect();
    let mut u = vec![0.0; disk.vertex_count()];
    let mut lengths = rest.clone();
    for _ in 0..ROUNDS {
        let total: f64 = lengths.iter().sum();
        let mut rhs = Mat::<f64>::zeros(u.len(), 1);
        for v in disk.vertices() {
            rhs[(v.idx(), 0)] = -defect[v.idx()];
        }
        for i in 0..n {
            let target = PI * (lengths[(i + n - 1) % n] + lengths[i]) / total;
            rhs[(ring[i].idx(), 0)] = target - defect[ring[i].idx()];
        }
        rhs[(held.idx(), 0)] = 0.0;
        solver.solve_in_place(rhs.as_mut())?;
        for (i, x) in u.iter_mut().enumerate() {
            *x = rhs[(i, 0)];
        }
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            lengths[i] = ((u[a.idx()] + u[b.idx()]) / 2.0).exp() * rest[i];
        }
    }
    if lengths.iter().any(|l| !(l.is_finite() && *l > 0.0)) {
        return Ok(Err(FlattenFailure::CurveDoesNotClose));
    }
    let total: f64 = lengths.iter().sum();
    let mut position = vec![[0.0; 2]; disk.vertex_count()];
    let mut walked = 0.0;
    for i in 0..n {
        let angle = TAU * walked / total;
        position[ring[i].idx()] = [angle.cos(), angle.sin()];
        walked += lengths[i];
    }
    // The harmonic extension of the boundary on the same pattern (its symbolic
    // factorization reused): the boundary held by the penalty. The held values miss
    // the given ones by about 1/PENALTY of them; the extension of that miss, solved
    // once more, is taken off, which leaves 1/PENALTY^2.
    let mut matrix = laplacian.clone();
    hold(&mut matrix, &slots, &ring);
    solver.factorize(matrix.as_ref())?;
    let weights: Vec<f64> = ring.iter().map(|v| matrix.val()[slots[v.idx()]]).collect();
    let mut extension = Mat::<f64>::zeros(disk.vertex_count(), 2);
    for (&v, &weight) in ring.iter().zip(&weights) {
        for axis in 0..2 {
            extension[(v.idx(), axis)] = weight * position[v.idx()][axis];
        }
    }
    solver.solve_in_place(extension.as_mut())?;
    let mut miss = Mat::<f64>::zeros(disk.vertex_count(), 2);
    for (&v, &weight) in ring.iter().zip(&weights) {
        for axis in 0..2 {
            miss[(v.idx(), axis)] = weight * (extension[(v.idx(), axis)] - position[v.idx()][axis]);
        }
    }
    solver.solve_in_place(miss.as_mut())?;
    for v in disk.vertices().filter(|&v| !disk.is_boundary_vertex(v)) {
        let i = v.idx();
        position[i] = [
            extension[(i, 0)] - miss[(i, 0)],
            extension[(i, 1)] - miss[(i, 1)],
        ];
    }
    let folded = folded_faces(disk, &position) > 0;
    if folded {
        return Ok(Err(FlattenFailure::Folded));
    }
    Ok(Ok(position))
}

/// Adds the [`PENALTY`] relative to each entry to the diagonal entries of `vertices`.
/// `slots` are the matrix's [`diagonal_slots`].
fn hold(matrix: &mut SparseColMat<usize, f64>, slots: &[usize], vertices: &[VertexId]) {
    let values = matrix.val_mut();
    for &v in vertices {
        let k = slots[v.idx()];
        values[k] += PENALTY * values[k].abs().max(f64::MIN_POSITIVE);
    }
}
