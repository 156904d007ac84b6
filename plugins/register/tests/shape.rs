//! Registration by shape (the option `match-shape`) on generated pairs with a known
//! answer: the target is a remeshed copy of the source under a smooth deformation that is
//! far from a similarity and from conformal, and the registration must land nearer the
//! truth with the shape matched than without, with no face flipped.

mod common;
#[path = "fixtures/blob.rs"]
mod fixtures;

use beltrami_core::{OptionValue, Problem, Solution, Solver, Target};
use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{Mesh, Point3, Vector3};
use beltrami_register::Register;
use beltrami_spatial::SurfaceIndex;
use common::run_against_truth;
use fixtures::{blob_pair, deform};

/// Registers `source` onto `target`, with the shape matched when `shape`, taken in
/// place when `in_place` (checks of [`run_against_truth`]).
fn register_with(
    source: &Mesh,
    target: &Mesh,
    truth: &dyn Fn(&Point3<f64>) -> Point3<f64>,
    shape: bool,
    in_place: bool,
) -> (f64, Solution) {
    let mut problem = Problem::new(source, Target::Mesh(target));
    if shape {
        problem.options.set("match-shape", OptionValue::Bool(true));
    }
    if in_place {
        problem.options.set("in-place", OptionValue::Bool(true));
    }
    run_against_truth(&problem, source, target, truth)
}

/// The mean distance to the truth of the closest points on `target` of `source` placed
/// by the similarity of centroids and root-mean-square radii: the peer's correspondence
/// for a pair that overlaps in space (a projection, not a bijection).
fn closest_point_of_placed_source(
    source: &Mesh,
    target: &Mesh,
    truth: &dyn Fn(&Point3<f64>) -> Point3<f64>,
) -> f64 {
    let spread = |mesh: &Mesh| {
        let n = mesh.vertex_count() as f64;
        let centre = mesh
            .positions()
            .iter()
            .map(|p| p.coords)
            .sum::<Vector3<f64>>()
            / n;
        let radius = (mesh
            .positions()
            .iter()
            .map(|p| (p.coords - centre).norm_squared())
            .sum::<f64>()
            / n)
            .sqrt();
        (centre, radius)
    };
    let ((cs, rs), (ct, rt)) = (spread(source), spread(target));
    let placed: Vec<Point3<f64>> = source
        .positions()
        .iter()
        .map(|p| Point3::from((p.coords - cs) * (rt / rs) + ct))
        .collect();
    let closest = SurfaceIndex::new(target)
        .unwrap()
        .locate_all(&placed)
        .unwrap();
    source
        .positions()
        .iter()
        .zip(&closest)
        .map(|(p, c)| (c.position - truth(p)).norm())
        .sum::<f64>()
        / source.vertex_count() as f64
}

/// [`register_with`] with the source aligned.
fn register(
    source: &Mesh,
    target: &Mesh,
    truth: &dyn Fn(&Point3<f64>) -> Point3<f64>,
    shape: bool,
) -> (f64, Solution) {
    register_with(source, target, truth, shape, false)
}

#[test]
fn a_deformed_blob_is_found_by_its_shape() {
    let (source, target) = blob_pair(4);
    let (conformal, _) = register(&source, &target, &deform, false);
    let (matched, solution) = register(&source, &target, &deform, true);
    let distance = solution.extras.shape.expect("the shape match is reported");
    assert!(distance.after < distance.before, "{distance:?}");
    let closest = closest_point_of_placed_source(&source, &target, &deform);
    eprintln!(
        "deformed blob: mean distance to the truth {matched:.4} with the shape, {conformal:.4} without, {closest:.4} for the closest points of the placed source"
    );
    // Measured 0.031 against 0.169: the non-rigid ICP's template follows the
    // deformation and the matched coordinates keep the map a bijection.
    assert!(
        matched < 0.3 * conformal,
        "mean distance to the truth: {matched:.4} with the shape, {conformal:.4} without"
    );
    // The bar for pairs that overlap in space: no farther from the truth than
    // the closest points of the placed source (measured 0.031 against 0.100).
    assert!(
        matched < closest,
        "mean distance to the truth: {matched:.4} with the shape, {closest:.4} for the closest points of the placed source"
    );
}

/// The blob of `blob_pair(level)` and an offset of it, every vertex moved along its
/// normal by `thickness` (as a cortex's pial surface lies outside its white surface):
/// `(offset, blob)`, vertex `i` of one onto vertex `i` of the other.
fn offset_pair(level: usize, thickness: f64) -> (Mesh, Mesh) {
    let (blob, _) = blob_pair(level);
    let mut soup = primitives::icosphere(level);
    for v in blob.vertices() {
        soup.positions[blob.vertex_map().to_input(v)] =
            blob.position(v) + thickness * blob.vertex_normal(v);
    }
    (Mesh::from_soup(&soup).unwrap(), blob)
}

#[test]
fn an_offset_surface_in_place_lands_near_its_correspondence() {
    // An offset is no similarity of the blob: aligned as a whole, the source slides
    // along the target; taken in place, the supple non-rigid ICP follows the normals.
    let thickness = 0.05;
    let (source, target) = offset_pair(4, thickness);
    let truth = |p: &Point3<f64>| {
        let v = source
            .vertices()
            .find(|&v| source.position(v) == *p)
            .expect("a source vertex");
        let input = source.vertex_map().to_input(v);
        target.position(
            target
                .vertex_map()
                .from_input(input)
                .expect("one numbering"),
        )
    };
    let (aligned, _) = register_with(&source, &target, &truth, true, false);
    let (in_place, _) = register_with(&source, &target, &truth, true, true);
    let closest = closest_point_of_placed_source(&source, &target, &truth);
    eprintln!(
        "offset blob: mean distance to the truth {in_place:.4} in place, {aligned:.4} aligned, {closest:.4} for the closest points of the placed source"
    );
    assert!(
        in_place < 0.5 * aligned && in_place < 0.5 * thickness,
        "mean distance to the truth: {in_place:.4} in place, {aligned:.4} aligned"
    );
}

#[test]
fn in_place_without_the_shape_match_is_refused_before_work() {
    let (source, target) = blob_pair(2);
    let mut problem = Problem::new(&source, Target::Mesh(&target));
    problem.options.set("in-place", OptionValue::Bool(true));
    let error = Register.check(&problem).unwrap_err();
    assert!(
        error.to_string().contains("in-place") && error.to_string().contains("match-shape"),
        "{error}"
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
