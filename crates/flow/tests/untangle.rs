//! Untangling on a target mesh: a vertex dragged out of the kernel of its star flips
//! faces; moving it back into the kernel removes them, and nothing else moves.

use beltrami_fem::{Elements, Frame};
use beltrami_flow_engine::measure::{ImageFace, image_faces};
use beltrami_flow_engine::mesh_target::{MeshTarget, TargetCurve};
use beltrami_flow_engine::target::{Role, TargetGeometry};
use beltrami_flow_engine::untangle::{UntangleRounds, untangle};
use beltrami_mesh::primitives::{Cells, grid};
use beltrami_mesh::{Mesh, Point3, Vector3};
use beltrami_spatial::SurfaceIndex;

/// The unit-square grid lifted onto the paraboloid `z = c (x^2 + y^2)` (a curved
/// target, so that projection matters) and its boundary/interior roles.
fn lifted(n: usize, c: f64) -> (Mesh, Vec<Role>) {
    let mut soup = grid(n, n, Cells::Triangles);
    for p in &mut soup.positions {
        p.z = c * (p.x * p.x + p.y * p.y);
    }
    let mesh = Mesh::from_soup(&soup).expect("a grid is a valid mesh");
    let roles = mesh
        .vertices()
        .map(|v| {
            if mesh.is_boundary_vertex(v) {
                Role::Curve(0)
            } else {
                Role::Free
            }
        })
        .collect();
    (mesh, roles)
}

/// The vertex at grid point (4, 4) of [`lifted`]`(8, _)`.
const DRAGGED: usize = 4 + 9 * 4;

/// Drags [`DRAGGED`] past its neighbour (6, 4) (off the grid points, so that its star's
/// kernel centroid is not its place) and returns the images' normals and faces.
fn drag(
    target: &MeshTarget<'_>,
    elements: &Elements,
    image: &mut [Point3<f64>],
) -> (Vec<Vector3<f64>>, Vec<ImageFace>) {
    image[DRAGGED] = target.project(Role::Free, &Point3::new(0.8, 0.52, 0.0));
    let normals: Vec<Vector3<f64>> = image.iter().map(|p| target.normal(p)).collect();
    let mut faces = Vec::new();
    image_faces(elements, &normals, image, &mut faces, 1);
    (normals, faces)
}

#[test]
fn a_vertex_dragged_across_its_neighbour_comes_back_into_its_star() {
    for c in [0.0, 0.5] {
        let (mesh, roles) = lifted(8, c);
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let index = SurfaceIndex::new(&mesh).unwrap();
        let target = MeshTarget::new(&index, TargetCurve::boundary_loops(&mesh).unwrap());
        // The identity map, with vertex (4, 4) dragged past its neighbour (6, 4).
        let mut image: Vec<Point3<f64>> = mesh.positions().to_vec();
        let dragged = DRAGGED;
        let (mut normals, mut faces) = drag(&target, &elements, &mut image);
        let before = faces.iter().filter(|f| f.flipped()).count();
        assert!(before >= 2, "the drag flips faces: {before}");
        let original = image.clone();
        let done = untangle(
            &elements,
            &target,
            &roles,
            &mut image,
            &mut normals,
            &mut faces,
            UntangleRounds {
                rounds: 8,
                previous: None,
            },
        );
        assert_eq!(done.before, before);
        assert_eq!(done.after, 0, "c = {c}: {done:?}");
        let mut check = Vec::new();
        image_faces(&elements, &normals, &image, &mut check, 2);
        assert_eq!(check.iter().filter(|f| f.flipped()).count(), 0);
        // The boundary never moves, and the untangled point lies on the target.
        for v in mesh.vertices() {
            if roles[v.idx()] != Role::Free {
                assert_eq!(image[v.idx()], original[v.idx()]);
            }
            let p = image[v.idx()];
            assert!((p.z - c * (p.x * p.x + p.y * p.y)).abs() < 0.02, "{p}");
        }
        // The dragged vertex is back among its neighbours: inside the 2h-square around
        // its place in the grid.
        let home = mesh.positions()[dragged];
        let p = image[dragged];
        assert!(
            (p.x - home.x).abs() < 0.25 && (p.y - home.y).abs() < 0.25,
            "c = {c}: {p} vs {home}"
        );
    }
}

#[test]
fn a_vertex_a_step_folded_goes_back_to_its_place_before_the_step() {
    // The step search of the flow untangles a trial step's flips with the images before
    // the step: the vertex that folded its star goes back exactly where it was (the
    // least move), not to its star's kernel centroid, and nothing else moves.
    let (mesh, _) = lifted(8, 0.5);
    let elements = Elements::new(&mesh, Frame::Face).unwrap();
    let index = SurfaceIndex::new(&mesh).unwrap();
    let target = MeshTarget::new(&index, TargetCurve::boundary_loops(&mesh).unwrap());
    let before_step: Vec<Point3<f64>> = mesh.positions().to_vec();
    let mut image = before_step.clone();
    let dragged = DRAGGED;
    // Only the dragged vertex may move.
    let roles: Vec<Role> = (0..image.len())
        .map(|v| {
            if v == dragged {
                Role::Free
            } else {
                Role::Fixed
            }
        })
        .collect();
    let (mut normals, mut faces) = drag(&target, &elements, &mut image);
    let done = untangle(
        &elements,
        &target,
        &roles,
        &mut image,
        &mut normals,
        &mut faces,
        UntangleRounds {
            rounds: 4,
            previous: Some(&before_step),
        },
    );
    assert_eq!(done.after, 0, "{done:?}");
    assert_eq!(done.moves, 1, "{done:?}");
    for v in 0..image.len() {
        assert!(
            (image[v] - before_step[v]).norm() < 1e-12,
            "vertex {v}: {} vs {}",
            image[v],
            before_step[v]
        );
    }
}
