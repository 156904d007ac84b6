//! The weighted-mean system: linear precision of mean-value (sparse LU) and cotangent
//! (sparse Cholesky) weights, and the error for a boundary of another mesh.

mod common;

use beltrami_fem::{EdgeWeights, WeightedMeanSystem, boundary};
use beltrami_mesh::primitives::Cells;
use beltrami_sparse::{SolveError, SolveOptions};
use common::jittered;
use num_complex::Complex64;

#[test]
fn linear_precision_reproduces_a_planar_mesh_from_its_boundary() {
    for (cells, seed) in [(Cells::Triangles, 5), (Cells::Quads, 6)] {
        let mesh = jittered(10, cells, 0.3, seed);
        let kept = boundary::keep(&mesh).unwrap();
        for weights in [
            EdgeWeights::mean_value(&mesh).unwrap(),
            EdgeWeights::cotangent(&mesh).unwrap(),
        ] {
            let system = WeightedMeanSystem::new(&weights, &kept).unwrap();
            assert_eq!(
                system.interior().len(),
                mesh.vertex_count() - kept.vertices.len()
            );
            let map = system.solve(SolveOptions::default()).unwrap();
            let err = mesh
                .vertices()
                .map(|v| {
                    let p = mesh.position(v);
                    (map[v.idx()] - Complex64::new(p.x, p.y)).norm()
                })
                .fold(0.0, f64::max);
            assert!(
                err < 1e-12,
                "{cells:?}, symmetric {}: {err:e}",
                weights.is_symmetric()
            );
        }
    }
}

#[test]
fn a_boundary_of_a_larger_mesh_is_a_length_error() {
    let small = jittered(3, Cells::Triangles, 0.2, 7);
    let large = jittered(6, Cells::Triangles, 0.2, 8);
    let weights = EdgeWeights::uniform(&small);
    let boundary = boundary::circle(&large, None).unwrap();
    assert!(matches!(
        WeightedMeanSystem::new(&weights, &boundary),
        Err(SolveError::Length { got, .. }) if got == small.vertex_count()
    ));
}
