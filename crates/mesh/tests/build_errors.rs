//! Every build error names the offending element by its input index; every repair is
//! opt-in and reported.

use std::f64::consts::TAU;

use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{
    BuildOptions, BuildReport, Mesh, MeshError, Point3, PolygonSoup, Repair, VertexId,
};

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

fn soup(positions: Vec<Point3<f64>>, faces: &[&[u32]]) -> PolygonSoup {
    let mut s = PolygonSoup::new(positions);
    for f in faces {
        s.push_face(f);
    }
    s
}

fn build(s: &PolygonSoup) -> Result<(Mesh, BuildReport), MeshError> {
    Mesh::build(s, &BuildOptions::default())
}

fn build_err(s: &PolygonSoup) -> MeshError {
    match build(s) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}

fn with_repair(repair: Repair) -> BuildOptions {
    BuildOptions {
        repair,
        ..Default::default()
    }
}

/// The unit square as two triangles plus a few extra vertices.
fn square_positions() -> Vec<Point3<f64>> {
    vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(1.0, 1.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(2.0, 0.0, 0.0),
        p(2.0, 1.0, 0.0),
    ]
}

/// A copy of `s` with `face` inserted at face index `at`.
fn insert_face(s: &PolygonSoup, at: usize, face: &[u32]) -> PolygonSoup {
    let mut out = PolygonSoup::new(s.positions.clone());
    for (i, f) in s.faces().enumerate() {
        if i == at {
            out.push_face(face);
        }
        out.push_face(f);
    }
    if at >= s.face_count() {
        out.push_face(face);
    }
    out
}

// ---------------------------------------------------------------------------------------
// One test per error kind
// ---------------------------------------------------------------------------------------

#[test]
fn no_faces() {
    assert_eq!(build_err(&PolygonSoup::new(Vec::new())), MeshError::NoFaces);
    // Vertices but no faces.
    assert_eq!(
        build_err(&PolygonSoup::new(square_positions())),
        MeshError::NoFaces
    );
    assert_eq!(MeshError::NoFaces.to_string(), "the mesh has no faces");
}

#[test]
fn default_soup_is_an_empty_soup() {
    // `PolygonSoup` derives `Default`; the default must behave like `PolygonSoup::new`.
    let s = PolygonSoup::default();
    assert_eq!(s.face_count(), 0);
    assert_eq!(s.vertex_count(), 0);
    assert_eq!(build_err(&s), MeshError::NoFaces);
    let mut s = PolygonSoup::default();
    s.positions = square_positions();
    s.push_face(&[0, 1, 2]);
    assert_eq!(s.face_count(), 1);
    assert_eq!(s.face(0), &[0, 1, 2]);
    assert_eq!(Mesh::from_soup(&s).unwrap().face_count(), 1);
}

#[test]
fn unsupported_face_size() {
    let pos = square_positions();
    // A pentagon at face 2.
    let s = soup(
        pos.clone(),
        &[&[0, 1, 2], &[0, 2, 3], &[0, 1, 4, 5, 2], &[1, 4, 5]],
    );
    let e = build_err(&s);
    assert_eq!(e, MeshError::UnsupportedFaceSize { face: 2, size: 5 });
    assert!(e.to_string().contains("face 2"), "{e}");
    assert!(e.to_string().contains("5 vertices"), "{e}");
    // A 2-gon at face 1.
    let s = soup(pos.clone(), &[&[0, 1, 2], &[0, 2], &[0, 2, 3]]);
    assert_eq!(
        build_err(&s),
        MeshError::UnsupportedFaceSize { face: 1, size: 2 }
    );
    // A 1-gon and an empty face.
    let s = soup(pos.clone(), &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 5], &[3]]);
    let e = build_err(&s);
    assert_eq!(e, MeshError::UnsupportedFaceSize { face: 3, size: 1 });
    assert!(e.to_string().contains("face 3"), "{e}");
    let s = soup(pos.clone(), &[&[], &[0, 1, 2]]);
    assert_eq!(
        build_err(&s),
        MeshError::UnsupportedFaceSize { face: 0, size: 0 }
    );
    // A hexagon, not repaired by any repair option.
    let s = soup(pos, &[&[0, 1, 2], &[0, 1, 4, 5, 2, 3]]);
    let e = Mesh::build(&s, &with_repair(Repair::ALL)).unwrap_err();
    assert_eq!(e, MeshError::UnsupportedFaceSize { face: 1, size: 6 });
}

#[test]
fn vertex_index_out_of_range() {
    let s = soup(
        square_positions(),
        &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 6], &[1, 4, 7]],
    );
    let e = build_err(&s);
    assert_eq!(
        e,
        MeshError::VertexIndexOutOfRange {
            face: 2,
            index: 6,
            vertex_count: 6
        }
    );
    assert!(e.to_string().contains("face 2"), "{e}");
    assert!(e.to_string().contains("vertex 6"), "{e}");
    // A huge index in a quad.
    let s = soup(square_positions(), &[&[0, 1, 2, u32::MAX - 1]]);
    assert_eq!(
        build_err(&s),
        MeshError::VertexIndexOutOfRange {
            face: 0,
            index: (u32::MAX - 1) as usize,
            vertex_count: 6
        }
    );
}

