//! Behaviour of the flow solver: exact fixed points, goals, targets, constraints,
//! cancellation and the errors it reports.

mod common;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use beltrami_core::OptionValue;
use beltrami_core::{
    Context, Goal, Map, Output, Pin, PlanarBoundary, Position, Problem, Solver, SolverError, Target,
};
use beltrami_fem::{BeltramiField, Frame};
use beltrami_flow::BeltramiFlow;
use beltrami_init::Tutte;
use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{Mesh, Point3, PolygonSoup, Vector3, VertexId};
use common::*;
use num_complex::Complex64;

/// The identity of `mesh` with every interior vertex but vertex 0 (a pin) moved by up to
/// `amount` in x and y.
fn perturbed(mesh: &Mesh, amount: f64) -> Vec<Complex64> {
    mesh.vertices()
        .map(|v| {
            let z = complex(&mesh.position(v));
            if mesh.is_boundary_vertex(v) || v.idx() == 0 {
                z
            } else {
                z + amount * Complex64::new(noise(1, 2 * v.idx()), noise(1, 2 * v.idx() + 1))
            }
        })
        .collect()
}

fn largest_distance(a: &[Complex64], mesh: &Mesh) -> f64 {
    mesh.vertices()
        .map(|v| (a[v.idx()] - complex(&mesh.position(v))).norm())
        .fold(0.0, f64::max)
}

#[test]
fn conformal_flow_on_the_disk_returns_to_the_identity() {
    // mu = 0 of the identity is optimal on a disk mesh whose boundary is on the circle:
    // start elsewhere.
    let mesh = Mesh::from_soup(&primitives::disk(4)).unwrap();
    let start = perturbed(&mesh, 0.01);
    assert!(largest_distance(&start, &mesh) > 5e-3);
    let mut problem = Problem::new(&mesh, Target::Disk);
    problem.initial = Some(Map::Planar(start));
    problem.constraints = pins(&[0, 1]).into();
    problem.options.set("tolerance", OptionValue::Float(1e-10));
    let solution = flow(&problem);
    assert!(largest_distance(planar(&solution), &mesh) < 1e-8);
    assert!(solution.metrics.distortion.unwrap().mu_max < 1e-8);
    let history = &solution.metrics.energy_history;
    assert!(history.windows(2).all(|w| w[1] < w[0]), "{history:?}");
    assert_eq!(history.len(), solution.metrics.step_sizes.len() + 1);
}

#[test]
fn conformal_flow_on_a_polygon_slides_sides_and_keeps_corners() {
    // An L-shaped region: corners at the six turns, sides with many vertices.
    let soup = primitives::grid(12, 12, Cells::Triangles);
    let keep: Vec<bool> = (0..soup.face_count())
        .map(|f| {
            let c = soup.face(f).iter().fold(Point3::origin(), |a, &v| {
                a + soup.positions[v as usize].coords / 3.0
            });
            !(c.x > 0.5 && c.y > 0.5)
        })
        .collect();
    let mut l_shape = PolygonSoup::new(soup.positions.clone());
    for f in (0..soup.face_count()).filter(|&f| keep[f]) {
        l_shape.push_face(soup.face(f));
    }
    let mesh = Mesh::build(&l_shape, &Default::default()).unwrap().0;
    let start = perturbed(&mesh, 0.01);
    let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Keep));
    problem.initial = Some(Map::Planar(start));
    problem.options.set("tolerance", OptionValue::Float(1e-10));
    let solution = flow(&problem);
    // The identity is conformal and the region's own: the flow goes back to it.
    assert!(largest_distance(planar(&solution), &mesh) < 1e-8);
}

