//! Wong-Zhao 2014, section 5: Tables 5.1-5.3 and Fig. 5.9 reproduced.
//!
//! What the paper's columns measure: [`beltrami_flow::paper`]. Our tables next to the
//! paper's are in `docs/flow.md` (`beltrami bench flow` prints them).

mod common;

use beltrami_core::OptionValue;
use beltrami_core::{PlanarBoundary, Problem, Target};
use beltrami_fem::{BeltramiField, Frame};
use beltrami_flow::paper::*;
use beltrami_flow::stereographic::{self, inverse_stereographic, stereographic};
use beltrami_mesh::{Mesh, Point3, primitives};
use common::*;
use num_complex::Complex64;

#[test]
fn table_5_1_disk_with_mu_0_6_z() {
    let mut rows = Vec::new();
    for &DiskRow {
        level,
        faces,
        steps: paper_steps,
        sup: paper_sup,
        ..
    } in &TABLE_5_1
    {
        let mesh = Mesh::from_soup(&primitives::disk(level)).unwrap();
        assert_eq!(mesh.face_count(), faces);
        let sigma = sample(&mesh, |z| 0.6 * z);
        let mut problem = Problem::new(&mesh, Target::Disk);
        problem.goal =
            beltrami_core::Goal::Prescribed(BeltramiField::new(Frame::Global, sigma.clone()));
        // Vertex 0 is the centre, vertex 1 the point 1.
        problem.constraints = pins(&[0, 1]).into();
        problem.options.set("tolerance", OptionValue::Float(1e-8));
        let solution = flow(&problem);
        let error = mu_error(&mesh, &solution, &sigma, Frame::Global);
        let z = planar(&solution);
        println!(
            "level {level}: {faces} faces, {} steps (paper {paper_steps}), sup {:.4} (paper {paper_sup}), L2^2 {:.3e}, RMS {:.3e}",
            solution.metrics.iterations, error.sup, error.l2_squared, error.rms
        );
        assert_eq!(solution.metrics.flipped(), Some(0), "level {level}");
        assert!(
            solution
                .report
                .notes
                .iter()
                .any(|n| n.starts_with("converged")),
            "level {level}: {:?}",
            solution.report.notes
        );
        assert!(
            error.sup <= paper_sup + 1e-4,
            "level {level}: sup {}",
            error.sup
        );
        assert!(
            solution.metrics.iterations <= paper_steps + 3,
            "level {level}"
        );
        assert!(
            z[0].norm() < 1e-15 && (z[1] - 1.0).norm() < 1e-15,
            "pins hold"
        );
        for l in mesh.boundary_loop_list() {
            for v in l.vertices {
                assert!(
                    (z[v.idx()].norm() - 1.0).abs() < 1e-12,
                    "boundary on the circle"
                );
            }
        }
        rows.push(error);
    }
    for (level, pair) in rows.windows(2).enumerate().skip(3) {
        let rms = pair[0].rms / pair[1].rms;
        let l2 = pair[0].l2_squared / pair[1].l2_squared;
        assert!(
            (1.7..2.3).contains(&rms),
            "RMS ratio {rms} at level {level}"
        );
        assert!((3.2..4.8).contains(&l2), "L2^2 ratio {l2} at level {level}");
    }
}

#[test]
fn table_5_2_sphere_with_constant_mu() {
    let k = Complex64::new(0.3, 0.3);
    // In the stereographic coordinate the solution fixing 0, 1 and infinity is real-linear.
    let exact = |k: Complex64, p: &Point3<f64>| {
        if p.z >= 1.0 - 1e-12 {
            return *p;
        }
        let z = stereographic(p);
        inverse_stereographic((z + k * z.conj()) / (1.0 + k))
    };
    let mut l2 = Vec::new();
    let mut position = Vec::new();
    for &SphereRow {
        level,
        faces,
        steps: paper_steps,
        l2: paper_l2,
    } in &TABLE_5_2
    {
        let mesh = Mesh::from_soup(&primitives::octahedral_sphere(level)).unwrap();
        assert_eq!(mesh.face_count(), faces);
        let field = stereographic::field(&mesh, |_| k).unwrap();
        let mut problem = Problem::new(&mesh, Target::Sphere);
        problem.goal = beltrami_core::Goal::Prescribed(field.clone());
        // Vertices 0, 1, 5 are the points 0, 1 and infinity.
        problem.constraints = pins(&[0, 1, 5]).into();
        problem.options.set("tolerance", OptionValue::Float(1e-5));
        let solution = flow(&problem);
        let error = mu_error(&mesh, &solution, &field.mu, Frame::Face);
        let image = spatial(&solution);
        let worst = mesh
            .vertices()
            .map(|v| (image[v.idx()] - exact(k, &mesh.position(v))).norm())
            .fold(0.0, f64::max);
        println!(
            "level {level}: {faces} faces, {} steps (paper {paper_steps}), L2^2 {:.4} (paper {paper_l2}), largest vertex error {worst:.3e}",
            solution.metrics.iterations, error.l2_squared
        );
        assert_eq!(solution.metrics.flipped(), Some(0), "level {level}");
        assert!(
            error.l2_squared <= paper_l2,
            "level {level}: {}",
            error.l2_squared
        );
        assert!(
            solution.metrics.iterations <= 2 * paper_steps,
            "level {level}"
        );
        for p in image {
            assert!((p.coords.norm() - 1.0).abs() < 1e-12, "on the sphere");
        }
        l2.push(error.l2_squared);
        position.push(worst);
    }
    for level in 3..6 {
        assert!(
            l2[level] / l2[level + 1] > 2.5,
            "L2^2 rate at level {level}"
        );
        assert!(position[level + 1] < position[level], "positions converge");
    }
    // The conjugate coefficient's solution is far from ours: the test tells them apart.
    let mesh = Mesh::from_soup(&primitives::octahedral_sphere(6)).unwrap();
    let apart = mesh
        .vertices()
        .map(|v| (exact(k, &mesh.position(v)) - exact(k.conj(), &mesh.position(v))).norm())
        .fold(0.0, f64::max);
    assert!(
        position[6] < 0.02 && apart > 10.0 * position[6],
        "{} vs {apart}",
        position[6]
    );
}

