//! Tests of the general DOF map (`dof::DofBuilder`): nodes with values in R^2, R^3 or C,
//! per-node bases (fixed, line, plane, free, a basis of their own) and unknowns shared
//! between nodes along different directions. Patch tests of `expand` and `reduce` on
//! each kind of node, the structure of `K`, refilled directions, constrained least
//! squares with known solutions, and typed errors.

use beltrami_fem::LeastSquaresSolver;
use beltrami_fem::dof::{DofBuilder, DofError, DofMap, NodeDof};
use beltrami_mesh::VertexId;
use beltrami_sparse::SolveOptions;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, MatRef};
use num_complex::Complex64;

mod common;
use common::Rng;

fn v(i: u32) -> VertexId {
    VertexId(i)
}

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

fn node(x: &[f64], i: usize) -> V3 {
    [x[3 * i], x[3 * i + 1], x[3 * i + 2]]
}

/// The kinds of spatial nodes of [`spatial_map`], their origins and directions.
const P0: V3 = [1.0, -2.0, 0.5]; // node 0: fixed
const P1: V3 = [0.0, 1.0, 2.0]; // node 1: on the line P1 + t D1
const D1: V3 = [1.0, 2.0, -2.0];
const P2: V3 = [-1.0, 0.0, 3.0]; // node 2: in the plane P2 + a U2 + b W2
const U2: V3 = [1.0, 0.0, 1.0];
const W2: V3 = [0.5, 1.0, 0.0];
// node 3: free (the axes); node 4: free in a basis of its own.
const B4: [V3; 3] = [[1.0, 1.0, 0.0], [0.0, 1.0, 1.0], [1.0, 0.0, 2.0]];
const P5: V3 = [2.0, 2.0, 2.0]; // nodes 5 and 6: an offset shared along S5 and S6,
const S5: V3 = [0.0, 0.0, 1.0]; // node 5 otherwise fixed,
const P6: V3 = [3.0, -1.0, 0.0]; // node 6 also on the line P6 + t D6
const S6: V3 = [0.6, 0.8, 0.0];
const D6: V3 = [0.0, 0.0, 1.0];

/// Seven spatial nodes, one of each kind (constants above), with the unknowns declared
/// in the order 3 (free: 0, 1, 2), 1 (line: 3), 2 (plane: 4, 5), 4 (basis: 6, 7, 8),
/// 6 (line: 9), shared offset of 5 and 6 (10).
fn spatial_map() -> DofMap<f64> {
    let mut b = DofBuilder::<f64>::new(7, 3).unwrap();
    b.origin(v(0), &P0).unwrap();
    assert_eq!(b.free(&[v(3)]).unwrap(), 0..3);
    assert_eq!(b.span(v(1), &P1, [D1]).unwrap(), 3..4);
    assert_eq!(b.span(v(2), &P2, [U2, W2]).unwrap(), 4..6);
    assert_eq!(b.span(v(4), &[0.0; 3], B4).unwrap(), 6..9);
    assert_eq!(b.span(v(6), &P6, [D6]).unwrap(), 9..10);
    b.origin(v(5), &P5).unwrap();
    assert_eq!(b.unknown([(v(5), S5), (v(6), S6)]).unwrap(), 10);
    assert_eq!(b.unknowns(), 11);
    b.build().unwrap()
}

/// The value of every node of [`spatial_map`] for `y`, by the formulas of each kind.
fn spatial_values(y: &[f64]) -> Vec<V3> {
    vec![
        P0,
        add(P1, scale(y[3], D1)),
        add(P2, add(scale(y[4], U2), scale(y[5], W2))),
        [y[0], y[1], y[2]],
        add(
            scale(y[6], B4[0]),
            add(scale(y[7], B4[1]), scale(y[8], B4[2])),
        ),
        add(P5, scale(y[10], S5)),
        add(P6, add(scale(y[9], D6), scale(y[10], S6))),
    ]
}

fn random(rng: &mut Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.uniform()).collect()
}

