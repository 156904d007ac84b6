//! Cut graphs and cutting into a disk: generator counts (2g + b - 1), closed simple
//! generator loops, pruned cut graphs, disks with the original faces and positions, the
//! four sides of a cut torus, shortest generators on tori (greedy basis), and the typed
//! errors. The shared meshes (`../shared/meshes`) are skipped with a message when absent.

use std::f64::consts::TAU;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{
    BuildOptions, CutError, CutGraph, CutMesh, GeneratorKind, Mesh, Point3, PolygonSoup, VertexId,
    cut_graph, cut_to_disk, io,
};

fn mesh(soup: &PolygonSoup) -> Mesh {
    Mesh::from_soup(soup).expect("valid mesh")
}

fn shared_meshes() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes");
    if dir.is_dir() {
        Some(dir)
    } else {
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: {} not found; the shared-mesh cut tests need ../shared beside the repo",
            dir.display()
        );
        None
    }
}

/// Generators: the right number of handle and boundary loops, each a closed simple cycle
/// of edges on the cut graph with its stated length; the cut graph has every boundary
/// edge and no vertex of degree 1.
fn check_cut_graph(m: &Mesh, g: &CutGraph, genus: usize, loops: usize) {
    let handles = g
        .generators
        .iter()
        .filter(|x| x.kind == GeneratorKind::Handle)
        .count();
    let boundary = g.generators.len() - handles;
    assert_eq!(handles, 2 * genus, "handle generators");
    assert_eq!(boundary, loops.saturating_sub(1), "boundary generators");
    let mut in_cut = vec![false; m.edge_count()];
    for &e in &g.edges {
        in_cut[e.idx()] = true;
    }
    for x in &g.generators {
        let n = x.halfedges.len();
        assert!(n >= 3, "a loop of {n} edges");
        for i in 0..n {
            let (h, next) = (x.halfedges[i], x.halfedges[(i + 1) % n]);
            assert_eq!(m.target(h), m.origin(next), "loop is not connected at {i}");
        }
        let mut vs = x.vertices(m);
        vs.sort_unstable();
        vs.dedup();
        assert_eq!(vs.len(), n, "loop visits a vertex twice");
        let length: f64 = x.edges(m).iter().map(|&e| m.edge_length(e)).sum();
        assert!((length - x.length).abs() <= 1e-9 * length);
        for e in x.edges(m) {
            assert!(
                in_cut[e.idx()],
                "generator edge {e} is not on the cut graph"
            );
        }
    }
    let mut degree = vec![0usize; m.vertex_count()];
    for &e in &g.edges {
        for v in m.edge_vertices(e) {
            degree[v.idx()] += 1;
        }
    }
    assert!(
        degree.iter().all(|&d| d != 1),
        "the cut graph has a vertex of degree 1"
    );
    for e in m.edges().filter(|&e| m.is_boundary_edge(e)) {
        assert!(in_cut[e.idx()], "boundary edge {e} is not on the cut graph");
    }
    // Cycle rank of the cut graph: 2g + b.
    let vertices = degree.iter().filter(|&&d| d > 0).count();
    if !g.edges.is_empty() {
        assert_eq!(
            g.edges.len() + 1 - vertices,
            2 * genus + loops,
            "cycle rank"
        );
    }
}

