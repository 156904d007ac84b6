//! The sphere solver: closed genus-0 meshes onto the unit sphere (the conformal start by
//! default, the Tutte embedding of the mesh minus one face on request; inverse
//! stereographic projection, Moebius centering, untangling). Checked
//! here without the solver's own helpers: unit length, the centre of mass of the area,
//! the covering degree (signed solid angles add up to 4 pi), faces facing outward, and
//! near-conformality on a round sphere.

mod common;

use std::f64::consts::PI;
use std::io::Write as _;
use std::path::PathBuf;

use beltrami_core::{
    Context, Curve, Goal, Map, Pin, PlanarBoundary, Problem, Solution, Solver, SolverError, Target,
};
use beltrami_init::Sphere;
use beltrami_mesh::io::read;
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::renumber_breadth_first;
use beltrami_mesh::{BuildOptions, FaceId, Mesh, Point3, PolygonSoup, Vector3, VertexId};
use common::{hemisphere, summary};

/// The triangles a face's image is judged by: the face itself, or both diagonal splits
/// of a quad (its four corner triangles).
fn judged_triangles(mesh: &Mesh, f: FaceId) -> Vec<[VertexId; 3]> {
    let v: Vec<VertexId> = mesh.face_vertices(f).collect();
    if v.len() == 3 {
        vec![[v[0], v[1], v[2]]]
    } else {
        vec![
            [v[0], v[1], v[2]],
            [v[0], v[2], v[3]],
            [v[0], v[1], v[3]],
            [v[1], v[2], v[3]],
        ]
    }
}

/// Faces whose image faces the centre: a judged triangle whose normal has a
/// non-positive component along the mean of the face's vertex images.
fn inward_count(mesh: &Mesh, image: &[Point3<f64>]) -> usize {
    mesh.faces()
        .filter(|&f| {
            let mean: Vector3<f64> = mesh
                .face_vertices(f)
                .map(|v| image[v.idx()].coords)
                .sum::<Vector3<f64>>();
            judged_triangles(mesh, f).iter().any(|t| {
                let [a, b, c] = t.map(|v| image[v.idx()]);
                (b - a).cross(&(c - a)).dot(&mean) <= 0.0
            })
        })
        .count()
}