#[test]
fn prescribed_mu_on_the_square_fixes_corners_and_slides_sides() {
    let mesh = square(16);
    let sigma = sample(&mesh, |z| 0.3 * z.conj() + 0.1);
    let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Keep));
    problem.goal = Goal::Prescribed(BeltramiField::new(Frame::Global, sigma.clone()));
    let solution = flow(&problem);
    let z = planar(&solution);
    let mut slid = 0.0f64;
    for v in mesh.vertices() {
        let p = mesh.position(v);
        let w = z[v.idx()];
        if p.x.abs() == 1.0 && p.y.abs() == 1.0 {
            assert_eq!(w, complex(&p), "corner {v}");
        } else if p.x.abs() == 1.0 {
            assert!((w.re - p.x).abs() < 1e-13 && w.im.abs() < 1.0);
            slid = slid.max((w.im - p.y).abs());
        } else if p.y.abs() == 1.0 {
            assert!((w.im - p.y).abs() < 1e-13 && w.re.abs() < 1.0);
            slid = slid.max((w.re - p.x).abs());
        }
    }
    assert!(slid > 1e-2, "boundary vertices slid along their sides");
    assert_eq!(solution.metrics.flipped(), Some(0));
    let error = mu_error(&mesh, &solution, &sigma, Frame::Global);
    let start = mu_error(
        &mesh,
        &flow(&{
            let mut p = problem.clone();
            p.options.set("max-iters", OptionValue::Int(0));
            p
        }),
        &sigma,
        Frame::Global,
    );
    // Four fixed corners fix the conformal modulus: no map has exactly this mu, the flow
    // finds a compromise.
    assert!(
        error.rms < 0.6 * start.rms,
        "{} vs {}",
        error.rms,
        start.rms
    );
}

/// Tutte's map of `mesh` onto the unit circle.
fn tutte_disk(mesh: &Mesh) -> Vec<Complex64> {
    let problem = Problem::new(mesh, Target::Plane(PlanarBoundary::Circle));
    match Tutte.solve(&problem, &mut Context::new()).unwrap().output {
        Output::Map(Map::Planar(z)) => z,
        other => panic!("Tutte's map is planar: {other:?}"),
    }
}