#[test]
fn non_finite_coordinate() {
    let mut pos = square_positions();
    pos[2].y = f64::NAN;
    let s = soup(pos, &[&[0, 1, 2], &[0, 2, 3]]);
    let e = build_err(&s);
    match &e {
        MeshError::NonFiniteCoordinate { vertex, x, y, z } => {
            assert_eq!(*vertex, 2);
            assert_eq!((*x, *z), (1.0, 0.0));
            assert!(y.is_nan());
        }
        other => panic!("wrong error {other:?}"),
    }
    assert!(e.to_string().contains("vertex 2"), "{e}");

    let mut pos = square_positions();
    pos[3].x = f64::INFINITY;
    pos[5].z = f64::NEG_INFINITY;
    let s = soup(pos, &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 5]]);
    assert_eq!(
        build_err(&s),
        MeshError::NonFiniteCoordinate {
            vertex: 3,
            x: f64::INFINITY,
            y: 1.0,
            z: 0.0
        }
    );
    let mut pos = square_positions();
    pos[5].z = f64::NEG_INFINITY;
    let s = soup(pos, &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 5]]);
    let e = build_err(&s);
    assert_eq!(
        e,
        MeshError::NonFiniteCoordinate {
            vertex: 5,
            x: 2.0,
            y: 1.0,
            z: f64::NEG_INFINITY
        }
    );
    assert!(e.to_string().contains("vertex 5"), "{e}");
}

#[test]
fn repeated_vertex() {
    let s = soup(square_positions(), &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 1]]);
    let e = build_err(&s);
    assert_eq!(e, MeshError::RepeatedVertex { face: 2, vertex: 1 });
    assert!(e.to_string().contains("face 2"), "{e}");
    assert!(e.to_string().contains("vertex 1"), "{e}");
    // In a quad, not adjacent.
    let s = soup(square_positions(), &[&[0, 1, 2, 3], &[1, 4, 5, 4]]);
    assert_eq!(
        build_err(&s),
        MeshError::RepeatedVertex { face: 1, vertex: 4 }
    );
    let s = soup(square_positions(), &[&[3, 3, 3]]);
    assert_eq!(
        build_err(&s),
        MeshError::RepeatedVertex { face: 0, vertex: 3 }
    );
}

#[test]
fn a_quad_that_folds_is_refused_naming_the_face_and_vertex() {
    // A dart: vertex 3 at (0.7, 0.7) lies inside the triangle of the other three, so the
    // quad is concave at it.
    let dart = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(0.7, 0.7, 0.0),
        p(1.0, 1.0, 0.0),
    ];
    let s = soup(dart, &[&[1, 4, 2, 3], &[0, 1, 3]]);
    let e = build_err(&s);
    assert_eq!(e, MeshError::FoldedQuad { face: 0, vertex: 3 });
    assert!(
        e.to_string()
            .contains("face 0 is a quad that folds at its vertex 3"),
        "{e}"
    );

    // A bow tie whose vector area is not zero: (0,0), (2,0), (0,1), (1,1) crosses itself.
    let bow = vec![
        p(0.0, 0.0, 0.0),
        p(2.0, 0.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(1.0, 1.0, 0.0),
    ];
    assert!(matches!(
        build_err(&soup(bow, &[&[0, 1, 2, 3]])),
        MeshError::FoldedQuad { face: 0, .. }
    ));

    // A dart with its reflex vertex lifted off the plane: concave seen along its mean
    // normal, so its patch still turns over.
    let lifted = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(0.7, 0.7, 0.2),
        p(1.0, 1.0, 0.0),
    ];
    assert_eq!(
        build_err(&soup(lifted, &[&[1, 4, 2, 3], &[0, 1, 3]])),
        MeshError::FoldedQuad { face: 0, vertex: 3 }
    );

    // A unit square bent about its diagonal 0-2 by 120 degrees is a valid non-planar
    // quad (its patch stays an immersion), as is a convex planar one.
    let (a, b) = (0.5, 0.5);
    let (c, s) = (120f64.to_radians().cos(), 120f64.to_radians().sin());
    let bent = vec![
        p(0.0, 0.0, 0.0),
        p(a + b * c, a - b * c, b * s),
        p(1.0, 1.0, 0.0),
        p(0.0, 1.0, 0.0),
    ];
    build(&soup(bent, &[&[0, 1, 2, 3]])).expect("a quad bent by 120 degrees");
    let kite = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.2, 0.0),
        p(1.2, 1.2, 0.0),
        p(0.2, 1.0, 0.0),
    ];
    build(&soup(kite, &[&[0, 1, 2, 3]])).expect("a convex quad");
    // A straight corner (vertex 1 on the side from 0 to 2): the patch's normal vanishes
    // at that corner only, and the quad is valid.
    let straight = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(2.0, 0.0, 0.0),
        p(1.0, 1.0, 0.0),
    ];
    build(&soup(straight, &[&[0, 1, 2, 3]])).expect("a quad with a straight corner");
}

