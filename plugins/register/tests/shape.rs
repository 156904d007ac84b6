//! Registration by shape (the option `match-shape`) on generated pairs with a known
//! answer: the target is a remeshed copy of the source under a smooth deformation that is
//! far from a similarity and from conformal, and the registration must land nearer the
//! truth with the shape matched than without, with no face flipped.

mod common;
#[path = "fixtures/blob.rs"]
mod fixtures;

use beltrami_core::{OptionValue, Problem, Solution, Solver, Target};
use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{Mesh, Point3};
use beltrami_register::Register;
use common::run_against_truth;
use fixtures::{blob_pair, deform};

/// Registers `source` onto `target`, with the shape matched when `shape` (checks of
/// [`run_against_truth`]).
fn register(
    source: &Mesh,
    target: &Mesh,
    truth: &dyn Fn(&Point3<f64>) -> Point3<f64>,
    shape: bool,
) -> (f64, Solution) {
    let mut problem = Problem::new(source, Target::Mesh(target));
    if shape {
        problem.options.set("match-shape", OptionValue::Bool(true));
    }
    run_against_truth(&problem, source, target, truth)
}

#[test]
fn a_deformed_blob_is_found_by_its_shape() {
    let (source, target) = blob_pair(4);
    let (conformal, _) = register(&source, &target, &deform, false);
    let (matched, solution) = register(&source, &target, &deform, true);
    let distance = solution.extras.shape.expect("the shape match is reported");
    assert!(distance.after < distance.before, "{distance:?}");
    eprintln!(
        "deformed blob: mean distance to the truth {matched:.4} with the shape, {conformal:.4} without"
    );
    // Measured 0.030 against 0.169: the non-rigid ICP's template follows the
    // deformation and the matched coordinates keep the map a bijection.
    assert!(
        matched < 0.3 * conformal,
        "mean distance to the truth: {matched:.4} with the shape, {conformal:.4} without"
    );
}

#[test]
fn the_shape_of_a_torus_is_refused_before_work() {
    let torus = Mesh::from_soup(&primitives::torus(20, 8, 3.0, 1.0, Cells::Triangles)).unwrap();
    let mut problem = Problem::new(&torus, Target::Mesh(&torus));
    problem.options.set("match-shape", OptionValue::Bool(true));
    let error = Register.check(&problem).unwrap_err();
    assert!(
        error.to_string().contains("match-shape") && error.to_string().contains("genus-0"),
        "{error}"
    );
}
