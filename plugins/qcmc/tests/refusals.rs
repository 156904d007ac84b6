//! What qcmc refuses, with the same typed error through `check` and `solve`.

mod common;

use beltrami_core::{Context, Goal, Problem, Solver, SolverError, Target};
use beltrami_fem::{BeltramiField, Frame};
use beltrami_mesh::{Mesh, primitives};
use beltrami_qcmc::Qcmc;
use beltrami_qcmc::moebius::PlaneCircle;
use num_complex::Complex64;

/// `check` and `solve` give the same error; returns its text.
fn refused(problem: &Problem<'_>) -> String {
    let checked = Qcmc.check(problem).unwrap_err();
    let solved = Qcmc.solve(problem, &mut Context::new()).unwrap_err();
    assert_eq!(checked.to_string(), solved.to_string());
    checked.to_string()
}

fn annulus() -> Mesh {
    Mesh::from_soup(&primitives::annulus(0.4, 3, 24)).unwrap()
}

#[test]
fn a_disk_is_refused() {
    let disk = Mesh::from_soup(&primitives::disk(2)).unwrap();
    let message = refused(&Problem::new(&disk, Target::CircleDomain));
    assert!(message.contains("disk"), "{message}");
    assert!(matches!(
        Qcmc.check(&Problem::new(&disk, Target::CircleDomain)),
        Err(SolverError::Unsupported { .. })
    ));
}

#[test]
fn closed_and_higher_genus_meshes_are_refused() {
    for soup in [
        primitives::icosphere(1),
        primitives::torus(12, 8, 2.0, 0.5, primitives::Cells::Triangles),
    ] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let message = refused(&Problem::new(&mesh, Target::CircleDomain));
        assert!(message.contains("no boundary"), "{message}");
    }
}

#[test]
fn other_targets_and_exponents_are_refused() {
    let mesh = annulus();
    refused(&Problem::new(&mesh, Target::Disk));
    let mut problem = Problem::new(&mesh, Target::CircleDomain);
    problem.goal = Goal::Conformal { p: 3.0 };
    assert!(refused(&problem).contains("p = 2"));
}

#[test]
fn an_outer_loop_that_does_not_exist_is_named() {
    let mesh = annulus();
    let mut problem = Problem::new(&mesh, Target::CircleDomain);
    problem.options.set_text("outer", "3");
    let message = refused(&problem);
    assert!(
        message.contains("outer") && message.contains("loop 2"),
        "{message}"
    );
}

#[test]
fn a_mu_of_modulus_one_names_its_face() {
    let mesh = annulus();
    let mut mu = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
    mu[7] = Complex64::new(0.0, 1.0);
    let mut problem = Problem::new(&mesh, Target::CircleDomain);
    problem.goal = Goal::Prescribed(BeltramiField::new(Frame::Global, mu));
    let message = refused(&problem);
    assert!(message.contains('7'), "{message}");
}

#[test]
fn either_loop_can_be_the_outer_one() {
    // The annulus 0.4 < |z| < 1 with its inner loop outer: the map z -> 0.4 / z is
    // conformal, so the other circle has radius 0.4 again.
    let holes = [PlaneCircle {
        center: Complex64::new(0.0, 0.0),
        radius: 0.4,
    }];
    let mesh = common::circle_domain(&holes, 0.05);
    let loops = mesh.boundary_loop_list();
    let inner = (0..2)
        .min_by(|&a, &b| loops[a].length.total_cmp(&loops[b].length))
        .unwrap();
    let outer = (inner + 1).to_string();
    let solution = common::run(&mesh, Goal::Conformal { p: 2.0 }, &[("outer", &outer)]);
    let circles = solution.extras.circles.unwrap();
    assert_eq!(circles[0].boundary_loop, inner);
    assert_eq!(solution.metrics.flipped(), Some(0));
    assert!(
        (circles[1].radius - 0.4).abs() < 1e-3,
        "{}",
        circles[1].radius
    );
}

#[test]
fn a_cancelled_run_returns_its_map_so_far() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let holes = [PlaneCircle {
        center: Complex64::new(0.3, 0.0),
        radius: 0.3,
    }];
    let mesh = common::circle_domain(&holes, 0.05);
    let flag = Arc::new(AtomicBool::new(false));
    let raise = flag.clone();
    let mut context = Context::new()
        .with_cancel_flag(flag)
        .with_progress(move |p| {
            if p.stage == "iteration" {
                raise.store(true, Ordering::Relaxed);
            }
        });
    let solution = Qcmc
        .solve(&Problem::new(&mesh, Target::CircleDomain), &mut context)
        .unwrap();
    assert_eq!(solution.metrics.stop, Some(beltrami_core::Stop::Cancelled));
    assert_eq!(solution.metrics.iterations, 1);
    assert_eq!(solution.metrics.flipped(), Some(0));
    assert_eq!(solution.extras.circles.unwrap().len(), 2);
}