/// The cut mesh is a disk with the original faces (through the seam map), positions and
/// a boundary loop that runs twice along every interior cut edge and once along every
/// original boundary edge.
fn check_disk(m: &Mesh, cut: &CutMesh) {
    let c = &cut.mesh;
    assert!(c.is_disk(), "not a disk: {:?}", c.components());
    assert_eq!(c.euler_characteristic(), 1);
    assert_eq!(c.face_count(), m.face_count());
    assert_eq!(cut.to_original.len(), c.vertex_count());
    for v in m.vertices() {
        assert_eq!(cut.original_vertex(v), v, "first copies keep their ids");
    }
    for v in c.vertices() {
        assert_eq!(c.position(v), m.position(cut.original_vertex(v)));
    }
    for f in c.faces() {
        let mapped: Vec<VertexId> = c.face_vertices(f).map(|v| cut.original_vertex(v)).collect();
        let original: Vec<VertexId> = m.face_vertices(cut.original_face(f)).collect();
        assert_eq!(mapped, original, "face {f}");
    }
    // The boundary is the one loop of the disk, walked in order.
    let n = cut.boundary.len();
    assert_eq!(vec![n], c.boundary_loop_sizes());
    for i in 0..n {
        assert!(c.is_boundary_halfedge(cut.boundary[i]));
        assert_eq!(c.next(cut.boundary[i]), cut.boundary[(i + 1) % n]);
    }
    let (mut interior, mut border) = (0.0, 0.0);
    for &e in &cut.cut.edges {
        if m.is_boundary_edge(e) {
            border += m.edge_length(e);
        } else {
            interior += m.edge_length(e);
        }
    }
    let expected = 2.0 * interior + border;
    assert!(
        (cut.boundary_length() - expected).abs() <= 1e-9 * expected,
        "boundary {} vs cut graph {expected}",
        cut.boundary_length()
    );
    // Every vertex is split into as many copies as boundary visits (at least one).
    let mut visits = vec![0usize; m.vertex_count()];
    for v in cut.boundary_vertices() {
        visits[cut.original_vertex(v).idx()] += 1;
    }
    let mut copies = vec![0usize; m.vertex_count()];
    for v in c.vertices() {
        copies[cut.original_vertex(v).idx()] += 1;
    }
    for v in m.vertices() {
        let on_boundary = visits[v.idx()];
        assert_eq!(copies[v.idx()], on_boundary.max(1), "copies of {v}");
    }
}

/// The four sides of a cut torus: contiguous, the whole boundary, `a` against `a^-1` and
/// `b` against `b^-1` vertex by vertex in reverse, all corners one original vertex.
fn check_torus_sides(cut: &CutMesh) {
    let sides = cut.torus_sides.as_ref().expect("a torus has four sides");
    let [a, b, a_inv, b_inv] = sides.sides();
    assert_eq!(a.start, 0);
    assert_eq!(
        (a.end, b.end, a_inv.end),
        (b.start, a_inv.start, b_inv.start)
    );
    assert_eq!(b_inv.end, cut.boundary.len());
    assert!(!a.is_empty() && !b.is_empty());
    let original = |r: std::ops::Range<usize>| -> Vec<VertexId> {
        cut.path_vertices(r)
            .into_iter()
            .map(|v| cut.original_vertex(v))
            .collect()
    };
    for (x, y) in [(a.clone(), a_inv.clone()), (b.clone(), b_inv.clone())] {
        assert_eq!(x.len(), y.len());
        let mut back = original(y.clone());
        back.reverse();
        assert_eq!(original(x.clone()), back);
        let (lx, ly) = (cut.path_length(x), cut.path_length(y));
        assert!((lx - ly).abs() <= 1e-9 * lx);
    }
    let corner = original(a.clone())[0];
    for r in [a, b, a_inv, b_inv] {
        let vs = original(r);
        assert_eq!(vs[0], corner);
        assert_eq!(*vs.last().unwrap(), corner);
        // The corner appears only at the ends of each side.
        assert!(vs[1..vs.len() - 1].iter().all(|&v| v != corner));
    }
}

fn torus(n_major: usize, n_minor: usize, major: f64, minor: f64, cells: Cells) -> Mesh {
    mesh(&primitives::torus(n_major, n_minor, major, minor, cells))
}

