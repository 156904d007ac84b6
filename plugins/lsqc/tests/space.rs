//! lsqc into R^3 (`Target::Surface`, the quaternionic least-squares map of
//! Gruber-Aulisa 2022) against exact answers: the identity of a curved surface is
//! conformal (`df^- = 0`) and comes back from its own boundary; an affine planar map
//! comes back from its own measured mu (the complex special case), triangles and quads;
//! the solve commutes with rotations of R^3 (frames and normals handled consistently);
//! a map between coaxial cylinders that keeps every normal comes back from its
//! developed mu under refinement (a developable surface); the frame rule of Lemma 3.4;
//! the area constraint (section 4.2) keeps the area to second order and fixes a closed
//! surface with one pin; a problem that fixes nothing is refused.

use beltrami_core::{Constraint, Context, Goal, Map, Pin, Position, Problem, Solver, Target};
use beltrami_fem::beltrami::{face_mu, rotate_frame};
use beltrami_fem::quaternion::quaternionic_mu;
use beltrami_fem::{BeltramiField, Elements, Frame};
use beltrami_lsqc::Lsqc;
use beltrami_mesh::primitives::{Cells, jittered_grid};
use beltrami_mesh::{Mesh, Point3, Vector3};
use nalgebra::{Rotation3, Unit};
use num_complex::Complex64;

/// A jittered grid bent onto a paraboloid cap `z = 0.4 (x^2 + y^2)` (curved, not
/// developable).
fn cap(n: usize, cells: Cells) -> Mesh {
    let mut soup = jittered_grid(n, n, cells, 0.3, 5);
    for p in &mut soup.positions {
        p.z = 0.4 * (p.x * p.x + p.y * p.y);
    }
    Mesh::from_soup(&soup).unwrap()
}

/// The problem of mapping `mesh` into space with `field` (`None`: conformal) and the
/// boundary held at `held`'s positions.
fn problem<'a>(mesh: &'a Mesh, field: Option<BeltramiField>, held: &[Point3<f64>]) -> Problem<'a> {
    let mut problem = Problem::new(mesh, Target::Surface);
    problem.goal = match field {
        Some(f) => Goal::Prescribed(f),
        None => Goal::Conformal { p: 2.0 },
    };
    for l in mesh.boundary_loop_list() {
        for v in l.vertices {
            problem.constraints.push(Constraint::Pin(Pin {
                vertex: v,
                position: Some(Position::Spatial(held[v.idx()])),
            }));
        }
    }
    problem
}

fn image(problem: &Problem<'_>) -> Vec<Point3<f64>> {
    let solution = Lsqc.solve(problem, &mut Context::new()).unwrap();
    match solution.map() {
        Some(Map::Spatial(points)) => points.clone(),
        other => panic!("expected a map into space, got {other:?}"),
    }
}

/// Held points for the cap's boundary: the cap sheared and bent.
fn bent(mesh: &Mesh) -> Vec<Point3<f64>> {
    mesh.positions()
        .iter()
        .map(|p| Point3::new(p.x + 0.3 * p.y * p.y, p.y, p.z + 0.2 * p.x))
        .collect()
}

fn largest_distance(a: &[Point3<f64>], b: &[Point3<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

#[test]
fn the_identity_of_a_curved_surface_is_conformal_and_comes_back() {
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = cap(8, cells);
        let own = mesh.positions().to_vec();
        let got = image(&problem(&mesh, None, &own));
        let error = largest_distance(&got, &own);
        assert!(error < 1e-10, "{cells:?}: identity off by {error}");
    }
}

#[test]
fn a_planar_map_with_its_own_measured_mu_comes_back() {
    // N = (0, 0, 1): the quaternionic problem is the complex one of Lui et al. 2014. An
    // affine map of a jittered planar grid into the plane z = 0, its mu measured per face
    // (Lemma 5.2) and prescribed, its boundary held: its residual vanishes, so the
    // least-squares map is the affine map itself, triangles and quads.
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = Mesh::from_soup(&jittered_grid(9, 9, cells, 0.3, 3)).unwrap();
        let exact: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::new(1.3 * p.x + 0.4 * p.y, 0.2 * p.x + 0.8 * p.y, 0.0))
            .collect();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let mu = face_mu(
            &elements,
            &quaternionic_mu(&elements, mesh.vertex_count(), &exact).unwrap(),
        );
        assert!(mu.iter().all(|m| m.norm() > 0.1), "a non-conformal map");
        let got = image(&problem(
            &mesh,
            Some(BeltramiField::new(Frame::Face, mu)),
            &exact,
        ));
        let error = largest_distance(&got, &exact);
        assert!(error < 1e-10, "{cells:?}: affine map off by {error}");
    }
}