#[test]
fn expand_gives_each_kind_of_node_its_value() {
    let dofs = spatial_map();
    assert_eq!(
        (
            dofs.n_nodes(),
            dofs.dim(),
            dofs.full_len(),
            dofs.reduced_len()
        ),
        (7, 3, 21, 11)
    );
    let mut rng = Rng(31);
    let y = random(&mut rng, 11);
    let x = dofs.expand(&y).unwrap();
    for (i, expected) in spatial_values(&y).into_iter().enumerate() {
        let got = node(&x, i);
        assert!(
            norm(sub(got, expected)) < 1e-14,
            "node {i}: {got:?} != {expected:?}"
        );
    }
    // x = K y + x0 with the sparse K.
    let ky = dofs.k() * MatRef::from_column_major_slice(&y, y.len(), 1);
    for (l, &xl) in x.iter().enumerate() {
        assert!((ky[(l, 0)] + dofs.x0()[l] - xl).abs() < 1e-14);
    }
    // Expanding into a buffer gives the same, and checks lengths.
    let mut into = vec![0.0; 21];
    dofs.expand_into(&y, &mut into).unwrap();
    assert_eq!(into, x);
    assert_eq!(
        dofs.expand_into(&y, &mut into[..20]).unwrap_err(),
        DofError::Length {
            what: "x",
            expected: 21,
            got: 20
        }
    );
}

#[test]
fn k_stores_every_component_of_a_direction_and_one_per_axis() {
    let dofs = spatial_map();
    let k = dofs.k();
    // The free node's axes: one entry each, at its rows 9, 10, 11.
    for c in 0..3 {
        assert_eq!(k.row_idx_of_col_raw(c), &[9 + c]);
        assert_eq!(k.val_of_col(c), &[1.0]);
    }
    // The line of node 1: rows 3..6 = D1.
    assert_eq!(k.row_idx_of_col_raw(3), &[3, 4, 5]);
    assert_eq!(k.val_of_col(3), &D1);
    // The shared offset: S5 in rows 15..18 (node 5), S6 in rows 18..21 (node 6), the
    // explicit zero of S6 included.
    assert_eq!(k.row_idx_of_col_raw(10), &[15, 16, 17, 18, 19, 20]);
    assert_eq!(k.val_of_col(10), &[0.0, 0.0, 1.0, 0.6, 0.8, 0.0]);
    // Node 6's rows have two entries (its line and the offset); node 0's none.
    let rows_with = |row: usize| (0..11).filter(move |&j| k.row_idx_of_col_raw(j).contains(&row));
    assert_eq!(rows_with(20).collect::<Vec<_>>(), vec![9, 10]);
    assert_eq!(rows_with(0).count(), 0);
    // Terms node by node, in increasing order of their unknowns.
    let terms: Vec<Vec<usize>> = (0..7)
        .map(|i| {
            dofs.terms(v(i))
                .unwrap()
                .map(|t| dofs.term(t).unwrap().dof)
                .collect()
        })
        .collect();
    assert_eq!(
        terms,
        vec![
            vec![],
            vec![3],
            vec![4, 5],
            vec![0, 1, 2],
            vec![6, 7, 8],
            vec![10],
            vec![9, 10]
        ]
    );
    let t = dofs.terms(v(6)).unwrap().start + 1;
    assert_eq!(dofs.term(t).unwrap().direction, &S6);
    assert_eq!(&dofs.directions()[3 * t..3 * t + 3], &S6);
    assert!(dofs.term(1000).is_none());
    let node6: Vec<(usize, usize)> = dofs
        .node_terms(v(6))
        .unwrap()
        .map(|(t, term)| (t, term.dof))
        .collect();
    assert_eq!(node6, vec![(t - 1, 9), (t, 10)]);
    // The nodes of each unknown, and the smallest one.
    let nodes: Vec<VertexId> = dofs.unknown_nodes(10).unwrap().collect();
    assert_eq!(nodes, vec![v(5), v(6)]);
    assert_eq!(dofs.unknown_nodes(4).unwrap().count(), 1);
    assert!(dofs.unknown_nodes(11).is_none());
    assert_eq!(dofs.dof_node(10), Some(v(5)));
    assert_eq!(dofs.dof_node(0), Some(v(3)));
    assert_eq!(dofs.origin(v(2)).unwrap(), &P2);
    // Spatial nodes are not planar NodeDofs, nor complex positions.
    assert_eq!(
        dofs.node_dof(v(3)).unwrap_err(),
        DofError::GeneralNode { node: v(3) }
    );
    assert_eq!(
        dofs.positions(&[0.0; 21]).unwrap_err(),
        DofError::NotPlanar { dim: 3 }
    );
}