#[test]
fn a_torus_has_two_generators_and_cuts_into_a_square() {
    for cells in [Cells::Triangles, Cells::Quads] {
        for (nu, nv) in [(3, 3), (4, 3), (12, 7), (40, 16)] {
            let m = torus(nu, nv, 3.0, 1.0, cells);
            let g = cut_graph(&m);
            assert_eq!(g.components.len(), 1);
            assert_eq!(g.components[0].genus, 1);
            check_cut_graph(&m, &g, 1, 0);
            let cut = cut_to_disk(&m).expect("a torus cuts");
            check_cut_graph(&m, &cut.cut, 1, 0);
            check_disk(&m, &cut);
            check_torus_sides(&cut);
            // A figure-eight: two loops crossing at one vertex, four copies of it.
            let [x, y] = [&cut.cut.generators[0], &cut.cut.generators[1]];
            let mut common: Vec<VertexId> = x
                .vertices(&m)
                .into_iter()
                .filter(|v| y.vertices(&m).contains(v))
                .collect();
            common.dedup();
            assert_eq!(common.len(), 1, "{cells:?} {nu}x{nv}");
            // Two copies of every loop vertex, four of the crossing one.
            assert_eq!(
                cut.mesh.vertex_count(),
                m.vertex_count() + x.halfedges.len() + y.halfedges.len() + 1
            );
        }
    }
}

#[test]
fn torus_generators_are_shortest_loops() {
    let (major, minor) = (3.0, 1.0);
    for cells in [Cells::Triangles, Cells::Quads] {
        let m = torus(48, 20, major, minor, cells);
        let g = cut_graph(&m);
        let lengths: Vec<f64> = g.generators.iter().map(|x| x.length).collect();
        let tube = TAU * minor;
        assert!(
            lengths[0] >= 0.95 * tube && lengths[0] <= 1.5 * tube,
            "{cells:?}: shortest generator {} vs tube circle {tube}",
            lengths[0]
        );
        assert!(
            lengths[1] <= 1.5 * TAU * (major + minor),
            "{cells:?}: second generator {}",
            lengths[1]
        );
        // The cut torus: side a is the tube circle, side b goes around the axis.
        let cut = cut_to_disk(&m).unwrap();
        let sides = cut.torus_sides.as_ref().unwrap();
        let a = cut.path_length(sides.a.clone());
        let b = cut.path_length(sides.b.clone());
        assert!((a - lengths[0]).abs() < 1e-9 * a, "a {a}");
        assert!(
            b >= 0.95 * TAU * (major - minor) && b <= 1.1 * TAU * (major + minor),
            "b {b}"
        );
    }
}

#[test]
fn a_torus_with_a_hole_cuts_into_a_disk() {
    let soup = primitives::torus(16, 8, 3.0, 1.0, Cells::Triangles);
    let mut holed = PolygonSoup::new(soup.positions.clone());
    for (i, f) in soup.faces().enumerate() {
        if i != 5 {
            holed.push_face(f);
        }
    }
    let m = mesh(&holed);
    let g = cut_graph(&m);
    check_cut_graph(&m, &g, 1, 1);
    let cut = cut_to_disk(&m).unwrap();
    assert!(cut.torus_sides.is_none());
    check_disk(&m, &cut);
}

#[test]
fn a_disk_comes_back_unchanged_and_an_annulus_is_cut_once() {
    let m = mesh(&primitives::grid(5, 4, Cells::Quads));
    let g = cut_graph(&m);
    check_cut_graph(&m, &g, 0, 1);
    assert!(g.generators.is_empty());
    let cut = cut_to_disk(&m).unwrap();
    check_disk(&m, &cut);
    assert_eq!(cut.mesh.vertex_count(), m.vertex_count());

    // A 4 x 4 grid without its middle 2 x 2 cells: an annulus.
    let full = primitives::grid(4, 4, Cells::Triangles);
    let mut soup = PolygonSoup::new(full.positions.clone());
    for (i, f) in full.faces().enumerate() {
        let cell = i / 2;
        let (x, y) = (cell % 4, cell / 4);
        if !((1..3).contains(&x) && (1..3).contains(&y)) {
            soup.push_face(f);
        }
    }
    let m = mesh(&soup);
    let g = cut_graph(&m);
    check_cut_graph(&m, &g, 0, 2);
    assert!(matches!(g.generators[0].kind, GeneratorKind::Boundary(_)));
    let cut = cut_to_disk(&m).unwrap();
    check_disk(&m, &cut);
    assert!(cut.mesh.vertex_count() > m.vertex_count());
}

