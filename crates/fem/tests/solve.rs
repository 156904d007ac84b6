//! Tests of the DOF map (`dof`) and the constrained sparse solves (`solve`): exact
//! constraint satisfaction, agreement with dense normal equations (nalgebra), symbolic
//! reuse, complex form = real form, singular systems, saddle points, typed errors.

use beltrami_fem::LeastSquaresSolver;
use beltrami_fem::dof::{DofConstraints, DofError, DofMap, DofScalar, NodeDof};
use beltrami_mesh::VertexId;
use beltrami_sparse::{SolveError, SolveOptions, solve_saddle_point, solve_spd};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, MatRef};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

mod common;
use common::Rng;

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

fn v(i: u32) -> VertexId {
    VertexId(i)
}

/// A random value of the scalar type.
trait Random: DofScalar {
    fn random(rng: &mut Rng) -> Self;
    fn to_c64(self) -> Complex64;
}

impl Random for f64 {
    fn random(rng: &mut Rng) -> Self {
        rng.uniform()
    }
    fn to_c64(self) -> Complex64 {
        c(self, 0.0)
    }
}

impl Random for Complex64 {
    fn random(rng: &mut Rng) -> Self {
        c(rng.uniform(), rng.uniform())
    }
    fn to_c64(self) -> Complex64 {
        self
    }
}

/// A random sparse `m x ncols` matrix: every row has `per_row` entries in distinct
/// random columns, and every column at least one entry (so no unknown is left out).
fn random_entries(rng: &mut Rng, m: usize, ncols: usize, per_row: usize) -> Vec<(usize, usize)> {
    let mut positions = Vec::new();
    for i in 0..m {
        let mut cols: Vec<usize> = Vec::new();
        if i < ncols {
            cols.push(i);
        }
        while cols.len() < per_row {
            let j = rng.below(ncols);
            if !cols.contains(&j) {
                cols.push(j);
            }
        }
        positions.extend(cols.into_iter().map(|j| (i, j)));
    }
    positions
}

fn assemble<T: Random>(
    m: usize,
    ncols: usize,
    positions: &[(usize, usize)],
    values: &[T],
) -> SparseColMat<usize, T> {
    let triplets: Vec<_> = positions
        .iter()
        .zip(values)
        .map(|(&(i, j), &x)| Triplet::new(i, j, x))
        .collect();
    SparseColMat::try_new_from_triplets(m, ncols, &triplets).unwrap()
}

fn random_values<T: Random>(rng: &mut Rng, n: usize) -> Vec<T> {
    (0..n).map(|_| T::random(rng)).collect()
}

fn random_weights(rng: &mut Rng, m: usize) -> Vec<f64> {
    (0..m).map(|_| 0.5 + 0.5 * rng.uniform().abs()).collect()
}

/// The minimizer from dense normal equations in complex arithmetic (a real problem is
/// a complex one with zero imaginary parts):
/// `(K^H A^H W A K) y = K^H A^H W (b - A x0)`, `x = K y + x0`.
fn dense_reference<T: Random>(
    a: &SparseColMat<usize, T>,
    weights: &[f64],
    b: &[T],
    dofs: &DofMap<T>,
) -> Vec<Complex64> {
    let to_na = |m: Mat<T>| DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)].to_c64());
    let a = to_na(a.to_dense());
    let k = to_na(dofs.k().to_dense());
    let x0 = DVector::from_iterator(dofs.full_len(), dofs.x0().iter().map(|x| x.to_c64()));
    let w = DMatrix::from_diagonal(&DVector::from_iterator(
        weights.len(),
        weights.iter().map(|&w| c(w, 0.0)),
    ));
    let b = DVector::from_iterator(b.len(), b.iter().map(|x| x.to_c64()));
    let ak = &a * &k;
    let normal = ak.adjoint() * &w * &ak;
    let rhs = ak.adjoint() * &w * (b - &a * &x0);
    let y = normal.lu().solve(&rhs).unwrap();
    (k * y + x0).iter().copied().collect()
}

fn max_diff<T: Random>(x: &[T], reference: &[Complex64]) -> f64 {
    assert_eq!(x.len(), reference.len());
    x.iter()
        .zip(reference)
        .map(|(a, b)| (a.to_c64() - b).norm())
        .fold(0.0, f64::max)
}

fn max_abs(x: &[Complex64]) -> f64 {
    x.iter().map(|z| z.norm()).fold(0.0, f64::max)
}

/// The constraints used by most tests: node 0 fixed, node 1 fixed, nodes 2 ~ 5 ~ 7
/// shared (chain), node 3 sliding (real form only).
fn constraints(with_slide: bool) -> DofConstraints {
    let mut cons = DofConstraints::new();
    cons.fix(v(0), c(0.25, -1.5))
        .fix(v(1), c(2.0, 0.5))
        .share(v(2), v(5))
        .share(v(7), v(5));
    if with_slide {
        cons.slide(v(3), c(1.0, 1.0), c(3.0, 4.0));
    }
    cons
}

/// A least-squares problem `min sum_i w_i |(A x - b)_i|^2` and the positions of the
/// entries of `A`.
struct Problem<T> {
    positions: Vec<(usize, usize)>,
    a: SparseColMat<usize, T>,
    w: Vec<f64>,
    b: Vec<T>,
}

/// Random least-squares problem in the DOF map's form: `m` rows, 3 entries per row.
fn random_problem<T: Random>(rng: &mut Rng, dofs: &DofMap<T>, m: usize) -> Problem<T> {
    let positions = random_entries(rng, m, dofs.full_len(), 3);
    let values = random_values::<T>(rng, positions.len());
    let a = assemble(m, dofs.full_len(), &positions, &values);
    let w = random_weights(rng, m);
    let b = random_values::<T>(rng, m);
    Problem { positions, a, w, b }
}

