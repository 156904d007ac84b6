//! What the registration tests on generated pairs share.

use beltrami_core::{Context, Map, Problem, Solution, Solver};
use beltrami_mesh::{Mesh, Point3};
use beltrami_register::Register;

/// Runs `problem` (of `source` onto `target`), checks that no face is flipped, and
/// returns the mean distance of the images from `truth` with the solution.
pub fn run_against_truth(
    problem: &Problem<'_>,
    source: &Mesh,
    target: &Mesh,
    truth: &dyn Fn(&Point3<f64>) -> Point3<f64>,
) -> (f64, Solution) {
    let settings = Register.check(problem).unwrap();
    let solution = Register
        .run(problem, &settings, &mut Context::new())
        .unwrap();
    assert_eq!(solution.metrics.flipped(), Some(0));
    let Some(Map::OnMesh(points)) = solution.map() else {
        panic!("a map onto the target mesh");
    };
    let error = source
        .vertices()
        .map(|v| (points[v.idx()].position(target) - truth(&source.position(v))).norm())
        .sum::<f64>()
        / source.vertex_count() as f64;
    (error, solution)
}
