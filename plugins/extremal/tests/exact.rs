//! The extremal solver against exact extremal maps: affine maps of a disk (reproduced
//! exactly by P1 elements) and the ring map between annuli (paper section 5), with
//! convergence under refinement; independence of the start (harmonic, Tutte, noisy,
//! folded).

mod common;

use beltrami_core::{Context, Goal, PlanarBoundary, Problem, Solver, Stop, Target};
use beltrami_extremal::Extremal;
use beltrami_mesh::{Mesh, primitives};
use common::*;
use num_complex::Complex64;

fn ring() -> RingMap {
    RingMap {
        r0: 0.4,
        r1: 1.0,
        s0: 0.25,
        s1: 1.2,
    }
}

/// Boundary values of the affine map `z + a conj(z)` (|a| < 1): the extremal map is the
/// affine map itself (constant mu = a, phi constant), which P1 elements reproduce, so
/// the solver must find it to rounding on an irregular mesh, from a folded start too.
#[test]
fn affine_boundary_gives_the_affine_map() {
    let mesh = Mesh::from_soup(&primitives::jittered_grid(
        12,
        12,
        primitives::Cells::Triangles,
        0.3,
        7,
    ))
    .unwrap();
    let a = Complex64::new(0.3, 0.2);
    let exact = image(&mesh, |z| z + a * z.conj());
    let solution = solve(&mesh, exact.clone(), None, "harmonic");
    let map = solution.planar().unwrap();
    assert!(
        max_distance(map, &exact) < 1e-8,
        "{}",
        max_distance(map, &exact)
    );
    let k = solution.metrics.k.unwrap();
    assert!((k - a.norm()).abs() < 1e-8, "k = {k}");
    let mu = &solution.metrics.mu.as_ref().unwrap().mu;
    assert!(mu.iter().all(|m| (m - a).norm() < 1e-7));
    // phi = conj(mu) / k up to a positive factor: constant direction conj(a)/|a|.
    let qd = solution.extras.quadratic_differential.as_ref().unwrap();
    let dir = a.conj() / a.norm();
    assert!(qd.values.iter().all(|p| (p / p.norm() - dir).norm() < 1e-6));
}

/// The ring map on irregular annuli: k within 1% of the exact one (from the second
/// level, 1.5K faces, on), |mu| at least as close to k as the exact map's own P1
/// interpolant, no flips, and the errors fall under refinement.
#[test]
fn ring_map_converges_to_the_exact_extremal_map() {
    let ring = ring();
    let mut last: Option<(f64, f64)> = None;
    for (level, (rings, sectors)) in [(6, 32), (12, 64), (24, 128)].into_iter().enumerate() {
        let mesh = irregular_annulus(ring.r0, rings, sectors, 11 + level as u64);
        let exact = image(&mesh, |z| ring.at(z));
        let solution = solve(&mesh, exact.clone(), None, "harmonic");
        assert!(matches!(
            solution.metrics.stop,
            Some(Stop::Converged { .. })
        ));
        let map = solution.planar().unwrap();
        let k = solution.metrics.k.unwrap();
        let k_error = (k - ring.k()).abs() / ring.k();
        let deviation = l2_deviation(&mesh, map, ring.k());
        let interpolant = l2_deviation(&mesh, &exact, ring.k());
        let distance = max_distance(map, &exact);
        eprintln!(
            "ring {rings}x{sectors}: faces {} k {k:.6} (exact {:.6}, rel {k_error:.2e}) L2(|mu|-k) {deviation:.3e} (interpolant {interpolant:.3e}) max|f - f_exact| {distance:.3e} iterations {}",
            mesh.face_count(),
            ring.k(),
            solution.metrics.iterations
        );
        assert!(k_error < 0.01 || level == 0, "k = {k}, exact {}", ring.k());
        assert!(deviation <= interpolant, "{deviation} > {interpolant}");
        assert_eq!(solution.metrics.flipped(), Some(0));
        if let Some((d, m)) = last {
            assert!(deviation < 0.7 * d, "L2 {deviation} after {d}");
            assert!(distance < 0.7 * m, "map error {distance} after {m}");
        }
        last = Some((deviation, distance));
    }
}

