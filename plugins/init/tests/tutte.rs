//! Tutte's embedding: bijective on every disk mesh for convex boundaries and positive
//! weights (Tutte 1963, Floater 2003), boundary exactly on the target, interior vertices
//! at weighted means of their neighbours.

mod common;

use std::f64::consts::TAU;

use beltrami_core::Options;
use beltrami_core::{
    Constraint, Context, Pin, PlanarBoundary, Position, Problem, Solver, SolverError, Target,
};
use beltrami_fem::EdgeWeights;
use beltrami_init::Tutte;
use beltrami_init::Weights;
use beltrami_mesh::primitives::{Cells, grid, torus};
use beltrami_mesh::{FaceId, Mesh};
use common::{
    boundary_vertices, cross, flipped_faces, hemisphere, identity_error, jittered, planar,
    shared_disks, summary, weighted_mean_error,
};
use num_complex::Complex64;

/// A regular octagon, counter-clockwise. Its corners sit at multiples of 1/8 of the
/// perimeter, so the grid's corners (at quarters) land on corners, not on straight
/// sides where their ear triangles would collapse.
fn octagon() -> Vec<Complex64> {
    (0..8)
        .map(|k| Complex64::from_polar(1.0, TAU * k as f64 / 8.0 + 0.3))
        .collect()
}

/// The targets every mesh is tested on.
fn targets() -> Vec<(&'static str, PlanarBoundary)> {
    vec![
        ("circle", PlanarBoundary::Circle),
        ("square", PlanarBoundary::Square { corners: None }),
        ("octagon", PlanarBoundary::Polygon(octagon())),
    ]
}

/// Distance of `z` from the boundary of the convex polygon `corners` (ccw).
fn polygon_distance(corners: &[Complex64], z: Complex64) -> f64 {
    let m = corners.len();
    (0..m)
        .map(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % m]);
            let t = ((z - a) * (b - a).conj()).re / (b - a).norm_sqr();
            (a + (b - a) * t.clamp(0.0, 1.0) - z).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Distance of a boundary image from the target curve.
fn off_target(boundary: &PlanarBoundary, z: Complex64) -> f64 {
    match boundary {
        PlanarBoundary::Circle => (z.norm() - 1.0).abs(),
        PlanarBoundary::Square { .. } => {
            // On a side of [0, 1]^2 exactly: one coordinate is exactly 0 or 1.
            let inside = (0.0..=1.0).contains(&z.re) && (0.0..=1.0).contains(&z.im);
            let on_side = [z.re, z.im].iter().any(|&c| c == 0.0 || c == 1.0);
            if inside && on_side { 0.0 } else { 1.0 }
        }
        PlanarBoundary::Polygon(corners) => polygon_distance(corners, z),
        _ => unreachable!("not a tested target"),
    }
}

/// True if every vertex of `f` is a boundary vertex and the images are collinear.
fn collapsed_on_the_boundary(mesh: &Mesh, map: &[Complex64], f: FaceId) -> bool {
    let z: Vec<Complex64> = mesh.face_vertices(f).map(|v| map[v.idx()]).collect();
    let scale = z.iter().map(|w| (w - z[0]).norm_sqr()).fold(0.0, f64::max);
    mesh.face_vertices(f).all(|v| mesh.is_boundary_vertex(v))
        && z.iter()
            .all(|&w| cross(z[1] - z[0], w - z[0]).abs() <= 1e-12 * scale)
}

/// The edge weights of `kind`, as the solver builds them.
fn edge_weights(mesh: &Mesh, kind: Weights) -> EdgeWeights {
    match kind {
        Weights::Uniform => EdgeWeights::uniform(mesh),
        Weights::MeanValue => EdgeWeights::mean_value(mesh).unwrap(),
        Weights::Cotan => EdgeWeights::cotangent(mesh).unwrap(),
    }
}