#[test]
fn degenerate_face() {
    // Three collinear points in face 2; the bounding box is [0,2] x [0,1], so the
    // threshold is 1e-12 * 5.
    let pos = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(1.0, 1.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(2.0, 0.0, 0.0),
    ];
    let s = soup(pos.clone(), &[&[0, 1, 2], &[0, 2, 3], &[0, 1, 4]]);
    let e = build_err(&s);
    match &e {
        MeshError::DegenerateFace {
            face,
            area,
            threshold,
        } => {
            assert_eq!(*face, 2);
            assert_eq!(*area, 0.0);
            assert!((threshold - 5e-12).abs() < 1e-25, "{threshold}");
        }
        other => panic!("wrong error {other:?}"),
    }
    assert!(e.to_string().contains("face 2"), "{e}");
    assert!(e.to_string().contains("degenerate"), "{e}");

    // A sliver just below and just above the threshold; the box is the same (y in [0, 1]).
    // (A separate sliver: vertex 6 is a copy of vertex 1's position, so the sliver does not
    // touch the square.)
    let thin = |h: f64| {
        let mut q = pos.clone();
        q.push(p(1.5, h, 0.0));
        q.push(p(1.0, 0.0, 0.0));
        soup(q, &[&[0, 1, 2], &[0, 2, 3], &[6, 4, 5]])
    };
    // Area of (1,0), (2,0), (1.5,h) is h / 2.
    let e = build_err(&thin(0.9e-11));
    assert!(
        matches!(e, MeshError::DegenerateFace { face: 2, area, threshold }
            if (area - 0.45e-11).abs() < 1e-24 && (threshold - 5e-12).abs() < 1e-25),
        "{e:?}"
    );
    let (_, report) = build(&thin(1.1e-11)).expect("just above the threshold");
    assert!((report.degenerate_area_threshold - 5e-12).abs() < 1e-25);

    // A self-crossing quad with zero vector area.
    let s = soup(pos.clone(), &[&[0, 1, 2, 3], &[0, 2, 1, 3]]);
    assert!(matches!(
        build_err(&s),
        MeshError::DegenerateFace { face: 1, .. }
    ));

    // The tolerance is an option, scaled by the squared diagonal of all input vertices.
    let s = primitives::grid(4, 4, Cells::Triangles);
    let (_, report) = build(&s).unwrap();
    assert_eq!(report.degenerate_area_threshold, 1e-12 * 2.0);
    let loose = BuildOptions {
        degenerate_area_tolerance: 0.02,
        ..Default::default()
    };
    // Its triangles have area 1/32 = 0.03125, below 0.02 * 2 = 0.04.
    let e = Mesh::build(&s, &loose).unwrap_err();
    assert_eq!(
        e,
        MeshError::DegenerateFace {
            face: 0,
            area: 1.0 / 32.0,
            threshold: 0.04
        }
    );
}

#[test]
fn duplicate_face() {
    let pos = square_positions();
    // Same orientation, rotated.
    let s = soup(
        pos.clone(),
        &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 5], &[1, 2, 0]],
    );
    let e = build_err(&s);
    assert_eq!(e, MeshError::DuplicateFace { face: 3, first: 0 });
    assert!(e.to_string().contains("face 3"), "{e}");
    assert!(e.to_string().contains("face 0"), "{e}");
    // Reversed orientation.
    let s = soup(
        pos.clone(),
        &[&[0, 1, 2], &[0, 2, 3], &[1, 4, 5], &[3, 2, 0]],
    );
    assert_eq!(
        build_err(&s),
        MeshError::DuplicateFace { face: 3, first: 1 }
    );
    // Quads, reversed and rotated.
    let s = soup(pos.clone(), &[&[0, 1, 2, 3], &[1, 4, 5, 2], &[2, 5, 4, 1]]);
    assert_eq!(
        build_err(&s),
        MeshError::DuplicateFace { face: 2, first: 1 }
    );
    // Duplicate before its original in a larger mesh: the earlier copy is `first`.
    let g = primitives::grid(3, 3, Cells::Quads);
    let copy = g.face(7).to_vec();
    let s = insert_face(&g, 2, &copy);
    assert_eq!(
        build_err(&s),
        MeshError::DuplicateFace { face: 8, first: 2 }
    );
}

#[test]
fn non_manifold_edge() {
    // Edge (1, 2) shared by faces 0, 2 and 3 (face 1 is elsewhere).
    let pos = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(1.0, 1.0, 0.0),
        p(2.0, 0.0, 0.0),
        p(1.0, 0.0, 1.0),
        p(5.0, 5.0, 5.0),
        p(6.0, 5.0, 5.0),
        p(5.0, 6.0, 5.0),
        p(1.0, -1.0, -1.0),
    ];
    let s = soup(
        pos,
        &[&[0, 1, 2], &[5, 6, 7], &[2, 1, 3], &[1, 2, 4], &[0, 8, 1]],
    );
    let e = build_err(&s);
    assert_eq!(
        e,
        MeshError::NonManifoldEdge {
            a: 1,
            b: 2,
            faces: vec![0, 2, 3]
        }
    );
    assert!(e.to_string().contains("(1, 2)"), "{e}");
    assert!(e.to_string().contains("[0, 2, 3]"), "{e}");
    // Four quads on one edge (a "book").
    let mut pos = vec![p(0.0, 0.0, 0.0), p(0.0, 0.0, 1.0)];
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for k in 0..4u32 {
        let t = TAU * k as f64 / 4.0;
        pos.push(p(t.cos(), t.sin(), 0.0));
        pos.push(p(t.cos(), t.sin(), 1.0));
        faces.push(vec![0, 2 + 2 * k, 3 + 2 * k, 1]);
    }
    let refs: Vec<&[u32]> = faces.iter().map(|f| f.as_slice()).collect();
    assert_eq!(
        build_err(&soup(pos, &refs)),
        MeshError::NonManifoldEdge {
            a: 0,
            b: 1,
            faces: vec![0, 1, 2, 3]
        }
    );
}

