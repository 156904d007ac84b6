//! Helpers shared by the integration tests of beltrami-init: jittered planar grids, the
//! bundled and shared meshes, and checks of maps that do not go through the code under
//! test.
// Each test binary compiles this module and uses only part of it.
#![allow(dead_code)]

use std::io::Write as _;
use std::path::{Path, PathBuf};

use beltrami_core::{Map, Solution};
use beltrami_mesh::io::read;
use beltrami_mesh::primitives::{Cells, jittered_grid};
use beltrami_mesh::{BuildOptions, FaceId, Mesh, VertexId};
use num_complex::Complex64;

/// The unit-square grid of `n x n` cells with interior vertices moved randomly by up to
/// `amount` cells in x and y.
pub fn jittered(n: usize, cells: Cells, amount: f64, seed: u64) -> Mesh {
    Mesh::from_soup(&jittered_grid(n, n, cells, amount, seed))
        .expect("a jittered grid is a valid mesh")
}

/// The bundled hemisphere (a cap of the unit sphere, 3600 triangles).
pub fn hemisphere() -> Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../meshes/disk_hemisphere.obj"
    );
    read(Path::new(path), &BuildOptions::default())
        .expect("the bundled hemisphere reads")
        .mesh
}

/// The shared disk meshes (`disk_*.obj`, `quad_disk_inspired.obj`) by name, or `None`
/// (after printing SKIPPED) when `../shared/meshes` is absent.
pub fn shared_disks(test: &str) -> Option<Vec<(String, Mesh)>> {
    let dir = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/meshes"
    ));
    let Ok(entries) = std::fs::read_dir(&dir) else {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED {test}: {} is absent",
            dir.display()
        );
        return None;
    };
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| {
            (n.starts_with("disk_") && n.ends_with(".obj")) || n == "quad_disk_inspired.obj"
        })
        .collect();
    names.sort();
    Some(
        names
            .into_iter()
            .map(|name| {
                let mesh = read(&dir.join(&name), &BuildOptions::default())
                    .unwrap_or_else(|e| panic!("{name}: {e}"))
                    .mesh;
                (name, mesh)
            })
            .collect(),
    )
}

/// The planar images of a solution.
pub fn planar(map: &Map) -> &[Complex64] {
    map.as_planar().expect("a planar map")
}

/// `a.re b.im - a.im b.re`.
pub fn cross(a: Complex64, b: Complex64) -> f64 {
    a.re * b.im - a.im * b.re
}

/// Faces whose image is not positively oriented, computed here without the fem crate:
/// a triangle with signed image area `<= 0`, or a quad whose bilinear image has a
/// Jacobian `<= 0` at one of its 2x2 Gauss points.
pub fn flipped_faces(mesh: &Mesh, map: &[Complex64]) -> Vec<FaceId> {
    let g = [0.5 - 0.5 / 3f64.sqrt(), 0.5 + 0.5 / 3f64.sqrt()];
    mesh.faces()
        .filter(|&f| {
            let z: Vec<Complex64> = mesh.face_vertices(f).map(|v| map[v.idx()]).collect();
            if z.len() == 3 {
                cross(z[1] - z[0], z[2] - z[0]) <= 0.0
            } else {
                g.iter().any(|&u| {
                    g.iter().any(|&v| {
                        let xu = (z[1] - z[0]) * (1.0 - v) + (z[2] - z[3]) * v;
                        let xv = (z[3] - z[0]) * (1.0 - u) + (z[2] - z[1]) * u;
                        cross(xu, xv) <= 0.0
                    })
                })
            }
        })
        .collect()
}

/// Boundary vertices of the (single) boundary loop.
pub fn boundary_vertices(mesh: &Mesh) -> Vec<VertexId> {
    mesh.boundary_loop_list()[0].vertices.clone()
}

/// The largest `|x_i - sum_j w_ij x_j / sum_j w_ij|` over interior vertices.
pub fn weighted_mean_error(
    mesh: &Mesh,
    weights: &beltrami_fem::EdgeWeights,
    map: &[Complex64],
) -> f64 {
    mesh.vertices()
        .filter(|&v| !mesh.is_boundary_vertex(v))
        .map(|v| {
            let (mut sum, mut total) = (Complex64::new(0.0, 0.0), 0.0);
            for (j, w) in weights.row(v) {
                sum += w * map[j.idx()];
                total += w;
            }
            (map[v.idx()] - sum / total).norm()
        })
        .fold(0.0, f64::max)
}

/// Largest distance between the map and the source's own (x, y) positions.
pub fn identity_error(mesh: &Mesh, map: &[Complex64]) -> f64 {
    mesh.vertices()
        .map(|v| {
            let p = mesh.position(v);
            (map[v.idx()] - Complex64::new(p.x, p.y)).norm()
        })
        .fold(0.0, f64::max)
}

/// One line with the solution's timings, flips and |mu| statistics.
pub fn summary(solution: &Solution) -> String {
    let report = &solution.report;
    let d = solution.metrics.distortion.expect("distortion measured");
    let timings: Vec<String> = report
        .timings
        .iter()
        .map(|(name, s)| format!("{name} {:.3}s", s))
        .collect();
    format!(
        "flipped {} / {}, mu mean {:.4} max {:.4} l2 {:.4}; {} (total {:.3}s)",
        d.flipped,
        d.faces,
        d.mu_mean,
        d.mu_max,
        d.mu_l2,
        timings.join(", "),
        report.seconds()
    )
}

/// The shared mesh `name` (in `../shared/meshes`), or `None` (after printing SKIPPED for
/// `test`) when it is absent.
pub fn shared_mesh(test: &str, name: &str) -> Option<Mesh> {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/meshes"
    ))
    .join(name);
    if !path.exists() {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED {test}: {} is absent",
            path.display()
        );
        return None;
    }
    Some(
        read(&path, &BuildOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .mesh,
    )
}