#[test]
fn fixed_nodes_end_exactly_at_their_values() {
    let mut rng = Rng(1);
    let real = DofMap::real(12, &constraints(true)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &real, 50);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &real, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    assert_eq!(real.node_position(&x, v(0)).unwrap(), c(0.25, -1.5));
    assert_eq!(real.node_position(&x, v(1)).unwrap(), c(2.0, 0.5));

    let complex = DofMap::complex(12, &constraints(false)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &complex, 30);
    let mut solver =
        LeastSquaresSolver::new(a.symbolic(), &complex, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    assert_eq!(x[0], c(0.25, -1.5));
    assert_eq!(x[1], c(2.0, 0.5));
}

/// A map whose slide moves between solves keeps the solver's symbolic phase, and the
/// solve equals that of a solver built for the new map; a map with other unknowns does
/// not keep it and still solves right.
#[test]
fn updated_maps_keep_the_symbolic_phase_and_solve_as_new_ones() {
    let mut rng = Rng(9);
    let first = DofMap::real(12, &constraints(true)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &first, 50);
    let mut kept = LeastSquaresSolver::new(a.symbolic(), &first, SolveOptions::default()).unwrap();
    kept.solve(a.as_ref(), Some(&w), &b).unwrap();

    let mut moved = DofConstraints::new();
    moved
        .fix(v(0), c(-0.5, 1.0))
        .fix(v(1), c(2.0, 0.5))
        .share(v(2), v(5))
        .share(v(7), v(5))
        .slide(v(3), c(-2.0, 0.5), c(1.0, -2.0));
    let second = DofMap::real(12, &moved).unwrap();
    assert!(kept.update_dofs(&second).unwrap());
    let x = kept.solve(a.as_ref(), Some(&w), &b).unwrap();
    let mut fresh =
        LeastSquaresSolver::new(a.symbolic(), &second, SolveOptions::default()).unwrap();
    let y = fresh.solve(a.as_ref(), Some(&w), &b).unwrap();
    let scale = y.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    for (x, y) in x.iter().zip(&y) {
        assert!((x - y).abs() <= 1e-12 * scale, "{x} != {y}");
    }
    assert_eq!(second.node_position(&x, v(0)).unwrap(), c(-0.5, 1.0));

    // Node 3 fixed instead of sliding: one unknown fewer, a new symbolic phase.
    let mut fixed = constraints(false);
    fixed.fix(v(3), c(1.0, 1.0));
    let third = DofMap::real(12, &fixed).unwrap();
    assert!(!kept.update_dofs(&third).unwrap());
    let x = kept.solve(a.as_ref(), Some(&w), &b).unwrap();
    let mut fresh = LeastSquaresSolver::new(a.symbolic(), &third, SolveOptions::default()).unwrap();
    let y = fresh.solve(a.as_ref(), Some(&w), &b).unwrap();
    for (x, y) in x.iter().zip(&y) {
        assert!((x - y).abs() <= 1e-12 * scale.max(1.0), "{x} != {y}");
    }
}

#[test]
fn sliding_node_ends_on_its_line() {
    let mut rng = Rng(2);
    let dofs = DofMap::real(12, &constraints(true)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &dofs, 50);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    let p = dofs.node_position(&x, v(3)).unwrap();
    let (point, direction) = (c(1.0, 1.0), c(0.6, 0.8));
    let offset = p - point;
    let distance = (direction.re * offset.im - direction.im * offset.re).abs();
    assert!(distance < 1e-12, "distance from the line {distance:e}");
    // The node did move along the line: the constraint is not satisfied trivially.
    assert!(offset.norm() > 1e-3, "offset {offset}");
    match dofs.node_dof(v(3)).unwrap() {
        NodeDof::Sliding {
            point: q,
            direction: d,
            ..
        } => {
            assert_eq!(q, point);
            assert!((d - direction).norm() < 1e-15);
        }
        other => panic!("node 3 should slide, got {other:?}"),
    }
}

#[test]
fn shared_nodes_get_identical_values() {
    let mut rng = Rng(3);
    let real = DofMap::real(12, &constraints(true)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &real, 50);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &real, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    let p2 = real.node_position(&x, v(2)).unwrap();
    assert_eq!(p2, real.node_position(&x, v(5)).unwrap());
    assert_eq!(p2, real.node_position(&x, v(7)).unwrap());
    // One group, one pair of reduced unknowns, named by its smallest node.
    assert_eq!(real.node_dof(v(7)).unwrap(), real.node_dof(v(2)).unwrap());
    let NodeDof::Free { dof } = real.node_dof(v(5)).unwrap() else {
        panic!("node 5 should be free")
    };
    assert_eq!(real.dof_node(dof), Some(v(2)));
    assert_eq!(real.dof_node(dof + 1), Some(v(2)));

    let complex = DofMap::complex(12, &constraints(false)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &complex, 30);
    let mut solver =
        LeastSquaresSolver::new(a.symbolic(), &complex, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    assert_eq!(x[2], x[5]);
    assert_eq!(x[2], x[7]);
}

/// Unknown counts: 12 nodes, 2 fixed, a group of 3, one slide (real form).
#[test]
fn reduced_unknown_counts() {
    let real = DofMap::real(12, &constraints(true)).unwrap();
    // Free groups: nodes {2,5,7}, 4, 6, 8, 9, 10, 11 -> 7 groups x 2, plus 1 slide.
    assert_eq!(real.full_len(), 24);
    assert_eq!(real.reduced_len(), 15);
    let complex = DofMap::complex(12, &constraints(false)).unwrap();
    assert_eq!(complex.full_len(), 12);
    // Free groups: {2,5,7}, 3, 4, 6, 8, 9, 10, 11.
    assert_eq!(complex.reduced_len(), 8);
    assert_eq!(complex.x0()[1], c(2.0, 0.5));
}

fn reuse_matches_fresh<T: Random>(dofs: &DofMap<T>, seed: u64) {
    let mut rng = Rng(seed);
    let m = 3 * dofs.full_len();
    let Problem { positions, a, w, b } = random_problem(&mut rng, dofs, m);
    let mut reused = LeastSquaresSolver::new(a.symbolic(), dofs, SolveOptions::default()).unwrap();
    assert_eq!(reused.pattern().col_ptr(), a.symbolic().col_ptr());
    assert_eq!(reused.pattern().row_idx(), a.symbolic().row_idx());
    assert_eq!(reused.dofs().reduced_len(), dofs.reduced_len());
    reused.solve(a.as_ref(), Some(&w), &b).unwrap();
    // New values, weights and right-hand side in the same pattern.
    let values2 = random_values::<T>(&mut rng, positions.len());
    let a2 = assemble(m, dofs.full_len(), &positions, &values2);
    let w2 = random_weights(&mut rng, m);
    let b2 = random_values::<T>(&mut rng, m);
    let x_reused = reused.solve(a2.as_ref(), Some(&w2), &b2).unwrap();
    let mut fresh = LeastSquaresSolver::new(a2.symbolic(), dofs, SolveOptions::default()).unwrap();
    let x_fresh = fresh.solve(a2.as_ref(), Some(&w2), &b2).unwrap();
    let fresh_c: Vec<Complex64> = x_fresh.iter().map(|x| x.to_c64()).collect();
    let diff = max_diff(&x_reused, &fresh_c);
    assert!(
        diff <= 1e-12 * max_abs(&fresh_c),
        "reuse differs by {diff:e}"
    );
    // And a third call with the first values again reproduces the first answer of a
    // fresh solver: no state leaks between numeric refills.
    let mut x_into = vec![T::from_f64(0.0); dofs.full_len()];
    reused
        .solve_into(a.as_ref(), Some(&w), &b, &mut x_into)
        .unwrap();
    let first = dense_reference(&a, &w, &b, dofs);
    assert!(max_diff(&x_into, &first) <= 1e-10 * max_abs(&first));
}

#[test]
fn symbolic_reuse_matches_fresh_factorization() {
    reuse_matches_fresh(&DofMap::real(40, &constraints(true)).unwrap(), 4);
    reuse_matches_fresh(&DofMap::complex(40, &constraints(false)).unwrap(), 5);
}

/// A nearby system (every value of `A` moved by up to 1e-3 of its size) is solved by
/// conjugate gradients on the kept factorization, without factoring, to the dense
/// answer within the tolerance; a system far from it fails to converge in the
/// iterations given and is factored, as a first call (nothing factored) is.
#[test]
fn reusing_solves_a_nearby_system_without_factoring_and_factors_a_far_one() {
    let dofs = DofMap::complex(40, &constraints(false)).unwrap();
    let mut rng = Rng(11);
    let m = 3 * dofs.full_len();
    let Problem { positions, a, w, b } = random_problem(&mut rng, &dofs, m);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let mut x = vec![c(0.0, 0.0); dofs.full_len()];
    let first = solver
        .solve_into_reusing(a.as_ref(), Some(&w), &b, &mut x, 1e-10, 5)
        .unwrap();
    assert!(!first.converged && first.iterations == 0, "{first:?}");
    let reference = dense_reference(&a, &w, &b, &dofs);
    assert!(max_diff(&x, &reference) <= 1e-10 * max_abs(&reference));

    let nearby: Vec<Complex64> = a
        .val()
        .iter()
        .map(|&z| z * (1.0 + 1e-3 * rng.uniform()))
        .collect();
    let a_near = SparseColMat::new(a.symbolic().to_owned().unwrap(), nearby);
    let near = solver
        .solve_into_reusing(a_near.as_ref(), Some(&w), &b, &mut x, 1e-10, 5)
        .unwrap();
    assert!(near.converged && near.iterations >= 1, "{near:?}");
    let reference = dense_reference(&a_near, &w, &b, &dofs);
    assert!(max_diff(&x, &reference) <= 1e-8 * max_abs(&reference));

    let far = random_values::<Complex64>(&mut rng, positions.len());
    let a_far = assemble(m, dofs.full_len(), &positions, &far);
    let outcome = solver
        .solve_into_reusing(a_far.as_ref(), Some(&w), &b, &mut x, 1e-10, 2)
        .unwrap();
    assert!(!outcome.converged, "{outcome:?}");
    let reference = dense_reference(&a_far, &w, &b, &dofs);
    assert!(max_diff(&x, &reference) <= 1e-10 * max_abs(&reference));
}

fn matches_dense<T: Random>(dofs: &DofMap<T>, seed: u64) {
    let mut rng = Rng(seed);
    let m = 2 * dofs.full_len() + 5;
    let Problem { a, w, b, .. } = random_problem(&mut rng, dofs, m);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    let reference = dense_reference(&a, &w, &b, dofs);
    let diff = max_diff(&x, &reference);
    assert!(
        diff <= 1e-11 * max_abs(&reference),
        "sparse vs dense: {diff:e}"
    );
    // Unit weights (`None`) equal explicit ones.
    let x1 = solver.solve(a.as_ref(), None, &b).unwrap();
    let reference1 = dense_reference(&a, &vec![1.0; m], &b, dofs);
    assert!(max_diff(&x1, &reference1) <= 1e-11 * max_abs(&reference1));
}

#[test]
fn least_squares_matches_dense_normal_equations_real() {
    matches_dense(&DofMap::real(30, &constraints(true)).unwrap(), 6);
    matches_dense(&DofMap::real(30, &DofConstraints::new()).unwrap(), 7);
}

#[test]
fn least_squares_matches_dense_normal_equations_complex() {
    matches_dense(&DofMap::complex(30, &constraints(false)).unwrap(), 8);
    matches_dense(&DofMap::complex(30, &DofConstraints::new()).unwrap(), 9);
}

/// The complex problem `min sum w_i |(A x - b)_i|^2` and its real 2x2-block
/// counterpart (`a = p + i q` acting on `[re, im]` as `[[p, -q], [q, p]]`) have the same
/// minimizer.
#[test]
fn complex_form_equals_real_form() {
    let mut rng = Rng(10);
    let n_nodes = 25;
    let cons = constraints(false);
    let complex = DofMap::complex(n_nodes, &cons).unwrap();
    let real = DofMap::real(n_nodes, &cons).unwrap();
    let m = 60;
    let Problem { a, w, b, .. } = random_problem::<Complex64>(&mut rng, &complex, m);
    let mut triplets = Vec::new();
    for j in 0..a.ncols() {
        for (i, &z) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            triplets.push(Triplet::new(2 * i, 2 * j, z.re));
            triplets.push(Triplet::new(2 * i, 2 * j + 1, -z.im));
            triplets.push(Triplet::new(2 * i + 1, 2 * j, z.im));
            triplets.push(Triplet::new(2 * i + 1, 2 * j + 1, z.re));
        }
    }
    let a_real = SparseColMat::try_new_from_triplets(2 * m, 2 * n_nodes, &triplets).unwrap();
    let w_real: Vec<f64> = w.iter().flat_map(|&w| [w, w]).collect();
    let b_real: Vec<f64> = b.iter().flat_map(|z| [z.re, z.im]).collect();

    let mut sc = LeastSquaresSolver::new(a.symbolic(), &complex, SolveOptions::default()).unwrap();
    let xc = sc.solve(a.as_ref(), Some(&w), &b).unwrap();
    let mut sr =
        LeastSquaresSolver::new(a_real.symbolic(), &real, SolveOptions::default()).unwrap();
    let xr = real
        .positions(&sr.solve(a_real.as_ref(), Some(&w_real), &b_real).unwrap())
        .unwrap();
    let diff = max_diff(&xc, &xr);
    assert!(
        diff <= 1e-12 * max_abs(&xr),
        "complex vs real form: {diff:e}"
    );
}

/// Edge-difference operator of an `nx x ny` grid with per-edge weights: rows
/// `x_a - x_b`, so that `A^T W A` is the weighted graph Laplacian. Real form: each row
/// acts on both coordinates (two rows per edge).
fn grid_gradient(nx: usize, ny: usize) -> (SparseColMat<usize, f64>, usize) {
    let id = |i: usize, j: usize| i + nx * j;
    let mut triplets = Vec::new();
    let mut row = 0;
    for j in 0..ny {
        for i in 0..nx {
            let mut edge = |a: usize, b: usize| {
                for coord in 0..2 {
                    triplets.push(Triplet::new(row, 2 * a + coord, 1.0));
                    triplets.push(Triplet::new(row, 2 * b + coord, -1.0));
                    row += 1;
                }
            };
            if i + 1 < nx {
                edge(id(i, j), id(i + 1, j));
            }
            if j + 1 < ny {
                edge(id(i, j), id(i, j + 1));
            }
        }
    }
    let a = SparseColMat::try_new_from_triplets(row, 2 * nx * ny, &triplets).unwrap();
    (a, row)
}

/// Weighted grid Laplacian (real, both triangles), optionally with the Dirichlet node 0
/// eliminated by adding 1 to its diagonal.
fn grid_laplacian(nx: usize, ny: usize, seed: Option<u64>) -> SparseColMat<usize, f64> {
    let mut rng = seed.map(Rng);
    let id = |i: usize, j: usize| i + nx * j;
    let mut triplets = Vec::new();
    let mut edge = |a: usize, b: usize, t: &mut Vec<Triplet<usize, usize, f64>>| {
        let w = rng.as_mut().map_or(1.0, |r| 1.0 + 0.9 * r.uniform());
        t.extend([
            Triplet::new(a, a, w),
            Triplet::new(b, b, w),
            Triplet::new(a, b, -w),
            Triplet::new(b, a, -w),
        ]);
    };
    for j in 0..ny {
        for i in 0..nx {
            if i + 1 < nx {
                edge(id(i, j), id(i + 1, j), &mut triplets);
            }
            if j + 1 < ny {
                edge(id(i, j), id(i, j + 1), &mut triplets);
            }
        }
    }
    SparseColMat::try_new_from_triplets(nx * ny, nx * ny, &triplets).unwrap()
}

#[test]
fn singular_least_squares_gives_typed_error_not_nan() {
    let (a, m) = grid_gradient(30, 30);
    let mut rng = Rng(11);
    let b: Vec<f64> = (0..m).map(|_| rng.uniform()).collect();
    let w = random_weights(&mut rng, m);
    // No fixed node: translations are in the kernel.
    let free = DofMap::real(900, &DofConstraints::new()).unwrap();
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &free, SolveOptions::default()).unwrap();
    for weights in [None, Some(w.as_slice())] {
        match solver.solve(a.as_ref(), weights, &b) {
            Err(SolveError::Singular { node, ratio, .. }) => {
                assert!(node.is_some());
                assert!(ratio < 1e-10);
            }
            other => panic!("expected Singular, got {other:?}"),
        }
    }
    // One pinned node makes it regular, with the same solver pattern on a new map.
    let mut cons = DofConstraints::new();
    cons.fix(v(0), c(0.0, 0.0));
    let pinned = DofMap::real(900, &cons).unwrap();
    let mut solver =
        LeastSquaresSolver::new(a.symbolic(), &pinned, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    assert!(x.iter().all(|x| x.is_finite()));
}

/// A 300 x 300 grid (90K nodes, 180K real unknowns) goes through faer's supernodal
/// Cholesky: the pivot test must read the supernodal factor too.
#[test]
fn singular_detection_on_a_large_grid() {
    let (a, m) = grid_gradient(300, 300);
    let mut rng = Rng(12);
    let b: Vec<f64> = (0..m).map(|_| rng.uniform()).collect();
    let w = random_weights(&mut rng, m);
    let free = DofMap::real(90_000, &DofConstraints::new()).unwrap();
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &free, SolveOptions::default()).unwrap();
    assert!(matches!(
        solver.solve(a.as_ref(), Some(&w), &b),
        Err(SolveError::Singular { .. })
    ));
    let mut cons = DofConstraints::new();
    cons.fix(v(0), c(1.0, 2.0)).fix(v(89_999), c(-1.0, 0.5));
    let pinned = DofMap::real(90_000, &cons).unwrap();
    let mut solver =
        LeastSquaresSolver::new(a.symbolic(), &pinned, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    // Optimality: the reduced gradient K^T A^T W (A x - b) vanishes.
    let x_mat = MatRef::from_column_major_slice(&x, x.len(), 1);
    let r = a.as_ref() * x_mat;
    let wr = Mat::<f64>::from_fn(m, 1, |i, _| w[i] * (r[(i, 0)] - b[i]));
    let g = pinned.k().transpose() * (a.as_ref().transpose() * wr.as_ref());
    let scale = b.iter().fold(0.0_f64, |s, b| s.max(b.abs()));
    let gmax = (0..g.nrows()).fold(0.0_f64, |s, i| s.max(g[(i, 0)].abs()));
    assert!(gmax < 1e-9 * scale, "reduced gradient {gmax:e}");
}

#[test]
fn unconstrained_unknown_is_reported_at_construction() {
    // Node 3 appears in no row.
    let triplets = [
        Triplet::new(0, 0, 1.0),
        Triplet::new(1, 1, 1.0),
        Triplet::new(1, 2, -1.0),
    ];
    let a = SparseColMat::<usize, Complex64>::try_new_from_triplets(
        2,
        4,
        &triplets.map(|t| Triplet::new(t.row, t.col, c(t.val, 0.0))),
    )
    .unwrap();
    let dofs = DofMap::complex(4, &DofConstraints::new()).unwrap();
    match LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()) {
        Err(SolveError::Unconstrained { index: 3, node }) => assert_eq!(node, Some(3)),
        other => panic!("expected Unconstrained, got {other:?}"),
    }
    // Fixing node 3 removes the problem.
    let mut cons = DofConstraints::new();
    cons.fix(v(3), c(1.0, 1.0));
    let dofs = DofMap::complex(4, &cons).unwrap();
    assert!(LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).is_ok());
}