#[test]
fn non_manifold_vertex_bowtie() {
    // Two triangles touching at input vertex 2 (0 is unreferenced, so the mesh numbering
    // differs from the input's).
    let pos = vec![
        p(9.0, 9.0, 9.0),
        p(-1.0, -1.0, 0.0),
        p(0.0, 0.0, 0.0),
        p(0.0, -1.0, 0.0),
        p(1.0, 1.0, 0.0),
        p(0.0, 1.0, 0.0),
    ];
    let s = soup(pos, &[&[1, 3, 2], &[2, 4, 5]]);
    let e = build_err(&s);
    assert_eq!(e, MeshError::NonManifoldVertex { vertex: 2, fans: 2 });
    assert!(e.to_string().contains("vertex 2"), "{e}");
    assert!(e.to_string().contains("2 separate fans"), "{e}");

    // Two quad grids touching at one corner: grid A's (1, 1) is grid B's (0, 0).
    let a = primitives::grid(2, 2, Cells::Quads);
    let b = primitives::grid(2, 2, Cells::Quads);
    let mut pos = a.positions.clone();
    let shared = 8u32; // (1, 1) of A
    let mut b_index = Vec::new();
    for (i, q) in b.positions.iter().enumerate() {
        if i == 0 {
            b_index.push(shared);
        } else {
            b_index.push(pos.len() as u32);
            pos.push(q + offset(1.0, 1.0));
        }
    }
    let mut s = PolygonSoup::new(pos);
    for f in a.faces() {
        s.push_face(f);
    }
    for f in b.faces() {
        let m: Vec<u32> = f.iter().map(|&v| b_index[v as usize]).collect();
        s.push_face(&m);
    }
    assert_eq!(
        build_err(&s),
        MeshError::NonManifoldVertex { vertex: 8, fans: 2 }
    );

    // Three triangles around one vertex, pairwise sharing only it.
    let mut pos = vec![p(0.0, 0.0, 0.0)];
    let mut faces: Vec<[u32; 3]> = Vec::new();
    for k in 0..3u32 {
        let t = TAU * k as f64 / 3.0;
        pos.push(p(t.cos(), t.sin(), 0.0));
        pos.push(p((t + 0.5).cos(), (t + 0.5).sin(), 0.0));
        faces.push([0, 1 + 2 * k, 2 + 2 * k]);
    }
    let s = PolygonSoup::from_triangles(pos, &faces);
    assert_eq!(
        build_err(&s),
        MeshError::NonManifoldVertex { vertex: 0, fans: 3 }
    );
}

fn offset(x: f64, y: f64) -> beltrami_mesh::Vector3<f64> {
    beltrami_mesh::Vector3::new(x, y, 0.0)
}

/// Faces of a tetrahedron on vertices `v` (any orientation; the builder orients).
fn tetra_faces(v: [u32; 4]) -> Vec<[u32; 3]> {
    vec![
        [v[0], v[2], v[1]],
        [v[0], v[1], v[3]],
        [v[0], v[3], v[2]],
        [v[1], v[2], v[3]],
    ]
}

