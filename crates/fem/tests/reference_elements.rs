//! Elements on reference polygons with given corner angles (Gruber-Aulisa 2022, section
//! 6.2): the surface's own angles give back the surface's own elements; other angles
//! measure a map from the reference shapes; angles that make no polygon are refused
//! with the face named.

use beltrami_fem::beltrami::{face_mu, point_mu, surface_map};
use beltrami_fem::{Elements, FemError, Frame, ReferenceNormal};
use beltrami_mesh::primitives::{Cells, jittered_grid};
use beltrami_mesh::{FaceId, Mesh};
use num_complex::Complex64;

fn own_angles(mesh: &Mesh) -> Vec<f64> {
    mesh.halfedges()
        .map(|h| {
            if mesh.is_boundary_halfedge(h) {
                0.0
            } else {
                mesh.corner_angle(h)
            }
        })
        .collect()
}

#[test]
fn a_surfaces_own_angles_give_its_own_elements() {
    let mut curved = jittered_grid(6, 6, Cells::Triangles, 0.3, 2);
    for p in &mut curved.positions {
        p.z = 0.4 * (p.x * p.x - p.y * p.y);
    }
    let planar_quads = jittered_grid(6, 6, Cells::Quads, 0.3, 2);
    for soup in [curved, planar_quads] {
        let mesh = Mesh::from_soup(&soup).unwrap();
        let own = Elements::new(&mesh, Frame::Face).unwrap();
        let reference = Elements::with_reference_angles(&mesh, &own_angles(&mesh)).unwrap();
        let mut worst: f64 = 0.0;
        for (p, q) in own.points().iter().zip(reference.points()) {
            worst = worst
                .max((p.weight - q.weight).abs() / p.weight)
                .max((p.frame.normal - q.frame.normal).norm())
                .max((p.frame.e1 - q.frame.e1).norm());
            for k in 0..4 {
                worst = worst.max((p.grad[k] - q.grad[k]).norm() * p.weight.sqrt());
            }
        }
        assert!(worst < 1e-9, "reference elements differ by {worst}");
    }
}

#[test]
fn equilateral_references_measure_the_map_from_the_equilateral_triangle() {
    // The identity of a planar mesh seen from equilateral reference triangles is, per
    // face, the affine map from an equilateral triangle onto the face. In the frame of
    // the first side (corners 0, a, w) it is z -> alpha z + beta conj(z) with 1 -> a and
    // e^{i pi/3} -> w (the scale of the reference does not change mu = beta / alpha).
    let mesh = Mesh::from_soup(&jittered_grid(5, 5, Cells::Triangles, 0.3, 4)).unwrap();
    let angles = vec![std::f64::consts::FRAC_PI_3; mesh.halfedge_count()];
    let elements = Elements::with_reference_angles(&mesh, &angles).unwrap();
    let d = surface_map(
        &elements,
        mesh.vertex_count(),
        mesh.positions(),
        ReferenceNormal::Source,
    )
    .unwrap();
    let measured = face_mu(&elements, &point_mu(&d));
    for f in mesh.faces() {
        // Corners in the frame of the first side: 0, a (real), w.
        let (v, _) = mesh.face_vertex_array(f);
        let p: Vec<_> = v[..3].iter().map(|&v| mesh.position(v)).collect();
        let e1 = (p[1] - p[0]).normalize();
        let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
        let e2 = n.cross(&e1);
        let a = (p[1] - p[0]).norm();
        let w = Complex64::new((p[2] - p[0]).dot(&e1), (p[2] - p[0]).dot(&e2));
        // The affine map z -> alpha z + beta conj(z) with 1 -> a and e^{i pi/3} -> w.
        let u = Complex64::from_polar(1.0, std::f64::consts::FRAC_PI_3);
        let beta = (w - a * u) / (u.conj() - u);
        let alpha = a - beta;
        let expected = beta / alpha;
        let got = measured[f.idx()];
        assert!(
            (got - expected).norm() < 1e-10,
            "face {f}: {got} vs {expected}"
        );
    }
    assert!(measured.iter().any(|m| m.norm() > 0.05));
}

#[test]
fn angles_that_make_no_polygon_are_refused_naming_the_face() {
    let mesh = Mesh::from_soup(&jittered_grid(3, 3, Cells::Triangles, 0.2, 1)).unwrap();
    let mut angles = own_angles(&mesh);
    let corner = mesh.face_halfedge(FaceId(4));
    angles[corner.idx()] += 0.1;
    match Elements::with_reference_angles(&mesh, &angles) {
        Err(FemError::ReferenceAngles { face, .. }) => assert_eq!(face, FaceId(4)),
        other => panic!("expected a refusal of face 4, got {other:?}"),
    }
    assert!(matches!(
        Elements::with_reference_angles(&mesh, &angles[1..]),
        Err(FemError::Length { .. })
    ));
}
