//! Circle-domain meshes for the tests (`beltrami_remesh::circle_domain`) and
//! what the tests compare.
#![allow(dead_code)]

use beltrami_core::{Context, Goal, Problem, Solution, Solver, Target};
use beltrami_mesh::Mesh;
use beltrami_qcmc::Qcmc;
use beltrami_qcmc::moebius::{DiskAutomorphism, PlaneCircle};
use beltrami_remesh::circle_domain::Hole;
use num_complex::Complex64;

/// A triangle mesh of the unit disk minus the closed disks `holes`, edges about `h`
/// long ([`beltrami_remesh::circle_domain::circle_domain`]).
pub fn circle_domain(holes: &[PlaneCircle], h: f64) -> Mesh {
    let holes: Vec<Hole> = holes
        .iter()
        .map(|c| Hole {
            center: c.center,
            radius: c.radius,
        })
        .collect();
    beltrami_remesh::circle_domain::circle_domain(&holes, h).unwrap()
}

/// Runs qcmc on `mesh` with `goal` and the options `options` (name, text).
pub fn run(mesh: &Mesh, goal: Goal, options: &[(&str, &str)]) -> Solution {
    let mut problem = Problem::new(mesh, Target::CircleDomain);
    problem.goal = goal;
    for (name, value) in options {
        problem.options.set_text(name, value);
    }
    Qcmc.solve(&problem, &mut Context::new()).unwrap()
}

/// The planar map of a solution.
pub fn planar(solution: &Solution) -> Vec<Complex64> {
    solution.planar().unwrap().to_vec()
}

/// The solver's normalization of the circle domain `holes` (the domain of the mesh's
/// own vertices, `positions`): the disk automorphism that centres the circle of the
/// first inner loop and sends the first vertex of the outer loop to 1 (crate docs).
pub fn normalization(
    mesh: &Mesh,
    holes: &[PlaneCircle],
    positions: &[Complex64],
) -> DiskAutomorphism {
    let loops = mesh.boundary_loop_list();
    let outer = (0..loops.len())
        .max_by(|&a, &b| loops[a].length.total_cmp(&loops[b].length))
        .unwrap();
    let first_inner = (0..loops.len()).find(|&i| i != outer).unwrap();
    let hole = hole_of(holes, positions[loops[first_inner].vertices[0].idx()]);
    DiskAutomorphism::centering(&holes[hole], positions[loops[outer].vertices[0].idx()])
}

/// The hole whose circle passes through `z`.
pub fn hole_of(holes: &[PlaneCircle], z: Complex64) -> usize {
    (0..holes.len())
        .min_by(|&a, &b| {
            holes[a]
                .relative_distance(z)
                .total_cmp(&holes[b].relative_distance(z))
        })
        .unwrap()
}

/// The vertex positions `x + i y`.
pub fn positions(mesh: &Mesh) -> Vec<Complex64> {
    mesh.positions()
        .iter()
        .map(|p| Complex64::new(p.x, p.y))
        .collect()
}
