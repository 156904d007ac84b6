//! Fill-reducing orders: nested dissection against AMD, and the rule choosing between
//! them.

use beltrami_fem::vertex_graph::order_of_unknowns;
use beltrami_fem::{DofConstraints, DofMap};
use beltrami_mesh::VertexId;
use beltrami_sparse::{
    NESTED_DISSECTION_FROM, PlannedCholesky, SplitOrder, amd_order, factor_count,
    fill_reducing_order, first_split_order, nested_dissection_order, nested_dissection_split,
    two_core_order,
};
use beltrami_sparse::{SolveError, SolveOptions, SpdSolver};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{SymmetricOrdering, factorize_symbolic_cholesky};
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use faer::{Mat, Side};
use num_complex::Complex64;

/// The lower triangle (diagonal included) of a symmetric pattern with the given edges.
fn pattern(n: usize, edges: &[(usize, usize)]) -> SymbolicSparseColMat<usize> {
    let mut triplets: Vec<Triplet<usize, usize, f64>> =
        (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
    triplets.extend(
        edges
            .iter()
            .map(|&(a, b)| Triplet::new(a.max(b), a.min(b), 1.0)),
    );
    SparseColMat::try_new_from_triplets(n, n, &triplets)
        .unwrap()
        .symbolic()
        .to_owned()
        .unwrap()
}

/// The edges of a `k x k` grid of squares each split by a diagonal (a triangulated
/// square, every interior vertex of degree 6), vertices numbered row by row.
fn triangulated_grid(k: usize) -> Vec<(usize, usize)> {
    let id = |i: usize, j: usize| i + k * j;
    let mut edges = Vec::new();
    for j in 0..k {
        for i in 0..k {
            if i + 1 < k {
                edges.push((id(i, j), id(i + 1, j)));
            }
            if j + 1 < k {
                edges.push((id(i, j), id(i, j + 1)));
            }
            if i + 1 < k && j + 1 < k {
                edges.push((id(i, j), id(i + 1, j + 1)));
            }
        }
    }
    edges
}

fn assert_permutation(order: &[usize], n: usize) {
    assert_eq!(order.len(), n);
    let mut seen = vec![false; n];
    for &i in order {
        assert!(i < n && !seen[i], "{i} out of range or repeated");
        seen[i] = true;
    }
}

/// Entries of the Cholesky factor of `pattern` eliminated in `order`.
fn factor_entries(pattern: &SymbolicSparseColMat<usize>, order: &[usize]) -> usize {
    let mut inverse = vec![0; order.len()];
    for (k, &i) in order.iter().enumerate() {
        inverse[i] = k;
    }
    let perm = PermRef::new_checked(order, &inverse, order.len());
    factorize_symbolic_cholesky(
        pattern.as_ref(),
        Side::Lower,
        SymmetricOrdering::Custom(perm),
        Default::default(),
    )
    .unwrap()
    .len_val()
}

#[test]
fn nested_dissection_orders_every_vertex_once() {
    // Empty, a single vertex, a long path, a star (no balanced separator), a clique,
    // two grids side by side without an edge between them, and a grid.
    let path: Vec<_> = (0..999).map(|i| (i, i + 1)).collect();
    let star: Vec<_> = (1..2000).map(|i| (0, i)).collect();
    let clique: Vec<_> = (0..300).flat_map(|a| (0..a).map(move |b| (a, b))).collect();
    let mut two_grids = triangulated_grid(40);
    two_grids.extend(
        triangulated_grid(40)
            .iter()
            .map(|&(a, b)| (a + 1600, b + 1600)),
    );
    let cases: [(usize, Vec<(usize, usize)>); 7] = [
        (0, Vec::new()),
        (1, Vec::new()),
        (1000, path),
        (2000, star),
        (300, clique),
        (3200, two_grids),
        (90_000, triangulated_grid(300)),
    ];
    for (n, edges) in cases {
        let order = nested_dissection_order(pattern(n, &edges).as_ref()).unwrap();
        assert_permutation(&order, n);
    }
}

#[test]
fn nested_dissection_beats_amd_on_a_large_regular_mesh() {
    // The triangulated 400 x 400 grid (160K vertices): the factor's entries in nested
    // dissection order against AMD's (measured: 9.78M against 10.35M) and against the
    // bound of a planar mesh's factor, O(n log n) (George 1973), here with the constant
    // 5 (measured: 3.5; the banded row-by-row order has n^(3/2), 4.6x the bound).
    let k = 400;
    let n = k * k;
    let p = pattern(n, &triangulated_grid(k));
    let nd = factor_entries(&p, &nested_dissection_order(p.as_ref()).unwrap());
    let amd = factor_entries(&p, &amd_order(p.as_ref()).unwrap());
    let bound = 5.0 * n as f64 * (n as f64).log2();
    assert!(nd < amd, "nested dissection {nd} entries, AMD {amd}");
    assert!((nd as f64) < bound, "{nd} entries, bound {bound:.0}");
}

#[test]
fn fill_reducing_order_switches_only_on_large_regular_meshes() {
    // Below the size threshold the order is AMD's.
    let small = pattern(10_000, &triangulated_grid(100));
    assert_eq!(
        fill_reducing_order(small.as_ref()).unwrap(),
        amd_order(small.as_ref()).unwrap()
    );
    // Above it, on a regular mesh, nested dissection, whose factor costs few
    // operations for the size (the triangulated 700 x 700 grid: under 16 n^(3/2)
    // multiply-subtracts, so AMD's order is not computed to compare).
    let k = 700;
    let n = k * k;
    assert!(n >= NESTED_DISSECTION_FROM);
    let large = pattern(n, &triangulated_grid(k));
    let nested = nested_dissection_order(large.as_ref()).unwrap();
    let count = factor_count(large.as_ref(), &nested).unwrap();
    assert!(count.multiply_subtracts <= 16.0 * (n as f64).powf(1.5));
    assert_eq!(fill_reducing_order(large.as_ref()).unwrap(), nested);
}

#[test]
fn fill_reducing_order_takes_the_cheaper_order_where_the_dissection_is_costly() {
    // A 47 x 47 x 47 grid of cubes (103,823 vertices, neighbours along the axes): its
    // separators are planes of about n^(2/3) vertices, so the dissection's factor costs
    // far more than 16 n^(3/2) operations; AMD's order is computed too, and the one
    // with fewer operations taken.
    let k = 47;
    let n = k * k * k;
    let id = |i: usize, j: usize, l: usize| i + k * (j + k * l);
    let mut edges = Vec::new();
    for l in 0..k {
        for j in 0..k {
            for i in 0..k {
                if i + 1 < k {
                    edges.push((id(i, j, l), id(i + 1, j, l)));
                }
                if j + 1 < k {
                    edges.push((id(i, j, l), id(i, j + 1, l)));
                }
                if l + 1 < k {
                    edges.push((id(i, j, l), id(i, j, l + 1)));
                }
            }
        }
    }
    let p = pattern(n, &edges);
    let cost = |order: &[usize]| factor_count(p.as_ref(), order).unwrap().multiply_subtracts;
    let nested = cost(&nested_dissection_order(p.as_ref()).unwrap());
    let amd = cost(&amd_order(p.as_ref()).unwrap());
    assert!(nested > 16.0 * (n as f64).powf(1.5), "{nested:e}");
    assert_eq!(
        cost(&fill_reducing_order(p.as_ref()).unwrap()),
        nested.min(amd)
    );
    // A solver analyses the dissection's two sides before counting; their stored
    // factors exceed the bound too, so it makes the same choice by the exact counts:
    // two sides at once in the dissection's order, or AMD's whole.
    let solver = SpdSolver::<f64>::new(p.as_ref(), SolveOptions::default()).unwrap();
    assert_eq!(solver.is_split(), nested <= amd);
}

/// The triangulated `k x k` grid's Laplacian plus `shift` times the identity (lower
/// triangle), and a right-hand side.
fn shifted_grid_laplacian(k: usize, shift: f64) -> (SparseColMat<usize, f64>, Vec<f64>) {
    let n = k * k;
    let mut triplets: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut degree = vec![0.0; n];
    for &(a, b) in &triangulated_grid(k) {
        triplets.push(Triplet::new(a.max(b), a.min(b), -1.0));
        degree[a] += 1.0;
        degree[b] += 1.0;
    }
    triplets.extend((0..n).map(|i| Triplet::new(i, i, degree[i] + shift)));
    let m = SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap();
    let rhs = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
    (m, rhs)
}

/// Factors `m` with `solver`, solves `m x = rhs` and returns its
/// [`relative_residual`].
fn factored_residual(
    solver: &mut SpdSolver<f64>,
    m: &SparseColMat<usize, f64>,
    rhs: &[f64],
) -> f64 {
    let n = rhs.len();
    solver.factorize(m.as_ref()).unwrap();
    let mut x = Mat::from_fn(n, 1, |i, _| rhs[i]);
    solver.solve_in_place(x.as_mut()).unwrap();
    let x: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    relative_residual(m, &x, rhs)
}

/// `max |M x - b|` over `max |b|` for `M` given by its lower triangle.
fn relative_residual(m: &SparseColMat<usize, f64>, x: &[f64], b: &[f64]) -> f64 {
    let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
    for j in 0..m.ncols() {
        for (i, &v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            r[i] += v * x[j];
            if i != j {
                r[j] += v * x[i];
            }
        }
    }
    let scale = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    r.iter().fold(0.0f64, |a, v| a.max(v.abs())) / scale
}

#[test]
fn solves_in_nested_dissection_order_match_amd_order() {
    // The solution does not depend on the order.
    let k = 120;
    let n = k * k;
    let (m, rhs) = shifted_grid_laplacian(k, 0.01);
    let solve = |order: Vec<usize>| {
        let mut solver =
            SpdSolver::with_order(m.symbolic(), &order, SolveOptions::default()).unwrap();
        solver.factorize(m.as_ref()).unwrap();
        let mut x = Mat::from_fn(n, 1, |i, _| rhs[i]);
        solver.solve_in_place(x.as_mut()).unwrap();
        x
    };
    let nd = solve(nested_dissection_order(m.symbolic()).unwrap());
    let amd = solve(amd_order(m.symbolic()).unwrap());
    let scale = amd.norm_max();
    assert!((&nd - &amd).norm_max() < 1e-10 * scale);
}

#[test]
fn a_large_solver_refactors_correctly_in_nested_dissection_order() {
    // The 700 x 700 grid takes nested dissection (test above), whose factor is stored in
    // the block touched while the dissection was computed. Two matrices with one pattern
    // through one solver: both solutions satisfy their systems.
    let k = 700;
    for (round, shift) in [0.01, 1.0].into_iter().enumerate() {
        let (m, rhs) = shifted_grid_laplacian(k, shift);
        let mut solver = SpdSolver::new(m.symbolic(), SolveOptions::default()).unwrap();
        // Taken from the count of the two sides' stored factors, without the exact one.
        assert!(solver.is_split());
        for pass in 0..2 {
            let residual = factored_residual(&mut solver, &m, &rhs);
            assert!(
                residual < 1e-9,
                "round {round}, pass {pass}: residual {residual:e}"
            );
        }
    }
}

#[test]
fn the_first_split_separates_two_balanced_sides_dissected_further() {
    let k = 150;
    let n = k * k;
    let edges = triangulated_grid(k);
    let grid = pattern(n, &edges);
    let split = first_split_order(grid.as_ref()).unwrap();
    assert_permutation(&split.order, n);
    let [a, b] = split.sides.expect("a grid splits");
    let s = n - a - b;
    // Balanced to 52% (the nested dissection's first split), a separator of about one
    // grid line.
    assert!(a.max(b) as f64 <= 0.52 * n as f64, "sides {a}, {b}");
    assert!(s > 0 && s <= 2 * k, "separator {s}");
    let mut side = vec![2u8; n];
    split.order[..a].iter().for_each(|&i| side[i] = 0);
    split.order[a..a + b].iter().for_each(|&i| side[i] = 1);
    for &(p, q) in &edges {
        assert!(
            side[p] == 2 || side[q] == 2 || side[p] == side[q],
            "edge {p}-{q} joins the sides"
        );
    }
    // Inside the sides further separators, not AMD: fewer multiply-subtracts than AMD
    // on the whole grid, and far fewer than AMD inside the same sides.
    let cost = |order: &[usize]| {
        factor_count(grid.as_ref(), order)
            .unwrap()
            .multiply_subtracts
    };
    let amd = cost(&amd_order(grid.as_ref()).unwrap());
    let mut amd_sides = Vec::with_capacity(n);
    for range in [0..a, a..a + b] {
        let rows = &split.order[range];
        let mut local = vec![usize::MAX; n];
        rows.iter().enumerate().for_each(|(k, &i)| local[i] = k);
        let side_edges: Vec<(usize, usize)> = edges
            .iter()
            .filter(|&&(p, q)| local[p] != usize::MAX && local[q] != usize::MAX)
            .map(|&(p, q)| (local[p], local[q]))
            .collect();
        let side = pattern(rows.len(), &side_edges);
        amd_sides.extend(amd_order(side.as_ref()).unwrap().iter().map(|&k| rows[k]));
    }
    amd_sides.extend_from_slice(&split.order[a + b..]);
    let dissected = cost(&split.order);
    let with_amd = cost(&amd_sides);
    // Measured: 3.32e7 against AMD's 3.38e7 on the whole grid and 4.61e7 inside the
    // sides.
    assert!(dissected < amd, "{dissected:e} against AMD's {amd:e}");
    assert!(
        dissected < 0.8 * with_amd,
        "{dissected:e} against {with_amd:e} with AMD in the sides"
    );
}

#[test]
fn a_split_solver_matches_the_whole_factorization() {
    let k = 150;
    let n = k * k;
    let (m, rhs) = shifted_grid_laplacian(k, 0.01);
    let split = first_split_order(m.symbolic()).unwrap();
    let mut two =
        SpdSolver::with_split_order(m.symbolic(), &split, SolveOptions::default()).unwrap();
    assert!(two.is_split());
    let mut whole =
        SpdSolver::with_order(m.symbolic(), &split.order, SolveOptions::default()).unwrap();
    assert!(!whole.is_split());
    let columns = Mat::from_fn(n, 2, |i, c| rhs[i] * (1.0 + c as f64) - c as f64);
    let mut solutions = Vec::new();
    for solver in [&mut two, &mut whole] {
        // Twice, as the flow refactors one pattern.
        for _ in 0..2 {
            solver.factorize(m.as_ref()).unwrap();
        }
        let mut x = columns.clone();
        solver.solve_in_place(x.as_mut()).unwrap();
        solutions.push(x);
    }
    for c in 0..2 {
        let x: Vec<f64> = (0..n).map(|i| solutions[0][(i, c)]).collect();
        let b: Vec<f64> = (0..n).map(|i| columns[(i, c)]).collect();
        let residual = relative_residual(&m, &x, &b);
        assert!(residual < 1e-12, "column {c}: residual {residual:e}");
    }
    let scale = solutions[1].norm_max();
    assert!((&solutions[0] - &solutions[1]).norm_max() < 1e-10 * scale);
    // A split with no second side is factored whole.
    let one_side = beltrami_sparse::SplitOrder {
        order: split.order.clone(),
        sides: Some([n, 0]),
    };
    let solver =
        SpdSolver::<f64>::with_split_order(m.symbolic(), &one_side, SolveOptions::default());
    assert!(!solver.unwrap().is_split());
}

#[test]
fn two_cores_split_where_the_separator_is_small_against_the_factorization() {
    // A square grid: one line of about k vertices separates, against AMD's n^(3/2)
    // growth, so the two sides are factored at once.
    let k = 200;
    let grid = pattern(k * k, &triangulated_grid(k));
    let split = two_core_order(grid.as_ref()).unwrap();
    assert_permutation(&split.order, k * k);
    assert_eq!(split, first_split_order(grid.as_ref()).unwrap());
    // The same grid closed into a torus: a separator takes two loops, whose dense
    // elimination costs more than the second core saves, so AMD's order stays whole.
    let id = |i: usize, j: usize| (i % k) + k * (j % k);
    let torus_edges: Vec<(usize, usize)> = (0..k)
        .flat_map(|j| (0..k).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            [
                (id(i, j), id(i + 1, j)),
                (id(i, j), id(i, j + 1)),
                (id(i, j), id(i + 1, j + 1)),
            ]
        })
        .collect();
    let torus = pattern(k * k, &torus_edges);
    let whole = two_core_order(torus.as_ref()).unwrap();
    assert_eq!(whole.sides, None);
    assert_eq!(whole.order, amd_order(torus.as_ref()).unwrap());
    // Where `fill_reducing_order` takes nested dissection (the 700 x 700 grid of the
    // test above), the sides keep its further separators.
    let k = 700;
    let large = pattern(k * k, &triangulated_grid(k));
    let split = two_core_order(large.as_ref()).unwrap();
    assert!(split.sides.is_some());
    assert_eq!(
        split.order,
        nested_dissection_order(large.as_ref()).unwrap()
    );
}