#[test]
fn reduce_inverts_expand_on_every_kind_of_node() {
    let dofs = spatial_map();
    let mut rng = Rng(32);
    for _ in 0..5 {
        let y = random(&mut rng, 11);
        let x = dofs.expand(&y).unwrap();
        let back = dofs.reduce(&x).unwrap();
        for (a, b) in y.iter().zip(&back) {
            assert!((a - b).abs() < 1e-13, "{a} != {b}");
        }
    }
}

/// Off the admissible set, `reduce` is the least-squares projection: the residual
/// `x - expand(reduce(x))` is orthogonal to every column of `K` (`K^T r = 0`), and
/// each kind of node gets its nearest admissible value.
#[test]
fn reduce_projects_onto_the_admissible_set() {
    let dofs = spatial_map();
    let mut rng = Rng(33);
    let x: Vec<f64> = random(&mut rng, 21).iter().map(|r| 3.0 * r).collect();
    let y = dofs.reduce(&x).unwrap();
    let projected = dofs.expand(&y).unwrap();
    let r: Vec<f64> = x.iter().zip(&projected).map(|(a, b)| a - b).collect();
    let kt_r = dofs.k().transpose() * MatRef::from_column_major_slice(&r, 21, 1);
    for j in 0..11 {
        assert!(
            kt_r[(j, 0)].abs() < 1e-13,
            "K^T r at {j}: {:e}",
            kt_r[(j, 0)]
        );
    }
    // A line: the foot of the perpendicular; a plane: the orthogonal projection; a
    // free node keeps its value; a fixed node its origin.
    let foot = add(P1, scale(dot(sub(node(&x, 1), P1), D1) / dot(D1, D1), D1));
    assert!(norm(sub(node(&projected, 1), foot)) < 1e-14);
    let n2 = cross(U2, W2);
    let q = node(&x, 2);
    let in_plane = sub(q, scale(dot(sub(q, P2), n2) / dot(n2, n2), n2));
    assert!(norm(sub(node(&projected, 2), in_plane)) < 1e-14);
    assert_eq!(node(&projected, 3), node(&x, 3));
    assert!(norm(sub(node(&projected, 4), node(&x, 4))) < 1e-14);
    assert_eq!(node(&projected, 0), P0);
}

/// The complex form with a rotated share (`x_b = x0_b + e^{i theta} y`, a seam whose
/// copies differ by a rotation and a period) and a free node: expand, reduce, and the
/// planar vocabulary of `node_dof` where it applies.
#[test]
fn complex_nodes_share_an_unknown_along_rotated_directions() {
    let c = Complex64::new;
    let rotation = Complex64::from_polar(1.0, 0.7);
    let period = c(2.0, 0.0);
    let mut b = DofBuilder::<Complex64>::new(3, 1).unwrap();
    assert_eq!(b.free(&[v(1)]).unwrap(), 0..1);
    b.origin(v(2), &[period]).unwrap();
    assert_eq!(
        b.unknown([(v(0), [c(1.0, 0.0)]), (v(2), [rotation])])
            .unwrap(),
        1
    );
    let dofs = b.build().unwrap();
    let y = [c(0.3, -0.2), c(1.5, 0.5)];
    let x = dofs.expand(&y).unwrap();
    assert_eq!(x[0], y[1]);
    assert_eq!(x[1], y[0]);
    assert!((x[2] - (period + rotation * y[1])).norm() < 1e-15);
    let back = dofs.reduce(&x).unwrap();
    for (a, b) in y.iter().zip(&back) {
        assert!((a - b).norm() < 1e-15);
    }
    assert_eq!(dofs.node_dof(v(1)).unwrap(), NodeDof::Free { dof: 0 });
    assert_eq!(
        dofs.node_dof(v(2)).unwrap_err(),
        DofError::GeneralNode { node: v(2) }
    );
    assert_eq!(dofs.node_position(&x, v(2)).unwrap(), x[2]);
}