/// Solves with Tutte and checks: no flipped face except collapsed boundary faces (the
/// report and an independent count agree), every boundary vertex on the target,
/// interior vertices at weighted means.
fn check_bijective(name: &str, mesh: &Mesh) {
    for kind in [Weights::Uniform, Weights::MeanValue] {
        let weights = edge_weights(mesh, kind);
        for (target_name, target) in targets() {
            let mut problem = Problem::new(mesh, Target::Plane(target.clone()));
            problem.options.set_text(
                "weights",
                match kind {
                    Weights::MeanValue => "mean-value",
                    _ => "uniform",
                },
            );
            let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
            let map = planar(solution.map().expect("a map"));
            println!("{name} {kind:?} {target_name}: {}", summary(&solution));
            // Tutte's theorem: no flips on a convex boundary with positive weights. The
            // only exception are faces whose vertices all lie on the boundary and land on
            // one straight side of a polygon (quad_disk_inspired has such "double ear"
            // quads): they collapse to a segment, the sign of their Jacobian is rounding
            // noise, and the report names them in a note.
            let flipped = flipped_faces(mesh, map);
            let collapsed: Vec<FaceId> = mesh
                .faces()
                .filter(|&f| collapsed_on_the_boundary(mesh, map, f))
                .collect();
            let bad: Vec<FaceId> = flipped
                .iter()
                .copied()
                .filter(|f| !collapsed.contains(f))
                .collect();
            assert!(bad.is_empty(), "{name} {kind:?} {target_name}: {bad:?}");
            if matches!(target, PlanarBoundary::Circle) {
                assert!(collapsed.is_empty(), "{name} {kind:?}: {collapsed:?}");
            }
            let reported = solution.metrics.flipped().unwrap();
            assert!(
                reported <= collapsed.len(),
                "{name} {kind:?} {target_name}: {reported} > {}",
                collapsed.len()
            );
            let note = format!(
                "{} faces have all their vertices on one straight side",
                collapsed.len()
            );
            assert_eq!(
                solution.report.notes.iter().any(|n| n.contains(&note)),
                !collapsed.is_empty(),
                "{name} {kind:?} {target_name}: {:?}",
                solution.report.notes
            );
            let worst = boundary_vertices(mesh)
                .iter()
                .map(|v| off_target(&target, map[v.idx()]))
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-14,
                "{name} {kind:?} {target_name}: off by {worst:e}"
            );
            let err = weighted_mean_error(mesh, &weights, map);
            assert!(
                err < 1e-10,
                "{name} {kind:?} {target_name}: mean error {err:e}"
            );
        }
    }
}

#[test]
fn bijective_on_jittered_grids() {
    for (cells, seed) in [(Cells::Triangles, 1), (Cells::Quads, 2)] {
        let mesh = jittered(20, cells, 0.35, seed);
        check_bijective(&format!("grid {cells:?}"), &mesh);
    }
}

#[test]
fn bijective_on_the_hemisphere() {
    check_bijective("hemisphere", &hemisphere());
}

#[test]
fn bijective_on_the_shared_disks() {
    let Some(meshes) = shared_disks("bijective_on_the_shared_disks") else {
        return;
    };
    for (name, mesh) in &meshes {
        check_bijective(name, mesh);
    }
}

#[test]
fn mean_value_weights_reproduce_a_planar_mesh() {
    // Mean-value coordinates have linear precision: with the source's own boundary the
    // interior vertices come back where they were.
    for (cells, seed) in [(Cells::Triangles, 3), (Cells::Quads, 4)] {
        let mesh = jittered(12, cells, 0.3, seed);
        let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Keep));
        problem.options.set_text("weights", "mean-value");
        let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
        let err = identity_error(&mesh, planar(solution.map().expect("a map")));
        assert!(err < 1e-12, "{cells:?}: {err:e}");
        // Uniform weights do not have linear precision: the jitter is smoothed out.
        problem.options.set_text("weights", "uniform");
        let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
        assert!(identity_error(&mesh, planar(solution.map().expect("a map"))) > 1e-3);
    }
}

#[test]
fn boundary_runs_clockwise_in_loop_order_and_faces_stay_counter_clockwise() {
    let mesh = Mesh::from_soup(&grid(6, 6, Cells::Triangles)).unwrap();
    let problem = Problem::new(&mesh, Target::Disk);
    let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    let loop_vertices = boundary_vertices(&mesh);
    let n = loop_vertices.len();
    let signed_area: f64 = (0..n)
        .map(|k| {
            cross(
                map[loop_vertices[k].idx()],
                map[loop_vertices[(k + 1) % n].idx()],
            )
        })
        .sum::<f64>()
        / 2.0;
    // The mesh's own boundary is clockwise in loop order, and so is its image.
    assert!(signed_area < 0.0, "{signed_area}");
    for f in mesh.faces() {
        let z: Vec<Complex64> = mesh.face_vertices(f).map(|v| map[v.idx()]).collect();
        assert!(cross(z[1] - z[0], z[2] - z[0]) > 0.0, "{f}");
    }
}

#[test]
fn a_pin_chooses_the_start_of_the_circle() {
    let mesh = jittered(8, Cells::Quads, 0.2, 5);
    let start = boundary_vertices(&mesh)[5];
    let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Circle));
    problem.constraints.push(Constraint::Pin(Pin {
        vertex: start,
        position: None,
    }));
    let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
    assert_eq!(
        planar(solution.map().expect("a map"))[start.idx()],
        Complex64::new(1.0, 0.0)
    );
}