#[test]
fn singular_laplacian_spd_gives_typed_error_not_nan() {
    let rhs = Mat::<f64>::from_fn(400, 1, |i, _| (i as f64).sin());
    // Unit weights: elimination meets an exact zero pivot.
    let unit = grid_laplacian(20, 20, None);
    // Random weights: rounding leaves a tiny positive pivot.
    let random = grid_laplacian(20, 20, Some(13));
    for l in [unit, random] {
        match solve_spd(l.as_ref(), rhs.as_ref(), SolveOptions::default()) {
            Err(SolveError::Singular { .. } | SolveError::NotPositiveDefinite { .. }) => {}
            other => panic!("expected a singularity error, got {other:?}"),
        }
    }
    // A 300 x 300 grid goes through the supernodal factorization.
    let big = grid_laplacian(300, 300, Some(21));
    let rhs_big = Mat::<f64>::from_fn(90_000, 1, |i, _| (i as f64).cos());
    match solve_spd(big.as_ref(), rhs_big.as_ref(), SolveOptions::default()) {
        Err(SolveError::Singular { .. } | SolveError::NotPositiveDefinite { .. }) => {}
        other => panic!("expected a singularity error, got {other:?}"),
    }
    // Indefinite: -L with a Dirichlet node.
    let mut t = vec![Triplet::new(0, 0, 1.0)];
    let l = grid_laplacian(20, 20, Some(14));
    for j in 0..400 {
        for (i, &x) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
            t.push(Triplet::new(i, j, -x));
        }
    }
    let neg = SparseColMat::try_new_from_triplets(400, 400, &t).unwrap();
    assert!(matches!(
        solve_spd(neg.as_ref(), rhs.as_ref(), SolveOptions::default()),
        Err(SolveError::NotPositiveDefinite { .. })
    ));
}

