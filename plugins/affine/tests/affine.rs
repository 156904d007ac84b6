//! The affine solver against its exact answer: `|mu| = |k|` on every face, as measured
//! independently of the solver, and its refusals through `check` and `solve` alike.

use beltrami_affine::Affine;
use beltrami_core::{Context, Goal, Map, PlanarBoundary, Problem, Solver, SolverError, Target};
use beltrami_fem::distortion::measure_planar;
use beltrami_fem::{BeltramiField, Frame};
use beltrami_mesh::primitives::{Cells, jittered_grid};
use beltrami_mesh::{Mesh, Point3};
use num_complex::Complex64;

fn jittered(cells: Cells) -> Mesh {
    Mesh::from_soup(&jittered_grid(9, 9, cells, 0.24, 5)).unwrap()
}

fn prescribed(mesh: &Mesh, mu: Vec<Complex64>) -> Problem<'_> {
    let mut problem = Problem::new(mesh, Target::Plane(PlanarBoundary::Free));
    problem.goal = Goal::Prescribed(BeltramiField::new(Frame::Global, mu));
    problem
}

#[test]
fn a_constant_mu_is_met_on_every_face_to_rounding() {
    let k = Complex64::new(0.3, -0.45);
    for cells in [Cells::Triangles, Cells::Quads] {
        let mesh = jittered(cells);
        let problem = prescribed(&mesh, vec![k; mesh.face_count()]);
        let solution = Affine.solve(&problem, &mut Context::new()).unwrap();
        let Some(Map::Planar(map)) = solution.map() else {
            panic!("a planar map");
        };
        // Measured apart from the solver, in every face's own frame too.
        for frame in [Frame::Global, Frame::Face] {
            let measured = measure_planar(&mesh, map, frame).unwrap();
            let worst = measured
                .field
                .mu
                .iter()
                .map(|mu| (mu.norm() - k.norm()).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-13, "{cells:?} {frame:?}: |mu| off by {worst}");
            assert_eq!(measured.stats.flipped, 0);
        }
        let error = solution.metrics.mu_error.as_ref().expect("mu error");
        assert!(error.sup < 1e-13, "{cells:?}: {error:?}");
    }
}

#[test]
fn a_varying_mu_or_a_curved_mesh_is_refused_before_work() {
    let mesh = jittered(Cells::Triangles);
    let mut mu = vec![Complex64::new(0.2, 0.0); mesh.face_count()];
    mu[7] = Complex64::new(0.25, 0.0);
    let problem = prescribed(&mesh, mu);
    for error in [
        Affine.check(&problem).unwrap_err(),
        Affine.solve(&problem, &mut Context::new()).unwrap_err(),
    ] {
        match &error {
            SolverError::Unsupported { message, .. } => {
                assert!(message.contains("face 7"), "{message}");
            }
            other => panic!("expected Unsupported, got {other:?}"),
        }
    }
    let bent: Vec<Point3<f64>> = mesh
        .positions()
        .iter()
        .map(|p| Point3::new(p.x, p.y, 0.1 * p.x * p.y))
        .collect();
    let curved = mesh.with_positions(bent).unwrap();
    let problem = prescribed(&curved, vec![Complex64::new(0.2, 0.0); curved.face_count()]);
    assert!(Affine.check(&problem).is_err());
}
