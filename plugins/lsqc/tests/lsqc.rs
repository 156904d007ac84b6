//! LSQC: `mu = 0` is lscm; a constant `mu = k` with a free boundary and two pins gives
//! back the affine map `z + k conj(z)` (which catches a conjugated or negated `mu`); a
//! non-constant `mu = 0.6 z` on the disk converges at first order; clear errors for
//! `|mu| >= 1`, other topologies and unsupported targets.

use std::path::Path;

use beltrami_core::{
    Context, Goal, Map, Pin, PlanarBoundary, Position, Problem, Solver, SolverError, Target,
};
use beltrami_fem::Expr;
use beltrami_fem::MuError;
use beltrami_fem::{BeltramiField, Elements, FieldError, Frame};
use beltrami_init::Lscm;
use beltrami_lsqc::Lsqc;
use beltrami_mesh::io::read;
use beltrami_mesh::primitives::{Cells, jittered_grid, torus};
use beltrami_mesh::subdivision::subdivide;
use beltrami_mesh::{BuildOptions, FaceId, Mesh, PolygonSoup, VertexId};
use num_complex::Complex64;

fn jittered(n: usize, cells: Cells, seed: u64) -> Mesh {
    Mesh::from_soup(&jittered_grid(n, n, cells, 0.3, seed)).unwrap()
}

fn hemisphere() -> Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/disk_hemisphere.obj"
    );
    read(Path::new(path), &BuildOptions::default())
        .unwrap()
        .mesh
}

fn planar(map: &Map) -> &[Complex64] {
    match map {
        Map::Planar(z) => z,
        other => panic!("expected a planar map, got {other:?}"),
    }
}

fn z_of(mesh: &Mesh, v: VertexId) -> Complex64 {
    let p = mesh.position(v);
    Complex64::new(p.x, p.y)
}

fn prescribed<'a>(mesh: &'a Mesh, target: Target<'a>, field: BeltramiField) -> Problem<'a> {
    let mut problem = Problem::new(mesh, target);
    problem.goal = Goal::Prescribed(field);
    problem
}

