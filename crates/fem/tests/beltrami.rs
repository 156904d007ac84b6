//! Beltrami coefficients: affine maps (exact), conformal maps (mu -> 0 at O(h)), flips,
//! frames, surface-to-surface and quaternionic coefficients.

use beltrami_fem::beltrami::{
    MU_CAP, ReferenceNormal, face_mu, flipped_faces, image_derivatives, planar_map, point_mu,
    rotate_frame, surface_map,
};
use beltrami_fem::quaternion::quaternionic_mu;
use beltrami_fem::{Elements, Frame};
use beltrami_mesh::primitives::{Cells, grid, icosphere, torus};
use beltrami_mesh::{Mesh, Point3, PolygonSoup, Vector3};
use nalgebra::{Rotation3, Unit};
use num_complex::Complex64;

mod common;
use common::Rng;

/// Unit-square grid, interior vertices moved by up to `amount` cells, mapped by `warp`.
fn planar_mesh(n: usize, cells: Cells, amount: f64, warp: impl Fn(f64, f64) -> (f64, f64)) -> Mesh {
    let mut soup = grid(n, n, cells);
    let mut rng = Rng(42);
    let h = 1.0 / n as f64;
    for p in &mut soup.positions {
        if p.x > 1e-9 && p.x < 1.0 - 1e-9 && p.y > 1e-9 && p.y < 1.0 - 1e-9 {
            p.x += (rng.next() - 0.5) * 2.0 * amount * h;
            p.y += (rng.next() - 0.5) * 2.0 * amount * h;
        }
        let (x, y) = warp(p.x, p.y);
        p.x = x;
        p.y = y;
    }
    Mesh::from_soup(&soup).unwrap()
}

fn z_of(p: &Point3<f64>) -> Complex64 {
    Complex64::new(p.x, p.y)
}

fn face_mu_of(mesh: &Mesh, frame: Frame, f: impl Fn(Complex64) -> Complex64) -> Vec<Complex64> {
    let elements = Elements::new(mesh, frame).unwrap();
    let map: Vec<Complex64> = mesh.positions().iter().map(|p| f(z_of(p))).collect();
    let d = planar_map(&elements, mesh.vertex_count(), &map).unwrap();
    face_mu(&elements, &point_mu(&d))
}

#[test]
fn affine_map_has_constant_mu_k() {
    let k = Complex64::new(0.35, -0.2);
    // P1 on an irregular mesh, Q1 on a parallelogram mesh and on an irregular quad mesh.
    let meshes = [
        planar_mesh(10, Cells::Triangles, 0.35, |x, y| (x, y)),
        planar_mesh(10, Cells::Quads, 0.0, |x, y| (x + 0.4 * y, 0.8 * y)),
        planar_mesh(10, Cells::Quads, 0.3, |x, y| (x, y)),
    ];
    for mesh in &meshes {
        let mu = face_mu_of(mesh, Frame::Global, |z| 2.0 * z + 2.0 * k * z.conj() + 1.0);
        for (f, m) in mu.iter().enumerate() {
            assert!((m - k).norm() < 1e-12, "face {f}: {m}");
        }
    }
}

/// Largest |mu| over the faces of a conformal map on meshes of n x n cells: a smoothly
/// warped grid over [1, 2] x [0, 1], so that refinement keeps the element shapes and the
/// rate is not blurred by random element quality.
fn conformal_error(n: usize, cells: Cells, f: &dyn Fn(Complex64) -> Complex64) -> f64 {
    let warp = |x: f64, y: f64| {
        (
            1.0 + x + 0.15 * x * (1.0 - x) * y,
            y + 0.1 * (std::f64::consts::PI * x).sin() * y * (1.0 - y),
        )
    };
    let mesh = planar_mesh(n, cells, 0.0, warp);
    face_mu_of(&mesh, Frame::Global, f)
        .iter()
        .map(|m| m.norm())
        .fold(0.0, f64::max)
}