#[test]
fn non_manifold_vertex_pinch() {
    // Two closed tetrahedra sharing input vertex 5; input vertex 0 is unreferenced.
    let pos = vec![
        p(7.0, 7.0, 7.0),
        p(1.0, 0.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(0.0, 0.0, 1.0),
        p(-1.0, 0.0, 0.0),
        p(0.0, 0.0, 0.0),
        p(0.0, -1.0, 0.0),
        p(0.0, 0.0, -1.0),
    ];
    let mut faces = tetra_faces([5, 1, 2, 3]);
    faces.extend(tetra_faces([5, 4, 6, 7]));
    let s = PolygonSoup::from_triangles(pos.clone(), &faces);
    let e = build_err(&s);
    assert_eq!(e, MeshError::NonManifoldVertex { vertex: 5, fans: 2 });
    assert!(e.to_string().contains("vertex 5"), "{e}");
    // Each tetrahedron alone is a fine closed surface.
    let one = PolygonSoup::from_triangles(pos.clone(), &tetra_faces([5, 1, 2, 3]));
    let (m, report) = build(&one).unwrap();
    assert!(m.is_closed());
    assert_eq!(m.genus(), Some(0));
    assert_eq!(report.unreferenced_vertices, vec![0, 4, 6, 7]);

    // Two closed octahedra (quads would not close; use triangles) touching at a vertex.
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for cx in [0.0, 2.0] {
        let base = pos.len() as u32;
        for q in [
            p(1.0, 0.0, 0.0),
            p(-1.0, 0.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(0.0, -1.0, 0.0),
            p(0.0, 0.0, 1.0),
            p(0.0, 0.0, -1.0),
        ] {
            pos.push(q + offset(cx, 0.0));
        }
        let tri = |a: u32, b: u32, c: u32| [base + a, base + b, base + c];
        for (a, b) in [(0, 2), (2, 1), (1, 3), (3, 0)] {
            faces.push(tri(a, b, 4));
            faces.push(tri(b, a, 5));
        }
    }
    // Vertex 0 (+x of the first) coincides with vertex 7 (-x of the second): share it.
    for f in &mut faces {
        for v in f.iter_mut() {
            if *v == 7 {
                *v = 0;
            }
        }
    }
    let s = PolygonSoup::from_triangles(pos, &faces);
    assert_eq!(
        build_err(&s),
        MeshError::NonManifoldVertex { vertex: 0, fans: 2 }
    );

    // A disk touching a closed tetrahedron at a vertex: one open and one closed fan.
    let g = primitives::grid(2, 2, Cells::Triangles);
    let mut pos = g.positions.clone();
    let n = pos.len() as u32;
    pos.extend([p(-1.0, 0.0, 0.0), p(0.0, -1.0, 0.0), p(0.0, 0.0, -1.0)]);
    let mut s = PolygonSoup::new(pos);
    for f in g.faces() {
        s.push_face(f);
    }
    for t in tetra_faces([0, n, n + 1, n + 2]) {
        s.push_face(&t);
    }
    assert_eq!(
        build_err(&s),
        MeshError::NonManifoldVertex { vertex: 0, fans: 2 }
    );
}

/// A band of `n` quads around a circle, triangulated or not, with or without a half twist.
fn band(n: usize, twist: bool, triangles: bool) -> PolygonSoup {
    let (radius, width) = (2.0, 0.5);
    let mut pos = Vec::new();
    for i in 0..n {
        let t = TAU * i as f64 / n as f64;
        let turn = if twist { t / 2.0 } else { 0.0 };
        let radial = beltrami_mesh::Vector3::new(t.cos(), t.sin(), 0.0);
        let across = radial * turn.cos() + beltrami_mesh::Vector3::z() * turn.sin();
        let c = p(radius * t.cos(), radius * t.sin(), 0.0);
        pos.push(c + width * across); // a_i = 2 i
        pos.push(c - width * across); // b_i = 2 i + 1
    }
    let mut s = PolygonSoup::new(pos);
    let n32 = n as u32;
    for i in 0..n32 {
        let (a0, b0) = (2 * i, 2 * i + 1);
        let (a1, b1) = if i + 1 < n32 {
            (2 * i + 2, 2 * i + 3)
        } else if twist {
            (1, 0)
        } else {
            (0, 1)
        };
        if triangles {
            s.push_face(&[a0, b0, b1]);
            s.push_face(&[a0, b1, a1]);
        } else {
            s.push_face(&[a0, b0, b1, a1]);
        }
    }
    s
}

#[test]
fn non_orientable_moebius_strip() {
    // Without the twist the band is an annulus.
    for triangles in [true, false] {
        let (m, _) = build(&band(8, false, triangles)).unwrap();
        assert_eq!(m.euler_characteristic(), 0);
        assert_eq!(m.boundary_loop_count(), 2);
        assert_eq!(m.genus(), Some(0));
    }
    for (n, triangles) in [(8, true), (8, false), (5, true), (12, false)] {
        let s = band(n, true, triangles);
        let e = build_err(&s);
        let MeshError::NonOrientable {
            face,
            neighbor,
            a,
            b,
        } = e.clone()
        else {
            panic!("n = {n}: wrong error {e:?}");
        };
        // The two faces are distinct neighbours across edge (a, b), a < b.
        assert_ne!(face, neighbor);
        assert!(a < b, "{e:?}");
        for f in [face, neighbor] {
            let verts = s.face(f);
            let k = verts
                .iter()
                .position(|&v| v as usize == a)
                .expect("a in face");
            let len = verts.len();
            let next = verts[(k + 1) % len] as usize;
            let prev = verts[(k + len - 1) % len] as usize;
            assert!(
                next == b || prev == b,
                "{e:?}: ({a}, {b}) is not a side of face {f}"
            );
        }
        assert!(
            e.to_string()
                .contains(&format!("faces {face} and {neighbor}")),
            "{e}"
        );
        assert!(e.to_string().contains("non-orientable"), "{e}");
        // Repairs do not help.
        assert!(matches!(
            Mesh::build(&s, &with_repair(Repair::ALL)),
            Err(MeshError::NonOrientable { .. })
        ));
    }
}

// ---------------------------------------------------------------------------------------
// Repairs
// ---------------------------------------------------------------------------------------

#[test]
fn drop_degenerate_faces() {
    let g = primitives::grid(2, 2, Cells::Quads); // vertices 0..9, row 0 is 0, 1, 2
    // A collinear triangle on the bottom row at index 1, a repeated-vertex face at 3 and
    // a self-crossing quad at the end.
    let s = insert_face(&g, 1, &[0, 1, 2]);
    let s = insert_face(&s, 3, &[4, 5, 4]);
    let s = insert_face(&s, 6, &[0, 4, 1, 3]);
    assert_eq!(s.face_count(), 7);
    // Never silently repaired.
    assert!(matches!(
        build_err(&s),
        MeshError::DegenerateFace { face: 1, .. }
    ));
    let no_degenerate = insert_face(&insert_face(&g, 3, &[4, 5, 4]), 4, &[0, 4, 1, 3]);
    assert_eq!(
        build_err(&no_degenerate),
        MeshError::RepeatedVertex { face: 3, vertex: 4 }
    );
    // Other repairs do not drop them.
    let others = Repair {
        drop_degenerate_faces: false,
        ..Repair::ALL
    };
    assert!(matches!(
        Mesh::build(&s, &with_repair(others)),
        Err(MeshError::DegenerateFace { face: 1, .. })
    ));

    let repair = Repair {
        drop_degenerate_faces: true,
        ..Repair::NONE
    };
    let (m, report) = Mesh::build(&s, &with_repair(repair)).unwrap();
    assert_eq!(report.dropped_degenerate_faces, vec![1, 3, 6]);
    assert!(report.dropped_duplicate_faces.is_empty());
    assert!(report.merged_vertices.is_empty());
    assert!(report.repaired());
    assert_eq!(m.face_count(), 4);
    assert!(m.is_disk());
    assert!((m.total_area() - 1.0).abs() < 1e-15);
    let inputs: Vec<usize> = m.faces().map(|f| m.face_to_input(f)).collect();
    assert_eq!(inputs, vec![0, 2, 4, 5]);
    for f in m.faces() {
        let expected: Vec<VertexId> = s
            .face(m.face_to_input(f))
            .iter()
            .map(|&v| VertexId(v))
            .collect();
        assert_eq!(m.face_vertices(f).collect::<Vec<_>>(), expected);
    }
    assert!(m.vertex_map().is_identity());

    // Dropping every face leaves nothing.
    let s = soup(square_positions(), &[&[0, 1, 0], &[0, 1, 4]]);
    assert_eq!(
        Mesh::build(&s, &with_repair(repair)).unwrap_err(),
        MeshError::NoFaces
    );
}

#[test]
fn drop_degenerate_faces_leaves_unreferenced_vertices() {
    // A degenerate face using a vertex no other face uses: dropping it leaves that
    // vertex unreferenced.
    let g = primitives::grid(1, 1, Cells::Triangles);
    let mut pos = g.positions.clone();
    pos.push(p(2.0, 0.0, 0.0)); // 4, collinear with 0 and 1
    let mut s = PolygonSoup::new(pos);
    for f in g.faces() {
        s.push_face(f);
    }
    s.push_face(&[0, 1, 4]);
    let repair = Repair {
        drop_degenerate_faces: true,
        ..Repair::NONE
    };
    let (m, report) = Mesh::build(&s, &with_repair(repair)).unwrap();
    assert_eq!(report.dropped_degenerate_faces, vec![2]);
    assert_eq!(report.unreferenced_vertices, vec![4]);
    assert_eq!(m.vertex_count(), 4);
    assert_eq!(m.vertex_map().from_input(4), None);
}

#[test]
fn drop_duplicate_faces() {
    let g = primitives::grid(3, 3, Cells::Quads);
    // A reversed copy of face 7 inserted at 2 (so the original moves to 8), and a rotated
    // copy of face 0 appended at the end (index 10), and a second copy of face 0 at 11.
    let mut rev = g.face(7).to_vec();
    rev.reverse();
    let s = insert_face(&g, 2, &rev);
    let rot = [g.face(0)[2], g.face(0)[3], g.face(0)[0], g.face(0)[1]];
    let s = insert_face(&s, 10, &rot);
    let s = insert_face(&s, 11, g.face(0));
    assert_eq!(s.face_count(), 12);
    // Never silently repaired.
    assert_eq!(
        build_err(&s),
        MeshError::DuplicateFace { face: 8, first: 2 }
    );
    let others = Repair {
        drop_duplicate_faces: false,
        ..Repair::ALL
    };
    assert_eq!(
        Mesh::build(&s, &with_repair(others)).unwrap_err(),
        MeshError::DuplicateFace { face: 8, first: 2 }
    );

    let repair = Repair {
        drop_duplicate_faces: true,
        ..Repair::NONE
    };
    let (m, report) = Mesh::build(&s, &with_repair(repair)).unwrap();
    assert_eq!(report.dropped_duplicate_faces, vec![8, 10, 11]);
    assert!(report.dropped_degenerate_faces.is_empty());
    assert!(report.repaired());
    assert_eq!(m.face_count(), 9);
    assert!(m.is_disk());
    assert!((m.total_area() - 1.0).abs() < 1e-15);
    let inputs: Vec<usize> = m.faces().map(|f| m.face_to_input(f)).collect();
    assert_eq!(inputs, vec![0, 1, 2, 3, 4, 5, 6, 7, 9]);
    // The kept copy at input 2 is reversed relative to its neighbours: it is the one
    // re-oriented (keeping its first vertex), and all normals are +z.
    assert_eq!(report.faces_reoriented, 1);
    for f in m.faces() {
        assert!(m.face_normal(f).z > 0.0);
    }
}

/// A 4 x 2 quad grid whose left and right halves have separate vertices on the seam
/// x = 0.5: the right half's seam vertices are appended at the end (indices 15, 16, 17).
fn split_grid() -> (PolygonSoup, Vec<(usize, usize)>) {
    let g = primitives::grid(4, 2, Cells::Quads);
    let mut pos = g.positions.clone();
    let seam: Vec<usize> = (0..3).map(|j| 2 + 5 * j).collect();
    let mut dup = Vec::new();
    for &v in &seam {
        dup.push((pos.len(), v));
        pos.push(g.positions[v]);
    }
    let mut s = PolygonSoup::new(pos);
    for (f, face) in g.faces().enumerate() {
        let right = f % 4 >= 2;
        let mapped: Vec<u32> = face
            .iter()
            .map(
                |&v| match dup.iter().find(|&&(_, orig)| orig == v as usize) {
                    Some(&(new, _)) if right => new as u32,
                    _ => v,
                },
            )
            .collect();
        s.push_face(&mapped);
    }
    (s, dup)
}

#[test]
fn merge_coincident_vertices() {
    let (s, dup) = split_grid();
    assert_eq!(dup, vec![(15, 2), (16, 7), (17, 12)]);
    // Never silently merged: two components.
    let (m, report) = build(&s).unwrap();
    assert_eq!(m.component_count(), 2);
    assert!(!m.is_disk());
    assert_eq!(m.genus(), None);
    assert!(report.merged_vertices.is_empty());
    assert!(!report.repaired());
    assert_eq!(m.vertex_count(), 18);
    assert_ne!(m.vertex_map().from_input(2), m.vertex_map().from_input(15));

    let repair = Repair {
        merge_coincident_vertices: true,
        ..Repair::NONE
    };
    let (m, report) = Mesh::build(&s, &with_repair(repair)).unwrap();
    assert_eq!(m.component_count(), 1);
    assert!(m.is_disk());
    assert_eq!(m.vertex_count(), 15);
    assert_eq!(m.edge_count(), 22);
    assert_eq!(report.merged_vertices, dup);
    assert!(report.repaired());
    assert!(report.unreferenced_vertices.is_empty());
    let map = m.vertex_map();
    for &(merged, kept) in &dup {
        let v = map.from_input(kept).unwrap();
        assert_eq!(map.from_input(merged), Some(v));
        assert_eq!(map.to_input(v), kept);
        assert_eq!(m.position(v), s.positions[merged]);
        assert!(!m.is_boundary_vertex(v) || m.position(v).y == 0.0 || m.position(v).y == 1.0);
    }
    for i in 0..15 {
        assert_eq!(map.from_input(i), Some(VertexId(i as u32)));
        assert_eq!(map.to_input(VertexId(i as u32)), i);
    }
    assert_eq!(map.input_len(), 18);
    assert!(!map.is_identity());
    assert!(!map.is_order_preserving());
    // The seam's middle vertex is now interior with 4 quads around it.
    assert_eq!(m.vertex_faces(VertexId(7)).count(), 4);
    assert!(!m.is_boundary_vertex(VertexId(7)));
}

#[test]
fn merge_needs_bit_identical_positions() {
    let repair = Repair {
        merge_coincident_vertices: true,
        ..Repair::NONE
    };
    // Move every seam copy by one ulp: nothing is merged, two components remain.
    let (mut s, dup) = split_grid();
    for &(copy, _) in &dup {
        s.positions[copy].x = f64::from_bits(s.positions[copy].x.to_bits() + 1);
    }
    let (m, report) = Mesh::build(&s, &with_repair(repair)).unwrap();
    assert!(report.merged_vertices.is_empty());
    assert_eq!(m.component_count(), 2);
    assert_eq!(m.vertex_count(), 18);

    // Move only the two ends: the halves then share just the middle seam vertex, a pinch.
    let (mut s, dup) = split_grid();
    for &(copy, _) in [dup[0], dup[2]].iter() {
        s.positions[copy].x = f64::from_bits(s.positions[copy].x.to_bits() + 1);
    }
    let e = Mesh::build(&s, &with_repair(repair)).unwrap_err();
    assert_eq!(e, MeshError::NonManifoldVertex { vertex: 7, fans: 2 });
}

#[test]
fn merge_treats_negative_zero_as_zero() {
    // Two triangles sharing an edge whose endpoints are written once with 0.0 and once
    // with -0.0.
    let pos = vec![
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(-0.0, 0.0, -0.0),
        p(1.0, -0.0, 0.0),
        p(1.0, -1.0, 0.0),
    ];
    let s = soup(pos, &[&[0, 1, 2], &[3, 5, 4]]);
    let (m, _) = build(&s).unwrap();
    assert_eq!(m.component_count(), 2);
    let repair = Repair {
        merge_coincident_vertices: true,
        ..Repair::NONE
    };
    let (m, report) = Mesh::build(&s, &with_repair(repair)).unwrap();
    assert_eq!(report.merged_vertices, vec![(3, 0), (4, 1)]);
    assert_eq!(m.component_count(), 1);
    assert!(m.is_disk());
    assert_eq!(m.vertex_count(), 4);
}

#[test]
fn merge_creating_repeated_vertex() {
    // A triangle that uses both copies of a merged vertex becomes degenerate after the
    // merge: an error naming the input vertex, unless degenerate faces are dropped too.
    let (s, dup) = split_grid();
    let (merged, kept) = dup[0];
    let s = insert_face(&s, 3, &[kept as u32, 1, merged as u32]);
    let repair = Repair {
        merge_coincident_vertices: true,
        ..Repair::NONE
    };
    let e = Mesh::build(&s, &with_repair(repair)).unwrap_err();
    assert_eq!(
        e,
        MeshError::RepeatedVertex {
            face: 3,
            vertex: merged
        }
    );
    // Without merging, `kept` and `merged` are distinct vertices at the same position,
    // so the triangle has zero area.
    assert!(matches!(
        build_err(&s),
        MeshError::DegenerateFace { face: 3, .. }
    ));
    let (m, report) = Mesh::build(&s, &with_repair(Repair::ALL)).unwrap();
    assert_eq!(report.dropped_degenerate_faces, vec![3]);
    assert_eq!(report.merged_vertices, dup);
    assert!(m.is_disk());
}

#[test]
fn all_repairs_together() {
    let (s, dup) = split_grid();
    let s = insert_face(&s, 0, &[0, 1, 2]); // collinear on the bottom row
    let copy = s.face(5).to_vec();
    let s = insert_face(&s, 9, &copy); // duplicate of face 5
    let (m, report) = Mesh::build(&s, &with_repair(Repair::ALL)).unwrap();
    assert_eq!(report.dropped_degenerate_faces, vec![0]);
    assert_eq!(report.dropped_duplicate_faces, vec![9]);
    assert_eq!(report.merged_vertices, dup);
    assert!(m.is_disk());
    assert_eq!(m.face_count(), 8);
    assert!((m.total_area() - 1.0).abs() < 1e-15);
    // Nothing repaired when nothing is wrong.
    let (_, report) = Mesh::build(&primitives::icosphere(1), &with_repair(Repair::ALL)).unwrap();
    assert!(!report.repaired());
    assert_eq!(report.faces_reoriented, 0);
}

#[test]
fn merging_unreferenced_coincident_vertices_keeps_them_unreferenced() {
    // Vertices 3 and 4 coincide but no face uses either: they stay unreferenced, are not
    // reported as merged, and the input numbering can still be restored on write.
    let soup = PolygonSoup::from_triangles(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(5.0, 5.0, 5.0),
            Point3::new(5.0, 5.0, 5.0),
        ],
        &[[0, 1, 2]],
    );
    let options = BuildOptions {
        repair: Repair::ALL,
        ..Default::default()
    };
    let (mesh, report) = Mesh::build(&soup, &options).unwrap();
    assert!(report.merged_vertices.is_empty());
    assert_eq!(report.unreferenced_vertices, vec![3, 4]);
    assert_eq!(mesh.vertex_map().unreferenced().len(), 2);
    assert!(mesh.vertex_map().is_order_preserving());
}

#[test]
fn large_meshes_group_their_edges_in_ranges_as_in_one() {
    // 240,000 corners: the edges are grouped in ranges of vertices on several threads.
    let g = primitives::grid(200, 200, Cells::Triangles);
    let (nv, nf) = (g.vertex_count(), g.face_count());
    let (mesh, _) = build(&g).unwrap();
    // A disk: V - E + F = 1.
    assert_eq!(mesh.edge_count(), nv + nf - 1);
    for h in mesh.halfedges() {
        assert_eq!(mesh.twin(mesh.twin(h)), h);
        assert_eq!(mesh.origin(mesh.twin(h)), mesh.origin(mesh.next(h)));
    }
    let last = (nv - 1) as u32;
    // Two more faces on a boundary edge at each end of the vertex numbering: the first
    // in vertex order is reported, as one pass over the vertices finds it.
    let with = |extra: &[[u32; 3]]| {
        let mut positions = g.positions.clone();
        for k in 0..extra.len() {
            positions.push(p(-1.0 - k as f64, -1.0, 1.0 + k as f64));
        }
        let mut s = PolygonSoup::new(positions);
        for f in g.faces() {
            s.push_face(f);
        }
        for f in extra {
            s.push_face(f);
        }
        s
    };
    let n = nv as u32;
    let both = with(&[
        [last - 1, last, n],
        [last, last - 1, n + 1],
        [0, 1, n + 2],
        [1, 0, n + 3],
    ]);
    match build_err(&both) {
        MeshError::NonManifoldEdge { a, b, faces } => {
            assert_eq!((a, b), (0, 1));
            assert_eq!(faces.len(), 3);
        }
        e => panic!("{e}"),
    }
    let high = with(&[[last - 1, last, n], [last, last - 1, n + 1]]);
    match build_err(&high) {
        MeshError::NonManifoldEdge { a, b, .. } => {
            assert_eq!((a, b), (last as usize - 1, last as usize))
        }
        e => panic!("{e}"),
    }
    // A duplicate of the first face with a non-manifold edge at the far end: the edge,
    // as one pass finds it after the duplicate; the duplicate alone is named.
    let mut dup = high.clone();
    dup.push_face(g.face(0));
    assert!(matches!(build_err(&dup), MeshError::NonManifoldEdge { .. }));
    let mut only = PolygonSoup::new(g.positions.clone());
    for f in g.faces() {
        only.push_face(f);
    }
    only.push_face(g.face(nf - 1));
    assert_eq!(
        build_err(&only),
        MeshError::DuplicateFace {
            face: nf,
            first: nf - 1
        }
    );
}

#[test]
fn an_unreferenced_vertex_far_away_does_not_make_faces_degenerate() {
    // A unit square of two triangles and a vertex no face uses at 1e12: the faces'
    // area 0.5 is far above 1e-12 of their own extent, though not of the outlier's.
    let positions = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(1e12, 0.0, 0.0),
    ];
    let soup = PolygonSoup::from_triangles(positions, &[[0, 1, 2], [0, 2, 3]]);
    let (mesh, report) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
    assert_eq!(mesh.face_count(), 2);
    assert_eq!(report.unreferenced_vertices, [4]);
    assert!((report.degenerate_area_threshold - 2e-12).abs() < 1e-24);
}

