//! Elements and assembled operators: patch tests, cotangent Laplacian, mass, Poisson
//! convergence rates for P1 and Q1.

use std::f64::consts::PI;

use beltrami_fem::operators::{
    ElementMatrices, apply, complex_derivatives, cotan_laplacian, lumped_mass, real_block_form,
    stiffness_matrix,
};
use beltrami_fem::{Elements, Frame};
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::{Mesh, Point3};
use faer::Side;
use faer::sparse::SparseColMat;
use num_complex::Complex64;

mod common;
use common::{Rng, jittered};

fn dense_mul(m: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; m.nrows()];
    for (c, &xc) in x.iter().enumerate() {
        for (&r, &v) in m.row_idx_of_col_raw(c).iter().zip(m.val_of_col(c)) {
            y[r] += v * xc;
        }
    }
    y
}

#[test]
fn stiffness_annihilates_linear_fields_at_interior_nodes() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(9, cells, 0.3, 7);
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let k = stiffness_matrix(&mesh, &elements).unwrap();
        let field: Vec<f64> = mesh
            .positions()
            .iter()
            .map(|p| 0.3 + 2.0 * p.x - 1.5 * p.y)
            .collect();
        let r = dense_mul(&k, &field);
        for v in mesh.vertices() {
            if !mesh.is_boundary_vertex(v) {
                assert!(r[v.idx()].abs() < 1e-12, "{cells:?} {v}: {}", r[v.idx()]);
            }
        }
        // Constants are in the kernel everywhere.
        let ones = vec![1.0; mesh.vertex_count()];
        assert!(dense_mul(&k, &ones).iter().all(|x| x.abs() < 1e-12));
    }
}

#[test]
fn derivatives_of_linear_and_bilinear_fields_are_exact() {
    // P1 and Q1 on jittered meshes reproduce linear fields; Q1 on a rectangular grid of
    // uneven spacing also reproduces the bilinear field x y.
    let a = Complex64::new(1.3, -0.4);
    let b = Complex64::new(0.2, 0.5);
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(8, cells, 0.3, 11);
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let d = complex_derivatives(&mesh, &elements).unwrap();
        let f: Vec<Complex64> = mesh
            .positions()
            .iter()
            .map(|p| {
                let z = Complex64::new(p.x, p.y);
                a * z + b * z.conj() + 0.7
            })
            .collect();
        for (fz, fzbar) in apply(&d.dz, &f).iter().zip(apply(&d.dzbar, &f)) {
            assert!((fz - a).norm() < 1e-12 && (fzbar - b).norm() < 1e-12);
        }
    }
    let mut soup = grid(6, 5, Cells::Quads);
    for p in &mut soup.positions {
        p.x = p.x * p.x + 0.5 * p.x;
        p.y = 2.0 * p.y + 0.3 * p.y * p.y;
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    let d = complex_derivatives(&mesh, &elements).unwrap();
    let f: Vec<Complex64> = mesh
        .positions()
        .iter()
        .map(|p| Complex64::new(p.x * p.y, 0.0))
        .collect();
    let fz = apply(&d.dz, &f);
    for (q, fz) in elements.points().iter().zip(fz) {
        let x: f64 = elements
            .nodes(q.face)
            .iter()
            .zip(q.shape)
            .map(|(v, s)| s * mesh.position(*v).x)
            .sum();
        let y: f64 = elements
            .nodes(q.face)
            .iter()
            .zip(q.shape)
            .map(|(v, s)| s * mesh.position(*v).y)
            .sum();
        // f = x y: f_x = y, f_y = x, f_z = (y - i x) / 2.
        assert!((fz - Complex64::new(0.5 * y, -0.5 * x)).norm() < 1e-12);
    }
}

#[test]
fn p1_stiffness_is_the_cotangent_laplacian() {
    for soup in [icosphere(2), torus(12, 8, 2.0, 0.7, Cells::Triangles)] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let k = stiffness_matrix(&mesh, &elements).unwrap();
        let l = cotan_laplacian(&mesh).unwrap();
        let mut rng = Rng(3);
        let x: Vec<f64> = (0..mesh.vertex_count()).map(|_| rng.next()).collect();
        let (kx, lx) = (dense_mul(&k, &x), dense_mul(&l, &x));
        for (a, b) in kx.iter().zip(&lx) {
            assert!((a - b).abs() < 1e-12 * (1.0 + a.abs()), "{a} vs {b}");
        }
    }
}