#[test]
fn mu_of_conformal_maps_vanishes_at_first_order() {
    let a = Complex64::new(0.3, 0.2);
    let square = |z: Complex64| z * z;
    let moebius = move |z: Complex64| (z - a) / (1.0 - a.conj() * z);
    let maps: [(&str, &dyn Fn(Complex64) -> Complex64); 2] =
        [("z^2", &square), ("moebius", &moebius)];
    for (name, f) in maps {
        for cells in [Cells::Triangles, Cells::Quads] {
            let errors: Vec<f64> = [8, 16, 32, 64]
                .iter()
                .map(|&n| conformal_error(n, cells, f))
                .collect();
            for w in errors.windows(2) {
                let rate = (w[0] / w[1]).log2();
                println!(
                    "{name} {cells:?}: max|mu| {:.3e} -> {:.3e}, rate {rate:.2}",
                    w[0], w[1]
                );
                // At least first order; the face means of Q1 on these smooth meshes are even
                // second order (superconvergence at the element centre).
                assert!(rate > 0.9, "{name} {cells:?}: rate {rate}");
            }
            assert!(errors[3] < 0.05, "{name} {cells:?}: {}", errors[3]);
        }
    }
}

#[test]
fn a_reflected_face_is_flipped() {
    let mesh = planar_mesh(6, Cells::Triangles, 0.0, |x, y| (x, y));
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    // Push one interior vertex past its neighbours: the faces around it whose image
    // turns clockwise are flipped, and only those.
    let v = mesh.vertex_map().from_input(3 + 7 * 3).unwrap();
    let mut map: Vec<Complex64> = mesh.positions().iter().map(z_of).collect();
    map[v.idx()] += Complex64::new(0.4, 0.1);
    let d = planar_map(&elements, mesh.vertex_count(), &map).unwrap();
    let flipped = flipped_faces(&elements, &d);
    let mu = face_mu(&elements, &point_mu(&d));
    let mut count = 0;
    for f in mesh.faces() {
        let z: Vec<Complex64> = mesh.face_vertices(f).map(|v| map[v.idx()]).collect();
        let signed = ((z[1] - z[0]).conj() * (z[2] - z[0])).im;
        assert_eq!(flipped[f.idx()], signed < 0.0, "face {f}");
        assert_eq!(mu[f.idx()].norm() > 1.0, signed < 0.0, "face {f}");
        count += usize::from(signed < 0.0);
    }
    assert!(count >= 1, "the test must flip at least one face");
}

#[test]
fn face_frame_mu_follows_the_rotation_rule() {
    let k = Complex64::new(0.25, 0.4);
    let map = |z: Complex64| z + k * z.conj();
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = planar_mesh(6, cells, 0.3, |x, y| (x, y));
        let global = face_mu_of(&mesh, Frame::Global, map);
        let local = face_mu_of(&mesh, Frame::Face, map);
        for f in mesh.faces() {
            let e1 = mesh.face_frame(f).e1;
            let theta = e1.y.atan2(e1.x);
            let expected = rotate_frame(global[f.idx()], theta);
            assert!((local[f.idx()] - expected).norm() < 1e-12, "face {f}");
        }
    }
}

/// A planar mesh moved into R^3 by a rotation and translation, with that rigid motion.
fn tilted(mesh: &Mesh) -> (Mesh, Rotation3<f64>, Vector3<f64>) {
    let rotation =
        Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, -2.0, 0.5)), 0.9);
    let shift = Vector3::new(0.3, -1.0, 2.0);
    let positions: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| rotation * p + shift)
        .collect();
    let mut soup = PolygonSoup::new(positions);
    for f in mesh.faces() {
        let vs: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        soup.push_face(&vs);
    }
    (Mesh::from_soup(&soup).unwrap(), rotation, shift)
}