fn max_distance(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

#[test]
fn zero_mu_with_default_pins_is_lscm() {
    let meshes = [
        ("hemisphere", hemisphere()),
        ("jittered triangles", jittered(12, Cells::Triangles, 31)),
        ("jittered quads", jittered(12, Cells::Quads, 32)),
    ];
    for (name, mesh) in &meshes {
        let free = Target::Plane(PlanarBoundary::Free);
        let lscm = Lscm
            .solve(&Problem::new(mesh, free.clone()), &mut Context::new())
            .unwrap();
        let field = BeltramiField::zero(Frame::Face, mesh.face_count());
        let lsqc = Lsqc
            .solve(&prescribed(mesh, free, field), &mut Context::new())
            .unwrap();
        let err = max_distance(
            planar(lsqc.map().expect("a map")),
            planar(lscm.map().expect("a map")),
        );
        println!("{name}: |lsqc - lscm| = {err:e}");
        assert!(err < 1e-10, "{name}: {err:e}");
        assert!(lsqc.report.notes.iter().any(|n| n.contains("pinned")));
    }
}

/// `f = z + k conj(z)`, whose Beltrami coefficient is `k` everywhere (global frame).
fn affine(k: Complex64, z: Complex64) -> Complex64 {
    z + k * z.conj()
}

/// Solves with a free boundary, constant `mu` in `frame`, and two boundary vertices far
/// apart pinned at their images under the affine map of `k`.
fn affine_solve(mesh: &Mesh, mu: Complex64, frame: Frame, k: Complex64) -> Vec<Complex64> {
    let field = BeltramiField::new(Frame::Global, vec![mu; mesh.face_count()])
        .to_frame(mesh, frame)
        .unwrap();
    let mut problem = prescribed(mesh, Target::Plane(PlanarBoundary::Free), field);
    let corner = |x: f64, y: f64| {
        mesh.vertices()
            .min_by(|&u, &v| {
                let target = Complex64::new(x, y);
                (z_of(mesh, u) - target)
                    .norm()
                    .total_cmp(&(z_of(mesh, v) - target).norm())
            })
            .unwrap()
    };
    problem.constraints = [corner(0.0, 0.0), corner(1.0, 1.0)]
        .into_iter()
        .map(|v| Pin {
            vertex: v,
            position: Some(Position::Planar(affine(k, z_of(mesh, v)))),
        })
        .collect::<Vec<_>>()
        .into();
    let solution = Lsqc.solve(&problem, &mut Context::new()).unwrap();
    planar(solution.map().expect("a map")).to_vec()
}

#[test]
fn constant_mu_with_free_boundary_reproduces_the_affine_map() {
    let k = Complex64::new(0.3, 0.2);
    for (cells, seed) in [(Cells::Triangles, 41), (Cells::Quads, 42)] {
        let mesh = jittered(10, cells, seed);
        let exact: Vec<Complex64> = mesh.vertices().map(|v| affine(k, z_of(&mesh, v))).collect();
        for frame in [Frame::Global, Frame::Face] {
            let map = affine_solve(&mesh, k, frame, k);
            let err = max_distance(&map, &exact);
            assert!(err < 1e-10, "{cells:?} {frame:?}: {err:e}");
        }
        // The test can fail: a conjugated or negated mu gives another map.
        for wrong in [k.conj(), -k] {
            let map = affine_solve(&mesh, wrong, Frame::Global, k);
            let err = max_distance(&map, &exact);
            assert!(err > 1e-2, "{cells:?} mu = {wrong}: {err:e}");
        }
    }
}

#[test]
fn given_boundary_of_the_affine_map_reproduces_it() {
    let k = Complex64::new(-0.2, 0.4);
    let mesh = jittered(9, Cells::Triangles, 43);
    let exact: Vec<Complex64> = mesh.vertices().map(|v| affine(k, z_of(&mesh, v))).collect();
    let field = BeltramiField::new(Frame::Global, vec![k; mesh.face_count()]);
    let problem = prescribed(
        &mesh,
        Target::Plane(PlanarBoundary::Given(exact.clone())),
        field,
    );
    let solution = Lsqc.solve(&problem, &mut Context::new()).unwrap();
    let err = max_distance(planar(solution.map().expect("a map")), &exact);
    assert!(err < 1e-10, "{err:e}");
    assert!(solution.metrics.energy_history[0] < 1e-20);
}

#[test]
fn zero_mu_keeping_the_boundary_is_the_identity() {
    let mesh = jittered(9, Cells::Quads, 44);
    let field = BeltramiField::zero(Frame::Global, mesh.face_count());
    let problem = prescribed(&mesh, Target::Plane(PlanarBoundary::Keep), field);
    let solution = Lsqc.solve(&problem, &mut Context::new()).unwrap();
    let identity: Vec<Complex64> = mesh.vertices().map(|v| z_of(&mesh, v)).collect();
    let err = max_distance(planar(solution.map().expect("a map")), &identity);
    assert!(err < 1e-10, "{err:e}");
    let names: Vec<&str> = solution
        .report
        .timings
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    assert_eq!(names, ["assembly", "solve", "distortion"]);
}

/// A jittered grid of `[0, 1]^2` mapped into the unit disk (the square's boundary onto
/// the circle).
fn disk_soup(n: usize) -> PolygonSoup {
    let mut soup = jittered_grid(n, n, Cells::Triangles, 0.25, 51);
    for p in &mut soup.positions {
        let (x, y) = (2.0 * p.x - 1.0, 2.0 * p.y - 1.0);
        p.x = x * (1.0 - 0.5 * y * y).sqrt();
        p.y = y * (1.0 - 0.5 * x * x).sqrt();
    }
    soup
}

/// One 1-to-4 subdivision of a disk mesh with the new boundary vertices projected onto
/// the unit circle.
fn refine(mesh: &Mesh) -> Mesh {
    let mut soup = subdivide(mesh);
    let fine = Mesh::from_soup(&soup).unwrap();
    assert_eq!(fine.vertex_count(), soup.positions.len());
    for v in fine.vertices() {
        if fine.is_boundary_vertex(v) {
            let p = &mut soup.positions[v.idx()];
            let r = (p.x * p.x + p.y * p.y).sqrt();
            p.x /= r;
            p.y /= r;
        }
    }
    Mesh::from_soup(&soup).unwrap()
}

#[test]
fn disk_with_mu_0_6_z_converges_at_first_order() {
    let expr = Expr::parse("0.6*z").unwrap();
    let mut mesh = Mesh::from_soup(&disk_soup(8)).unwrap();
    let mut errors = Vec::new();
    for level in 0..4 {
        let field = expr.field(&mesh).unwrap();
        let nearest = |target: Complex64| {
            mesh.vertices()
                .min_by(|&u, &v| {
                    (z_of(&mesh, u) - target)
                        .norm()
                        .total_cmp(&(z_of(&mesh, v) - target).norm())
                })
                .unwrap()
        };
        let mut problem = prescribed(&mesh, Target::Plane(PlanarBoundary::Free), field.clone());
        // Pins without positions stay where they are on a planar source.
        problem.constraints = [Complex64::new(0.0, 0.0), Complex64::new(1.0, 0.0)]
            .into_iter()
            .map(|z| Pin {
                vertex: nearest(z),
                position: None,
            })
            .collect::<Vec<_>>()
            .into();
        let solution = Lsqc.solve(&problem, &mut Context::new()).unwrap();
        let map = planar(solution.map().expect("a map"));
        for pin in problem.constraints.pins() {
            assert_eq!(map[pin.vertex.idx()], z_of(&mesh, pin.vertex));
        }
        assert_eq!(solution.metrics.flipped(), Some(0));
        let measured = solution.metrics.mu.as_ref().unwrap();
        assert_eq!(measured.frame, Frame::Global);
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let error = MuError::new(&elements, &measured.mu, &field.mu).unwrap();
        println!(
            "level {level}: {} faces, rms {:.3e}, sup {:.3e}, sum A |e|^2 {:.3e}",
            mesh.face_count(),
            error.rms,
            error.sup,
            error.l2_squared
        );
        assert_eq!(solution.metrics.mu_error, Some(error));
        errors.push(error);
        mesh = refine(&mesh);
    }
    assert!(errors[0].rms < 0.1, "{:e}", errors[0].rms);
    for pair in errors.windows(2) {
        let ratio = pair[0].rms / pair[1].rms;
        assert!(ratio > 1.7, "rms ratio {ratio}");
        let ratio = pair[0].l2_squared / pair[1].l2_squared;
        assert!(ratio > 3.0, "squared L2 ratio {ratio}");
    }
}

#[test]
fn rejects_mu_of_modulus_one_naming_the_face() {
    let mesh = jittered(6, Cells::Triangles, 61);
    let mut mu = vec![Complex64::new(0.1, 0.0); mesh.face_count()];
    mu[7] = Complex64::new(0.6, 0.8);
    let problem = prescribed(
        &mesh,
        Target::Plane(PlanarBoundary::Free),
        BeltramiField::new(Frame::Global, mu),
    );
    let err = Lsqc.check(&problem).unwrap_err();
    assert!(
        matches!(
            err,
            SolverError::Field(FieldError::NotQuasiconformal { face, .. }) if face == FaceId(7)
        ),
        "{err}"
    );
    assert!(err.to_string().contains(&FaceId(7).to_string()), "{err}");
    assert!(Lsqc.solve(&problem, &mut Context::new()).is_err());
}

#[test]
fn rejects_a_torus() {
    let mesh = Mesh::from_soup(&torus(12, 8, 1.0, 0.3, Cells::Triangles)).unwrap();
    let field = BeltramiField::zero(Frame::Face, mesh.face_count());
    let problem = prescribed(&mesh, Target::Plane(PlanarBoundary::Free), field);
    let err = Lsqc.solve(&problem, &mut Context::new()).unwrap_err();
    assert!(matches!(err, SolverError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("genus 1"), "{err}");
}

#[test]
fn rejects_bad_setups() {
    let mesh = jittered(6, Cells::Quads, 62);
    let zero = || BeltramiField::zero(Frame::Global, mesh.face_count());
    // A global-frame field on a curved surface.
    let sphere = hemisphere();
    let field = BeltramiField::zero(Frame::Global, sphere.face_count());
    let problem = prescribed(&sphere, Target::Plane(PlanarBoundary::Free), field);
    assert!(matches!(
        Lsqc.check(&problem),
        Err(SolverError::Unsupported { .. })
    ));
    // Keeping the boundary of a curved surface.
    let field = BeltramiField::zero(Frame::Face, sphere.face_count());
    let problem = prescribed(&sphere, Target::Plane(PlanarBoundary::Keep), field);
    assert!(matches!(
        Lsqc.check(&problem),
        Err(SolverError::Unsupported { .. })
    ));
    // A field of the wrong length.
    let field = BeltramiField::zero(Frame::Global, mesh.face_count() - 1);
    let problem = prescribed(&mesh, Target::Plane(PlanarBoundary::Free), field);
    assert!(matches!(
        Lsqc.check(&problem),
        Err(SolverError::Field(FieldError::Length { .. }))
    ));
    // One pin with a free boundary; a pin off the mesh; other targets.
    let mut problem = prescribed(&mesh, Target::Plane(PlanarBoundary::Free), zero());
    problem.constraints = vec![Pin {
        vertex: VertexId(0),
        position: None,
    }]
    .into();
    assert!(matches!(
        Lsqc.check(&problem),
        Err(SolverError::Unsupported { .. })
    ));
    problem.constraints = vec![Pin {
        vertex: VertexId(10_000),
        position: None,
    }]
    .into();
    assert!(matches!(
        Lsqc.check(&problem),
        Err(SolverError::Constraint {
            error: beltrami_core::ConstraintError::MissingVertex { .. },
            ..
        })
    ));
    for target in [Target::Sphere, Target::Plane(PlanarBoundary::Circle)] {
        let problem = prescribed(&mesh, target, zero());
        assert!(matches!(
            Lsqc.check(&problem),
            Err(SolverError::Unsupported { .. })
        ));
    }
}