/// The pivot test reads the factor right, simplicial and supernodal: a grid Laplacian
/// grounded at node 0 by a weak spring `eps` has a smallest relative pivot of about
/// `eps / diagonal` (the effective conductance to ground of the last node eliminated
/// is at most `eps`), so a tolerance above it reports it and one below accepts.
#[test]
fn pivot_test_reads_simplicial_and_supernodal_factors() {
    let eps = 1e-4;
    for side in [10, 300] {
        let n = side * side;
        let l = grid_laplacian(side, side, None);
        let mut t = vec![Triplet::new(0, 0, eps)];
        for j in 0..n {
            for (i, &x) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
                t.push(Triplet::new(i, j, x));
            }
        }
        let grounded = SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
        let rhs = Mat::<f64>::from_fn(n, 1, |i, _| (i as f64).cos());
        let strict = SolveOptions {
            singularity_tolerance: Some(1e-2),
            ..SolveOptions::default()
        };
        match solve_spd(grounded.as_ref(), rhs.as_ref(), strict) {
            Err(SolveError::Singular { ratio, .. }) => {
                // Diagonals are 2 to 4 (+ eps); pivots may sit anywhere below eps.
                assert!(ratio > 0.0 && ratio <= eps / 2.0, "ratio {ratio:e}");
            }
            other => panic!("expected Singular, got {other:?}"),
        }
        let x = solve_spd(grounded.as_ref(), rhs.as_ref(), SolveOptions::default()).unwrap();
        let residual = grounded.as_ref() * x.as_ref() - &rhs;
        let rmax = (0..n).fold(0.0_f64, |s, i| s.max(residual[(i, 0)].abs()));
        assert!(rmax < 1e-8, "residual {rmax:e}");
    }
}

