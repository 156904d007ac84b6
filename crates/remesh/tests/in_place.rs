//! Remeshing in place by reference angles (`beltrami_remesh::in_place`, Gruber-Aulisa
//! 2022, section 6.2): bad triangles of a sphere and of a bumpy disk become nearly the
//! reference shapes with the vertices kept on the surface, the faces and vertices
//! unchanged, no face turned that was not turned in the input; the area constraint
//! remeshes a closed surface held at one vertex; sharp creases stay where they are.

use beltrami_core::Context;
use beltrami_mesh::primitives::{Cells, icosphere, jittered_grid};
use beltrami_mesh::{Mesh, Point3, Vector3};
use beltrami_qc_iteration::QcIteration;
use beltrami_remesh::in_place::{InPlaceOptions, Keep, remesh_in_place};
use beltrami_remesh::quality;
use beltrami_remesh::reference_angles::Reference;

/// The unit icosphere of level 3 with every vertex slid along the sphere by up to
/// `amount` of an edge (a fixed pseudo-random pattern): bad angles on an exact sphere.
fn shaken_sphere(amount: f64) -> Mesh {
    let mut soup = icosphere(3);
    let h = 0.15;
    for (i, p) in soup.positions.iter_mut().enumerate() {
        let n = p.coords.normalize();
        let a = Vector3::new(0.3, 0.5, 0.8).cross(&n).normalize();
        let b = n.cross(&a);
        let (s, t) = (
            ((i * 7919) % 101) as f64 / 50.0 - 1.0,
            ((i * 104729) % 97) as f64 / 48.0 - 1.0,
        );
        *p = Point3::from((n + (a * s + b * t) * amount * h).normalize());
    }
    Mesh::from_soup(&soup).unwrap()
}

/// The remeshed mesh; checks that no face turned against the surface that was not
/// turned in the input.
fn run(mesh: &Mesh, options: &InPlaceOptions) -> Mesh {
    let result = remesh_in_place(mesh, &QcIteration, options, &mut Context::new()).unwrap();
    assert!(
        result.flipped <= result.input_flipped,
        "{} faces turned, {} in the input",
        result.flipped,
        result.input_flipped
    );
    result.mesh
}

#[test]
fn a_shaken_sphere_gets_its_shapes_back_and_stays_a_sphere() {
    let mesh = shaken_sphere(0.3);
    let before = quality::shape(&mesh);
    for reference in [Reference::Optimized, Reference::Equiangular] {
        let options = InPlaceOptions {
            reference,
            ..InPlaceOptions::default()
        };
        let out = run(&mesh, &options);
        let after = quality::measure(&mesh, &out).unwrap();
        println!(
            "{reference:?}: min angle {:.2} -> {:.2}, under 30 {:.3} -> {:.3}, Hausdorff {:.2e}",
            before.min_angle,
            after.min_angle,
            before.share_below_30,
            after.share_below_30,
            after.hausdorff
        );
        assert_eq!(out.face_count(), mesh.face_count());
        assert!(after.min_angle > before.min_angle + 10.0, "{after:?}");
        assert!(
            after.share_below_30 < 0.2 * before.share_below_30,
            "{after:?}"
        );
        // On the sphere: every vertex projected, every face centroid within the
        // chord error of the sphere.
        let off = out
            .faces()
            .map(|f| (1.0 - out.face_centroid(f).coords.norm()).abs())
            .fold(0.0, f64::max);
        assert!(off < 0.02, "a face centroid is {off} off the sphere");
    }
}

/// A jittered grid on the bump `z = 0.2 sin 3x cos 2y`.
fn bumpy_disk() -> Mesh {
    let mut soup = jittered_grid(16, 16, Cells::Triangles, 0.45, 3);
    for p in &mut soup.positions {
        p.z = 0.2 * (3.0 * p.x).sin() * (2.0 * p.y).cos();
    }
    Mesh::from_soup(&soup).unwrap()
}

