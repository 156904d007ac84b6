//! Circle-domain meshes for the tests (spade's constrained Delaunay triangulation) and
//! what the tests compare.
#![allow(dead_code)]

use beltrami_core::{Context, Goal, Problem, Solution, Solver, Target};
use beltrami_mesh::{Mesh, Point3, PolygonSoup};
use beltrami_qcmc::Qcmc;
use beltrami_qcmc::moebius::{DiskAutomorphism, PlaneCircle};
use num_complex::Complex64;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// A triangle mesh of the unit disk minus the closed disks `holes`, edges about `h`
/// long: the circles sampled evenly (as constraint edges), a hexagonal lattice of
/// spacing `h` inside, at least `h / 2` from the circles.
pub fn circle_domain(holes: &[PlaneCircle], h: f64) -> Mesh {
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut circle = |c: Complex64, r: f64| {
        let n = ((2.0 * std::f64::consts::PI * r / h).ceil() as usize).max(8);
        let handles: Vec<_> = (0..n)
            .map(|i| {
                let z = c + r * Complex64::cis(2.0 * std::f64::consts::PI * i as f64 / n as f64);
                cdt.insert(Point2::new(z.re, z.im)).unwrap()
            })
            .collect();
        for i in 0..n {
            cdt.add_constraint(handles[i], handles[(i + 1) % n]);
        }
    };
    circle(Complex64::new(0.0, 0.0), 1.0);
    for hole in holes {
        circle(hole.center, hole.radius);
    }
    let inside = |z: Complex64, margin: f64| {
        z.norm() < 1.0 - margin
            && holes
                .iter()
                .all(|c| (z - c.center).norm() > c.radius + margin)
    };
    let rows = (2.0 / (h * 0.75f64.sqrt())).ceil() as i64;
    for j in -rows..=rows {
        for i in -rows..=rows {
            let z = Complex64::new(
                h * (i as f64 + 0.5 * (j.rem_euclid(2)) as f64),
                h * 0.75f64.sqrt() * j as f64,
            );
            if inside(z, 0.5 * h) {
                cdt.insert(Point2::new(z.re, z.im)).unwrap();
            }
        }
    }
    let positions: Vec<Point3<f64>> = cdt
        .vertices()
        .map(|v| Point3::new(v.position().x, v.position().y, 0.0))
        .collect();
    let mut soup = PolygonSoup::new(positions);
    for f in cdt.inner_faces() {
        let [a, b, c] = f.vertices();
        let centroid = Complex64::new(
            (a.position().x + b.position().x + c.position().x) / 3.0,
            (a.position().y + b.position().y + c.position().y) / 3.0,
        );
        if inside(centroid, 0.0) {
            soup.push_face(&[
                a.fix().index() as u32,
                b.fix().index() as u32,
                c.fix().index() as u32,
            ]);
        }
    }
    Mesh::from_soup(&soup).unwrap()
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