/// The signed solid angle of the spherical triangle `a b c` (unit vectors), by
/// Van Oosterom and Strackee's formula.
fn solid_angle(a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> f64 {
    let numerator = a.dot(&b.cross(&c));
    let denominator = 1.0 + a.dot(&b) + b.dot(&c) + c.dot(&a);
    2.0 * numerator.atan2(denominator)
}

/// `(sum of signed solid angles, sum of their absolute values)` of the image faces
/// (quads split along `v0 v2`): `4 pi` and `4 pi` for a map covering the sphere once
/// without folds.
fn solid_angles(mesh: &Mesh, image: &[Point3<f64>]) -> (f64, f64) {
    let mut signed = 0.0;
    let mut absolute = 0.0;
    for f in mesh.faces() {
        let v: Vec<Vector3<f64>> = mesh
            .face_vertices(f)
            .map(|v| image[v.idx()].coords)
            .collect();
        for k in 1..v.len() - 1 {
            let omega = solid_angle(v[0], v[k], v[k + 1]);
            signed += omega;
            absolute += omega.abs();
        }
    }
    (signed, absolute)
}

/// `sum_f A_f x_f / sum_f A_f` with source face areas `A_f` and `x_f` the mean of face
/// `f`'s vertex images projected onto the sphere.
fn center_of_mass(mesh: &Mesh, image: &[Point3<f64>]) -> Vector3<f64> {
    let mut sum = Vector3::zeros();
    let mut total = 0.0;
    for f in mesh.faces() {
        let mean: Vector3<f64> = mesh
            .face_vertices(f)
            .map(|v| image[v.idx()].coords)
            .sum::<Vector3<f64>>();
        let area = mesh.face_area(f);
        sum += area * mean.normalize();
        total += area;
    }
    sum / total
}

fn solve(mesh: &Mesh) -> Solution {
    solve_with(&Problem::new(mesh, Target::Sphere))
}

fn solve_with(problem: &Problem<'_>) -> Solution {
    Sphere
        .solve(problem, &mut Context::new())
        .unwrap_or_else(|e| panic!("sphere failed: {e}"))
}

fn spatial(map: &Map) -> &[Point3<f64>] {
    map.as_spatial().expect("a spatial map")
}

/// Checks a solution of `mesh`: unit-length images, the centre of mass within 1e-3 of
/// the origin, covering degree 1, the report's flip count equal to this file's count
/// and at most `max_flipped`. Returns the flip count.
fn check(name: &str, mesh: &Mesh, solution: &Solution, max_flipped: usize) -> usize {
    let image = spatial(solution.map().expect("a map"));
    let report = &solution.report;
    let metrics = &solution.metrics;
    println!("{name}: {}", summary(solution));
    for note in &report.notes {
        println!("  {note}");
    }
    assert_eq!(image.len(), mesh.vertex_count(), "{name}");
    for (i, p) in image.iter().enumerate() {
        let off = (p.coords.norm() - 1.0).abs();
        assert!(off <= 1e-12, "{name}: vertex {i} is {off:e} off the sphere");
    }
    let c = center_of_mass(mesh, image);
    println!(
        "  centre of mass {:.2e} after {} steps",
        c.norm(),
        metrics.iterations
    );
    assert!(c.norm() <= 1e-3, "{name}: centre of mass {c:?}");
    assert!(metrics.iterations <= 100, "{name}");
    assert_eq!(metrics.energy_history.len(), metrics.iterations, "{name}");
    let (signed, absolute) = solid_angles(mesh, image);
    assert!(
        (signed - 4.0 * PI).abs() <= 1e-8,
        "{name}: the image covers the sphere {} times",
        signed / (4.0 * PI)
    );
    let flipped = inward_count(mesh, image);
    assert_eq!(
        metrics.flipped(),
        Some(flipped),
        "{name}: flip counts differ"
    );
    if flipped == 0 {
        assert!(
            (absolute - 4.0 * PI).abs() <= 1e-8,
            "{name}: no face flipped but the image folds ({absolute} sr)"
        );
    }
    assert!(
        flipped <= max_flipped,
        "{name}: {flipped} flipped faces, at most {max_flipped} expected"
    );
    let stages: Vec<&str> = report.timings.iter().map(|(s, _)| s.as_str()).collect();
    let tutte = ["puncture", "tutte", "projection"];
    let conformal = ["harmonic", "projection", "corrections"];
    let start = if stages.starts_with(&tutte) {
        &tutte
    } else {
        &conformal
    };
    let last = ["normalization", "untangle", "distortion"];
    assert_eq!(stages[..3], start[..], "{name}: {stages:?}");
    assert_eq!(stages[3..], last[..], "{name}: {stages:?}");
    let removed = report.notes.iter().any(|n| {
        (n.starts_with("removed face") || n.starts_with("punctured face"))
            && n.contains("input index")
    });
    assert!(removed, "{name}: no note names the removed face");
    let mu = metrics.mu.as_ref().expect("mu measured");
    assert_eq!(mu.len(), mesh.face_count(), "{name}");
    flipped
}

#[test]
fn icosphere_goes_onto_the_sphere_nearly_conformally() {
    let mesh = Mesh::from_soup(&icosphere(3)).unwrap();
    let problem = Problem::new(&mesh, Target::Sphere);
    Sphere.check(&problem).unwrap();
    let solution = solve_with(&problem);
    assert_eq!(check("icosphere(3)", &mesh, &solution, 0), 0);
    // The identity has mu = 0; this map differs from a rotation by the discretization
    // error of the linear solves. Measured: mean 0.0008, l2 0.0011, max 0.0046.
    let d = solution.metrics.distortion.unwrap();
    assert!(d.mu_mean < 0.002, "mu mean {}", d.mu_mean);
    assert!(d.mu_l2 < 0.003, "mu l2 {}", d.mu_l2);
    assert!(d.mu_max < 0.01, "mu max {}", d.mu_max);
}

#[test]
fn the_distortion_of_the_icosphere_shrinks_under_refinement() {
    // Second order in the edge length. Measured mu mean: 0.0030, 0.0008, 0.0002 for 2, 3,
    // 4 subdivisions.
    let means: Vec<f64> = (2..=4)
        .map(|s| {
            let mesh = Mesh::from_soup(&icosphere(s)).unwrap();
            let solution = solve(&mesh);
            check(&format!("icosphere({s})"), &mesh, &solution, 0);
            solution.metrics.distortion.unwrap().mu_mean
        })
        .collect();
    println!("mu mean by subdivision 2, 3, 4: {means:.4?}");
    assert!(means[1] < 0.35 * means[0], "{means:?}");
    assert!(means[2] < 0.35 * means[1], "{means:?}");
}

#[test]
fn the_tutte_start_works_with_both_weights() {
    let mesh = Mesh::from_soup(&icosphere(2)).unwrap();
    for weights in ["mean-value", "uniform"] {
        let mut problem = Problem::new(&mesh, Target::Sphere);
        problem.options.set_text("start", "tutte");
        problem.options.set_text("weights", weights);
        let solution = solve_with(&problem);
        let name = format!("icosphere(2), tutte, {weights}");
        assert_eq!(check(&name, &mesh, &solution, 0), 0);
        assert_eq!(solution.report.timings[1].0, "tutte", "{name}");
    }
}

#[test]
fn the_smallest_spheres_work() {
    let tetrahedron = PolygonSoup::from_triangles(
        vec![
            Point3::new(1.0, 1.0, 1.0),
            Point3::new(1.0, -1.0, -1.0),
            Point3::new(-1.0, 1.0, -1.0),
            Point3::new(-1.0, -1.0, 1.0),
        ],
        &[[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    );
    let cube = PolygonSoup::from_quads(
        (0..8)
            .map(|i| {
                let bit = |k: u32| if i & (1 << k) != 0 { 1.0 } else { -1.0 };
                Point3::new(bit(0), bit(1), bit(2))
            })
            .collect(),
        &[
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ],
    );
    for (name, soup) in [("tetrahedron", tetrahedron), ("cube", cube)] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        assert!(signed_volume(&mesh) > 0.0, "{name} faces outward");
        let solution = solve(&mesh);
        assert_eq!(check(name, &mesh, &solution, 0), 0);
    }
}

/// The signed volume of a closed mesh (quads split along `v0 v2`).
fn signed_volume(mesh: &Mesh) -> f64 {
    mesh.faces()
        .map(|f| {
            let p: Vec<Vector3<f64>> = mesh
                .face_vertices(f)
                .map(|v| mesh.position(v).coords)
                .collect();
            (1..p.len() - 1)
                .map(|k| p[0].dot(&p[k].cross(&p[k + 1])))
                .sum::<f64>()
                / 6.0
        })
        .sum()
}

#[test]
fn inward_facing_sources_still_map_outward_with_a_note() {
    let soup = icosphere(2);
    let mut reversed = PolygonSoup::new(soup.positions.clone());
    for face in soup.faces() {
        let mut face = face.to_vec();
        face.reverse();
        reversed.push_face(&face);
    }
    let mesh = Mesh::from_soup(&reversed).unwrap();
    assert!(signed_volume(&mesh) < 0.0);
    let solution = solve(&mesh);
    assert_eq!(check("inward icosphere(2)", &mesh, &solution, 0), 0);
    assert!(
        solution
            .report
            .notes
            .iter()
            .any(|n| n.contains("negative signed volume")),
        "{:?}",
        solution.report.notes
    );
}

fn shared(name: &str) -> Option<Mesh> {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/meshes"
    ))
    .join(name);
    if !path.exists() {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED {name}: {} is absent",
            path.display()
        );
        return None;
    }
    Some(
        read(&path, &BuildOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .mesh,
    )
}