#[test]
fn a_planned_solver_solves_as_a_fresh_one() {
    // Below and above the nested-dissection size: the plan computed on its own (as on
    // another thread) factors and solves the matrix of its pattern.
    for k in [60, 400] {
        let n = k * k;
        let (m, rhs) = shifted_grid_laplacian(k, 0.01);
        let planned =
            PlannedCholesky::<f64>::new(m.symbolic().to_owned().unwrap(), SolveOptions::default())
                .unwrap();
        assert_eq!(planned.len(), n);
        assert_eq!(planned.pattern().row_idx(), m.symbolic().row_idx());
        let mut solver = SpdSolver::from_planned(planned, SolveOptions::default()).unwrap();
        assert_eq!(solver.is_split(), n >= NESTED_DISSECTION_FROM);
        assert_eq!(solver.pattern().col_ptr(), m.symbolic().col_ptr());
        let residual = factored_residual(&mut solver, &m, &rhs);
        assert!(residual < 1e-9, "k = {k}: residual {residual:e}");
    }
    let empty = SymbolicSparseColMat::new_checked(0, 0, vec![0], None, Vec::new());
    let planned = PlannedCholesky::<f64>::new(empty, SolveOptions::default()).unwrap();
    assert!(planned.is_empty());
    let mut solver = SpdSolver::from_planned(planned, SolveOptions::default()).unwrap();
    solver
        .solve_in_place(Mat::<f64>::zeros(0, 1).as_mut())
        .unwrap();
}

