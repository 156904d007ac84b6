//! The promise of `register` on every road: a registration that ends (exit 0) has every
//! landmark on its target to rounding and no flipped face, with the flow's polish
//! included. The disk and the sphere have their own tests (`initial_map.rs`, the
//! solver's unit tests); here the torus, the cut-graph polygon of genus 2 and a surface
//! with four boundary loops. The shared meshes (`../shared/meshes`) are skipped with a
//! message when absent.

use std::f64::consts::TAU;
use std::io::Write;
use std::path::{Path, PathBuf};

use beltrami_core::{Constraint, Context, Landmark, Position, Problem, Solution, Solver, Target};
use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{BuildOptions, Mesh, Point3, VertexId, io};
use beltrami_register::Register;

fn shared(file: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/meshes")
        .join(file);
    if path.exists() {
        Some(path)
    } else {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: {} not found; this test needs ../shared beside the repo",
            path.display()
        );
        None
    }
}

fn read(path: &Path) -> Mesh {
    io::read(path, &BuildOptions::default()).unwrap().mesh
}

/// Registers `source` onto `target` with `marks` (source vertex, target point) and
/// checks the promise: no flipped face, every landmark within 1e-12 of the target's
/// diagonal.
fn register_exactly(source: &Mesh, target: &Mesh, marks: &[(VertexId, Point3<f64>)]) -> Solution {
    let mut problem = Problem::new(source, Target::Mesh(target));
    for &(vertex, point) in marks {
        problem.constraints.push(Constraint::Landmark(Landmark {
            vertex,
            position: Position::Spatial(point),
        }));
    }
    let settings = Register.check(&problem).unwrap();
    let solution = Register
        .run(&problem, &settings, &mut Context::new())
        .unwrap();
    assert_eq!(solution.metrics.flipped(), Some(0), "{:?}", solution.report);
    let diagonal = target.bounding_box().diagonal();
    assert_eq!(solution.extras.landmarks.len(), marks.len());
    for mark in &solution.extras.landmarks {
        assert!(
            mark.distance <= 1e-12 * diagonal,
            "landmark {} (source vertex {}) at {:e}",
            mark.index,
            mark.vertex,
            mark.distance
        );
    }
    solution
}

fn route(solution: &Solution) -> &str {
    solution.extras.route.as_deref().unwrap_or_default()
}

#[test]
fn a_torus_under_a_twist_keeps_every_landmark() {
    // Six landmarks along a twist of the tube, up to two target edges off the rotation
    // that places the first: matched on the torus with its seams glued.
    let (nu, nv) = (40, 16);
    let source = Mesh::from_soup(&primitives::torus(nu, nv, 3.0, 1.0, Cells::Triangles)).unwrap();
    let target = Mesh::from_soup(&primitives::torus(60, 24, 3.0, 1.0, Cells::Triangles)).unwrap();
    let marks: Vec<(VertexId, Point3<f64>)> =
        [(0, 0), (7, 3), (13, 8), (20, 12), (27, 5), (33, 14)]
            .iter()
            .map(|&(i, j): &(usize, usize)| {
                let twist = 2.0 * (TAU * j as f64 / nv as f64).sin();
                let ti = (1.5 * i as f64 + twist).round().rem_euclid(60.0) as usize;
                let tj = (1.5 * j as f64).round() as usize % 24;
                (
                    VertexId::from_usize(i * nv + j),
                    target.position(VertexId::from_usize(ti * 24 + tj)),
                )
            })
            .collect();
    let solution = register_exactly(&source, &target, &marks);
    assert!(
        route(&solution).starts_with("torus"),
        "{}",
        route(&solution)
    );
}

#[test]
fn genus_two_point_landmarks_inside_faces_are_kept() {
    // A genus-2 surface onto a turned copy, each landmark onto the centroid of a target
    // face next to its partner vertex: the point is made a vertex of the target and the
    // cut graphs are drawn through it.
    let Some(path) = shared("g2_eight.obj") else {
        return;
    };
    let eight = read(&path);
    let turned: Vec<Point3<f64>> = eight
        .positions()
        .iter()
        .map(|p| Point3::new(-p.y, p.x, p.z))
        .collect();
    let target = eight.with_positions(turned).unwrap();
    let marks: Vec<(VertexId, Point3<f64>)> = [10u32, 210, 410, 610]
        .iter()
        .map(|&v| {
            let face = target.vertex_faces(VertexId(v)).next().unwrap();
            let sum: nalgebra::Vector3<f64> = target
                .face_vertices(face)
                .map(|w| target.position(w).coords)
                .sum();
            (VertexId(v), Point3::from(sum / 3.0))
        })
        .collect();
    let solution = register_exactly(&eight, &target, &marks);
    assert!(
        route(&solution).starts_with("polygon"),
        "{}",
        route(&solution)
    );
    assert!(
        solution
            .report
            .notes
            .iter()
            .any(|n| n.contains("made vertices of the target for the cuts")),
        "{:?}",
        solution.report.notes
    );
}

#[test]
fn a_face_with_three_holes_keeps_its_eighteen_landmarks() {
    // Choi's multiply-connected pair: 15 landmarks on the four boundary loops and 3
    // inside, all corresponding vertices.
    let (Some(a), Some(b), Some(json)) = (
        shared("mc4_face_a.obj"),
        shared("mc4_face_b.obj"),
        shared("mc4_face_pair_landmarks.json"),
    ) else {
        return;
    };
    let (source, target) = (read(&a), read(&b));
    let text = std::fs::read_to_string(json).unwrap();
    let lists = |mesh: &str, key: &str| -> Vec<u32> {
        // The file's "face_a"/"face_b" objects hold the vertex lists under `key`.
        let start = text.find(mesh).unwrap();
        let at = start + text[start..].find(key).unwrap() + key.len();
        let open = at + text[at..].find('[').unwrap();
        let mut depth = 0;
        let mut end = open;
        for (k, c) in text[open..].char_indices() {
            match c {
                '[' => depth += 1,
                ']' => depth -= 1,
                _ => {}
            }
            if depth == 0 {
                end = open + k;
                break;
            }
        }
        text[open..=end]
            .split(|c: char| !c.is_ascii_digit())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect()
    };
    let mut marks = Vec::new();
    for key in ["\"boundary_landmarks\"", "\"interior_landmarks\""] {
        let from = lists("\"face_a\"", key);
        let onto = lists("\"face_b\"", key);
        assert_eq!(from.len(), onto.len());
        marks.extend(
            from.iter()
                .zip(&onto)
                .map(|(&s, &t)| (VertexId(s), target.position(VertexId(t)))),
        );
    }
    assert_eq!(marks.len(), 18);
    let solution = register_exactly(&source, &target, &marks);
    assert!(
        route(&solution).starts_with("polygon"),
        "{}",
        route(&solution)
    );
}
