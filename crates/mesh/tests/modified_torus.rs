//! The modified tori of Wong-Zhao 2014, section 5.4: closed genus 1, outward faces, and
//! the formulas at a few parameters.

use beltrami_mesh::Mesh;
use beltrami_mesh::primitives::{ModifiedTorus, modified_torus};

#[test]
fn modified_tori_are_closed_genus_one_with_outward_faces() {
    for kind in [ModifiedTorus::Phi1, ModifiedTorus::Phi2] {
        let mesh = Mesh::from_soup(&modified_torus(kind, 40, 16)).unwrap();
        assert_eq!(mesh.face_count(), 2 * 40 * 16);
        assert!(mesh.is_closed());
        assert_eq!(mesh.genus(), Some(1));
        // Outward: positive signed volume.
        let volume: f64 = mesh
            .faces()
            .map(|f| {
                let v: Vec<_> = mesh.face_vertices(f).map(|v| mesh.position(v)).collect();
                v[0].coords.dot(&v[1].coords.cross(&v[2].coords)) / 6.0
            })
            .sum();
        assert!(volume > 0.0, "{kind:?}: {volume}");
    }
}

#[test]
fn modified_tori_follow_the_formulas() {
    // phi_1(0, 0) = (r1 + r2 + r3, 0, 0); phi_1(0, 1/4): r = 4 + 0 + 0.3 cos(3 pi / 2) = 4.
    let p = ModifiedTorus::Phi1.point(0.0, 0.0);
    assert!((p - nalgebra::Point3::new(6.0, 0.0, 0.0)).norm() < 1e-12);
    let p = ModifiedTorus::Phi1.point(0.0, 0.25);
    assert!((p - nalgebra::Point3::new(4.0, 0.0, 1.7)).norm() < 1e-12);
    // phi_2(1/10, 0): tube radius r2 - r3 = 1.1 at u = 1/10, x + i y = 5.1 e^{i pi / 5}.
    let p = ModifiedTorus::Phi2.point(0.1, 0.0);
    let angle = std::f64::consts::PI / 5.0;
    assert!((p - nalgebra::Point3::new(5.1 * angle.cos(), 5.1 * angle.sin(), 0.0)).norm() < 1e-12);
    let p = ModifiedTorus::Phi2.point(0.0, 0.25);
    assert!((p - nalgebra::Point3::new(4.0, 0.0, 1.9)).norm() < 1e-12);
}
