//! Opening surfaces into charts and sampling their boundaries once per surface curve.

use beltrami_mesh::primitives::{Cells, icosphere, torus};
use beltrami_mesh::{Mesh, cut_along};
use beltrami_remesh::boundary::sample;
use beltrami_remesh::chart::{Opening, open};
use num_complex::Complex64;

#[test]
fn a_closed_sphere_is_slit_into_a_disk_with_the_same_faces() {
    let sphere = Mesh::from_soup(&icosphere(3)).unwrap();
    let chart = open(&sphere, false).unwrap();
    let Opening::Slit { edges } = chart.opening else {
        panic!("{:?}", chart.opening);
    };
    assert!(chart.mesh.is_disk(), "{:?}", chart.mesh.components());
    // A path of `edges` edges has `edges - 1` inner vertices, each copied once.
    assert_eq!(chart.mesh.vertex_count(), sphere.vertex_count() + edges - 1);
    assert_eq!(chart.mesh.face_count(), sphere.face_count());
    for f in sphere.faces() {
        let theirs: Vec<_> = chart
            .mesh
            .face_vertices(f)
            .map(|v| chart.to_original[v.idx()])
            .collect();
        assert_eq!(
            theirs,
            sphere.face_vertices(f).collect::<Vec<_>>(),
            "face {f}"
        );
    }
    // The slit joins two far apart vertices: about half a great circle.
    let length: f64 = chart
        .mesh
        .boundary_loops()
        .flat_map(|b| chart.mesh.loop_halfedges(b))
        .map(|h| chart.mesh.halfedge_vector(h).norm())
        .sum();
    assert!(
        length > 2.0 * 2.9 && length < 2.0 * 3.6,
        "slit boundary {length}"
    );
}

#[test]
fn cutting_along_no_edge_changes_nothing() {
    let sphere = Mesh::from_soup(&icosphere(1)).unwrap();
    let (same, to_original) = cut_along(&sphere, &[]).unwrap();
    assert_eq!(same.vertex_count(), sphere.vertex_count());
    assert!(to_original.iter().enumerate().all(|(i, v)| v.idx() == i));
}

#[test]
fn both_copies_of_a_seam_point_share_one_vertex() {
    let torus = Mesh::from_soup(&torus(24, 10, 1.0, 0.4, Cells::Triangles)).unwrap();
    let chart = open(&torus, false).unwrap();
    assert!(matches!(chart.opening, Opening::CutGraph { .. }));
    // Any layout does for the sampling: use the cut mesh's own x, y.
    let uv: Vec<Complex64> = chart
        .mesh
        .positions()
        .iter()
        .map(|p| Complex64::new(p.x, p.y))
        .collect();
    let samples = sample(&chart.mesh, &uv, &chart.to_original, |_| 0.1, 0.2);
    // Every seam point of a torus cut along a figure-eight is on two sides of the
    // square, except the crossing, which is its four corners.
    let mut uses = vec![0usize; samples.vertex_count];
    for &v in &samples.vertex {
        uses[v as usize] += 1;
    }
    assert_eq!(uses.iter().filter(|&&n| n == 4).count(), 1, "{uses:?}");
    assert!(uses.iter().all(|&n| n == 2 || n == 4), "{uses:?}");
    assert_eq!(samples.edges.len(), samples.points.len());
}
