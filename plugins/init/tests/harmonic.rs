//! The harmonic map: linear precision of the cotangent weights (a planar mesh with its
//! own boundary comes back unchanged, triangles and quads), and honest flip reports.

mod common;

use beltrami_core::{Context, PlanarBoundary, Problem, Solver, SolverError, Target};
use beltrami_fem::EdgeWeights;
use beltrami_init::Harmonic;
use beltrami_mesh::primitives::{Cells, icosphere};
use beltrami_mesh::{Mesh, PolygonSoup};
use common::{
    flipped_faces, hemisphere, identity_error, jittered, planar, shared_disks, summary,
    weighted_mean_error,
};
use nalgebra::Point3;

#[test]
fn reproduces_a_planar_mesh_with_its_own_boundary() {
    // Quads jittered by 0.25 cells or more may fold (a concave quad is not a mesh).
    for (cells, amount, seed) in [(Cells::Triangles, 0.35, 11), (Cells::Quads, 0.24, 12)] {
        let mesh = jittered(16, cells, amount, seed);
        let problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Keep));
        let solution = Harmonic.solve(&problem, &mut Context::new()).unwrap();
        let err = identity_error(&mesh, planar(solution.map().expect("a map")));
        assert!(err < 1e-12, "{cells:?}: {err:e}");
        assert_eq!(solution.metrics.flipped(), Some(0));
        // The identity is conformal: |mu| vanishes to rounding.
        let mu_max = solution.metrics.distortion.unwrap().mu_max;
        assert!(mu_max < 1e-10, "{cells:?}: {mu_max:e}");
    }
}

#[test]
fn hemisphere_onto_the_circle_reports_its_flips() {
    let mesh = hemisphere();
    let problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Circle));
    let solution = Harmonic.solve(&problem, &mut Context::new()).unwrap();
    let map = planar(solution.map().expect("a map"));
    println!("hemisphere harmonic circle: {}", summary(&solution));
    assert!(map.iter().all(|z| z.is_finite()));
    let measured = flipped_faces(&mesh, map).len();
    assert_eq!(solution.metrics.flipped(), Some(measured));
    assert!(measured <= mesh.face_count() / 100, "{measured} flips");
    let noted = solution.report.notes.iter().any(|n| n.contains("flipped"));
    assert_eq!(noted, measured > 0, "{:?}", solution.report.notes);
    // The harmonic map of a cap of the sphere is nearly conformal (stereographic
    // projection is the conformal one, and it maps the boundary circle uniformly).
    // Measured: mu mean 0.0099, max 0.0290; asserted with a margin.
    let stats = solution.metrics.distortion.unwrap();
    assert!(stats.mu_mean < 0.02, "{}", stats.mu_mean);
    assert!(stats.mu_max < 0.06, "{}", stats.mu_max);
    let weights = EdgeWeights::cotangent(&mesh).unwrap();
    assert!(weighted_mean_error(&mesh, &weights, map) < 1e-10);
    // The Dirichlet energy is reported; it is at least the image area (pi, up to the
    // inscribed polygon), with equality only for conformal maps.
    let energy = solution.metrics.energy_history[0];
    assert!(energy > 3.1 && energy < 3.3, "{energy}");
}

/// A fan of eight triangles around one interior vertex, two of whose spokes face angles
/// adding up to more than `pi` (negative cotangent weights). Found by a random search;
/// its harmonic map onto the circle flips one triangle.
fn obtuse_fan() -> Mesh {
    let ring = [
        (-0.294, 0.054),
        (0.835, -0.213),
        (0.504, 0.823),
        (-0.216, 1.251),
        (-0.282, 0.332),
        (-1.190, 0.155),
        (-0.521, -0.574),
        (-0.122, -0.390),
        (1.242, -0.987),
    ];
    let positions: Vec<Point3<f64>> = ring.iter().map(|&(x, y)| Point3::new(x, y, 0.0)).collect();
    let triangles: Vec<[u32; 3]> = (0..8).map(|k| [0, 1 + k, 1 + (k + 1) % 8]).collect();
    Mesh::from_soup(&PolygonSoup::from_triangles(positions, &triangles)).unwrap()
}

#[test]
fn negative_weights_and_flips_are_noted() {
    let mesh = obtuse_fan();
    let problem = Problem::new(&mesh, Target::Plane(PlanarBoundary::Circle));
    let solution = Harmonic.solve(&problem, &mut Context::new()).unwrap();
    let notes = &solution.report.notes;
    assert!(
        notes
            .iter()
            .any(|n| n.contains("2 cotangent weights of interior vertices are negative")),
        "{notes:?}"
    );
    let measured = flipped_faces(&mesh, planar(solution.map().expect("a map"))).len();
    assert_eq!(measured, 1);
    assert_eq!(solution.metrics.flipped(), Some(measured));
    assert!(
        notes.iter().any(|n| n.contains("1 of 8 faces are flipped")),
        "{notes:?}"
    );
    // Tutte's positive weights never flip it.
    let tutte = beltrami_init::Tutte
        .solve(&problem, &mut Context::new())
        .unwrap();
    assert_eq!(tutte.metrics.flipped(), Some(0));
}

#[test]
fn other_weights_may_be_chosen() {
    let mesh = hemisphere();
    let mut problem = Problem::new(&mesh, Target::Disk);
    problem.options.set_text("weights", "mean-value");
    let solution = Harmonic.solve(&problem, &mut Context::new()).unwrap();
    assert_eq!(solution.metrics.flipped(), Some(0));
    assert!(solution.metrics.energy_history.is_empty());
}

#[test]
fn runs_on_the_shared_disks() {
    let Some(meshes) = shared_disks("harmonic runs_on_the_shared_disks") else {
        return;
    };
    for (name, mesh) in &meshes {
        let problem = Problem::new(mesh, Target::Plane(PlanarBoundary::Circle));
        let solution = Harmonic.solve(&problem, &mut Context::new()).unwrap();
        let map = planar(solution.map().expect("a map"));
        println!("{name} harmonic circle: {}", summary(&solution));
        assert!(map.iter().all(|z| z.is_finite()), "{name}");
        assert_eq!(
            solution.metrics.flipped(),
            Some(flipped_faces(mesh, map).len()),
            "{name}"
        );
    }
}

#[test]
fn rejects_closed_meshes() {
    let sphere = Mesh::from_soup(&icosphere(2)).unwrap();
    match Harmonic.check(&Problem::new(&sphere, Target::Disk)) {
        Err(SolverError::Unsupported { solver, message }) => {
            assert_eq!(solver, "harmonic");
            assert!(message.contains("genus 0 and no boundary"), "{message}");
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
}
