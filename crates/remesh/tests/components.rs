//! Meshes in several connected components, each remeshed on its own and joined
//! (`beltrami_remesh::components`): a flat square and a sphere far from it.

use beltrami_core::{Context, Solver};
use beltrami_init::{Lscm, Sphere, Tutte};
use beltrami_mesh::primitives::{Cells, grid, icosphere};
use beltrami_mesh::{Mesh, PolygonSoup, Vector3};
use beltrami_remesh::components::{Coverage, remesh_covering, remesh_each};
use beltrami_remesh::{RemeshError, RemeshOptions, Resolution, remesh};

/// `a` and `b` in one soup, `b` moved by `shift`, `a`'s faces first.
fn side_by_side(a: &PolygonSoup, b: &PolygonSoup, shift: Vector3<f64>) -> Mesh {
    let mut soup = a.clone();
    let offset = soup.positions.len() as u32;
    soup.positions.extend(b.positions.iter().map(|p| p + shift));
    let faces: Vec<Vec<u32>> = b
        .faces()
        .map(|f| f.iter().map(|i| i + offset).collect())
        .collect();
    for f in faces {
        soup.push_face(&f);
    }
    Mesh::from_soup(&soup).unwrap()
}

/// The parameterizers the CLI's `auto` picks for these surfaces: LSCM for the square,
/// the sphere's two charts for the sphere.
fn chosen(part: &Mesh) -> Result<Vec<&'static dyn Solver>, RemeshError> {
    if part.boundary_loop_list().is_empty() {
        Ok(vec![&Sphere])
    } else {
        Ok(vec![&Lscm, &Tutte])
    }
}

/// Where the sphere lies beside the square.
const SHIFT: Vector3<f64> = Vector3::new(4.0, 0.0, 0.0);

fn square_and_sphere() -> (PolygonSoup, PolygonSoup, Mesh) {
    let square = grid(8, 8, Cells::Triangles);
    let sphere = icosphere(3);
    let both = side_by_side(&square, &sphere, SHIFT);
    (square, sphere, both)
}

#[test]
fn each_component_is_remeshed_as_it_would_be_alone() {
    let (square, sphere, both) = square_and_sphere();
    let options = RemeshOptions::with_edge_length(0.1);
    let joined = remesh_each(&both, chosen, &options, &mut Context::new()).unwrap();
    assert_eq!(joined.components.len(), 2);
    assert_eq!(joined.remeshed.mesh.component_count(), 2);
    // Each component's new mesh is the one the component alone (where it lies) gets.
    let alone = [
        side_by_side(&square, &PolygonSoup::new(Vec::new()), Vector3::zeros()),
        side_by_side(&PolygonSoup::new(Vec::new()), &sphere, SHIFT),
    ];
    for (alone, component) in alone.iter().zip(&joined.components) {
        let solvers = chosen(alone).unwrap();
        let by_itself = remesh(alone, &solvers, &options, &mut Context::new()).unwrap();
        let new = &component.remeshing.remeshed.mesh;
        assert_eq!(new.vertex_count(), by_itself.remeshed.mesh.vertex_count());
        assert_eq!(new.face_count(), by_itself.remeshed.mesh.face_count());
        assert_eq!(component.input_faces, alone.face_count());
    }
    let square_vertices = joined.components[0].remeshing.remeshed.mesh.vertex_count();
    // Every joined vertex is its point on the whole input; the square's come first.
    let out = &joined.remeshed.mesh;
    assert_eq!(joined.remeshed.on_source.len(), out.vertex_count());
    for (v, point) in out.vertices().zip(&joined.remeshed.on_source) {
        let on_input = point.position(&both);
        assert!(
            (on_input - out.position(v)).norm() < 1e-9,
            "vertex {v:?} at {:?}, its input point at {on_input:?}",
            out.position(v)
        );
        let in_square =
            both.face_component(point.face) == both.face_component(both.faces().next().unwrap());
        assert_eq!(in_square, v.idx() < square_vertices, "vertex {v:?}");
    }
}