/// Fig. 5.9 keeps the inner radius 0.4. A prescribed `mu` also fixes the conformal
/// modulus of the image, so with the radius kept there is no exact solution and the
/// error stops falling at a residual; with the radius free (as in QCMC) the error
/// converges at first order and the radius settles.
#[test]
fn figure_5_9_annulus_with_mu_0_6_z_cubed() {
    for free in [false, true] {
        let mut errors = Vec::new();
        let mut radii = Vec::new();
        for (rings, sectors) in [(4, 32), (8, 64), (16, 128), (32, 256)] {
            let mesh = Mesh::from_soup(&primitives::annulus(0.4, rings, sectors)).unwrap();
            let sigma = sample(&mesh, |z| 0.6 * z * z * z);
            let inner_radius = (!free).then_some(0.4);
            let mut problem = Problem::new(&mesh, Target::Annulus { inner_radius });
            problem.goal =
                beltrami_core::Goal::Prescribed(BeltramiField::new(Frame::Global, sigma.clone()));
            // The vertex at z = 1.
            problem.constraints = pins(&[(sectors * rings) as u32]).into();
            problem.options.set("tolerance", OptionValue::Float(1e-8));
            let solution = flow(&problem);
            let error = mu_error(&mesh, &solution, &sigma, Frame::Global);
            let z = planar(&solution);
            let radius = z[0].norm();
            println!(
                "free radius {free}: {} faces, {} steps, sup {:.4}, RMS {:.3e}, inner radius {radius:.5}",
                mesh.face_count(),
                solution.metrics.iterations,
                error.sup,
                error.rms
            );
            assert_eq!(solution.metrics.flipped(), Some(0));
            assert!((z[sectors * rings] - 1.0).norm() < 1e-15, "the pin holds");
            for v in 0..sectors {
                assert!((z[v].norm() - radius).abs() < 1e-12, "inner circle");
                assert!(
                    (z[v + sectors * rings].norm() - 1.0).abs() < 1e-12,
                    "outer circle"
                );
            }
            if !free {
                assert_eq!(radius, 0.4);
            }
            errors.push(error);
            radii.push(radius);
        }
        if free {
            for pair in errors.windows(2) {
                assert!(pair[0].rms / pair[1].rms > 1.7, "first order");
                assert!(pair[1].sup < pair[0].sup);
            }
            assert!((radii[3] - radii[2]).abs() < 0.5 * (radii[2] - radii[1]).abs());
        } else {
            assert!(errors[3].rms > 0.5 * errors[2].rms, "a residual remains");
        }
    }
}

#[test]
fn table_5_3_square_diffeomorphism_reconstructed_at_second_order() {
    let mut errors = Vec::new();
    for &SquareRow {
        side: n,
        iterations: paper_iterations,
        ..
    } in &TABLE_5_3
    {
        let mesh = square(n - 1);
        let sigma = sample(&mesh, |z| beltrami_coefficient_of(square_diffeomorphism, z));
        let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Keep));
        problem.goal =
            beltrami_core::Goal::Prescribed(BeltramiField::new(Frame::Global, sigma.clone()));
        problem.options.set("tolerance", OptionValue::Float(1e-3));
        let loose = flow(&problem);
        problem.options.set("tolerance", OptionValue::Float(1e-10));
        let tight = flow(&problem);
        let z = planar(&tight);
        let rms = (mesh
            .vertices()
            .map(|v| (z[v.idx()] - square_diffeomorphism(complex(&mesh.position(v)))).norm_sqr())
            .sum::<f64>()
            / mesh.vertex_count() as f64)
            .sqrt();
        println!(
            "{n}^2 vertices: {} iterations at tolerance 1e-3 (paper {paper_iterations}), {} at 1e-10; RMS vertex error {rms:.3e}",
            loose.metrics.iterations, tight.metrics.iterations
        );
        for solution in [&loose, &tight] {
            assert_eq!(solution.metrics.flipped(), Some(0));
            assert!(solution.metrics.iterations <= paper_iterations);
        }
        // Corners stay, sides slide on themselves.
        for v in mesh.vertices() {
            let p = mesh.position(v);
            let w = z[v.idx()];
            if p.x.abs() == 1.0 {
                assert!((w.re - p.x).abs() < 1e-12);
            }
            if p.y.abs() == 1.0 {
                assert!((w.im - p.y).abs() < 1e-12);
            }
        }
        errors.push(rms);
    }
    for pair in errors.windows(2) {
        assert!(pair[0] / pair[1] > 3.4, "second order: {pair:?}");
    }
}