#[test]
fn a_dissection_given_from_outside_is_judged_and_solves() {
    // The 330 x 330 grid (108,900 rows, from the nested-dissection size): its own
    // dissection, given as computed elsewhere, is taken (two sides at once) and solves.
    let k = 330;
    let n = k * k;
    assert!(n >= NESTED_DISSECTION_FROM);
    let (m, rhs) = shifted_grid_laplacian(k, 0.01);
    let split = nested_dissection_split(m.symbolic()).unwrap();
    assert!(split.sides.is_some());
    let pattern = m.symbolic().to_owned().unwrap();
    let planned = PlannedCholesky::<f64>::with_dissection(
        pattern.clone(),
        split.clone(),
        SolveOptions::default(),
    )
    .unwrap();
    let mut solver = SpdSolver::from_planned(planned, SolveOptions::default()).unwrap();
    assert!(solver.is_split());
    let residual = factored_residual(&mut solver, &m, &rhs);
    assert!(residual < 1e-9, "residual {residual:e}");

    // Orders that are not the pattern's are refused.
    let short = SplitOrder {
        order: split.order[1..].to_vec(),
        sides: split.sides,
    };
    assert!(matches!(
        PlannedCholesky::<f64>::with_dissection(pattern.clone(), short, SolveOptions::default()),
        Err(SolveError::Length { .. })
    ));
    let mut repeated = split.clone();
    repeated.order[1] = repeated.order[0];
    assert!(matches!(
        PlannedCholesky::<f64>::with_dissection(pattern.clone(), repeated, SolveOptions::default()),
        Err(SolveError::InvalidOrder { .. })
    ));
    let wide = SplitOrder {
        order: split.order.clone(),
        sides: Some([n, 1]),
    };
    assert!(matches!(
        PlannedCholesky::<f64>::with_dissection(pattern, wide, SolveOptions::default()),
        Err(SolveError::Length { .. })
    ));

    // Below the nested-dissection size the given order is not used: AMD's, whole.
    let (small, _) = shifted_grid_laplacian(60, 0.01);
    let split = nested_dissection_split(small.symbolic()).unwrap();
    let planned = PlannedCholesky::<f64>::with_dissection(
        small.symbolic().to_owned().unwrap(),
        split,
        SolveOptions::default(),
    )
    .unwrap();
    let solver = SpdSolver::from_planned(planned, SolveOptions::default()).unwrap();
    assert!(!solver.is_split());
}