#[test]
fn spd_solve_matches_dense_and_reads_the_lower_triangle() {
    let l = grid_laplacian(12, 9, Some(15));
    let n = 108;
    // Dirichlet node 0 eliminated: replace row/column 0 by the identity.
    let mut full = Vec::new();
    let mut lower = Vec::new();
    for j in 0..n {
        for (i, &x) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
            let x = if i == 0 || j == 0 {
                if i == j { 1.0 } else { 0.0 }
            } else {
                x
            };
            full.push(Triplet::new(i, j, x));
            if i >= j {
                lower.push(Triplet::new(i, j, x));
            }
        }
    }
    let full = SparseColMat::try_new_from_triplets(n, n, &full).unwrap();
    let lower = SparseColMat::try_new_from_triplets(n, n, &lower).unwrap();
    let rhs = Mat::<f64>::from_fn(n, 2, |i, j| ((i * (j + 1)) as f64).cos());
    let x_full = solve_spd(full.as_ref(), rhs.as_ref(), SolveOptions::default()).unwrap();
    let x_lower = solve_spd(lower.as_ref(), rhs.as_ref(), SolveOptions::default()).unwrap();
    let dense = full.to_dense();
    let na = DMatrix::from_fn(n, n, |i, j| dense[(i, j)]);
    let lu = na.lu();
    for col in 0..2 {
        let b = DVector::from_fn(n, |i, _| rhs[(i, col)]);
        let reference = lu.solve(&b).unwrap();
        let scale = reference.amax();
        for i in 0..n {
            assert!((x_full[(i, col)] - reference[i]).abs() <= 1e-12 * scale);
            assert!((x_full[(i, col)] - x_lower[(i, col)]).abs() <= 1e-13 * scale);
        }
    }
}

/// `min |W^(1/2)(A x - b)|^2` subject to `C x = d` with `C` fixing nodes and tying two
/// nodes, against the DOF-map elimination of the same constraints.
fn saddle_matches_elimination<T: Form>(seed: u64) {
    let mut rng = Rng(seed);
    let n_nodes = 20;
    let dofs_free = T::full_free(n_nodes);
    let m = 3 * dofs_free.full_len();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &dofs_free, m);
    // H = A^H W A, g = A^H W b, dense then sparse (small).
    let ad = a.to_dense();
    let nfull = dofs_free.full_len();
    let mut h_t = Vec::new();
    for i in 0..nfull {
        for j in 0..nfull {
            let mut s = T::from_f64(0.0);
            for r in 0..m {
                s += ad[(r, i)].conjugate() * T::from_f64(w[r]) * ad[(r, j)];
            }
            h_t.push(Triplet::new(i, j, s));
        }
    }
    let h = SparseColMat::try_new_from_triplets(nfull, nfull, &h_t).unwrap();
    let g: Vec<T> = (0..nfull)
        .map(|i| {
            let mut s = T::from_f64(0.0);
            for r in 0..m {
                s += ad[(r, i)].conjugate() * T::from_f64(w[r]) * b[r];
            }
            s
        })
        .collect();

    // Constraints: node 0 = p, node 4 = q, node 6 - node 9 = 0 (per unknown of a node).
    let (p, q) = (c(1.0, -2.0), c(0.5, 3.0));
    let mut cons = DofConstraints::new();
    cons.fix(v(0), p).fix(v(4), q).share(v(6), v(9));
    let dofs = T::from_constraints(n_nodes, &cons);
    let per = T::PER_NODE;
    let mut c_t = Vec::new();
    let mut d = Vec::new();
    let mut row = 0;
    for (node, value) in [(0, p), (4, q)] {
        for k in 0..per {
            c_t.push(Triplet::new(row, per * node + k, T::from_f64(1.0)));
            d.push(T::component(value, k));
            row += 1;
        }
    }
    for k in 0..per {
        c_t.push(Triplet::new(row, per * 6 + k, T::from_f64(1.0)));
        c_t.push(Triplet::new(row, per * 9 + k, T::from_f64(-1.0)));
        d.push(T::from_f64(0.0));
        row += 1;
    }
    let cm = SparseColMat::try_new_from_triplets(row, nfull, &c_t).unwrap();
    let sol = solve_saddle_point(h.as_ref(), &g, cm.as_ref(), &d, SolveOptions::default()).unwrap();

    // C x = d.
    let cx = cm.as_ref() * MatRef::from_column_major_slice(&sol.x, nfull, 1);
    for (i, di) in d.iter().enumerate() {
        let e = (cx[(i, 0)] - *di).to_c64().norm();
        assert!(e < 1e-12, "constraint {i} violated by {e:e}");
    }
    // Same minimizer as the elimination.
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    let xc: Vec<Complex64> = x.iter().map(|x| x.to_c64()).collect();
    let diff = max_diff(&sol.x, &xc);
    assert!(
        diff <= 1e-10 * max_abs(&xc),
        "saddle vs elimination {diff:e}"
    );
    assert_eq!(sol.multipliers.len(), row);

    // A repeated constraint row makes the system singular.
    let mut c_t2 = c_t.clone();
    c_t2.push(Triplet::new(row, 0, T::from_f64(1.0)));
    let mut d2 = d.clone();
    d2.push(d[0]);
    let c2 = SparseColMat::try_new_from_triplets(row + 1, nfull, &c_t2).unwrap();
    match solve_saddle_point(h.as_ref(), &g, c2.as_ref(), &d2, SolveOptions::default()) {
        Err(
            SolveError::IllConditioned { .. }
            | SolveError::Singular { .. }
            | SolveError::NonFiniteSolution { .. },
        ) => {}
        other => panic!("expected a singularity error, got {other:?}"),
    }
}