#[test]
fn given_square_corners_go_to_the_corners() {
    let mesh = hemisphere();
    let b = boundary_vertices(&mesh);
    let n = b.len();
    // Counter-clockwise is against loop order.
    let corners = [b[0], b[3 * n / 4], b[n / 2], b[n / 4]];
    let problem = Problem::new(
        &mesh,
        Target::Plane(PlanarBoundary::Square {
            corners: Some(corners),
        }),
    );
    let solution = Tutte.solve(&problem, &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    let unit = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    for (v, (x, y)) in corners.iter().zip(unit) {
        assert_eq!(map[v.idx()], Complex64::new(x, y));
    }
    assert_eq!(solution.metrics.flipped(), Some(0));
}

#[test]
fn progress_reports_the_stages() {
    let mesh = jittered(6, Cells::Triangles, 0.2, 6);
    let problem = Problem::new(&mesh, Target::Disk);
    let mut stages = Vec::new();
    let solution = {
        let mut context = Context::new().with_progress(|p| {
            if p.done == 1 {
                stages.push(p.stage)
            }
        });
        Tutte.solve(&problem, &mut context).unwrap()
    };
    assert_eq!(stages, ["boundary", "assembly", "solve", "distortion"]);
    let timed: Vec<&str> = solution
        .report
        .timings
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    assert_eq!(timed, stages);
    assert_eq!(solution.report.solver, "tutte");
    assert!(solution.metrics.mu.is_some());
    assert_eq!(solution.metrics.energy_history.len(), 1);
}

#[test]
fn cancellation_stops_the_solve() {
    let mesh = jittered(6, Cells::Triangles, 0.2, 7);
    let problem = Problem::new(&mesh, Target::Disk);
    let context = Context::new();
    context
        .cancel_flag()
        .store(true, std::sync::atomic::Ordering::Relaxed);
    let mut context = context;
    assert!(matches!(
        Tutte.solve(&problem, &mut context),
        Err(SolverError::Cancelled)
    ));
}

fn unsupported_message<T: std::fmt::Debug>(result: Result<T, SolverError>) -> String {
    match result {
        Err(SolverError::Unsupported { solver, message }) => {
            assert_eq!(solver, "tutte");
            message
        }
        // An option outside the declared choices (cotangent weights for tutte).
        Err(SolverError::Option(e @ beltrami_core::OptionError::Choice { solver, .. })) => {
            assert_eq!(solver, "tutte");
            e.to_string()
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
}

#[test]
fn rejects_what_it_cannot_do() {
    let torus = Mesh::from_soup(&torus(12, 8, 2.0, 0.5, Cells::Quads)).unwrap();
    let message = unsupported_message(Tutte.check(&Problem::new(&torus, Target::Disk)));
    assert!(
        message.contains("genus 1") && message.contains("beltrami cut"),
        "{message}"
    );

    let mesh = jittered(6, Cells::Triangles, 0.2, 8);
    let mut problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Free));
    assert!(unsupported_message(Tutte.check(&problem)).contains("lscm"));
    problem.target = Target::Sphere;
    unsupported_message(Tutte.check(&problem));
    problem.target = Target::Disk;
    problem.options.set_text("weights", "cotan");
    assert!(unsupported_message(Tutte.check(&problem)).contains("harmonic"));
    problem.options = Options::new();
    problem.goal = beltrami_core::Goal::Extremal;
    unsupported_message(Tutte.check(&problem));
    problem.goal = beltrami_core::Goal::default();
    let b = boundary_vertices(&mesh);
    problem.constraints = vec![Pin {
        vertex: b[0],
        position: Some(Position::Planar(Complex64::new(0.0, 0.0))),
    }]
    .into();
    unsupported_message(Tutte.check(&problem));
    problem.constraints = vec![
        Pin {
            vertex: b[0],
            position: None,
        },
        Pin {
            vertex: b[1],
            position: None,
        },
    ]
    .into();
    unsupported_message(Tutte.check(&problem));
    problem.constraints = beltrami_core::Constraints::new();
    assert!(Tutte.check(&problem).is_ok());

    // A curved source cannot keep its boundary.
    let hemi = hemisphere();
    let message =
        unsupported_message(Tutte.check(&Problem::new(&hemi, Target::Plane(PlanarBoundary::Keep))));
    assert!(message.contains("z = 0"), "{message}");
}

#[test]
fn invalid_boundaries_name_the_culprit() {
    let mesh = jittered(6, Cells::Triangles, 0.2, 9);
    let invalid = |target: PlanarBoundary, pins: Vec<Pin>| {
        let mut problem = Problem::new(&mesh, Target::Plane(target));
        problem.constraints = pins.into();
        match Tutte.check(&problem) {
            Err(e @ SolverError::Boundary { solver, .. }) => {
                assert_eq!(solver, "tutte");
                // The typed boundary error is kept as the source.
                assert!(
                    std::error::Error::source(&e)
                        .is_some_and(|s| s.is::<beltrami_fem::BoundaryError>())
                );
                e.to_string()
            }
            other => panic!("expected a boundary error, got {other:?}"),
        }
    };
    let dart = vec![
        Complex64::new(0.0, 0.0),
        Complex64::new(2.0, 0.0),
        Complex64::new(1.0, 0.5),
        Complex64::new(1.0, 2.0),
    ];
    assert!(invalid(PlanarBoundary::Polygon(dart), vec![]).contains("corner 2"));
    let interior = mesh
        .vertices()
        .find(|&v| !mesh.is_boundary_vertex(v))
        .unwrap();
    let message = invalid(
        PlanarBoundary::Circle,
        vec![Pin {
            vertex: interior,
            position: None,
        }],
    );
    assert!(message.contains(&interior.to_string()), "{message}");
    let message = invalid(
        PlanarBoundary::Given(vec![Complex64::new(0.0, 0.0); 3]),
        vec![],
    );
    assert!(message.contains("3 values"), "{message}");
}