#[test]
fn a_bumpy_disk_is_remeshed_with_its_boundary_held() {
    let mesh = bumpy_disk();
    let before = quality::shape(&mesh);
    let out = run(&mesh, &InPlaceOptions::default());
    let after = quality::measure(&mesh, &out).unwrap();
    println!(
        "min angle {:.2} -> {:.2}, under 30 {:.3} -> {:.3}, Hausdorff {:.2e}",
        before.min_angle,
        after.min_angle,
        before.share_below_30,
        after.share_below_30,
        after.hausdorff
    );
    assert!(after.min_angle > before.min_angle);
    assert!(
        after.share_below_30 < 0.1 * before.share_below_30,
        "{after:?}"
    );
    assert!(after.hausdorff < 0.005 * after.diagonal, "{after:?}");
    for v in mesh.vertices().filter(|&v| mesh.is_boundary_vertex(v)) {
        assert_eq!(out.position(v), mesh.position(v));
    }
}

#[test]
fn the_area_constraint_remeshes_a_closed_surface_held_at_one_vertex() {
    // A closed surface held at one vertex: the distortion from the reference shapes
    // alone would shrink the image onto that vertex (it is homogeneous of degree 2);
    // the area constraint keeps its size, and the projected result has the reference
    // shapes nearly as well as with the normal constraint.
    let mesh = shaken_sphere(0.3);
    let before = quality::shape(&mesh);
    let image = run(
        &mesh,
        &InPlaceOptions {
            keep: Keep::Area,
            project: false,
            ..InPlaceOptions::default()
        },
    );
    let mean_radius = image
        .positions()
        .iter()
        .map(|p| p.coords.norm())
        .sum::<f64>()
        / image.vertex_count() as f64;
    let out = run(
        &mesh,
        &InPlaceOptions {
            keep: Keep::Area,
            ..InPlaceOptions::default()
        },
    );
    let after = quality::measure(&mesh, &out).unwrap();
    println!(
        "mean radius of the image {mean_radius:.4}; min angle {:.2} -> {:.2}, under 30 {:.3} -> {:.3}",
        before.min_angle, after.min_angle, before.share_below_30, after.share_below_30
    );
    assert!((mean_radius - 1.0).abs() < 0.2, "{mean_radius}");
    assert!(after.min_angle > before.min_angle + 10.0, "{after:?}");
    assert!(
        after.share_below_30 < 0.2 * before.share_below_30,
        "{after:?}"
    );
}

#[test]
fn sharp_creases_stay_in_place() {
    // A jittered grid folded at a right angle along x = 0.5: the crease vertices are
    // held (feature angle 60), so the fold line keeps its place; with every vertex free
    // (180), vertices slide across the crease and are projected to the other side.
    let mut soup = jittered_grid(12, 12, Cells::Triangles, 0.3, 8);
    for (i, p) in soup.positions.iter_mut().enumerate() {
        if i % 13 == 6 {
            p.x = 0.5;
        }
        if p.x > 0.5 {
            *p = Point3::new(0.5, p.y, p.x - 0.5);
        }
    }
    let mesh = Mesh::from_soup(&soup).unwrap();
    let on_crease: Vec<_> = mesh
        .vertices()
        .filter(|&v| (mesh.position(v).x - 0.5).abs() < 1e-12 && mesh.position(v).z == 0.0)
        .filter(|&v| !mesh.is_boundary_vertex(v))
        .collect();
    assert!(!on_crease.is_empty());
    let held = run(&mesh, &InPlaceOptions::default());
    for &v in &on_crease {
        assert_eq!(held.position(v), mesh.position(v));
    }
    let kept = quality::measure(&mesh, &held).unwrap();
    let free = run(
        &mesh,
        &InPlaceOptions {
            feature_angle: 180.0,
            ..InPlaceOptions::default()
        },
    );
    let lost = quality::measure(&mesh, &free).unwrap();
    println!(
        "Hausdorff with the crease held {:.3e}, free {:.3e}",
        kept.hausdorff, lost.hausdorff
    );
    assert!(kept.hausdorff < 0.5 * lost.hausdorff);
}