#[test]
fn lp_goals_lower_the_lp_norm_from_tutte() {
    let mesh = hemisphere();
    let tutte = tutte_disk(&mesh);
    for p in [2.0, 3.0, 4.0] {
        let mut problem = Problem::new(&mesh, Target::Disk);
        problem.goal = Goal::Conformal { p };
        problem.initial = Some(Map::Planar(tutte.clone()));
        problem.options.set("tolerance", OptionValue::Float(1e-6));
        let solution = flow(&problem);
        let history = &solution.metrics.energy_history;
        assert!(
            history.windows(2).all(|w| w[1] < w[0]),
            "p = {p}: {history:?}"
        );
        let (first, last) = (history[0], *history.last().unwrap());
        println!(
            "p = {p}: E {first:.3e} -> {last:.3e} in {} steps",
            solution.metrics.iterations
        );
        assert!(last < 0.05 * first, "p = {p}");
        assert_eq!(solution.metrics.flipped(), Some(0));
        for l in mesh.boundary_loop_list() {
            for v in l.vertices {
                assert!((planar(&solution)[v.idx()].norm() - 1.0).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn the_conformal_disk_flow_starts_from_the_boundary_first_map() {
    // Without a given start the disk flow starts from the boundary-first conformal map
    // (exactly on the circle), not from Tutte's: its error starts over ten times lower
    // and it settles in fewer steps, at no higher an error.
    let mesh = hemisphere();
    let mut problem = Problem::new(&mesh, Target::Disk);
    problem.goal = Goal::Conformal { p: 2.0 };
    let own = flow(&problem);
    problem.initial = Some(Map::Planar(tutte_disk(&mesh)));
    let from_tutte = flow(&problem);
    let (own_history, tutte_history) = (
        &own.metrics.energy_history,
        &from_tutte.metrics.energy_history,
    );
    println!("own start {own_history:?}\nTutte's {tutte_history:?}");
    assert!(own_history[0] < 0.1 * tutte_history[0]);
    assert!(own.metrics.iterations < from_tutte.metrics.iterations);
    let last = |h: &[f64]| *h.last().unwrap();
    assert!(last(own_history) <= 1.001 * last(tutte_history));
    assert_eq!(own.metrics.flipped(), Some(0));
    for l in mesh.boundary_loop_list() {
        for v in l.vertices {
            assert!((planar(&own)[v.idx()].norm() - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn conformal_flow_on_the_sphere_returns_to_the_identity() {
    let mesh = Mesh::from_soup(&primitives::octahedral_sphere(3)).unwrap();
    let pinned = [0usize, 1, 5];
    let start: Vec<Point3<f64>> = mesh
        .vertices()
        .map(|v| {
            let p = mesh.position(v);
            if pinned.contains(&v.idx()) {
                return p;
            }
            let d = 0.02
                * Vector3::new(
                    noise(3, 3 * v.idx()),
                    noise(3, 3 * v.idx() + 1),
                    noise(3, 3 * v.idx() + 2),
                );
            Point3::from((p.coords + d).normalize())
        })
        .collect();
    let mut problem = Problem::new(&mesh, Target::Sphere);
    problem.initial = Some(Map::Spatial(start));
    problem.options.set("tolerance", OptionValue::Float(1e-10));
    let solution = flow(&problem);
    let image = spatial(&solution);
    let worst = mesh
        .vertices()
        .map(|v| (image[v.idx()] - mesh.position(v)).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-7, "{worst}");
    assert!(
        solution
            .report
            .notes
            .iter()
            .any(|n| n.contains("pinned vertices 0, 1, 5"))
    );
}

#[test]
fn free_annulus_radius_recovers_the_modulus() {
    // A conformal map of 0.4 < |z| < 1 onto an annulus exists only for radius 0.4: from a
    // radial stretch onto 0.6 < |z| < 1, the free radius flows back.
    let mesh = Mesh::from_soup(&primitives::annulus(0.4, 8, 64)).unwrap();
    let stretched: Vec<Complex64> = mesh
        .vertices()
        .map(|v| {
            let z = complex(&mesh.position(v));
            z / z.norm() * (0.6 + (z.norm() - 0.4) * 0.4 / 0.6)
        })
        .collect();
    let mut problem = Problem::new(&mesh, Target::Annulus { inner_radius: None });
    problem.initial = Some(Map::Planar(stretched));
    problem.options.set("tolerance", OptionValue::Float(1e-9));
    let solution = flow(&problem);
    let radius = planar(&solution)[0].norm();
    assert!((radius - 0.4).abs() < 1e-6, "{radius}");
    assert!(solution.metrics.distortion.unwrap().mu_max < 1e-5);
    let found = solution
        .extras
        .annulus_radius
        .expect("the free radius is reported");
    assert!(
        (found.radius - radius).abs() < 1e-9 && (found.initial - 0.6).abs() < 1e-9,
        "{found:?}"
    );
}

#[test]
fn cancelled_flow_returns_the_map_so_far() {
    let mesh = Mesh::from_soup(&primitives::disk(3)).unwrap();
    let mut problem = Problem::new(&mesh, Target::Disk);
    problem.goal = Goal::Prescribed(BeltramiField::new(
        Frame::Global,
        sample(&mesh, |z| 0.5 * z),
    ));
    let complete = flow(&problem);
    // Cancelled before any work: an error, there is no map yet.
    let flag = Arc::new(AtomicBool::new(true));
    let mut context = Context::new().with_cancel_flag(Arc::clone(&flag));
    assert!(matches!(
        BeltramiFlow.solve(&problem, &mut context),
        Err(SolverError::Cancelled)
    ));
    // Cancelled after the first step: the map after that step.
    let flag = Arc::new(AtomicBool::new(false));
    let raise = Arc::clone(&flag);
    let mut context = Context::new()
        .with_cancel_flag(flag)
        .with_progress(move |p| {
            if p.stage == "flow" && p.done == 1 {
                raise.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        });
    let cancelled = BeltramiFlow.solve(&problem, &mut context).unwrap();
    assert_eq!(cancelled.metrics.iterations, 1);
    assert!(complete.metrics.iterations > 1);
    assert!(
        cancelled
            .report
            .notes
            .iter()
            .any(|n| n.starts_with("cancelled after 1 iterations"))
    );
    assert_eq!(
        cancelled.metrics.energy_history[..],
        complete.metrics.energy_history[..2]
    );
}

fn rejected(problem: &Problem<'_>) -> String {
    let checked = BeltramiFlow.check(problem).expect_err("check rejects");
    let solved = BeltramiFlow
        .solve(problem, &mut Context::new())
        .expect_err("solve rejects");
    assert_eq!(checked.to_string(), solved.to_string());
    solved.to_string()
}

#[test]
fn bad_problems_are_typed_errors() {
    let disk = Mesh::from_soup(&primitives::disk(2)).unwrap();
    let quads = Mesh::from_soup(&primitives::grid(3, 3, Cells::Quads)).unwrap();
    let sphere = Mesh::from_soup(&primitives::octahedral_sphere(1)).unwrap();

    let message = rejected(&Problem::new(&quads, Target::Disk));
    assert!(
        message.contains("face 0") && message.contains("4 vertices"),
        "{message}"
    );

    let mut p = Problem::new(&disk, Target::Disk);
    let mut mu = vec![Complex64::new(0.1, 0.0); disk.face_count()];
    mu[7] = Complex64::new(0.0, 1.0);
    p.goal = Goal::Prescribed(BeltramiField::new(Frame::Global, mu));
    let message = rejected(&p);
    assert!(message.contains("face f7 "), "{message}");

    let mut p = Problem::new(&disk, Target::Disk);
    for exponent in [1.5, 1e308, f64::NAN] {
        p.goal = Goal::Conformal { p: exponent };
        assert!(
            rejected(&p).contains("needs 2 <= p <= 100"),
            "p = {exponent}"
        );
    }

    assert!(rejected(&Problem::new(&disk, Target::Plane(PlanarBoundary::Free))).contains("lsqc"));
    assert!(rejected(&Problem::new(&disk, Target::Sphere)).contains("closed genus-0"));
    assert!(rejected(&Problem::new(&sphere, Target::Disk)).contains("disk"));
    assert!(
        rejected(&Problem::new(&disk, Target::Annulus { inner_radius: None }))
            .contains("two boundary loops")
    );

    let mut p = Problem::new(&disk, Target::Disk);
    p.constraints = vec![Pin {
        vertex: VertexId(0),
        position: Some(Position::Planar(Complex64::new(0.1, 0.0))),
    }]
    .into();
    assert!(rejected(&p).contains("given positions"));

    let mut p = Problem::new(&disk, Target::Disk);
    p.constraints = pins(&[10_000]).into();
    assert!(rejected(&p).contains("10000"));

    let cap = hemisphere();
    let mut p = Problem::new(&cap, Target::Disk);
    let faces = p.source.face_count();
    p.goal = Goal::Prescribed(BeltramiField::zero(Frame::Global, faces));
    assert!(rejected(&p).contains("face frame"));
}

#[test]
fn an_undetermined_flow_asks_for_pins() {
    // Pinning only the centre leaves the rotations free: V = i z is linear, so exactly
    // holomorphic on every triangle, and tangent to the circle at the boundary vertices.
    let mesh = Mesh::from_soup(&primitives::disk(3)).unwrap();
    let mut problem = Problem::new(&mesh, Target::Disk);
    problem.goal = Goal::Prescribed(BeltramiField::new(
        Frame::Global,
        sample(&mesh, |z| 0.3 * z),
    ));
    problem.constraints = pins(&[0]).into();
    match BeltramiFlow.solve(&problem, &mut Context::new()) {
        Err(SolverError::InvalidInput { message, .. }) => {
            assert!(message.contains("pin more vertices"), "{message}")
        }
        Err(other) => panic!("expected InvalidInput, got {other}"),
        Ok(_) => panic!("expected an error"),
    }
}