#[test]
fn the_solve_commutes_with_rotations() {
    let mesh = cap(8, Cells::Triangles);
    let bent = bent(&mesh);
    let field = BeltramiField::new(
        Frame::Face,
        vec![num_complex::Complex64::new(0.2, -0.1); mesh.face_count()],
    );
    let before = image(&problem(&mesh, Some(field.clone()), &bent));
    let rotation =
        Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 0.5)), 0.7);
    // The same surface, the same held points, rotated; the face frames rotate with it.
    let rotated_source: Vec<Point3<f64>> = mesh.positions().iter().map(|p| rotation * p).collect();
    let rotated_mesh = mesh.with_positions(rotated_source).unwrap();
    let rotated_held: Vec<Point3<f64>> = bent.iter().map(|p| rotation * p).collect();
    let after = image(&problem(&rotated_mesh, Some(field), &rotated_held));
    let expected: Vec<Point3<f64>> = before.iter().map(|p| rotation * p).collect();
    let error = largest_distance(&after, &expected);
    assert!(error < 1e-9, "rotation changed the map by {error}");
}

#[test]
fn a_problem_that_fixes_nothing_is_refused() {
    let closed = Mesh::from_soup(&beltrami_mesh::primitives::icosphere(2)).unwrap();
    let problem = Problem::new(&closed, Target::Surface);
    let error = Lsqc.check(&problem).unwrap_err().to_string();
    assert!(error.contains("no boundary"), "{error}");
    // A field in the global frame has no meaning on a curved surface's faces in space.
    let mesh = cap(4, Cells::Triangles);
    let own = mesh.positions().to_vec();
    let field = BeltramiField::zero(Frame::Global, mesh.face_count());
    let error = Lsqc
        .check(&problem_with(&mesh, field, &own))
        .unwrap_err()
        .to_string();
    assert!(error.contains("face frame"), "{error}");
}

fn problem_with<'a>(mesh: &'a Mesh, field: BeltramiField, held: &[Point3<f64>]) -> Problem<'a> {
    problem(mesh, Some(field), held)
}