/// A planar real map stated with the general builder reads back in the vocabulary of
/// `DofConstraints`: fixed, free, sliding; a node with a shared offset as well is
/// general.
#[test]
fn planar_builder_nodes_read_as_node_dofs() {
    let mut b = DofBuilder::<f64>::new(4, 2).unwrap();
    b.origin(v(0), &[1.0, 2.0]).unwrap();
    b.free(&[v(1)]).unwrap();
    b.span(v(2), &[0.5, 0.0], [[0.0, 1.0]]).unwrap();
    b.span(v(3), &[0.0, 0.0], [[1.0, 0.0]]).unwrap();
    b.unknown([(v(3), [0.0, 1.0])]).unwrap();
    let dofs = b.build().unwrap();
    assert_eq!(
        dofs.node_dof(v(0)).unwrap(),
        NodeDof::Fixed {
            value: Complex64::new(1.0, 2.0)
        }
    );
    assert_eq!(dofs.node_dof(v(1)).unwrap(), NodeDof::Free { dof: 0 });
    assert_eq!(
        dofs.node_dof(v(2)).unwrap(),
        NodeDof::Sliding {
            dof: 2,
            point: Complex64::new(0.5, 0.0),
            direction: Complex64::new(0.0, 1.0)
        }
    );
    assert_eq!(
        dofs.node_dof(v(3)).unwrap_err(),
        DofError::GeneralNode { node: v(3) }
    );
}

#[test]
fn refilled_directions_and_origins_change_k_and_expand_not_the_pattern() {
    let mut dofs = spatial_map();
    let pattern = dofs.k().symbolic().row_idx().to_vec();
    let y: Vec<f64> = (0..11).map(|j| 0.1 * (j as f64 + 1.0)).collect();
    // Turn node 2's plane: new directions, and a new origin.
    let (u, w): (V3, V3) = ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let terms = dofs.terms(v(2)).unwrap();
    dofs.set_direction(terms.start, &u).unwrap();
    dofs.set_direction(terms.start + 1, &w).unwrap();
    dofs.set_origin(v(2), &[5.0, 0.0, 0.0]).unwrap();
    // Node 6's share of the offset vanishes (an offset direction that does not exist
    // at this point): allowed, zero is refilled like any value.
    let t6 = dofs.terms(v(6)).unwrap().start + 1;
    dofs.set_direction(t6, &[0.0; 3]).unwrap();
    let x = dofs.expand(&y).unwrap();
    let expected = add([5.0, 0.0, 0.0], add(scale(y[4], u), scale(y[5], w)));
    assert!(norm(sub(node(&x, 2), expected)) < 1e-15);
    assert!(norm(sub(node(&x, 6), add(P6, scale(y[9], D6)))) < 1e-15);
    assert_eq!(dofs.k().symbolic().row_idx(), &pattern[..]);
    let ky = dofs.k() * MatRef::from_column_major_slice(&y, 11, 1);
    for (l, &xl) in x.iter().enumerate() {
        assert!((ky[(l, 0)] + dofs.x0()[l] - xl).abs() < 1e-15);
    }
    assert_eq!(dofs.term(terms.start).unwrap().direction, &u);

    // A line refilled to a zero direction: reduce reports the rank deficiency.
    let mut line = DofBuilder::<f64>::new(2, 2).unwrap();
    line.free(&[v(0)]).unwrap();
    line.span(v(1), &[0.0; 2], [[1.0, 0.0]]).unwrap();
    let mut line = line.build().unwrap();
    assert!(line.reduce(&[1.0; 4]).is_ok());
    line.set_direction(2, &[0.0; 2]).unwrap();
    assert!(matches!(line.reduce(&[1.0; 4]), Err(DofError::Reduce(_))));

    // Errors: a free node's axis, a term out of range, wrong components, NaN.
    let axis = dofs.terms(v(3)).unwrap().start;
    assert_eq!(
        dofs.set_direction(axis, &u).unwrap_err(),
        DofError::AxisDirection { node: v(3), dof: 0 }
    );
    assert_eq!(
        dofs.set_direction(99, &u).unwrap_err(),
        DofError::TermOutOfRange {
            term: 99,
            terms: 12
        }
    );
    assert_eq!(
        dofs.set_direction(terms.start, &[1.0, 0.0]).unwrap_err(),
        DofError::Components {
            node: v(2),
            what: "direction",
            expected: 3,
            got: 2
        }
    );
    assert_eq!(
        dofs.set_origin(v(1), &[f64::NAN, 0.0, 0.0]).unwrap_err(),
        DofError::NonFinite {
            node: v(1),
            what: "origin"
        }
    );
}

/// A dense `m x ncols` matrix with random entries, as sparse.
fn random_matrix(rng: &mut Rng, m: usize, ncols: usize) -> SparseColMat<usize, f64> {
    let triplets: Vec<_> = (0..m)
        .flat_map(|i| (0..ncols).map(move |j| (i, j)))
        .map(|(i, j)| Triplet::new(i, j, rng.uniform()))
        .collect();
    SparseColMat::try_new_from_triplets(m, ncols, &triplets).unwrap()
}