#[test]
fn spot_maps_without_flips() {
    let Some(mesh) = shared("g0_spot.obj") else {
        return;
    };
    let solution = solve(&mesh);
    assert_eq!(check("g0_spot", &mesh, &solution, 0), 0);
}

#[test]
fn bunny_maps_without_flips() {
    let Some(mesh) = shared("g0_bunny_closed.obj") else {
        return;
    };
    let solution = solve(&mesh);
    check("g0_bunny_closed", &mesh, &solution, 0);
}

#[test]
fn the_koala_renumbered_gets_the_same_patches_and_map() {
    let Some(mesh) = shared("g0_koala.obj") else {
        return;
    };
    let (renumbered, numbering) = renumber_breadth_first(&mesh).unwrap();
    // The Tutte start (registration's) folds 15 faces of the koala.
    let tutte = |mesh| {
        let mut problem = Problem::new(mesh, Target::Sphere);
        problem.options.set_text("start", "tutte");
        solve_with(&problem)
    };
    let (given, other) = (tutte(&mesh), tutte(&renumbered));
    let patches = |solution: &Solution| -> String {
        let notes = &solution.report.notes;
        let note = notes.iter().find(|n| n.contains("patches around them"));
        note.unwrap_or_else(|| panic!("no untangling: {notes:?}"))
            .clone()
    };
    // The solver renumbers the scattered koala itself, then patches the folded faces
    // in input order: the same patches as on the koala renumbered beforehand, and they
    // clear all 15 (in the renumbered face order they left 2).
    assert!(given.report.notes[0].starts_with("renumbered breadth-first"));
    assert_eq!(patches(&given), patches(&other));
    assert!(
        patches(&given).ends_with("leaving 0 flipped"),
        "{}",
        patches(&given)
    );
    let back = numbering.vertex_values_to_old(spatial(other.map().unwrap()));
    let image = spatial(given.map().unwrap());
    let apart = image
        .iter()
        .zip(&back)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max);
    assert!(apart < 1e-6, "maps {apart} apart");
}