#[test]
fn a_vertex_order_carries_over_to_the_unknowns() {
    // Seven vertices, one unknown each in the complex form, but vertex 2 is fixed and
    // vertices 4 and 6 share one unknown.
    let mut constraints = DofConstraints::new();
    constraints.fix(VertexId::from_usize(2), Complex64::new(1.0, 0.0));
    constraints.share(VertexId::from_usize(4), VertexId::from_usize(6));
    let dofs = DofMap::complex(7, &constraints).unwrap();
    assert_eq!(dofs.reduced_len(), 5);
    let unknown = |v: usize| {
        let mut terms = dofs.node_terms(VertexId::from_usize(v)).unwrap();
        terms.next().map(|(_, t)| t.dof)
    };
    let shared = unknown(4).unwrap();
    assert_eq!(unknown(6), Some(shared));
    // Sides {3, 0, 4} and {1, 2}, separator {5, 6}.
    let vertices = SplitOrder {
        order: vec![3, 0, 4, 1, 2, 5, 6],
        sides: Some([3, 2]),
    };
    let unknowns = order_of_unknowns(&vertices, &dofs).unwrap();
    let own = |v: usize| unknown(v).unwrap();
    assert_eq!(unknowns.order, vec![own(3), own(0), own(1), own(5), shared]);
    assert_eq!(unknowns.sides, Some([2, 1]));
    // Without sides, the shared unknown still goes last.
    let whole = SplitOrder {
        order: vertices.order.clone(),
        sides: None,
    };
    let unknowns = order_of_unknowns(&whole, &dofs).unwrap();
    assert_eq!(unknowns.order.last(), Some(&shared));
    assert_eq!(unknowns.sides, None);
    // An order of another vertex count, or naming a vertex beyond the map's, is refused.
    let short = SplitOrder {
        order: vec![0, 1, 2],
        sides: None,
    };
    assert!(matches!(
        order_of_unknowns(&short, &dofs),
        Err(SolveError::Length { .. })
    ));
    let beyond = SplitOrder {
        order: vec![0, 1, 2, 3, 4, 5, 9],
        sides: None,
    };
    assert!(matches!(
        order_of_unknowns(&beyond, &dofs),
        Err(SolveError::InvalidOrder { index: 6 })
    ));
}