#[test]
fn a_vertex_count_is_shared_out_by_area() {
    let (_, _, both) = square_and_sphere();
    let asked = 4000;
    let options = RemeshOptions {
        resolution: Resolution::Vertices(asked),
        ..RemeshOptions::default()
    };
    let joined = remesh_each(&both, chosen, &options, &mut Context::new()).unwrap();
    let total = joined.remeshed.mesh.vertex_count() as f64;
    assert!(
        (total / asked as f64 - 1.0).abs() < 0.1,
        "{total} vertices for {asked}"
    );
    // The sphere has 4 pi / 1 = 12.6 times the square's area: about as many times the
    // vertices, so one edge length throughout.
    let lengths: Vec<f64> = joined
        .components
        .iter()
        .map(|c| c.remeshing.edge_length)
        .collect();
    assert!((lengths[0] / lengths[1] - 1.0).abs() < 0.1, "{lengths:?}");
}

#[test]
fn a_component_that_fails_is_named() {
    // The sphere's parameterizer for every component: a bent square (the second
    // component, whose first face comes after the sphere's 1280) cannot be mapped onto
    // the sphere. (A flat one is its own parameterization and needs none.)
    let (mut square, sphere, _) = square_and_sphere();
    for p in &mut square.positions {
        p.z = 0.3 * (3.0 * p.x).sin();
    }
    let both = side_by_side(&sphere, &square, SHIFT);
    let onto_sphere =
        |_: &Mesh| -> Result<Vec<&'static dyn Solver>, RemeshError> { Ok(vec![&Sphere]) };
    let options = RemeshOptions::with_edge_length(0.1);
    let Err(error) = remesh_each(&both, onto_sphere, &options, &mut Context::new()) else {
        panic!("the square was mapped onto the sphere");
    };
    let RemeshError::InComponent {
        component,
        first_face,
        ..
    } = &error
    else {
        panic!("{error}")
    };
    assert_eq!((*component, *first_face), (1, 1280), "{error}");
    assert!(
        error
            .to_string()
            .starts_with("component 1 (the one with input face 1280): "),
        "{error}"
    );
}

#[test]
fn the_coverage_dispatch_remeshes_the_whole_each_or_the_largest() {
    let (_, sphere, both) = square_and_sphere();
    let options = RemeshOptions::with_edge_length(0.1);
    let run = |mesh: &Mesh, coverage| {
        remesh_covering(mesh, coverage, chosen, &options, &mut Context::new())
    };
    // The whole of a mesh in pieces is refused, naming the count.
    assert!(matches!(
        run(&both, Coverage::Whole),
        Err(RemeshError::Components { components: 2 })
    ));
    // Each: remesh_each's mesh and per-component list.
    let each = run(&both, Coverage::Each).unwrap();
    let joined = remesh_each(&both, chosen, &options, &mut Context::new()).unwrap();
    assert_eq!(each.mesh.positions(), joined.remeshed.mesh.positions());
    assert_eq!(each.components.len(), 2);
    assert!(each.part.is_none());
    assert!(std::ptr::eq(each.input(&both), &both));
    // Largest of the pieces: the sphere (more faces than the 8 x 8 square's 128), alone,
    // measured against itself, and said so in the notes.
    let largest = run(&both, Coverage::Largest).unwrap();
    let part = largest.part.as_ref().expect("the largest component");
    assert_eq!(part.mesh.face_count(), sphere.face_count());
    assert_eq!(largest.input(&both).face_count(), sphere.face_count());
    assert!(largest.components.is_empty());
    assert!(
        largest
            .summary
            .notes
            .iter()
            .any(|n| n.contains("largest of 2")),
        "{:?}",
        largest.summary.notes
    );
    // Largest of a mesh in one piece: the whole, as Whole remeshes it.
    let one = Mesh::from_soup(&sphere).unwrap();
    let (a, b) = (
        run(&one, Coverage::Largest).unwrap(),
        run(&one, Coverage::Whole).unwrap(),
    );
    assert!(a.part.is_none());
    assert_eq!(a.mesh.positions(), b.mesh.positions());
}