/// `b = A x*` with `x* = K y* + x0` admissible: the constrained minimizer is `x*` itself
/// (zero residual), whatever the weights.
#[test]
fn least_squares_recovers_an_admissible_solution() {
    let dofs = spatial_map();
    let mut rng = Rng(34);
    let a = random_matrix(&mut rng, 30, 21);
    let y_star = random(&mut rng, 11);
    let x_star = dofs.expand(&y_star).unwrap();
    let b_mat = a.as_ref() * MatRef::from_column_major_slice(&x_star, 21, 1);
    let b: Vec<f64> = (0..30).map(|i| b_mat[(i, 0)]).collect();
    let w: Vec<f64> = (0..30).map(|_| 0.5 + rng.next()).collect();
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), Some(&w), &b).unwrap();
    for (got, expected) in x.iter().zip(&x_star) {
        assert!((got - expected).abs() < 1e-11, "{got} != {expected}");
    }
}

/// `min sum_i |x_i - q_i|^2` over the admissible set: each node's nearest admissible
/// value, and for the shared offset of nodes 5 and 6 (node 6 also on its line)
/// the closed form of the 2 x 2 normal equations.
#[test]
fn least_squares_projection_has_the_closed_form() {
    let dofs = spatial_map();
    let mut rng = Rng(35);
    let q: Vec<f64> = random(&mut rng, 21);
    let eye: Vec<_> = (0..21).map(|l| Triplet::new(l, l, 1.0)).collect();
    let a = SparseColMat::try_new_from_triplets(21, 21, &eye).unwrap();
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), None, &q).unwrap();
    // Fixed, line, plane, free, own basis.
    assert_eq!(node(&x, 0), P0);
    let t = dot(sub(node(&q, 1), P1), D1) / dot(D1, D1);
    assert!(norm(sub(node(&x, 1), add(P1, scale(t, D1)))) < 1e-14);
    let n2 = cross(U2, W2);
    let q2 = node(&q, 2);
    let in_plane = sub(q2, scale(dot(sub(q2, P2), n2) / dot(n2, n2), n2));
    assert!(norm(sub(node(&x, 2), in_plane)) < 1e-14);
    assert!(norm(sub(node(&x, 3), node(&q, 3))) < 1e-14);
    assert!(norm(sub(node(&x, 4), node(&q, 4))) < 1e-14);
    // Nodes 5, 6: unknowns (t, s) with x5 = P5 + s S5, x6 = P6 + t D6 + s S6;
    // normal equations [[D6.D6, D6.S6], [D6.S6, S5.S5 + S6.S6]] (t, s) = rhs.
    let (r5, r6) = (sub(node(&q, 5), P5), sub(node(&q, 6), P6));
    let m = [
        [dot(D6, D6), dot(D6, S6)],
        [dot(D6, S6), dot(S5, S5) + dot(S6, S6)],
    ];
    let rhs = [dot(D6, r6), dot(S5, r5) + dot(S6, r6)];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let t = (rhs[0] * m[1][1] - m[0][1] * rhs[1]) / det;
    let s = (m[0][0] * rhs[1] - m[1][0] * rhs[0]) / det;
    assert!(norm(sub(node(&x, 5), add(P5, scale(s, S5)))) < 1e-14);
    assert!(norm(sub(node(&x, 6), add(P6, add(scale(t, D6), scale(s, S6))))) < 1e-14);
}

