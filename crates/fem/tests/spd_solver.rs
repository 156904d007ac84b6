//! `SpdSolver`: symbolic reuse, custom elimination orders, conjugate gradients with a
//! kept factorization, and `Pattern::value_slots`.

mod common;

use beltrami_fem::assembly::Pattern;
use beltrami_sparse::amd_order;
use beltrami_sparse::{SolveError, SolveOptions, SpdSolver};
use faer::sparse::SparseColMat;
use faer::{Mat, MatMut};

/// The lower triangle of the 2D grid Laplacian plus `shift * I` on `n x n` nodes (SPD for
/// `shift > 0`), as entry positions and values.
fn shifted_laplacian(n: usize, shift: f64) -> (Vec<(usize, usize)>, Vec<f64>) {
    let id = |i: usize, j: usize| i + n * j;
    let (mut positions, mut values) = (Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..n {
            let mut degree = 0.0;
            for (di, dj) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                let (a, b) = (i as i64 + di, j as i64 + dj);
                if a < 0 || b < 0 || a >= n as i64 || b >= n as i64 {
                    continue;
                }
                degree += 1.0;
                let other = id(a as usize, b as usize);
                if other > id(i, j) {
                    positions.push((other, id(i, j)));
                    values.push(-1.0);
                }
            }
            positions.push((id(i, j), id(i, j)));
            values.push(degree + shift);
        }
    }
    (positions, values)
}

fn matrix(n: usize, shift: f64) -> (Pattern, SparseColMat<usize, f64>) {
    let (positions, values) = shifted_laplacian(n, shift);
    let pattern = Pattern::new(n * n, n * n, &positions).unwrap();
    let m = pattern.assemble(&values).unwrap();
    (pattern, m)
}

/// `M x` for the lower triangle `m`.
fn apply(m: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; x.len()];
    for j in 0..m.ncols() {
        for (i, &v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            y[i] += v * x[j];
            if i != j {
                y[j] += v * x[i];
            }
        }
    }
    y
}

fn rhs(len: usize) -> Vec<f64> {
    (0..len)
        .map(|k| ((k * 37 % 11) as f64 - 5.0) / 3.0)
        .collect()
}

fn residual(m: &SparseColMat<usize, f64>, x: &[f64], b: &[f64]) -> f64 {
    let y = apply(m, x);
    y.iter()
        .zip(b)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
        / b.iter().map(|v| v * v).sum::<f64>().sqrt()
}

#[test]
fn refactoring_one_pattern_solves_each_matrix() {
    let n = 12;
    let (pattern, a) = matrix(n, 0.5);
    let (_, b) = matrix(n, 2.0);
    let mut solver = SpdSolver::new(pattern.symbolic().as_ref(), SolveOptions::default()).unwrap();
    let f = rhs(n * n);
    for m in [&a, &b, &a] {
        solver.factorize(m.as_ref()).unwrap();
        let mut x = f.clone();
        solver
            .solve_in_place(MatMut::from_column_major_slice_mut(&mut x, n * n, 1))
            .unwrap();
        assert!(residual(m, &x, &f) < 1e-13);
    }
}

#[test]
fn a_custom_order_gives_the_same_solution() {
    let n = 10;
    let (pattern, a) = matrix(n, 1.0);
    let f = rhs(n * n);
    let order = amd_order(pattern.symbolic().as_ref()).unwrap();
    let mut sorted = order.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..n * n).collect::<Vec<_>>(), "a permutation");
    let reversed: Vec<usize> = (0..n * n).rev().collect();
    let mut solutions = Vec::new();
    for o in [&order, &reversed] {
        let mut solver =
            SpdSolver::with_order(pattern.symbolic().as_ref(), o, SolveOptions::default()).unwrap();
        solver.factorize(a.as_ref()).unwrap();
        let mut x = Mat::from_fn(n * n, 1, |i, _| f[i]);
        solver.solve_in_place(x.as_mut()).unwrap();
        solutions.push((0..n * n).map(|i| x[(i, 0)]).collect::<Vec<_>>());
    }
    for (u, v) in solutions[0].iter().zip(&solutions[1]) {
        assert!((u - v).abs() < 1e-12);
    }
    let mut bad = order.clone();
    bad[3] = bad[4];
    assert!(matches!(
        SpdSolver::<f64>::with_order(pattern.symbolic().as_ref(), &bad, SolveOptions::default()),
        Err(SolveError::InvalidOrder { .. })
    ));
}