/// Test-only helpers to write the saddle test once for both forms.
trait Form: Random {
    fn full_free(n: usize) -> DofMap<Self>;
    fn from_constraints(n: usize, cons: &DofConstraints) -> DofMap<Self>;
    /// Component `k` of a complex value in this form's nodal layout.
    fn component(z: Complex64, k: usize) -> Self;
}

impl Form for f64 {
    fn full_free(n: usize) -> DofMap<Self> {
        DofMap::real(n, &DofConstraints::new()).unwrap()
    }
    fn from_constraints(n: usize, cons: &DofConstraints) -> DofMap<Self> {
        DofMap::real(n, cons).unwrap()
    }
    fn component(z: Complex64, k: usize) -> Self {
        if k == 0 { z.re } else { z.im }
    }
}

impl Form for Complex64 {
    fn full_free(n: usize) -> DofMap<Self> {
        DofMap::complex(n, &DofConstraints::new()).unwrap()
    }
    fn from_constraints(n: usize, cons: &DofConstraints) -> DofMap<Self> {
        DofMap::complex(n, cons).unwrap()
    }
    fn component(z: Complex64, _: usize) -> Self {
        z
    }
}

#[test]
fn saddle_point_satisfies_constraints_and_matches_elimination() {
    saddle_matches_elimination::<f64>(16);
    saddle_matches_elimination::<Complex64>(17);
}

/// Singular saddle-point systems that LU factors without a structural failure: the
/// condition estimate must catch them.
#[test]
fn numerically_singular_saddle_point_is_ill_conditioned() {
    let n = 100;
    let h = grid_laplacian(10, 10, Some(20));
    let g: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
    // x_0 - x_1 = 0 leaves the translations, on which H vanishes, in ker C.
    let c1 = SparseColMat::try_new_from_triplets(
        1,
        n,
        &[Triplet::new(0, 0, 1.0), Triplet::new(0, 1, -1.0)],
    )
    .unwrap();
    match solve_saddle_point(h.as_ref(), &g, c1.as_ref(), &[0.0], SolveOptions::default()) {
        Err(SolveError::IllConditioned { estimate, limit }) => {
            assert!(estimate.is_nan() || estimate > limit)
        }
        other => panic!("expected IllConditioned, got {other:?}"),
    }
    // Pinning x_0 = 1 as well makes it regular...
    let rows = [
        Triplet::new(0, 0, 1.0),
        Triplet::new(0, 1, -1.0),
        Triplet::new(1, 0, 1.0),
    ];
    let c2 = SparseColMat::try_new_from_triplets(2, n, &rows).unwrap();
    let sol = solve_saddle_point(
        h.as_ref(),
        &g,
        c2.as_ref(),
        &[0.0, 1.0],
        SolveOptions::default(),
    )
    .unwrap();
    assert!((sol.x[0] - 1.0).abs() < 1e-12 && (sol.x[1] - 1.0).abs() < 1e-12);
    // ... and a third row 0.3 row_0 + 0.7 row_1 (numerically, not structurally,
    // dependent) makes it singular again.
    let mut rows3 = rows.to_vec();
    rows3.extend([Triplet::new(2, 0, 0.3 + 0.7), Triplet::new(2, 1, -0.3)]);
    let c3 = SparseColMat::try_new_from_triplets(3, n, &rows3).unwrap();
    match solve_saddle_point(
        h.as_ref(),
        &g,
        c3.as_ref(),
        &[0.0, 1.0, 0.7],
        SolveOptions::default(),
    ) {
        Err(SolveError::IllConditioned { .. } | SolveError::Singular { .. }) => {}
        other => panic!("expected a singularity error, got {other:?}"),
    }
}

