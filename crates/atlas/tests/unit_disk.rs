//! The conformal map onto the unit disk by boundary first flattening: a flat round disk
//! comes back as itself turned, a hemisphere lands on the disk with its boundary exactly
//! on the circle and a small Beltrami coefficient.

use std::path::Path;

use beltrami_atlas::unit_disk::map_to_unit_disk;
use beltrami_fem::Frame;
use beltrami_fem::distortion::measure_planar;
use beltrami_fem::operators::cotan_laplacian;
use beltrami_mesh::io::read;
use beltrami_mesh::primitives::disk;
use beltrami_mesh::{BuildOptions, Mesh};
use num_complex::Complex64;

#[test]
fn a_round_flat_disk_is_mapped_onto_itself_by_a_rotation() {
    let mesh = Mesh::from_soup(&disk(4)).unwrap();
    let p = map_to_unit_disk(&mesh).unwrap().unwrap();
    // Lengths are kept (the map is a rotation: the coordinates are discrete harmonic).
    for e in mesh.edges() {
        let [a, b] = mesh.edge_vertices(e);
        let flat = (p[a.idx()][0] - p[b.idx()][0]).hypot(p[a.idx()][1] - p[b.idx()][1]);
        assert!((flat - mesh.edge_length(e)).abs() < 1e-12, "{e:?}");
    }
    // The centre stays at the centre.
    assert!(p[0][0].hypot(p[0][1]) < 1e-12);
}

#[test]
fn a_hemisphere_lands_on_the_unit_disk_nearly_conformally() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../meshes/disk_hemisphere.obj");
    let mesh = read(&path, &BuildOptions::default()).unwrap().mesh;
    let p = map_to_unit_disk(&mesh).unwrap().unwrap();
    for v in mesh.vertices().filter(|&v| mesh.is_boundary_vertex(v)) {
        assert!((p[v.idx()][0].hypot(p[v.idx()][1]) - 1.0).abs() < 1e-14);
    }
    let map: Vec<Complex64> = p.iter().map(|q| Complex64::new(q[0], q[1])).collect();
    let d = measure_planar(&mesh, &map, Frame::Face).unwrap();
    assert_eq!(d.stats.flipped, 0);
    // Measured 0.0095 and 0.022 (the linearized scale and the harmonic extension are
    // what keeps them above 0); Tutte's map of this mesh onto the circle has 0.135 and 0.48.
    assert!(
        d.stats.mu_mean < 0.012 && d.stats.mu_max < 0.03,
        "{:?}",
        d.stats
    );
}

#[test]
fn the_interior_is_the_harmonic_extension_of_the_boundary() {
    // The extension is solved with the boundary held by a penalty and the miss that
    // leaves (about 1e-10 of the positions) taken off by a second solve: the cotan
    // Laplacian of each coordinate vanishes at every interior vertex to rounding.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../meshes/disk_hemisphere.obj");
    let mesh = read(&path, &BuildOptions::default()).unwrap().mesh;
    let p = map_to_unit_disk(&mesh).unwrap().unwrap();
    let laplacian = cotan_laplacian(&mesh).unwrap();
    let symbolic = laplacian.symbolic();
    let (col_ptr, rows, values) = (symbolic.col_ptr(), symbolic.row_idx(), laplacian.val());
    let mut residual = vec![[0.0f64; 2]; mesh.vertex_count()];
    let mut scale = vec![0.0f64; mesh.vertex_count()];
    for col in 0..laplacian.ncols() {
        for k in col_ptr[col]..col_ptr[col + 1] {
            for axis in 0..2 {
                residual[rows[k]][axis] += values[k] * p[col][axis];
            }
            scale[rows[k]] += values[k].abs();
        }
    }
    let worst = mesh
        .vertices()
        .filter(|&v| !mesh.is_boundary_vertex(v))
        .map(|v| residual[v.idx()][0].hypot(residual[v.idx()][1]) / scale[v.idx()])
        .fold(0.0, f64::max);
    assert!(worst < 1e-13, "largest relative residual {worst:e}");
}