#[test]
fn a_mesh_far_from_the_origin_against_its_size_is_refused() {
    // A unit square translated by t: at 1e15 coordinates are 0.125 apart (a fold by
    // rounding alone); at 1e6 they are 1.2e-10 apart and the square is kept.
    let square = |t: f64| {
        let positions = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
            .map(|[x, y]| Point3::new(x + t, y, 0.0))
            .to_vec();
        PolygonSoup::from_triangles(positions, &[[0, 1, 2], [0, 2, 3]])
    };
    assert!(Mesh::build(&square(1e6), &BuildOptions::default()).is_ok());
    match Mesh::build(&square(1e15), &BuildOptions::default()) {
        Err(MeshError::PrecisionLoss {
            diagonal,
            magnitude,
            spacing,
        }) => {
            assert_eq!(
                (diagonal, magnitude, spacing),
                (2f64.sqrt(), 1e15 + 1.0, (1e15 + 1.0) * f64::EPSILON)
            );
        }
        other => panic!("{other:?}"),
    }
    // The limit: 2^26 coordinate steps across the diagonal (a translation of 9.5e7).
    let limit = 2f64.sqrt() * 2f64.powi(-26) / f64::EPSILON;
    assert!(Mesh::build(&square(0.9 * limit), &BuildOptions::default()).is_ok());
    assert!(Mesh::build(&square(1.1 * limit), &BuildOptions::default()).is_err());
}