#[test]
fn mass_matrices_integrate_constants_and_linears() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(7, cells, 0.25, 5);
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let m = ElementMatrices::new(mesh.vertex_count(), &elements)
            .unwrap()
            .mass(&elements)
            .unwrap();
        let ones = vec![1.0; mesh.vertex_count()];
        let x: Vec<f64> = mesh.positions().iter().map(|p| p.x).collect();
        let total: f64 = dense_mul(&m, &ones).iter().sum();
        let first_moment: f64 = dense_mul(&m, &x).iter().sum();
        assert!((total - 1.0).abs() < 1e-12, "{cells:?} area {total}");
        assert!(
            (first_moment - 0.5).abs() < 1e-12,
            "{cells:?} {first_moment}"
        );
        let lumped = lumped_mass(&mesh, &elements);
        assert!((lumped.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn real_block_form_matches_complex_multiplication() {
    let mesh = jittered(5, Cells::Quads, 0.2, 9);
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    let d = complex_derivatives(&mesh, &elements).unwrap();
    let real = real_block_form(&d.dzbar).unwrap();
    let mut rng = Rng(1);
    let f: Vec<Complex64> = (0..mesh.vertex_count())
        .map(|_| Complex64::new(rng.next(), rng.next()))
        .collect();
    let interleaved: Vec<f64> = f.iter().flat_map(|z| [z.re, z.im]).collect();
    let y = dense_mul(&real, &interleaved);
    for (k, z) in apply(&d.dzbar, &f).iter().enumerate() {
        assert!((y[2 * k] - z.re).abs() < 1e-14 && (y[2 * k + 1] - z.im).abs() < 1e-14);
    }
}

/// Solves -Lap u = f, u = 0 on the boundary of the unit square, for
/// u = sin(pi x) sin(pi y), and returns (h, L2 error, H1 seminorm error).
fn poisson_error(n: usize, cells: Cells) -> (f64, f64, f64) {
    let mesh = jittered(n, cells, 0.0, 1);
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    let matrices = ElementMatrices::new(mesh.vertex_count(), &elements).unwrap();
    let k = matrices.stiffness(&elements).unwrap();
    let m = matrices.mass(&elements).unwrap();
    let exact = |p: &Point3<f64>| (PI * p.x).sin() * (PI * p.y).sin();
    let source: Vec<f64> = mesh
        .positions()
        .iter()
        .map(|p| 2.0 * PI * PI * exact(p))
        .collect();
    let rhs_full = dense_mul(&m, &source);
    // Eliminate the boundary (u = 0 there): keep interior rows and columns.
    let interior: Vec<usize> = mesh
        .vertices()
        .filter(|&v| !mesh.is_boundary_vertex(v))
        .map(|v| v.idx())
        .collect();
    let mut slot = vec![usize::MAX; mesh.vertex_count()];
    for (i, &v) in interior.iter().enumerate() {
        slot[v] = i;
    }
    let mut triplets = Vec::new();
    for c in 0..k.ncols() {
        for (&r, &v) in k.row_idx_of_col_raw(c).iter().zip(k.val_of_col(c)) {
            if slot[r] != usize::MAX && slot[c] != usize::MAX {
                triplets.push(faer::sparse::Triplet::new(slot[r], slot[c], v));
            }
        }
    }
    let kii = SparseColMat::<usize, f64>::try_new_from_triplets(
        interior.len(),
        interior.len(),
        &triplets,
    )
    .unwrap();
    let llt = kii.sp_cholesky(Side::Lower).unwrap();
    let mut rhs = faer::Mat::<f64>::zeros(interior.len(), 1);
    for (i, &v) in interior.iter().enumerate() {
        rhs[(i, 0)] = rhs_full[v];
    }
    use faer::prelude::Solve;
    let sol = llt.solve(&rhs);
    let mut u = vec![0.0; mesh.vertex_count()];
    for (i, &v) in interior.iter().enumerate() {
        u[v] = sol[(i, 0)];
    }
    // Errors: the 3-point edge-midpoint rule on triangles (exact for quadratics), 3x3
    // Gauss on the square cells of the quad grid.
    let (mut l2, mut h1) = (0.0, 0.0);
    for f in mesh.faces() {
        let nodes = elements.nodes(f);
        let p: Vec<Point3<f64>> = nodes.iter().map(|&v| mesh.position(v)).collect();
        let vals: Vec<f64> = nodes.iter().map(|&v| u[v.idx()]).collect();
        let q = &elements.face_points(f)[0];
        if nodes.len() == 3 {
            let area = q.weight;
            let grad: nalgebra::Vector2<f64> = (0..3)
                .map(|k| q.grad[k] * vals[k])
                .sum::<nalgebra::Vector2<f64>>();
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let x = Point3::from((p[a].coords + p[b].coords) / 2.0);
                let uh = (vals[a] + vals[b]) / 2.0;
                let ex_grad = nalgebra::Vector2::new(
                    PI * (PI * x.x).cos() * (PI * x.y).sin(),
                    PI * (PI * x.x).sin() * (PI * x.y).cos(),
                );
                l2 += area / 3.0 * (uh - exact(&x)).powi(2);
                h1 += area / 3.0 * (grad - ex_grad).norm_squared();
            }
        } else {
            // Axis-aligned square cells: 3x3 Gauss on the bilinear interpolant.
            let g = [
                (0.5 - 0.5 * (0.6f64).sqrt(), 5.0 / 18.0),
                (0.5, 8.0 / 18.0),
                (0.5 + 0.5 * (0.6f64).sqrt(), 5.0 / 18.0),
            ];
            let (hx, hy) = (p[1].x - p[0].x, p[3].y - p[0].y);
            for &(s, ws) in &g {
                for &(t, wt) in &g {
                    let w = ws * wt * hx * hy;
                    let x = Point3::new(p[0].x + s * hx, p[0].y + t * hy, 0.0);
                    let n = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
                    let uh: f64 = (0..4).map(|k| n[k] * vals[k]).sum();
                    let dx = ((1.0 - t) * (vals[1] - vals[0]) + t * (vals[2] - vals[3])) / hx;
                    let dy = ((1.0 - s) * (vals[3] - vals[0]) + s * (vals[2] - vals[1])) / hy;
                    let ex_grad = nalgebra::Vector2::new(
                        PI * (PI * x.x).cos() * (PI * x.y).sin(),
                        PI * (PI * x.x).sin() * (PI * x.y).cos(),
                    );
                    l2 += w * (uh - exact(&x)).powi(2);
                    h1 += w * (nalgebra::Vector2::new(dx, dy) - ex_grad).norm_squared();
                }
            }
        }
    }
    (1.0 / n as f64, l2.sqrt(), h1.sqrt())
}

#[test]
fn poisson_converges_at_the_expected_rates() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let runs: Vec<(f64, f64, f64)> = [8, 16, 32, 64]
            .iter()
            .map(|&n| poisson_error(n, cells))
            .collect();
        println!("{cells:?}: h, L2 error, rate, H1 error, rate");
        for w in runs.windows(2) {
            let (h0, l0, g0) = w[0];
            let (h1, l1, g1) = w[1];
            let (rl, rg) = (
                (l0 / l1).ln() / (h0 / h1).ln(),
                (g0 / g1).ln() / (h0 / h1).ln(),
            );
            println!("  {h1:.5}  {l1:.3e}  {rl:.2}  {g1:.3e}  {rg:.2}");
            assert!(rl > 1.9 && rl < 2.2, "{cells:?} L2 rate {rl}");
            assert!(rg > 0.95 && rg < 1.2, "{cells:?} H1 rate {rg}");
        }
    }
}

