//! Flattening exact cases: surfaces that unroll onto the plane come out isometric.

use beltrami_atlas::boundary_first::flatten_disk;
use beltrami_atlas::{SeamedUv, stretch};
use beltrami_mesh::closed_curve::crosses_itself;
use beltrami_mesh::primitives::{Cells, grid};
use beltrami_mesh::{Mesh, Point3};

fn disk_uv(mesh: &Mesh, uv: Vec<[f64; 2]>) -> SeamedUv {
    SeamedUv {
        uvs: uv,
        corners: mesh
            .faces()
            .map(|f| {
                let (v, _) = mesh.face_vertex_array(f);
                [v[0].0, v[1].0, v[2].0]
            })
            .collect(),
    }
}

/// A planar square with no curvature is laid flat as itself (up to a rigid motion).
#[test]
fn a_flat_square_is_laid_flat_as_itself() {
    let mesh = Mesh::from_soup(&grid(12, 9, Cells::Triangles)).unwrap();
    let uv = flatten_disk(&mesh, &vec![0.0; mesh.vertex_count()])
        .unwrap()
        .unwrap();
    for e in mesh.edges() {
        let [a, b] = mesh.edge_vertices(e);
        let flat = (uv[a.idx()][0] - uv[b.idx()][0]).hypot(uv[a.idx()][1] - uv[b.idx()][1]);
        assert!(
            (flat - mesh.edge_length(e)).abs() < 1e-12,
            "edge {e:?}: {flat}"
        );
    }
    let s = stretch(&mesh, &disk_uv(&mesh, uv));
    assert!(
        (s.l2 - 1.0).abs() < 1e-12 && (s.linf - 1.0).abs() < 1e-12,
        "{s:?}"
    );
}

/// Half a cylinder (developable: no Gaussian curvature inside, straight rulings) unrolls
/// to a rectangle of the same size: stretch 1 to rounding.
#[test]
fn half_a_cylinder_unrolls_isometrically() {
    let (nx, ny) = (24, 10);
    let soup = grid(nx, ny, Cells::Triangles);
    let flat = Mesh::from_soup(&soup).unwrap();
    let positions: Vec<Point3<f64>> = flat
        .positions()
        .iter()
        .map(|p| {
            let angle = p.x * std::f64::consts::PI;
            Point3::new(angle.cos(), 2.0 * p.y, angle.sin())
        })
        .collect();
    let mesh = flat.with_positions(positions).unwrap();
    let uv = flatten_disk(&mesh, &vec![0.0; mesh.vertex_count()])
        .unwrap()
        .unwrap();
    let ring: Vec<[f64; 2]> = mesh
        .boundary_loops()
        .next()
        .map(|b| mesh.loop_vertices(b).map(|v| uv[v.idx()]).collect())
        .unwrap();
    assert!(!crosses_itself(&ring));
    let s = stretch(&mesh, &disk_uv(&mesh, uv));
    assert!(s.flipped_faces == 0 && (s.l2 - 1.0).abs() < 1e-9, "{s:?}");
}
