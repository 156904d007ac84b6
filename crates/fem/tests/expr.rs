//! `Expr::field`: the expression at the face centroids of a planar mesh, in the global
//! frame; a mesh off the plane is refused.

mod common;

use beltrami_fem::{Expr, FemError, Frame};
use beltrami_mesh::primitives::Cells;
use common::{hemisphere, jittered};
use num_complex::Complex64;

#[test]
fn field_is_the_expression_at_the_face_centroids() {
    let expr = Expr::parse("0.6*z - 0.1i*conj(z)^2").unwrap();
    for (cells, seed) in [(Cells::Triangles, 11), (Cells::Quads, 12)] {
        let mesh = jittered(5, cells, 0.3, seed);
        let field = expr.field(&mesh).unwrap();
        assert_eq!(field.frame, Frame::Global);
        assert_eq!(field.mu.len(), mesh.face_count());
        for f in mesh.faces() {
            let n = mesh.face_degree(f) as f64;
            let z = mesh
                .face_vertices(f)
                .map(|v| Complex64::new(mesh.position(v).x, mesh.position(v).y))
                .sum::<Complex64>()
                / n;
            let expected = 0.6 * z - Complex64::new(0.0, 0.1) * z.conj() * z.conj();
            assert!(
                (field.mu[f.idx()] - expected).norm() < 1e-15,
                "{cells:?} {f}"
            );
        }
    }
}

#[test]
fn field_needs_a_planar_mesh() {
    assert!(matches!(
        Expr::parse("z").unwrap().field(&hemisphere()),
        Err(FemError::NotPlanar { .. })
    ));
}