#[test]
fn a_sphere_has_nothing_to_cut() {
    let m = mesh(&primitives::icosphere(2));
    let g = cut_graph(&m);
    assert!(g.generators.is_empty() && g.edges.is_empty());
    let err = cut_to_disk(&m).unwrap_err();
    assert_eq!(err, CutError::ClosedGenusZero);
    let text = err.to_string();
    assert!(
        text.contains("genus 0") && text.contains("sphere"),
        "{text}"
    );
}

#[test]
fn several_components_are_named_in_the_error() {
    let a = primitives::torus(8, 5, 3.0, 1.0, Cells::Quads);
    let b = primitives::icosphere(1);
    let mut positions = a.positions.clone();
    let offset = positions.len() as u32;
    positions.extend(
        b.positions
            .iter()
            .map(|p| p + nalgebra::Vector3::new(10.0, 0.0, 0.0)),
    );
    let mut soup = PolygonSoup::new(positions);
    for f in a.faces() {
        soup.push_face(f);
    }
    for f in b.faces() {
        let shifted: Vec<u32> = f.iter().map(|&v| v + offset).collect();
        soup.push_face(&shifted);
    }
    let m = mesh(&soup);
    // The cut graph itself works per component.
    let g = cut_graph(&m);
    assert_eq!(g.components.len(), 2);
    assert_eq!(g.generators.len(), 2);
    assert!(
        g.generators
            .iter()
            .all(|x| x.component == g.components[0].id)
    );
    let err = cut_to_disk(&m).unwrap_err();
    assert!(matches!(&err, CutError::MultipleComponents { components } if components.len() == 2));
    let text = err.to_string();
    assert!(
        text.contains("2 connected components")
            && text.contains("c0: 40 faces, genus 1")
            && text.contains("c1: 80 faces, genus 0"),
        "{text}"
    );
}

#[test]
fn shared_meshes_of_genus_one_to_four_cut_into_disks() {
    let Some(dir) = shared_meshes() else { return };
    for (file, genus, loops) in [
        ("g1_kitten.obj", 1, 0),
        ("g1_bob.obj", 1, 0),
        ("g2_eight.obj", 2, 0),
        ("g2b1_eight_hole.obj", 2, 1),
        ("g4_fertility.obj", 4, 0),
    ] {
        let m = io::read(&dir.join(file), &BuildOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"))
            .mesh;
        let g = cut_graph(&m);
        assert_eq!(g.components[0].genus, genus as i64, "{file}");
        assert_eq!(g.generators.len(), 2 * genus + loops.max(1) - 1, "{file}");
        check_cut_graph(&m, &g, genus, loops);
        let cut = cut_to_disk(&m).unwrap_or_else(|e| panic!("{file}: {e}"));
        check_disk(&m, &cut);
        if genus == 1 && loops == 0 {
            check_torus_sides(&cut);
        } else {
            assert!(cut.torus_sides.is_none(), "{file}");
        }
        // Round trip: the written cut mesh reads back as a disk.
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("cut.obj");
        io::obj::write(&out, &cut.mesh, &Default::default()).unwrap();
        let back = io::read(&out, &BuildOptions::default()).unwrap().mesh;
        assert!(back.is_disk(), "{file}");
        assert_eq!(back.face_count(), m.face_count(), "{file}");
        let p: Point3<f64> = back.position(VertexId(0));
        assert_eq!(p, m.position(VertexId(0)));
    }
}