#[test]
fn quaternionic_intrinsic_and_planar_mu_agree_on_a_plane() {
    let k = Complex64::new(-0.3, 0.15);
    let map = |z: Complex64| 1.5 * z + k * 1.5 * z.conj();
    for cells in [Cells::Triangles, Cells::Quads] {
        let flat = planar_mesh(6, cells, 0.3, |x, y| (x, y));
        let planar = face_mu_of(&flat, Frame::Face, map);
        // The same mesh and map, rigidly moved into R^3: the image stays in the source's
        // tangent plane.
        let (surface, rotation, shift) = tilted(&flat);
        let image: Vec<Point3<f64>> = flat
            .positions()
            .iter()
            .map(|p| {
                let w = map(z_of(p));
                rotation * Point3::new(w.re, w.im, 0.0) + shift
            })
            .collect();
        let elements = Elements::new(&surface, Frame::Face).unwrap();
        let intrinsic = face_mu(
            &elements,
            &point_mu(
                &surface_map(
                    &elements,
                    surface.vertex_count(),
                    &image,
                    ReferenceNormal::Source,
                )
                .unwrap(),
            ),
        );
        let quaternionic = face_mu(
            &elements,
            &quaternionic_mu(&elements, surface.vertex_count(), &image).unwrap(),
        );
        for f in surface.faces() {
            let (p, i, q) = (planar[f.idx()], intrinsic[f.idx()], quaternionic[f.idx()]);
            assert!(
                (p - i).norm() < 1e-12,
                "{cells:?} face {f}: planar {p} intrinsic {i}"
            );
            assert!(
                (p - q).norm() < 1e-12,
                "{cells:?} face {f}: planar {p} quaternionic {q}"
            );
        }
    }
}

#[test]
fn identity_and_similarities_of_curved_surfaces_are_conformal() {
    let rotation =
        Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.2, 1.0, -0.3)), 2.1);
    let shift = Vector3::new(1.0, 2.0, 3.0);
    for soup in [
        icosphere(2),
        torus(16, 10, 2.0, 0.6, Cells::Quads),
        torus(12, 8, 2.0, 0.8, Cells::Triangles),
    ] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        for scale in [1.0, 0.37] {
            // A rotated copy: orientation is judged against the rotated normals (the
            // target's), since the source normals no longer describe the image.
            let image: Vec<Point3<f64>> = mesh
                .positions()
                .iter()
                .map(|p| rotation * (p * scale) + shift)
                .collect();
            let target_normals: Vec<Vector3<f64>> = mesh
                .faces()
                .map(|f| rotation * mesh.face_normal(f))
                .collect();
            let d = surface_map(
                &elements,
                mesh.vertex_count(),
                &image,
                ReferenceNormal::PerFace(&target_normals),
            )
            .unwrap();
            let worst = point_mu(&d).iter().map(|m| m.norm()).fold(0.0, f64::max);
            assert!(
                worst < 1e-12,
                "{} faces, scale {scale}: max |mu| {worst}",
                mesh.face_count()
            );
            assert!(flipped_faces(&elements, &d).iter().all(|&f| !f));

            // The quaternionic coefficient is taken with respect to the source's own
            // normal, so it sees scalings and translations as conformal (a rotation of the
            // image would not be, in that structure).
            let scaled: Vec<Point3<f64>> =
                mesh.positions().iter().map(|p| p * scale + shift).collect();
            let q = quaternionic_mu(&elements, mesh.vertex_count(), &scaled).unwrap();
            assert!(q.iter().all(|m| m.norm() < 1e-12));
        }
    }
}