#[test]
fn quad_meshes_map_without_flips() {
    for name in ["quad_horse.obj", "quad_fandisk.obj"] {
        let Some(mesh) = shared(name) else {
            continue;
        };
        assert!(mesh.quad_count() > 0, "{name} has quads");
        let solution = solve(&mesh);
        check(name, &mesh, &solution, 0);
    }
}

/// The error of solving `problem`, which `check` must give too.
fn rejected(problem: &Problem<'_>) -> String {
    let checked = Sphere.check(problem).expect_err("check accepts");
    let solved = Sphere
        .solve(problem, &mut Context::new())
        .expect_err("solve accepts");
    assert_eq!(checked.to_string(), solved.to_string());
    assert!(
        matches!(
            solved,
            SolverError::Unsupported { .. } | SolverError::Option(_)
        ),
        "{solved}"
    );
    solved.to_string()
}

#[test]
fn other_topologies_are_rejected_with_advice() {
    let ring = Mesh::from_soup(&torus(16, 8, 1.0, 0.3, Cells::Triangles)).unwrap();
    let message = rejected(&Problem::new(&ring, Target::Sphere));
    assert!(message.contains("genus 1"), "{message}");
    assert!(message.contains("beltrami cut"), "{message}");

    let square = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).unwrap();
    let disk = hemisphere();
    for mesh in [&square, &disk] {
        let message = rejected(&Problem::new(mesh, Target::Sphere));
        assert!(message.contains("one boundary loop"), "{message}");
        assert!(message.contains("lscm/tutte"), "{message}");
    }
}

#[test]
fn other_targets_goals_weights_and_constraints_are_rejected() {
    let mesh = Mesh::from_soup(&icosphere(1)).unwrap();
    let problem = |change: &dyn Fn(&mut Problem<'_>)| {
        let mut p = Problem::new(&mesh, Target::Sphere);
        change(&mut p);
        rejected(&p)
    };
    let message = problem(&|p| p.target = Target::Plane(PlanarBoundary::Circle));
    assert!(message.contains("unit sphere"), "{message}");
    let message = problem(&|p| p.target = Target::Surface);
    assert!(message.contains("unit sphere"), "{message}");
    let message = problem(&|p| p.goal = Goal::Conformal { p: 4.0 });
    assert!(message.contains("p = 4"), "{message}");
    let message = problem(&|p| p.goal = Goal::Extremal);
    assert!(message.contains("teichmuller"), "{message}");
    let message = problem(&|p| {
        p.options.set_text("weights", "cotan");
    });
    assert!(message.contains("cotangent"), "{message}");
    let message = problem(&|p| {
        p.constraints = vec![Pin {
            vertex: VertexId(3),
            position: None,
        }]
        .into()
    });
    assert!(
        message.contains("no pins") && message.contains("vertex v3"),
        "{message}"
    );
    let message = problem(&|p| {
        p.constraints = vec![Curve::open(
            vec![VertexId(0), VertexId(1)],
            vec![VertexId(0), VertexId(1)],
        )]
        .into()
    });
    assert!(message.contains("curves"), "{message}");
}

#[test]
fn the_solver_is_registered() {
    let mut registry = beltrami_core::Registry::new();
    beltrami_init::register(&mut registry);
    let solver = registry.get("sphere").unwrap();
    assert_eq!(solver.name(), "sphere");
    assert!(solver.description().contains("initialization"));
}