/// Harmonic, Tutte, noisy and folded starts give the same map and k.
#[test]
fn result_does_not_depend_on_the_start() {
    let ring = ring();
    let mesh = irregular_annulus(ring.r0, 10, 48, 5);
    let exact = image(&mesh, |z| ring.at(z));
    let reference = solve(&mesh, exact.clone(), None, "harmonic");
    let reference_map = reference.planar().unwrap().to_vec();

    let mut u = noise(99);
    let noisy: Vec<Complex64> = reference_map
        .iter()
        .map(|z| z + 0.05 * Complex64::new(u(), u()))
        .collect();
    // A folded start: the exact map with the images of the vertices near 0.7 mirrored
    // across the horizontal line through the image of 0.7, so that every face there is
    // flipped (orientation-reversing).
    let center = Complex64::new(0.7, 0.0);
    let fc = ring.at(center);
    let folded: Vec<Complex64> = mesh
        .positions()
        .iter()
        .zip(&exact)
        .map(|(p, &w)| {
            if (Complex64::new(p.x, p.y) - center).norm() < 0.15 {
                fc + (w - fc).conj()
            } else {
                w
            }
        })
        .collect();
    let starts = [
        ("tutte", None),
        ("noisy", Some(noisy)),
        ("folded", Some(folded)),
    ];
    for (name, start) in starts {
        let solution = solve(
            &mesh,
            exact.clone(),
            start,
            if name == "tutte" { "tutte" } else { "harmonic" },
        );
        if name == "folded" {
            let before = solution
                .metrics
                .initial_distortion
                .as_ref()
                .unwrap()
                .flipped;
            assert!(before > 10, "the folded start has {before} flips");
        }
        let map = solution.planar().unwrap();
        let dk = (solution.metrics.k.unwrap() - reference.metrics.k.unwrap()).abs();
        let d = max_distance(map, &reference_map);
        eprintln!(
            "start {name}: |dk| {dk:.2e} max|df| {d:.2e} iterations {} energy {:.6e} (reference {:.6e}) to exact {:.2e} (reference {:.2e})",
            solution.metrics.iterations,
            solution.metrics.energy_history.last().unwrap(),
            reference.metrics.energy_history.last().unwrap(),
            max_distance(map, &exact),
            max_distance(&reference_map, &exact)
        );
        assert!(dk < 1e-4, "{name}: k differs by {dk}");
        // The starts stop at slightly different discrete maps (the alternating
        // iteration is not exact); they agree to well below the discretization error.
        let discretization = max_distance(&reference_map, &exact);
        assert!(d < 0.5 * discretization, "{name}: maps differ by {d}");
        assert_eq!(solution.metrics.flipped(), Some(0), "{name}");
    }
}

/// Refusals name the problem: a non-extremal goal, a free boundary, a wrong-length
/// boundary map, a non-finite boundary value; check and solve agree.
#[test]
fn bad_problems_are_refused() {
    let mesh = Mesh::from_soup(&primitives::disk(2)).unwrap();
    let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Free));
    problem.goal = Goal::Extremal;
    let e = Extremal.check(&problem).unwrap_err().to_string();
    assert!(e.contains("boundary"), "{e}");
    assert_eq!(
        e,
        Extremal
            .solve(&problem, &mut Context::new())
            .unwrap_err()
            .to_string()
    );
    problem.target = Target::Plane(PlanarBoundary::Given(vec![Complex64::new(0.0, 0.0); 3]));
    let e = Extremal.check(&problem).unwrap_err().to_string();
    assert!(e.contains("3 values"), "{e}");
    let mut values = image(&mesh, |z| z);
    let b = mesh.boundary_loop_list()[0].vertices[2];
    values[b.idx()] = Complex64::new(f64::NAN, 0.0);
    problem.target = Target::Plane(PlanarBoundary::Given(values));
    let e = Extremal.check(&problem).unwrap_err().to_string();
    assert!(e.contains(&format!("vertex {b}")), "{e}");
    problem.target = Target::Plane(PlanarBoundary::Keep);
    problem.goal = Goal::Conformal { p: 2.0 };
    let e = Extremal.check(&problem).unwrap_err().to_string();
    assert!(e.contains("lsqc"), "{e}");
}

/// A boundary map that reverses the orientation (a mirror image) or whose boundary
/// curve crosses itself cannot be the boundary of a one-to-one map: refused, saying
/// which (both used to end in "the solution is not finite", or in flips blamed on
/// concave corners).
#[test]
fn a_mirrored_or_self_crossing_boundary_map_is_refused_as_such() {
    let mesh = Mesh::from_soup(&primitives::disk(2)).unwrap();
    let mut problem = Problem::new(
        &mesh,
        Target::Plane(PlanarBoundary::Given(image(&mesh, |z| z.conj()))),
    );
    problem.goal = Goal::Extremal;
    let e = Extremal
        .solve(&problem, &mut Context::new())
        .unwrap_err()
        .to_string();
    assert!(e.contains("the other way than the surface"), "{e}");
    // The lower half folded up: the boundary runs over its upper half twice.
    problem.target = Target::Plane(PlanarBoundary::Given(image(&mesh, |z| {
        Complex64::new(z.re, z.im.abs() * if z.re > 0.0 { -1.0 } else { 1.0 })
    })));
    let e = Extremal.check(&problem).unwrap_err().to_string();
    assert!(e.contains("crosses itself"), "{e}");
    // The identity passes both checks.
    problem.target = Target::Plane(PlanarBoundary::Given(image(&mesh, |z| z)));
    assert!(Extremal.solve(&problem, &mut Context::new()).is_ok());
}

/// A cancelled run returns the start's iteration count 0 and says so.
#[test]
fn cancellation_stops_the_iteration() {
    let ring = ring();
    let mesh = irregular_annulus(ring.r0, 6, 32, 3);
    let mut problem = Problem::new(
        &mesh,
        Target::Plane(PlanarBoundary::Given(image(&mesh, |z| ring.at(z)))),
    );
    problem.goal = Goal::Extremal;
    let settings = Extremal.check(&problem).unwrap();
    let mut context = Context::new();
    context
        .cancel_flag()
        .store(true, std::sync::atomic::Ordering::Relaxed);
    // The stages check cancellation before they start.
    assert!(Extremal.run(&problem, &settings, &mut context).is_err());
}