#[test]
fn conjugate_gradients_reuse_a_nearby_factorization() {
    let n = 16;
    let (pattern, a) = matrix(n, 1.0);
    let (_, near) = matrix(n, 1.02);
    let (_, far) = matrix(n, 40.0);
    let mut solver = SpdSolver::new(pattern.symbolic().as_ref(), SolveOptions::default()).unwrap();
    let f = rhs(n * n);
    let mut x = f.clone();
    assert!(matches!(
        solver.solve_preconditioned(near.as_ref(), &mut x, 1e-10, 10),
        Err(SolveError::NotFactored)
    ));
    solver.factorize(a.as_ref()).unwrap();
    // The factor of A solves a 2% shift in a few iterations.
    let mut x = f.clone();
    let outcome = solver
        .solve_preconditioned(near.as_ref(), &mut x, 1e-10, 10)
        .unwrap();
    assert!(outcome.converged);
    assert!((1..=6).contains(&outcome.iterations), "{outcome:?}");
    assert!(residual(&near, &x, &f) < 1e-10);
    // A far matrix is given up on, early.
    let mut x = f.clone();
    let outcome = solver
        .solve_preconditioned(far.as_ref(), &mut x, 1e-10, 4)
        .unwrap();
    assert!(!outcome.converged && outcome.iterations < 4, "{outcome:?}");
}

#[test]
fn conjugate_gradients_started_near_the_solution_take_fewer_iterations() {
    let n = 16;
    let (pattern, a) = matrix(n, 1.0);
    let (_, near) = matrix(n, 1.05);
    let (_, nearer) = matrix(n, 1.051);
    let mut solver = SpdSolver::new(pattern.symbolic().as_ref(), SolveOptions::default()).unwrap();
    let f = rhs(n * n);
    solver.factorize(a.as_ref()).unwrap();
    let solve_from = |solver: &mut SpdSolver<f64>, start: Option<&[f64]>| {
        let mut x = f.clone();
        let outcome = match start {
            Some(start) => {
                solver.solve_preconditioned_from(nearer.as_ref(), &mut x, start, 1e-10, 20)
            }
            None => solver.solve_preconditioned(nearer.as_ref(), &mut x, 1e-10, 20),
        }
        .unwrap();
        assert!(outcome.converged, "{outcome:?}");
        assert!(residual(&nearer, &x, &f) < 1e-10);
        (outcome.iterations, x)
    };
    let (from_zero, solution) = solve_from(&mut solver, None);
    // The solution of a system near `nearer` leaves a residual of the size of the change.
    let mut previous = f.clone();
    solver
        .solve_preconditioned(near.as_ref(), &mut previous, 1e-12, 30)
        .unwrap();
    let (from_previous, _) = solve_from(&mut solver, Some(&previous));
    assert!(
        from_previous < from_zero,
        "{from_previous} iterations from the last solution, {from_zero} from zero"
    );
    // From the solution itself, none.
    let (from_solution, x) = solve_from(&mut solver, Some(&solution));
    assert_eq!(from_solution, 0);
    assert_eq!(x, solution);
    let mut x = f.clone();
    assert!(matches!(
        solver.solve_preconditioned_from(nearer.as_ref(), &mut x, &solution[1..], 1e-10, 20),
        Err(SolveError::Length { .. })
    ));
    let mut bad = solution.clone();
    bad[7] = f64::NAN;
    assert!(matches!(
        solver.solve_preconditioned_from(nearer.as_ref(), &mut x, &bad, 1e-10, 20),
        Err(SolveError::NonFinite { index: 7, .. })
    ));
}

#[test]
fn value_slots_point_at_the_summed_entries() {
    let positions = [(0, 0), (2, 0), (1, 1), (2, 0), (2, 2), (2, 1)];
    let pattern = Pattern::new(3, 3, &positions).unwrap();
    let slots = pattern.value_slots(&positions).unwrap();
    assert_eq!(slots[1], slots[3], "duplicates share a slot");
    let values = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let assembled = pattern.assemble(&values).unwrap();
    let mut refilled = vec![0.0; assembled.val().len()];
    for (k, &v) in values.iter().enumerate() {
        refilled[slots[k]] += v;
    }
    assert_eq!(refilled, assembled.val());
    assert!(pattern.value_slots(&[(0, 2)]).is_err());
}
