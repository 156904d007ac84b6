//! LSCM: exact on planar meshes (the identity is conformal), close to conformal on the
//! hemisphere, pins honoured exactly, and clear errors for other topologies and pins.

mod common;

use beltrami_core::{Context, Pin, PlanarBoundary, Position, Problem, Solver, SolverError, Target};
use beltrami_fem::operators::{beltrami_operator, weighted_residual};
use beltrami_fem::{DofConstraints, DofMap, Elements, Frame, LeastSquaresSolver};
use beltrami_init::Lscm;
use beltrami_mesh::primitives::{Cells, icosphere, torus};
use beltrami_mesh::{Mesh, Point3};
use beltrami_sparse::NESTED_DISSECTION_FROM;
use beltrami_sparse::SolveOptions;
use common::{
    boundary_vertices, flipped_faces, hemisphere, identity_error, jittered, planar, shared_disks,
    summary,
};
use num_complex::Complex64;

fn free(mesh: &Mesh) -> Problem<'_> {
    Problem::new(mesh, Target::Plane(PlanarBoundary::Free))
}

fn own_position(mesh: &Mesh, v: beltrami_mesh::VertexId) -> Complex64 {
    let p = mesh.position(v);
    Complex64::new(p.x, p.y)
}

#[test]
fn reproduces_a_planar_mesh_pinned_at_its_own_positions() {
    // Quads jittered by 0.25 cells or more may fold (a concave quad is not a mesh).
    for (cells, amount, seed) in [(Cells::Triangles, 0.35, 21), (Cells::Quads, 0.24, 22)] {
        let mesh = jittered(16, cells, amount, seed);
        let b = boundary_vertices(&mesh);
        let mut problem = free(&mesh);
        problem.constraints = [b[0], b[b.len() / 3]]
            .iter()
            .map(|&v| Pin {
                vertex: v,
                position: Some(Position::Planar(own_position(&mesh, v))),
            })
            .collect::<Vec<_>>()
            .into();
        let solution = Lscm.solve(&problem, &mut Context::new()).unwrap();
        let err = identity_error(&mesh, planar(solution.map().expect("a map")));
        assert!(err < 1e-9, "{cells:?}: {err:e}");
        assert!(solution.metrics.energy_history[0] < 1e-20);
    }
}

/// The pinned vertices of a map with default pins (exactly at 0 and 1) and the largest
/// distance of the map from the similarity `z -> (z - z_p) / (z_q - z_p)` through them.
fn similarity_error(
    mesh: &Mesh,
    map: &[Complex64],
) -> (beltrami_mesh::VertexId, beltrami_mesh::VertexId, f64) {
    let at = |z: Complex64| mesh.vertices().find(|v| map[v.idx()] == z);
    let (Some(p), Some(q)) = (at(Complex64::new(0.0, 0.0)), at(Complex64::new(1.0, 0.0))) else {
        panic!("no vertex exactly at (0, 0) and (1, 0)");
    };
    let (zp, zq) = (own_position(mesh, p), own_position(mesh, q));
    let a = 1.0 / (zq - zp);
    let worst = mesh
        .vertices()
        .map(|v| (map[v.idx()] - a * (own_position(mesh, v) - zp)).norm())
        .fold(0.0, f64::max);
    (p, q, worst)
}