#[test]
fn bad_constraints_give_typed_errors() {
    let mut cons = DofConstraints::new();
    cons.slide(v(2), c(0.0, 0.0), c(1.0, 0.0));
    assert_eq!(
        DofMap::complex(5, &cons).unwrap_err(),
        DofError::SlideInComplexForm { node: v(2) }
    );
    assert!(DofMap::real(5, &cons).is_ok());

    // Conflicting fixes through a chain of shares: 1 ~ 3 ~ 4.
    let mut cons = DofConstraints::new();
    cons.share(v(1), v(3))
        .share(v(4), v(3))
        .fix(v(4), c(1.0, 0.0))
        .fix(v(1), c(0.0, 1.0));
    assert_eq!(
        DofMap::complex(5, &cons).unwrap_err(),
        DofError::ConflictingFixes {
            a: v(1),
            b: v(4),
            value_a: c(0.0, 1.0),
            value_b: c(1.0, 0.0),
        }
    );
    // Equal fixes in a group are fine and fix the whole group.
    let mut cons = DofConstraints::new();
    cons.share(v(1), v(3))
        .fix(v(3), c(1.0, 0.0))
        .fix(v(1), c(1.0, 0.0));
    let map = DofMap::complex(5, &cons).unwrap();
    assert_eq!(
        map.node_dof(v(1)).unwrap(),
        NodeDof::Fixed { value: c(1.0, 0.0) }
    );
    assert_eq!(map.node_dof(v(3)).unwrap(), map.node_dof(v(1)).unwrap());

    let mut cons = DofConstraints::new();
    cons.fix(v(5), c(1.0, 0.0));
    assert_eq!(
        DofMap::complex(5, &cons).unwrap_err(),
        DofError::NodeOutOfRange {
            node: v(5),
            n_nodes: 5
        }
    );
    let mut cons = DofConstraints::new();
    cons.share(v(0), v(9));
    assert_eq!(
        DofMap::real(5, &cons).unwrap_err(),
        DofError::NodeOutOfRange {
            node: v(9),
            n_nodes: 5
        }
    );

    let mut cons = DofConstraints::new();
    cons.slide(v(1), c(0.0, 0.0), c(0.0, 0.0));
    assert_eq!(
        DofMap::real(5, &cons).unwrap_err(),
        DofError::ZeroDirection { node: v(1) }
    );
    let mut cons = DofConstraints::new();
    cons.fix(v(2), c(f64::NAN, 0.0));
    assert_eq!(
        DofMap::real(5, &cons).unwrap_err(),
        DofError::NonFinite {
            node: v(2),
            what: "fixed value"
        }
    );

    // Fixed off the line its group slides on.
    let mut cons = DofConstraints::new();
    cons.share(v(0), v(1))
        .slide(v(0), c(0.0, 0.0), c(1.0, 0.0))
        .fix(v(1), c(0.5, 0.25));
    match DofMap::real(3, &cons).unwrap_err() {
        DofError::FixedOffSlideLine {
            fixed,
            sliding,
            distance,
        } => {
            assert_eq!((fixed, sliding), (v(1), v(0)));
            assert!((distance - 0.25).abs() < 1e-15);
        }
        other => panic!("expected FixedOffSlideLine, got {other:?}"),
    }
    // Distinct parallel lines.
    let mut cons = DofConstraints::new();
    cons.slide(v(2), c(0.0, 0.0), c(1.0, 1.0))
        .slide(v(2), c(0.0, 1.0), c(-2.0, -2.0));
    assert_eq!(
        DofMap::real(3, &cons).unwrap_err(),
        DofError::ParallelSlides { a: v(2), b: v(2) }
    );
}

#[test]
fn combined_constraints_on_one_node() {
    // A corner of the unit square whose sides slide: x = 1 and y = 1 meet at 1 + i.
    let mut cons = DofConstraints::new();
    cons.slide(v(0), c(1.0, -3.0), c(0.0, 2.0))
        .slide(v(0), c(5.0, 1.0), c(-1.0, 0.0));
    let map = DofMap::real(2, &cons).unwrap();
    assert_eq!(
        map.node_dof(v(0)).unwrap(),
        NodeDof::Fixed { value: c(1.0, 1.0) }
    );
    // The same line twice (other point, opposite direction) keeps the slide.
    let mut cons = DofConstraints::new();
    cons.slide(v(1), c(0.0, 0.0), c(1.0, 1.0))
        .slide(v(1), c(2.0, 2.0), c(-3.0, -3.0));
    let map = DofMap::real(2, &cons).unwrap();
    assert!(matches!(
        map.node_dof(v(1)).unwrap(),
        NodeDof::Sliding { dof: 2, .. }
    ));
    assert_eq!(map.reduced_len(), 3);
    // A fixed value on the sliding line wins.
    let mut cons = DofConstraints::new();
    cons.slide(v(1), c(0.0, 0.0), c(1.0, 1.0))
        .fix(v(1), c(0.5, 0.5));
    let map = DofMap::real(2, &cons).unwrap();
    assert_eq!(
        map.node_dof(v(1)).unwrap(),
        NodeDof::Fixed { value: c(0.5, 0.5) }
    );
}

#[test]
fn expand_and_reduce_are_inverse_on_admissible_vectors() {
    let mut rng = Rng(18);
    let real = DofMap::real(12, &constraints(true)).unwrap();
    let y: Vec<f64> = (0..real.reduced_len()).map(|_| rng.uniform()).collect();
    let x = real.expand(&y).unwrap();
    let y2 = real.reduce(&x).unwrap();
    for (a, b) in y.iter().zip(&y2) {
        assert!((a - b).abs() < 1e-15);
    }
    // x = K y + x0 agrees with the sparse K.
    let kx = real.k() * MatRef::from_column_major_slice(&y, y.len(), 1);
    for i in 0..real.full_len() {
        assert!((kx[(i, 0)] + real.x0()[i] - x[i]).abs() < 1e-15);
    }
    // Reduce averages a shared group and projects a slide on its line.
    let complex = DofMap::complex(12, &constraints(false)).unwrap();
    let mut x = vec![c(0.0, 0.0); 12];
    x[2] = c(1.0, 0.0);
    x[5] = c(2.0, 0.0);
    x[7] = c(6.0, 3.0);
    let y = complex.reduce(&x).unwrap();
    let NodeDof::Free { dof } = complex.node_dof(v(5)).unwrap() else {
        panic!("node 5 should be free")
    };
    assert!((y[dof] - c(3.0, 1.0)).norm() < 1e-15);
    assert_eq!(
        complex.expand(&y[..3]).unwrap_err(),
        DofError::Length {
            what: "y",
            expected: complex.reduced_len(),
            got: 3
        }
    );
}

#[test]
fn everything_fixed_gives_x0() {
    let mut cons = DofConstraints::new();
    cons.fix(v(0), c(1.0, 2.0)).fix(v(1), c(3.0, 4.0));
    let dofs = DofMap::complex(2, &cons).unwrap();
    assert_eq!(dofs.reduced_len(), 0);
    let a = SparseColMat::<usize, Complex64>::try_new_from_triplets(
        1,
        2,
        &[
            Triplet::new(0, 0, c(1.0, 0.0)),
            Triplet::new(0, 1, c(1.0, 0.0)),
        ],
    )
    .unwrap();
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), None, &[c(0.0, 0.0)]).unwrap();
    assert_eq!(x, vec![c(1.0, 2.0), c(3.0, 4.0)]);
}