/// With a residual left (a random overdetermined problem), the sliding node stays on
/// its line and the plane node in its plane, exactly, after moving.
#[test]
fn a_solve_keeps_lines_and_planes() {
    let dofs = spatial_map();
    let mut rng = Rng(36);
    let a = random_matrix(&mut rng, 40, 21);
    let b = random(&mut rng, 40);
    let mut solver = LeastSquaresSolver::new(a.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let x = solver.solve(a.as_ref(), None, &b).unwrap();
    let on_line = sub(node(&x, 1), P1);
    let off_line = norm(cross(on_line, D1)) / norm(D1);
    assert!(off_line < 1e-13, "distance from the line {off_line:e}");
    assert!(norm(on_line) > 1e-3, "the node did not move: {on_line:?}");
    let n2 = cross(U2, W2);
    let in_plane = sub(node(&x, 2), P2);
    let off_plane = dot(in_plane, n2).abs() / norm(n2);
    assert!(off_plane < 1e-13, "distance from the plane {off_plane:e}");
    assert!(norm(in_plane) > 1e-3, "the node did not move: {in_plane:?}");
    // Node 5 moves along S5 only (by the offset), node 0 not at all.
    let moved5 = sub(node(&x, 5), P5);
    assert!(norm(cross(moved5, S5)) < 1e-13 && norm(moved5) > 1e-3);
    assert_eq!(node(&x, 0), P0);
    // Optimality: K^T A^T (A x - b) = 0.
    let r = a.as_ref() * MatRef::from_column_major_slice(&x, 21, 1);
    let r = Mat::<f64>::from_fn(40, 1, |i, _| r[(i, 0)] - b[i]);
    let g = dofs.k().transpose() * (a.as_ref().transpose() * r.as_ref());
    for j in 0..11 {
        assert!(g[(j, 0)].abs() < 1e-11, "reduced gradient {:e}", g[(j, 0)]);
    }
}

#[test]
fn bad_statements_give_typed_errors_and_leave_the_builder_unchanged() {
    assert_eq!(
        DofBuilder::<f64>::new(3, 0).unwrap_err(),
        DofError::ZeroDimension
    );
    let mut b = DofBuilder::<f64>::new(3, 3).unwrap();
    assert_eq!(
        b.origin(v(3), &[0.0; 3]).unwrap_err(),
        DofError::NodeOutOfRange {
            node: v(3),
            n_nodes: 3
        }
    );
    assert_eq!(
        b.origin(v(0), &[0.0; 2]).unwrap_err(),
        DofError::Components {
            node: v(0),
            what: "origin",
            expected: 3,
            got: 2
        }
    );
    // A failed span declares nothing and keeps the origin.
    assert_eq!(
        b.span(
            v(1),
            &[1.0; 3],
            [[1.0, 0.0, 0.0], [f64::INFINITY, 0.0, 0.0]]
        )
        .unwrap_err(),
        DofError::NonFinite {
            node: v(1),
            what: "direction"
        }
    );
    assert_eq!(b.unknowns(), 0);
    assert_eq!(
        b.unknown(Vec::<(VertexId, V3)>::new()).unwrap_err(),
        DofError::NoNodes { dof: 0 }
    );
    assert_eq!(
        b.unknown([(v(1), [1.0, 0.0, 0.0]), (v(1), [0.0, 1.0, 0.0])])
            .unwrap_err(),
        DofError::RepeatedNode { node: v(1), dof: 0 }
    );
    assert_eq!(
        b.free(&[v(0), v(2), v(0)]).unwrap_err(),
        DofError::RepeatedNode { node: v(0), dof: 0 }
    );
    assert_eq!(b.unknowns(), 0);
    let map = b.build().unwrap();
    assert_eq!(map.reduced_len(), 0);
    assert_eq!(map.x0(), &[0.0; 9]);

    // Dependent directions at a node: parallel ones, a direction in the span of a
    // node's plane (shared), a zero one, more directions than components.
    let dependent = |b: DofBuilder<f64>, node: u32| {
        assert_eq!(
            b.build().unwrap_err(),
            DofError::DependentDirections { node: v(node) }
        );
    };
    let mut b = DofBuilder::<f64>::new(3, 3).unwrap();
    b.span(v(2), &[0.0; 3], [[1.0, 2.0, 3.0], [-2.0, -4.0, -6.0]])
        .unwrap();
    dependent(b, 2);
    let mut b = DofBuilder::<f64>::new(3, 3).unwrap();
    b.span(v(1), &[0.0; 3], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        .unwrap();
    b.unknown([(v(0), [0.0, 0.0, 1.0]), (v(1), [1.0, 1.0, 0.0])])
        .unwrap();
    dependent(b, 1);
    let mut b = DofBuilder::<f64>::new(3, 3).unwrap();
    b.unknown([(v(0), [0.0; 3])]).unwrap();
    dependent(b, 0);
    let mut b = DofBuilder::<f64>::new(1, 2).unwrap();
    b.free(&[v(0)]).unwrap();
    b.unknown([(v(0), [1.0, 1.0])]).unwrap();
    dependent(b, 0);
}