/// The largest distance from the unit sphere of the conformal map of a spherical cap
/// (the disk of level 4 lifted by inverse stereographic projection, radius 0.7 in the
/// plane) whose boundary slides along the sphere by the azimuth
/// `phi -> phi + amplitude sin phi`, with the normal constraint of weight `weight`
/// (`None`: without it).
fn cap_on_sphere(amplitude: f64, weight: Option<f64>) -> f64 {
    let mut soup = beltrami_mesh::primitives::disk(4);
    for p in &mut soup.positions {
        let (x, y) = (0.7 * p.x, 0.7 * p.y);
        let r2 = x * x + y * y;
        *p = Point3::new(2.0 * x, 2.0 * y, r2 - 1.0) / (r2 + 1.0);
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let held: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| {
            let phi = p.y.atan2(p.x);
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            let moved = phi + amplitude * phi.sin();
            Point3::new(rho * moved.cos(), rho * moved.sin(), p.z)
        })
        .collect();
    let mut problem = problem(&mesh, None, &held);
    if let Some(weight) = weight {
        problem.constraints.push(Constraint::Normal { weight });
    }
    image(&problem)
        .iter()
        .map(|p| (p.coords.norm() - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_normal_constraint_keeps_a_sphere_on_the_sphere_to_second_order() {
    // The constraint keeps every displacement tangent to the source (section 4.1,
    // linearized with N_old): the image leaves the sphere by the square of the
    // displacement, where the unconstrained map leaves it by the displacement itself.
    let amplitudes = [0.2, 0.1, 0.05];
    let free: Vec<f64> = amplitudes.iter().map(|&a| cap_on_sphere(a, None)).collect();
    let held: Vec<f64> = amplitudes
        .iter()
        .map(|&a| cap_on_sphere(a, Some(1e4)))
        .collect();
    println!("distance from the sphere: without {free:?}, with the normal constraint {held:?}");
    for (h, f) in held.iter().zip(&free) {
        assert!(h < f, "with {h}, without {f}");
    }
    for w in held.windows(2) {
        assert!(
            w[1] < 0.3 * w[0],
            "not second order in the displacement: {held:?}"
        );
    }
}

/// The developed coefficient of the linear map `(s, t) -> (a s, b s + c t)`:
/// `f_zbar / f_z` with `f_z = ((a + c) + i b) / 2`, `f_zbar = ((a - c) + i b) / 2`.
fn developed_mu(a: f64, b: f64, c: f64) -> Complex64 {
    Complex64::new(a - c, b) / Complex64::new(a + c, b)
}

/// A jittered `n x n` grid rolled onto the cylinder of radius 1 about the z axis
/// (`theta = 1.2 x`, `z = y`), and its developed coordinates `(s, t) = (theta, z)`.
fn cylinder(n: usize, cells: Cells) -> (Mesh, Vec<(f64, f64)>) {
    let soup = jittered_grid(n, n, cells, 0.3, 11);
    let developed: Vec<(f64, f64)> = soup.positions.iter().map(|p| (1.2 * p.x, p.y)).collect();
    let rolled: Vec<Point3<f64>> = developed
        .iter()
        .map(|&(s, t)| Point3::new(s.cos(), s.sin(), t))
        .collect();
    let mut rolled_soup = soup.clone();
    rolled_soup.positions = rolled;
    (Mesh::from_soup(&rolled_soup).unwrap(), developed)
}

/// The largest vertex error of lsqc on the cylinder of [`cylinder`] for the map onto the
/// coaxial cylinder of radius `a` with height `b s + c t` (developed: the linear map
/// `(s, t) -> (a s, b s + c t)`), given its developed coefficient in the face frames and
/// its boundary.
fn cylinder_error(n: usize, cells: Cells) -> f64 {
    let (a, b, c) = (1.3, 0.4, 0.8);
    let (mesh, developed) = cylinder(n, cells);
    let exact: Vec<Point3<f64>> = developed
        .iter()
        .map(|&(s, t)| Point3::new(a * s.cos(), a * s.sin(), b * s + c * t))
        .collect();
    let mu = mesh
        .faces()
        .map(|f| {
            let h = mesh.face_halfedge(f);
            let (p, q) = (
                developed[mesh.origin(h).idx()],
                developed[mesh.target(h).idx()],
            );
            rotate_frame(developed_mu(a, b, c), (q.1 - p.1).atan2(q.0 - p.0))
        })
        .collect();
    let got = image(&problem(
        &mesh,
        Some(BeltramiField::new(Frame::Face, mu)),
        &exact,
    ));
    largest_distance(&got, &exact)
}

#[test]
fn a_developable_surface_map_comes_back_under_refinement() {
    // The map of a cylinder patch onto a coaxial cylinder that keeps every normal,
    // developed the linear map (s, t) -> (1.3 s, 0.4 s + 0.8 t) (|mu| = 0.32): its
    // quaternionic mu is the developed one (mu1 + mu2 N with N the common normal), so
    // with that mu and its boundary the least-squares map reproduces it up to the
    // chords' error, which halves at least as the mesh does. (An unrolling into the
    // plane would not do: its image's tangent planes are not the source's, so df^- is
    // not mu df^+ for any normal-valued mu.)
    for cells in [Cells::Triangles, Cells::Quads] {
        let errors: Vec<f64> = [8, 16, 32]
            .iter()
            .map(|&n| cylinder_error(n, cells))
            .collect();
        println!("{cells:?}: vertex errors {errors:?}");
        for w in errors.windows(2) {
            assert!(w[1] < 0.5 * w[0], "{cells:?}: {errors:?}");
        }
        assert!(errors[2] < 2e-3, "{cells:?}: {errors:?}");
    }
}

#[test]
fn the_frame_rule_a_faces_first_edge_changed_gives_the_same_map() {
    // Listing a face from another corner turns its frame by the angle theta between the
    // old and the new first edge; by Lemma 3.4 its coefficient turns by e^{-2 i theta}
    // and the map stays.
    let mesh = cap(8, Cells::Triangles);
    let bent = bent(&mesh);
    let mu: Vec<Complex64> = (0..mesh.face_count())
        .map(|f| Complex64::from_polar(0.3, 0.7 * f as f64))
        .collect();
    let before = image(&problem(
        &mesh,
        Some(BeltramiField::new(Frame::Face, mu.clone())),
        &bent,
    ));
    let elements = Elements::new(&mesh, Frame::Face).unwrap();
    let mut soup = beltrami_mesh::PolygonSoup::new(mesh.positions().to_vec());
    let mut turned = Vec::with_capacity(mu.len());
    for f in mesh.faces() {
        let corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        let shift = f.idx() % 3;
        let listed: Vec<u32> = (0..3).map(|k| corners[(k + shift) % 3]).collect();
        soup.push_face(&listed);
        let frame = elements.face_points(f)[0].frame;
        let edge = mesh.position(beltrami_mesh::VertexId(listed[1]))
            - mesh.position(beltrami_mesh::VertexId(listed[0]));
        let theta = edge.dot(&frame.e2).atan2(edge.dot(&frame.e1));
        turned.push(rotate_frame(mu[f.idx()], theta));
    }
    let relisted = Mesh::from_soup(&soup).unwrap();
    assert!(
        relisted
            .faces()
            .any(|f| relisted.face_vertices(f).next() != mesh.face_vertices(f).next())
    );
    let after = image(&problem(
        &relisted,
        Some(BeltramiField::new(Frame::Face, turned)),
        &bent,
    ));
    let error = largest_distance(&after, &before);
    assert!(error < 1e-10, "the map moved by {error}");
}

/// The relative area change of the map of a paraboloid cap with boundary held in place
/// and `mu = amplitude e^{i 0.5 f}` per face, with or without the area constraint.
fn area_change(amplitude: f64, area: bool) -> f64 {
    let mesh = cap(12, Cells::Triangles);
    let own = mesh.positions().to_vec();
    let mu = (0..mesh.face_count())
        .map(|f| Complex64::from_polar(amplitude, 0.5 * f as f64))
        .collect();
    let mut problem = problem(&mesh, Some(BeltramiField::new(Frame::Face, mu)), &own);
    if area {
        problem.constraints.push(Constraint::Area);
    }
    let got = image(&problem);
    let moved = mesh.with_positions(got).unwrap();
    let total = |m: &Mesh| m.faces().map(|f| m.face_area(f)).sum::<f64>();
    (total(&moved) - total(&mesh)).abs() / total(&mesh)
}

#[test]
fn the_area_constraint_keeps_the_area_to_second_order() {
    // The constraint makes the first variation of the area vanish (section 4.2). With
    // the boundary held and a mostly tangential displacement the area change is of
    // second order either way, but the constraint removes most of it.
    let amplitudes = [0.2, 0.1, 0.05];
    let free: Vec<f64> = amplitudes.iter().map(|&a| area_change(a, false)).collect();
    let kept: Vec<f64> = amplitudes.iter().map(|&a| area_change(a, true)).collect();
    println!("relative area change: without {free:?}, with the area constraint {kept:?}");
    for (k, f) in kept.iter().zip(&free) {
        assert!(k < &(0.05 * f), "with {k}, without {f}");
    }
    for w in kept.windows(2) {
        assert!(w[1] < 0.35 * w[0], "not second order: {kept:?}");
    }
}

#[test]
fn the_area_constraint_fixes_a_closed_surface_with_one_pin() {
    // An ellipsoid, conformal goal, one vertex held: translations are fixed by the pin,
    // the scale by the area; the identity (zero distortion, the area kept) comes back.
    let mut soup = beltrami_mesh::primitives::icosphere(3);
    for p in &mut soup.positions {
        *p = Point3::new(1.5 * p.x, p.y, 0.7 * p.z);
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let mut problem = Problem::new(&mesh, Target::Surface);
    problem.goal = Goal::Conformal { p: 2.0 };
    problem.constraints.push(Constraint::Pin(Pin {
        vertex: beltrami_mesh::VertexId(0),
        position: Some(Position::Spatial(mesh.position(beltrami_mesh::VertexId(0)))),
    }));
    let error = Lsqc.check(&problem).unwrap_err().to_string();
    assert!(error.contains("pin a vertex"), "{error}");
    problem.constraints.push(Constraint::Area);
    let got = image(&problem);
    let error = largest_distance(&got, mesh.positions());
    assert!(error < 1e-8, "identity off by {error}");
}
