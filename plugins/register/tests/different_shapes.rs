//! Closed surfaces of one genus and different shapes, registered with no landmark: two
//! different implicit pretzels of genus 2 (marching tetrahedra, neither a remesh nor a
//! bent copy of the other). The target's cut graph is drawn where the placed source's
//! arcs lie, the placement pulled onto the target by closest points
//! (`src/routing.rs`); before that the arcs found no path on the other mesh.

#[path = "fixtures/implicit.rs"]
mod implicit;

use beltrami_core::{Context, Problem, Solver, Target};
use beltrami_mesh::Mesh;
use beltrami_register::Register;

fn register_without_flips(source: &Mesh, target: &Mesh) {
    let problem = Problem::new(source, Target::Mesh(target));
    let settings = Register.check(&problem).unwrap();
    let solution = Register
        .run(&problem, &settings, &mut Context::new())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(solution.metrics.flipped(), Some(0), "{:?}", solution.report);
    let mu = solution.metrics.distortion.unwrap();
    assert!(mu.mu_max < 1.0, "{mu:?}");
}

#[test]
fn two_different_pretzels_register_both_ways_without_a_flip() {
    let thin = implicit::pretzel(0.02, [1.0, 1.0, 1.0], 0.0, 56);
    let thick = implicit::pretzel(0.03, [1.15, 0.9, 1.3], 0.05, 56);
    assert_eq!((thin.genus(), thick.genus()), (Some(2), Some(2)));
    register_without_flips(&thin, &thick);
    register_without_flips(&thick, &thin);
}