#[test]
fn bad_solver_inputs_give_typed_errors() {
    let mut rng = Rng(19);
    let dofs = DofMap::real(10, &constraints(true)).unwrap();
    let Problem { positions, a, w, b } = random_problem(&mut rng, &dofs, 40);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();

    assert_eq!(
        solver.solve(a.as_ref(), Some(&w), &b[..39]).unwrap_err(),
        SolveError::Length {
            what: "the length of b",
            expected: 40,
            got: 39
        }
    );
    assert!(matches!(
        solver.solve(a.as_ref(), Some(&w[..3]), &b),
        Err(SolveError::Length { .. })
    ));
    let mut bad_w = w.clone();
    bad_w[7] = -1.0;
    assert_eq!(
        solver.solve(a.as_ref(), Some(&bad_w), &b).unwrap_err(),
        SolveError::InvalidWeight {
            row: 7,
            weight: -1.0
        }
    );
    let mut bad_b = b.clone();
    bad_b[4] = f64::INFINITY;
    assert_eq!(
        solver.solve(a.as_ref(), Some(&w), &bad_b).unwrap_err(),
        SolveError::NonFinite {
            what: "b",
            index: 4
        }
    );
    // NaN in A names its row and column.
    let mut values: Vec<f64> = (0..positions.len()).map(|_| rng.uniform()).collect();
    values[0] = f64::NAN;
    let a_nan = assemble(40, dofs.full_len(), &positions, &values);
    let (row, col) = positions[0];
    assert_eq!(
        solver.solve(a_nan.as_ref(), Some(&w), &b).unwrap_err(),
        SolveError::NonFiniteEntry {
            what: "A",
            row,
            col
        }
    );
    // Another pattern.
    let mut other = positions.clone();
    other.push((39, (other[other.len() - 1].1 + 1) % dofs.full_len()));
    other.sort();
    other.dedup();
    let values: Vec<f64> = (0..other.len()).map(|_| rng.uniform()).collect();
    let a_other = assemble(40, dofs.full_len(), &other, &values);
    assert!(matches!(
        solver.solve(a_other.as_ref(), Some(&w), &b),
        Err(SolveError::PatternMismatch { .. })
    ));
    // Wrong column count at construction.
    let a_short = assemble(2, 3, &[(0, 0), (1, 2)], &[1.0, 1.0]);
    assert_eq!(
        LeastSquaresSolver::new(a_short.symbolic(), &dofs, SolveOptions::default()).unwrap_err(),
        SolveError::Length {
            what: "the column count of A",
            expected: 20,
            got: 3
        }
    );
    // Output buffer of the wrong length.
    let mut x = vec![0.0; 3];
    assert!(matches!(
        solver.solve_into(a.as_ref(), Some(&w), &b, &mut x),
        Err(SolveError::Length { .. })
    ));
}

/// The minimizer under `<c, x> = d` from the dense saddle-point system of the reduced
/// problem (real form): `[N, K^T c; c^T K, 0] [y; l] = [K^T A^T W (b - A x0); d - <c, x0>]`.
fn dense_equality_reference(
    a: &SparseColMat<usize, f64>,
    weights: &[f64],
    b: &[f64],
    dofs: &DofMap<f64>,
    c: &[f64],
    d: f64,
) -> Vec<f64> {
    let to_na = |m: Mat<f64>| DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)]);
    let a = to_na(a.to_dense());
    let k = to_na(dofs.k().to_dense());
    let x0 = DVector::from_column_slice(dofs.x0());
    let w = DMatrix::from_diagonal(&DVector::from_column_slice(weights));
    let ak = &a * &k;
    let n = k.ncols();
    let kc = k.transpose() * DVector::from_column_slice(c);
    let mut kkt = DMatrix::zeros(n + 1, n + 1);
    kkt.view_mut((0, 0), (n, n))
        .copy_from(&(ak.transpose() * &w * &ak));
    kkt.view_mut((0, n), (n, 1)).copy_from(&kc);
    kkt.view_mut((n, 0), (1, n)).copy_from(&kc.transpose());
    let mut rhs = DVector::zeros(n + 1);
    rhs.rows_mut(0, n)
        .copy_from(&(ak.transpose() * &w * (DVector::from_column_slice(b) - &a * &x0)));
    rhs[n] = d - DVector::from_column_slice(c).dot(&x0);
    let y = kkt.lu().solve(&rhs).unwrap();
    (k * y.rows(0, n) + x0).iter().copied().collect()
}

#[test]
fn one_equality_is_met_exactly_whether_or_not_the_energy_alone_fixes_the_solution() {
    let mut rng = Rng(21);
    // Definite normal matrix: the rank-one elimination.
    let dofs = DofMap::real(12, &constraints(true)).unwrap();
    let Problem { a, w, b, .. } = random_problem(&mut rng, &dofs, 50);
    let c: Vec<f64> = (0..dofs.full_len()).map(|_| rng.uniform()).collect();
    let d = 0.7;
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver
        .solve_with_equality(a.as_ref(), Some(&w), &b, &c, d)
        .unwrap();
    let reference = dense_equality_reference(&a, &w, &b, &dofs, &c, d);
    let gap = x
        .iter()
        .zip(&reference)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(gap < 1e-9, "rank-one elimination off by {gap}");
    let met: f64 = c.iter().zip(&x).map(|(c, x)| c * x).sum();
    assert!((met - d).abs() < 1e-10, "<c, x> = {met}, asked {d}");
    // A difference operator on free nodes: the x translation is free (the y one is
    // anchored by one row), and the equality fixes it through the saddle-point system.
    let free = DofMap::real(6, &DofConstraints::new()).unwrap();
    let mut positions = Vec::new();
    let mut values = Vec::new();
    let mut row = 0;
    for (i, j) in [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (0, 3), (1, 4)] {
        for axis in 0..2 {
            positions.extend([(row, 2 * i + axis), (row, 2 * j + axis)]);
            values.extend([1.0, -1.0]);
            row += 1;
        }
    }
    positions.push((row, 1));
    values.push(1.0);
    row += 1;
    let a = assemble(row, free.full_len(), &positions, &values);
    let w = random_weights(&mut rng, row);
    let b: Vec<f64> = random_values(&mut rng, row);
    let c: Vec<f64> = (0..free.full_len())
        .map(|l| if l % 2 == 0 { 1.0 } else { 0.0 })
        .collect();
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &free, SolveOptions::default()).unwrap();
    assert!(matches!(
        solver.solve(a.as_ref(), Some(&w), &b),
        Err(SolveError::Singular { .. })
    ));
    let x = solver
        .solve_with_equality(a.as_ref(), Some(&w), &b, &c, 1.5)
        .unwrap();
    let reference = dense_equality_reference(&a, &w, &b, &free, &c, 1.5);
    let gap = x
        .iter()
        .zip(&reference)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(gap < 1e-9, "saddle-point path off by {gap}");
    // An equality on fixed unknowns only cannot be met by moving anything.
    let mut only_fixed = vec![0.0; dofs.full_len()];
    only_fixed[0] = 1.0;
    let Problem { a, w, b, .. } = random_problem(&mut rng, &dofs, 50);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    assert!(matches!(
        solver.solve_with_equality(a.as_ref(), Some(&w), &b, &only_fixed, 1.0),
        Err(SolveError::Unconstrained { .. })
    ));
}