#[test]
fn global_frame_needs_a_mesh_in_the_plane() {
    let sphere = Mesh::from_soup(&icosphere(1)).unwrap();
    match Elements::new(&sphere, Frame::Global) {
        Err(beltrami_fem::FemError::NotPlanar { z, .. }) => assert!(z.abs() > 0.1),
        other => panic!("unexpected {other:?}"),
    }
    let flat = Mesh::from_soup(&grid(2, 2, Cells::Quads)).unwrap();
    assert_eq!(
        Elements::new(&flat, Frame::Global).unwrap().point_count(),
        16
    );
}

#[test]
fn the_metric_gives_the_area_element_of_the_patch() {
    // Each point's frame spans the patch's tangent plane there (for planar meshes in the
    // global frame, the plane itself), so |det J| = |X_1 x X_2| = sqrt(det g) and the
    // weight is sqrt(det g) times the reference weight, non-planar quads included.
    let soup = beltrami_mesh::primitives::torus(10, 6, 2.0, 0.7, Cells::Quads);
    let torus = Mesh::from_soup(&soup).unwrap();
    for (mesh, frame) in [
        (jittered(5, Cells::Triangles, 0.3, 4), Frame::Global),
        (jittered(5, Cells::Quads, 0.3, 4), Frame::Face),
        (torus, Frame::Face),
    ] {
        let elements = Elements::new(&mesh, frame).unwrap();
        for q in elements.points() {
            let g = q.metric;
            assert!((g[0][1] - g[1][0]).abs() == 0.0);
            let area_element = (g[0][0] * g[1][1] - g[0][1] * g[1][0]).sqrt();
            let reference_weight = if elements.nodes(q.face).len() == 3 {
                0.5
            } else {
                0.25
            };
            assert!(
                (area_element * reference_weight - q.weight).abs() < 1e-12 * (1.0 + q.weight),
                "face {}: {} vs {}",
                q.face,
                area_element * reference_weight,
                q.weight
            );
        }
    }
}