#[test]
fn a_stretch_on_a_tilted_plane_has_the_analytic_mu_and_reflections_flip() {
    // Stretching by s along the in-plane direction at angle phi from the source's x axis
    // has mu = (s - 1) / (s + 1) e^{2 i phi} in the global frame of the flat mesh.
    let (s, phi) = (2.5_f64, 0.6_f64);
    let dir = Complex64::from_polar(1.0, phi);
    let stretch = |z: Complex64| {
        let along = (z * dir.conj()).re;
        z + (s - 1.0) * along * dir
    };
    let expected_global = Complex64::from_polar((s - 1.0) / (s + 1.0), 2.0 * phi);
    let flat = planar_mesh(5, Cells::Triangles, 0.3, |x, y| (x, y));
    let (surface, rotation, shift) = tilted(&flat);
    let image: Vec<Point3<f64>> = flat
        .positions()
        .iter()
        .map(|p| {
            let w = stretch(z_of(p));
            rotation * Point3::new(w.re, w.im, 0.0) + shift
        })
        .collect();
    let elements = Elements::new(&surface, Frame::Face).unwrap();
    let d = surface_map(
        &elements,
        surface.vertex_count(),
        &image,
        ReferenceNormal::Source,
    )
    .unwrap();
    let mu = face_mu(&elements, &point_mu(&d));
    for f in surface.faces() {
        // The face frame of the tilted face is the rotated face frame of the flat one.
        let e1 = flat.face_frame(f).e1;
        let expected = rotate_frame(expected_global, e1.y.atan2(e1.x));
        assert!((mu[f.idx()] - expected).norm() < 1e-12, "face {f}");
    }

    // Mirror the image through its plane's normal direction... a reflection inside the
    // plane (z -> conj z) reverses orientation: judged against the source normals every
    // face flips; judged against the opposite normals none does.
    let mirrored: Vec<Point3<f64>> = flat
        .positions()
        .iter()
        .map(|p| rotation * Point3::new(p.x, -p.y, 0.0) + shift)
        .collect();
    let d = surface_map(
        &elements,
        surface.vertex_count(),
        &mirrored,
        ReferenceNormal::Source,
    )
    .unwrap();
    assert!(flipped_faces(&elements, &d).iter().all(|&f| f));
    let opposite: Vec<Vector3<f64>> = surface.faces().map(|f| -surface.face_normal(f)).collect();
    let d = surface_map(
        &elements,
        surface.vertex_count(),
        &mirrored,
        ReferenceNormal::PerFace(&opposite),
    )
    .unwrap();
    assert!(flipped_faces(&elements, &d).iter().all(|&f| !f));
    assert!(point_mu(&d).iter().all(|m| m.norm() < 1e-12));
}

#[test]
fn the_kernel_judges_a_reflection_by_the_reference_normal() {
    // z -> conj z: f_x = (1, 0, 0), f_y = (0, -1, 0), so m = f_x x f_y = -z.
    let (dx, dy) = (Vector3::x(), -Vector3::y());
    let up = image_derivatives(&dx, &dy, &Vector3::z());
    assert!(up.jacobian() < 0.0, "{up:?}");
    assert_eq!(up.fz, Complex64::new(0.0, 0.0));
    assert_eq!(up.mu().norm(), MU_CAP);
    // Seen from below the same image is the identity: conformal, Jacobian 1.
    let down = image_derivatives(&dx, &dy, &-Vector3::z());
    assert!((down.jacobian() - 1.0).abs() < 1e-15, "{down:?}");
    assert_eq!(down.mu(), Complex64::new(0.0, 0.0));
    // A scale of the reference does not matter; one orthogonal to the image flips it.
    let far = image_derivatives(&dx, &dy, &(-1e-9 * Vector3::z()));
    assert_eq!(far, down);
    assert!(image_derivatives(&dx, &dy, &Vector3::x()).jacobian() < 0.0);
    // The identity with reference +z; a collapsed image: |mu| = 1, Jacobian 0.
    let identity = image_derivatives(&dx, &Vector3::y(), &Vector3::z());
    assert!(identity.jacobian() > 0.0 && identity.mu().norm() == 0.0);
    let collapsed = image_derivatives(&dx, &(2.0 * dx), &Vector3::z());
    assert_eq!(collapsed.jacobian(), 0.0);
    assert!((collapsed.mu().norm() - 1.0).abs() < 1e-15);
    assert_eq!(
        image_derivatives(&Vector3::zeros(), &Vector3::zeros(), &Vector3::z())
            .mu()
            .norm(),
        1.0
    );
}