#[test]
fn default_pins_give_a_similarity_of_a_planar_mesh() {
    let mesh = jittered(12, Cells::Triangles, 0.3, 23);
    let solution = Lscm.solve(&free(&mesh), &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    // The pinned vertices are exactly at 0 and 1; the map is z -> a z + b through them.
    let (p, q, worst) = similarity_error(&mesh, map);
    assert!(mesh.is_boundary_vertex(p) && mesh.is_boundary_vertex(q));
    assert!(worst < 1e-9, "{worst:e}");
    // Far apart: the diagonal of the unit square.
    let (zp, zq) = (own_position(&mesh, p), own_position(&mesh, q));
    assert!(((zq - zp).norm() - 2f64.sqrt()).abs() < 1e-12);
    assert!(solution.report.notes.iter().any(|n| n.contains("pinned")));
}

#[test]
fn a_mesh_ordered_from_its_vertex_graph_gives_the_similarity() {
    // 103,041 vertices: from the nested-dissection size, the vertex graph is dissected
    // while the DOF map and the pattern are made, and the order carried to the unknowns.
    // (Jittered by 0.1 of the spacing: by 0.3, 8 of the 204,800 faces turn over, and
    // the identity is no longer conformal.)
    let mesh = jittered(320, Cells::Triangles, 0.1, 24);
    assert!(mesh.vertex_count() >= NESTED_DISSECTION_FROM);
    let solution = Lscm.solve(&free(&mesh), &mut Context::new()).unwrap();
    let (_, _, worst) = similarity_error(&mesh, planar(solution.map().expect("a map")));
    // Two pins leave the free-boundary system ill-conditioned: 1.4e-6 on the
    // 1M-triangle disk (docs/benchmarks.md).
    assert!(worst < 1e-6, "{worst:e}");
}

#[test]
fn hemisphere_is_nearly_conformal() {
    let mesh = hemisphere();
    let solution = Lscm.solve(&free(&mesh), &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    println!("hemisphere lscm: {}", summary(&solution));
    let stats = solution.metrics.distortion.unwrap();
    assert_eq!(stats.flipped, 0);
    assert_eq!(flipped_faces(&mesh, map).len(), 0);
    // Measured: mu mean 0.0095, max 0.0234 (3600 triangles); asserted with a margin.
    assert!(stats.mu_mean < 0.02, "mu mean {}", stats.mu_mean);
    assert!(stats.mu_max < 0.05, "mu max {}", stats.mu_max);
    let at = |z: Complex64| map.iter().filter(|&&w| w == z).count();
    assert_eq!(at(Complex64::new(0.0, 0.0)), 1);
    assert_eq!(at(Complex64::new(1.0, 0.0)), 1);
}

/// On triangles LSCM assembles its normal equations from the faces' sides; the map is
/// the minimizer of `|W^(1/2) D_zbar x|^2` through the elements all the same.
#[test]
fn triangles_minimize_the_weighted_d_zbar_residual() {
    let mesh = hemisphere();
    let solution = Lscm.solve(&free(&mesh), &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    let pinned = |z: Complex64| {
        mesh.vertices()
            .find(|v| map[v.idx()] == z)
            .expect("a pinned vertex")
    };
    let mut constraints = DofConstraints::new();
    for z in [Complex64::new(0.0, 0.0), Complex64::new(1.0, 0.0)] {
        constraints.fix(pinned(z), z);
    }
    let dofs = DofMap::complex(mesh.vertex_count(), &constraints).unwrap();
    let elements = Elements::new(&mesh, Frame::Face).unwrap();
    let zero = vec![Complex64::new(0.0, 0.0); mesh.face_count()];
    let dzbar = beltrami_operator(&mesh, &elements, &zero).unwrap();
    let weights: Vec<f64> = elements.points().iter().map(|q| q.weight).collect();
    let mut solver =
        LeastSquaresSolver::new(dzbar.symbolic(), &dofs, SolveOptions::default()).unwrap();
    let rhs = vec![Complex64::new(0.0, 0.0); dzbar.nrows()];
    let expected = solver.solve(dzbar.as_ref(), Some(&weights), &rhs).unwrap();
    let worst = map
        .iter()
        .zip(&expected)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-11, "{worst:e}");
    let energy = weighted_residual(&dzbar, &expected, &weights);
    let reported = solution.metrics.energy_history[0];
    assert!(
        (reported - energy).abs() < 1e-9 * energy,
        "{reported} against {energy}"
    );
}

#[test]
fn pins_without_positions_go_to_zero_and_one() {
    let mesh = hemisphere();
    let b = boundary_vertices(&mesh);
    let mut problem = free(&mesh);
    problem.constraints = vec![
        Pin {
            vertex: b[7],
            position: None,
        },
        Pin {
            vertex: b[70],
            position: None,
        },
    ]
    .into();
    let solution = Lscm.solve(&problem, &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    assert_eq!(map[b[7].idx()], Complex64::new(0.0, 0.0));
    assert_eq!(map[b[70].idx()], Complex64::new(1.0, 0.0));
    assert!(solution.report.notes.iter().all(|n| !n.contains("pinned")));
}

#[test]
fn runs_on_the_shared_disks() {
    let Some(meshes) = shared_disks("lscm runs_on_the_shared_disks") else {
        return;
    };
    for (name, mesh) in &meshes {
        let solution = Lscm.solve(&free(mesh), &mut Context::new()).unwrap();
        let map = planar(solution.map().expect("a map"));
        println!("{name} lscm: {}", summary(&solution));
        assert!(map.iter().all(|z| z.is_finite()), "{name}");
        assert_eq!(
            solution.metrics.flipped(),
            Some(flipped_faces(mesh, map).len()),
            "{name}"
        );
    }
}

fn unsupported<T: std::fmt::Debug>(result: Result<T, SolverError>) -> String {
    match result {
        Err(SolverError::Unsupported { solver, message }) => {
            assert_eq!(solver, "lscm");
            message
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
}

#[test]
fn other_topologies_are_unsupported() {
    let torus = Mesh::from_soup(&torus(16, 8, 2.0, 0.6, Cells::Triangles)).unwrap();
    let message = unsupported(Lscm.check(&free(&torus)));
    assert!(message.contains("genus 1"), "{message}");
    assert!(message.contains("beltrami cut"), "{message}");
    let sphere = Mesh::from_soup(&icosphere(2)).unwrap();
    let message = unsupported(Lscm.check(&free(&sphere)));
    assert!(message.contains("genus 0 and no boundary"), "{message}");
    // solve checks too.
    assert!(matches!(
        Lscm.solve(&free(&sphere), &mut Context::new()),
        Err(SolverError::Unsupported { .. })
    ));
}

#[test]
fn pin_counts_and_targets_are_checked() {
    let mesh = jittered(6, Cells::Quads, 0.2, 24);
    let b = boundary_vertices(&mesh);
    let pin = |k: usize, position: Option<Complex64>| Pin {
        vertex: b[k],
        position: position.map(Position::Planar),
    };
    let mut problem = free(&mesh);
    problem.constraints = vec![pin(0, None)].into();
    assert!(unsupported(Lscm.check(&problem)).contains("two"));
    problem.constraints = vec![pin(0, None), pin(3, Some(Complex64::new(1.0, 1.0)))].into();
    unsupported(Lscm.check(&problem));
    problem.constraints = vec![pin(0, None), pin(3, None), pin(6, None)].into();
    unsupported(Lscm.check(&problem));
    problem.constraints = vec![
        Pin {
            vertex: b[0],
            position: Some(Position::Spatial(Point3::new(0.0, 0.0, 1.0))),
        },
        pin(3, Some(Complex64::new(1.0, 0.0))),
    ]
    .into();
    unsupported(Lscm.check(&problem));
    // Three pins with positions: all honoured.
    let z = [
        Complex64::new(0.0, 0.0),
        Complex64::new(2.0, 0.0),
        Complex64::new(1.0, 1.5),
    ];
    problem.constraints = vec![pin(0, Some(z[0])), pin(8, Some(z[1])), pin(16, Some(z[2]))].into();
    let solution = Lscm.solve(&problem, &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    for (k, zk) in [0, 8, 16].iter().zip(z) {
        assert_eq!(map[b[*k].idx()], zk);
    }
    // Coinciding pins would collapse the map.
    problem.constraints = vec![pin(0, Some(z[1])), pin(8, Some(z[1]))].into();
    assert!(matches!(
        Lscm.check(&problem),
        Err(SolverError::InvalidInput { .. })
    ));
    // A pin beyond the mesh.
    problem.constraints = vec![
        pin(0, None),
        Pin {
            vertex: beltrami_mesh::VertexId(10_000),
            position: None,
        },
    ]
    .into();
    match Lscm.check(&problem) {
        Err(e @ SolverError::Constraint { .. }) => {
            let message = e.to_string();
            assert!(message.contains("v10000"), "{message}")
        }
        other => panic!("expected a constraint error, got {other:?}"),
    }
    problem.constraints = beltrami_core::Constraints::new();
    problem.target = Target::Disk;
    assert!(unsupported(Lscm.check(&problem)).contains("harmonic"));
}