/// The lower triangle of `L (x) I_4 + blockdiag(h h^T)`, `L` the lower triangle `graph`
/// of the `k x k` grid's Laplacian and `h = (x, y, x y, 1)` at each vertex (four
/// independent functions, so that the sum is definite): the shape of the non-rigid
/// ICP's systems.
fn block_system(graph: &SparseColMat<usize, f64>, k: usize) -> SparseColMat<usize, f64> {
    let n = k * k;
    let h = |v: usize| {
        let (x, y) = ((v % k) as f64 / k as f64, (v / k) as f64 / k as f64);
        [x, y, x * y, 1.0]
    };
    let mut triplets = Vec::new();
    for j in 0..n {
        let hj = h(j);
        for (i, &value) in graph.row_idx_of_col(j).zip(graph.val_of_col(j)) {
            for r in 0..4 {
                for c in 0..4 {
                    let laplacian = if r == c { value } else { 0.0 };
                    let data = if i == j { hj[r] * hj[c] } else { 0.0 };
                    if 4 * i + r >= 4 * j + c {
                        triplets.push(Triplet::new(4 * i + r, 4 * j + c, laplacian + data));
                    }
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(4 * n, 4 * n, &triplets).unwrap()
}

/// A vertex graph's split order carried over to four unknowns per vertex (the block
/// systems of the non-rigid ICP: the graph's Laplacian times the 4 x 4 identity plus a
/// rank-one block per vertex) keeps each vertex's unknowns together, the sides four
/// times as long, and factors on two cores to the whole factorization's solution.
#[test]
fn a_vertex_split_carried_to_blocks_factors_the_block_system_in_two_sides() {
    let k = 80;
    let n = k * k;
    let (graph, _) = shifted_grid_laplacian(k, 0.0);
    let split = two_core_order(graph.symbolic()).unwrap();
    let [a, b] = split.sides.expect("the grid splits");
    let blocks = split.in_blocks(4);
    assert_permutation(&blocks.order, 4 * n);
    assert_eq!(blocks.sides, Some([4 * a, 4 * b]));
    for (v, unknowns) in split.order.iter().zip(blocks.order.chunks(4)) {
        assert_eq!(unknowns, [4 * v, 4 * v + 1, 4 * v + 2, 4 * v + 3]);
    }
    let m = block_system(&graph, k);
    let rhs: Vec<f64> = (0..4 * n)
        .map(|i| ((i * 7919) % 101) as f64 - 50.0)
        .collect();
    let mut two =
        SpdSolver::with_split_order(m.symbolic(), &blocks, SolveOptions::default()).unwrap();
    assert!(two.is_split());
    let residual = factored_residual(&mut two, &m, &rhs);
    assert!(residual < 1e-10, "residual {residual:e}");
}