#[test]
fn radial_reference_judges_maps_onto_a_sphere() {
    // A half turn of the sphere about z is a rigid motion: conformal and orientation
    // preserving. Judged radially no face flips; judged against the source normals the
    // faces near the equator, whose images point the other way, would.
    // Triangles, and quads (a cube's sides pushed onto the sphere: bilinear patches).
    let mut quads = cube_sphere(6);
    for p in &mut quads.positions {
        *p = Point3::from(p.coords.normalize());
    }
    for soup in [icosphere(3), quads] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let n = mesh.vertex_count();
        let turned: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::new(-p.x, -p.y, p.z))
            .collect();
        let d = surface_map(&elements, n, &turned, ReferenceNormal::Radial).unwrap();
        assert!(flipped_faces(&elements, &d).iter().all(|&f| !f));
        assert!(point_mu(&d).iter().all(|m| m.norm() < 1e-12));
        let source = surface_map(&elements, n, &turned, ReferenceNormal::Source).unwrap();
        let wrong = flipped_faces(&elements, &source)
            .iter()
            .filter(|&&f| f)
            .count();
        assert!(
            wrong > mesh.face_count() / 4,
            "{wrong} of {}",
            mesh.face_count()
        );
        // A reflection x -> -x turns every face inward: all flipped radially.
        let mirrored: Vec<Point3<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Point3::new(-p.x, p.y, p.z))
            .collect();
        let d = surface_map(&elements, n, &mirrored, ReferenceNormal::Radial).unwrap();
        assert!(flipped_faces(&elements, &d).iter().all(|&f| f));
        assert!(point_mu(&d).iter().all(|m| m.norm() > 1.0));
        // The image of the sphere scaled and off the unit radius: still radial.
        let scaled: Vec<Point3<f64>> = mesh.positions().iter().map(|p| p * 3.0).collect();
        assert_eq!(ReferenceNormal::for_image(&scaled), ReferenceNormal::Radial);
        let d = surface_map(&elements, n, &scaled, ReferenceNormal::Radial).unwrap();
        assert!(flipped_faces(&elements, &d).iter().all(|&f| !f));
    }
}

/// A cube `[-1, 1]^3` with `n x n` quads per side, outward.
fn cube_sphere(n: usize) -> PolygonSoup {
    let mut soup = PolygonSoup::new(Vec::new());
    // Each side: a corner and two edge vectors with `u x v` outward.
    let sides = [
        (Vector3::new(1.0, -1.0, -1.0), Vector3::y(), Vector3::z()),
        (Vector3::new(-1.0, -1.0, -1.0), Vector3::z(), Vector3::y()),
        (Vector3::new(-1.0, 1.0, -1.0), Vector3::z(), Vector3::x()),
        (Vector3::new(-1.0, -1.0, -1.0), Vector3::x(), Vector3::z()),
        (Vector3::new(-1.0, -1.0, 1.0), Vector3::x(), Vector3::y()),
        (Vector3::new(-1.0, -1.0, -1.0), Vector3::y(), Vector3::x()),
    ];
    let mut index = std::collections::HashMap::new();
    for (corner, u, v) in sides {
        let mut id = |i: usize, j: usize| {
            let p = corner + u * (2.0 * i as f64 / n as f64) + v * (2.0 * j as f64 / n as f64);
            let key = p.map(|x| (x * n as f64).round() as i64);
            *index.entry((key.x, key.y, key.z)).or_insert_with(|| {
                soup.positions.push(Point3::from(p));
                (soup.positions.len() - 1) as u32
            })
        };
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        for f in faces {
            soup.push_face(&f);
        }
    }
    soup
}

#[test]
fn bad_maps_are_typed_errors() {
    let mesh = planar_mesh(3, Cells::Triangles, 0.0, |x, y| (x, y));
    let elements = Elements::new(&mesh, Frame::Global).unwrap();
    let short = vec![Complex64::new(0.0, 0.0); 3];
    assert!(matches!(
        planar_map(&elements, mesh.vertex_count(), &short),
        Err(beltrami_fem::FemError::Length {
            expected: 16,
            got: 3,
            ..
        })
    ));
    let mut nan: Vec<Complex64> = mesh.positions().iter().map(z_of).collect();
    nan[5].im = f64::NAN;
    assert!(matches!(
        planar_map(&elements, mesh.vertex_count(), &nan),
        Err(beltrami_fem::FemError::NonFinite { index: 5, .. })
    ));
}
