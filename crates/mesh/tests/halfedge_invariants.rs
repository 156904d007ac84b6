//! Property tests of the halfedge structure on generated meshes (grids, icospheres, tori,
//! mixed triangle/quad grids, an annulus and a two-component mesh), on the same soups
//! after random re-indexing, after flipping some faces, and with unreferenced vertices.

use beltrami_mesh::primitives::{self, Cells};
use beltrami_mesh::{
    BuildOptions, BuildReport, EdgeId, FaceId, HalfedgeId, Mesh, Point3, PolygonSoup, Vector3,
    VertexId,
};

mod common;
use common::Rng;

// ---------------------------------------------------------------------------------------
// A tiny deterministic PRNG (xorshift64*), so that the tests need no new dependency.
// ---------------------------------------------------------------------------------------

// ---------------------------------------------------------------------------------------
// Soup manipulation
// ---------------------------------------------------------------------------------------

/// A soup after re-indexing: vertex order and face order permuted and every face's vertex
/// list rotated cyclically.
struct Reindexed {
    soup: PolygonSoup,
    /// `face_old[new]` is the original index of new face `new`.
    face_old: Vec<usize>,
}

fn reindex(soup: &PolygonSoup, rng: &mut Rng) -> Reindexed {
    let n = soup.vertex_count();
    let mut order: Vec<usize> = (0..n).collect(); // order[new] = old
    rng.shuffle(&mut order);
    let mut vertex_new = vec![0u32; n];
    for (new, &old) in order.iter().enumerate() {
        vertex_new[old] = new as u32;
    }
    let positions = order.iter().map(|&old| soup.positions[old]).collect();
    let mut face_old: Vec<usize> = (0..soup.face_count()).collect();
    rng.shuffle(&mut face_old);
    let mut out = PolygonSoup::new(positions);
    for &f in &face_old {
        let face = soup.face(f);
        let k = rng.below(face.len());
        let rotated: Vec<u32> = (0..face.len())
            .map(|i| vertex_new[face[(i + k) % face.len()] as usize])
            .collect();
        out.push_face(&rotated);
    }
    // Sanity of the helper itself: same positions per face, up to rotation.
    for (new, &old) in face_old.iter().enumerate() {
        let a: Vec<Point3<f64>> = soup
            .face(old)
            .iter()
            .map(|&v| soup.positions[v as usize])
            .collect();
        let b: Vec<Point3<f64>> = out
            .face(new)
            .iter()
            .map(|&v| out.positions[v as usize])
            .collect();
        assert!((0..a.len()).any(|k| (0..a.len()).all(|i| a[(i + k) % a.len()] == b[i])));
    }
    Reindexed {
        soup: out,
        face_old,
    }
}

/// Reverses the vertex order of each face with probability `p`; returns the new soup and
/// the flipped face indices.
fn flip_some(soup: &PolygonSoup, p: f64, rng: &mut Rng) -> (PolygonSoup, Vec<usize>) {
    let mut out = PolygonSoup::new(soup.positions.clone());
    let mut flipped = Vec::new();
    for (f, face) in soup.faces().enumerate() {
        if rng.unit() < p {
            let mut rev = face.to_vec();
            rev.reverse();
            out.push_face(&rev);
            flipped.push(f);
        } else {
            out.push_face(face);
        }
    }
    (out, flipped)
}

/// Inserts `count` unreferenced vertices at random positions of the vertex list (with
/// random coordinates inside the unit cube); returns the soup and the inserted indices.
fn insert_unreferenced(
    soup: &PolygonSoup,
    count: usize,
    rng: &mut Rng,
) -> (PolygonSoup, Vec<usize>) {
    let n = soup.vertex_count() + count;
    let mut extra = vec![false; n];
    let mut placed = 0;
    while placed < count {
        let i = rng.below(n);
        if !extra[i] {
            extra[i] = true;
            placed += 1;
        }
    }
    let mut positions = Vec::with_capacity(n);
    let mut old_to_new = Vec::with_capacity(soup.vertex_count());
    let mut old = soup.positions.iter();
    for (i, &is_extra) in extra.iter().enumerate() {
        if is_extra {
            positions.push(Point3::new(
                0.1 + 0.8 * rng.unit(),
                0.1 + 0.8 * rng.unit(),
                0.25 * rng.unit(),
            ));
        } else {
            positions.push(*old.next().unwrap());
            old_to_new.push(i as u32);
        }
    }
    let mut out = PolygonSoup::new(positions);
    for face in soup.faces() {
        let mapped: Vec<u32> = face.iter().map(|&v| old_to_new[v as usize]).collect();
        out.push_face(&mapped);
    }
    let inserted = (0..n).filter(|&i| extra[i]).collect();
    (out, inserted)
}

/// Appends `b` to `a` (vertex indices of `b` shifted), translating `b` by `offset`.
fn disjoint_union(a: &PolygonSoup, b: &PolygonSoup, offset: Vector3<f64>) -> PolygonSoup {
    let mut positions = a.positions.clone();
    positions.extend(b.positions.iter().map(|p| p + offset));
    let shift = a.vertex_count() as u32;
    let mut out = PolygonSoup::new(positions);
    for face in a.faces() {
        out.push_face(face);
    }
    for face in b.faces() {
        let shifted: Vec<u32> = face.iter().map(|&v| v + shift).collect();
        out.push_face(&shifted);
    }
    out
}

/// An `nx` by `ny` quad grid where the cells with `(i + 2 j) % 3 == 0` are split into two
/// triangles (alternating diagonals). Returns the soup and the number of split cells.
fn mixed_grid(nx: usize, ny: usize) -> (PolygonSoup, usize) {
    let quads = primitives::grid(nx, ny, Cells::Quads);
    let mut out = PolygonSoup::new(quads.positions.clone());
    let mut split = 0;
    for j in 0..ny {
        for i in 0..nx {
            let q = quads.face(i + nx * j);
            if (i + 2 * j) % 3 == 0 {
                split += 1;
                if (i + j) % 2 == 0 {
                    out.push_face(&[q[0], q[1], q[2]]);
                    out.push_face(&[q[0], q[2], q[3]]);
                } else {
                    out.push_face(&[q[0], q[1], q[3]]);
                    out.push_face(&[q[1], q[2], q[3]]);
                }
            } else {
                out.push_face(q);
            }
        }
    }
    (out, split)
}

/// A `n` by `n` quad grid with the cells in `lo..hi` (both directions) removed: an annulus.
fn annulus(n: usize, lo: usize, hi: usize, cells: Cells) -> PolygonSoup {
    let full = primitives::grid(n, n, cells);
    let per_cell = if cells == Cells::Quads { 1 } else { 2 };
    let mut out = PolygonSoup::new(full.positions.clone());
    for (f, face) in full.faces().enumerate() {
        let cell = f / per_cell;
        let (i, j) = (cell % n, cell / n);
        if (lo..hi).contains(&i) && (lo..hi).contains(&j) {
            continue;
        }
        out.push_face(face);
    }
    out
}

// ---------------------------------------------------------------------------------------
// Expected values
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    /// In the plane z = 0, faces counter-clockwise seen from +z.
    Planar,
    /// Centred at the origin, normals outward.
    Sphere,
    /// Torus around the z axis with major radius `TORUS_R`, normals outward of the tube.
    Torus,
    /// No normal check.
    Any,
}

const TORUS_R: f64 = 2.0;
const TORUS_TUBE: f64 = 0.6;

#[derive(Clone, Debug)]
struct Expect {
    vertices: usize,
    edges: usize,
    faces: usize,
    triangles: usize,
    quads: usize,
    chi: i64,
    components: usize,
    genus: Option<i64>,
    /// Sorted sizes of the boundary loops.
    loop_sizes: Vec<usize>,
    is_disk: bool,
    is_closed: bool,
    shape: Shape,
}

struct Case {
    name: String,
    soup: PolygonSoup,
    expect: Expect,
}

fn grid_case(nx: usize, ny: usize, cells: Cells) -> Case {
    let cellsn = nx * ny;
    let base_edges = nx * (ny + 1) + ny * (nx + 1);
    let (faces, edges, triangles, quads) = match cells {
        Cells::Triangles => (2 * cellsn, base_edges + cellsn, 2 * cellsn, 0),
        Cells::Quads => (cellsn, base_edges, 0, cellsn),
    };
    Case {
        name: format!("grid({nx}, {ny}, {cells:?})"),
        soup: primitives::grid(nx, ny, cells),
        expect: Expect {
            vertices: (nx + 1) * (ny + 1),
            edges,
            faces,
            triangles,
            quads,
            chi: 1,
            components: 1,
            genus: Some(0),
            loop_sizes: vec![2 * (nx + ny)],
            is_disk: true,
            is_closed: false,
            shape: Shape::Planar,
        },
    }
}

fn sphere_case(s: usize) -> Case {
    let p = 4usize.pow(s as u32);
    Case {
        name: format!("icosphere({s})"),
        soup: primitives::icosphere(s),
        expect: Expect {
            vertices: 10 * p + 2,
            edges: 30 * p,
            faces: 20 * p,
            triangles: 20 * p,
            quads: 0,
            chi: 2,
            components: 1,
            genus: Some(0),
            loop_sizes: vec![],
            is_disk: false,
            is_closed: true,
            shape: Shape::Sphere,
        },
    }
}

fn torus_case(n: usize, m: usize, cells: Cells) -> Case {
    let nm = n * m;
    let (faces, edges, triangles, quads) = match cells {
        Cells::Triangles => (2 * nm, 3 * nm, 2 * nm, 0),
        Cells::Quads => (nm, 2 * nm, 0, nm),
    };
    Case {
        name: format!("torus({n}, {m}, {cells:?})"),
        soup: primitives::torus(n, m, TORUS_R, TORUS_TUBE, cells),
        expect: Expect {
            vertices: nm,
            edges,
            faces,
            triangles,
            quads,
            chi: 0,
            components: 1,
            genus: Some(1),
            loop_sizes: vec![],
            is_disk: false,
            is_closed: true,
            shape: Shape::Torus,
        },
    }
}

fn mixed_case(nx: usize, ny: usize) -> Case {
    let (soup, split) = mixed_grid(nx, ny);
    let cells = nx * ny;
    Case {
        name: format!("mixed_grid({nx}, {ny})"),
        soup,
        expect: Expect {
            vertices: (nx + 1) * (ny + 1),
            edges: nx * (ny + 1) + ny * (nx + 1) + split,
            faces: cells + split,
            triangles: 2 * split,
            quads: cells - split,
            chi: 1,
            components: 1,
            genus: Some(0),
            loop_sizes: vec![2 * (nx + ny)],
            is_disk: true,
            is_closed: false,
            shape: Shape::Planar,
        },
    }
}

fn annulus_case(cells: Cells) -> Case {
    // 5x5 cells with the central 1x1 cell... use a 2x2 hole: cells 1..3 removed.
    let soup = annulus(5, 1, 3, cells);
    let removed = 4;
    let cellsn = 25 - removed;
    let (faces, triangles, quads) = match cells {
        Cells::Triangles => (2 * cellsn, 2 * cellsn, 0),
        Cells::Quads => (cellsn, 0, cellsn),
    };
    // Vertex (2, 2) (the hole's centre) is unreferenced and left out.
    let vertices = 36 - 1;
    // chi = 0 for an annulus.
    let edges = vertices + faces;
    Case {
        name: format!("annulus({cells:?})"),
        soup,
        expect: Expect {
            vertices,
            edges,
            faces,
            triangles,
            quads,
            chi: 0,
            components: 1,
            genus: Some(0),
            loop_sizes: vec![8, 20],
            is_disk: false,
            is_closed: false,
            shape: Shape::Planar,
        },
    }
}

fn two_components_case() -> Case {
    let a = primitives::grid(3, 2, Cells::Quads);
    let b = primitives::icosphere(1);
    let soup = disjoint_union(&a, &b, Vector3::new(5.0, 0.0, 0.0));
    Case {
        name: "grid(3, 2) + icosphere(1)".into(),
        soup,
        expect: Expect {
            vertices: 12 + 42,
            edges: 17 + 120,
            faces: 6 + 80,
            triangles: 80,
            quads: 6,
            chi: 1 + 2,
            components: 2,
            genus: None,
            loop_sizes: vec![10],
            is_disk: false,
            is_closed: false,
            shape: Shape::Any,
        },
    }
}

fn all_cases() -> Vec<Case> {
    vec![
        grid_case(1, 1, Cells::Triangles),
        grid_case(1, 1, Cells::Quads),
        grid_case(3, 2, Cells::Triangles),
        grid_case(3, 2, Cells::Quads),
        grid_case(1, 6, Cells::Triangles),
        grid_case(7, 5, Cells::Quads),
        grid_case(9, 8, Cells::Triangles),
        sphere_case(0),
        sphere_case(1),
        sphere_case(2),
        torus_case(3, 3, Cells::Quads),
        torus_case(4, 3, Cells::Triangles),
        torus_case(8, 5, Cells::Triangles),
        torus_case(9, 6, Cells::Quads),
        mixed_case(4, 3),
        mixed_case(7, 6),
        annulus_case(Cells::Quads),
        annulus_case(Cells::Triangles),
        two_components_case(),
    ]
}

// ---------------------------------------------------------------------------------------
// Checks
// ---------------------------------------------------------------------------------------

fn build(soup: &PolygonSoup, name: &str) -> (Mesh, BuildReport) {
    Mesh::build(soup, &BuildOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn face_edges(mesh: &Mesh, f: FaceId) -> Vec<EdgeId> {
    mesh.face_halfedges(f).map(|h| mesh.edge(h)).collect()
}

/// Edges of face `f` incident to vertex `v`.
fn face_edges_at(mesh: &Mesh, f: FaceId, v: VertexId) -> Vec<EdgeId> {
    mesh.face_halfedges(f)
        .filter(|&h| mesh.origin(h) == v || mesh.target(h) == v)
        .map(|h| mesh.edge(h))
        .collect()
}

fn share_edge_at(mesh: &Mesh, f: FaceId, g: FaceId, v: VertexId) -> bool {
    let a = face_edges_at(mesh, f, v);
    face_edges_at(mesh, g, v).iter().any(|e| a.contains(e))
}

/// Every connectivity invariant of the halfedge structure.
fn check_connectivity(mesh: &Mesh, name: &str) {
    let nh = mesh.halfedge_count();
    let nf = mesh.face_count();
    let ne = mesh.edge_count();
    let nv = mesh.vertex_count();
    assert_eq!(mesh.halfedges().len(), nh, "{name}");

    // Per-halfedge identities.
    for h in mesh.halfedges() {
        let t = mesh.twin(h);
        assert!(t.idx() < nh, "{name}: twin of {h:?} out of range");
        assert_ne!(t, h, "{name}: twin({h:?}) == {h:?}");
        assert_eq!(mesh.twin(t), h, "{name}: twin(twin({h:?}))");
        assert_eq!(mesh.next(mesh.prev(h)), h, "{name}: next(prev({h:?}))");
        assert_eq!(mesh.prev(mesh.next(h)), h, "{name}: prev(next({h:?}))");
        assert_eq!(
            mesh.origin(mesh.next(h)),
            mesh.target(h),
            "{name}: origin(next({h:?})) != target"
        );
        assert_eq!(mesh.target(h), mesh.origin(t), "{name}: target({h:?})");
        assert_ne!(
            mesh.origin(h),
            mesh.target(h),
            "{name}: loop halfedge {h:?}"
        );
        assert!(mesh.origin(h).idx() < nv, "{name}");
        assert_eq!(
            mesh.edge(h),
            mesh.edge(t),
            "{name}: edge({h:?}) != edge(twin)"
        );
        assert!(mesh.edge(h).idx() < ne, "{name}");
        // A boundary halfedge's twin is a face halfedge (the surface is on its right).
        assert!(
            !(mesh.is_boundary_halfedge(h) && mesh.is_boundary_halfedge(t)),
            "{name}: both halfedges of {:?} are boundary",
            mesh.edge(h)
        );
        assert_eq!(
            mesh.face(h).is_none(),
            mesh.is_boundary_halfedge(h),
            "{name}"
        );
        assert_eq!(
            mesh.boundary_loop(h).is_some(),
            mesh.is_boundary_halfedge(h),
            "{name}"
        );
        let v = mesh.halfedge_vector(h);
        assert_eq!(
            v,
            mesh.position(mesh.target(h)) - mesh.position(mesh.origin(h))
        );
    }

    // Face cycles and boundary cycles: every halfedge in exactly one.
    let mut visits = vec![0u32; nh];
    let mut face_corners = 0usize;
    for f in mesh.faces() {
        let start = mesh.face_halfedge(f);
        let deg = mesh.face_degree(f);
        assert!(deg == 3 || deg == 4, "{name}: face {f:?} has degree {deg}");
        let mut h = start;
        let mut walk = Vec::new();
        for _ in 0..4 {
            walk.push(h);
            h = mesh.next(h);
            if h == start {
                break;
            }
        }
        assert_eq!(
            h, start,
            "{name}: next cycle of {f:?} does not close within 4 steps"
        );
        assert_eq!(walk.len(), deg, "{name}: face {f:?}");
        let listed: Vec<HalfedgeId> = mesh.face_halfedges(f).collect();
        assert_eq!(listed, walk, "{name}: face_halfedges({f:?})");
        // Consecutive ids starting at face_halfedge.
        for (k, h) in listed.iter().enumerate() {
            assert_eq!(h.idx(), start.idx() + k, "{name}");
        }
        let verts: Vec<VertexId> = mesh.face_vertices(f).collect();
        let origins: Vec<VertexId> = walk.iter().map(|&h| mesh.origin(h)).collect();
        assert_eq!(verts, origins, "{name}: face_vertices({f:?})");
        let (arr, n) = mesh.face_vertex_array(f);
        assert_eq!(&arr[..n], &verts[..], "{name}");
        let mut distinct = verts.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct.len(), deg, "{name}: repeated vertex in {f:?}");
        for &h in &walk {
            assert_eq!(mesh.face(h), Some(f), "{name}: face({h:?})");
            assert!(!mesh.is_boundary_halfedge(h), "{name}");
            visits[h.idx()] += 1;
        }
        face_corners += deg;
    }
    assert_eq!(mesh.triangle_count() + mesh.quad_count(), nf, "{name}");
    assert_eq!(
        3 * mesh.triangle_count() + 4 * mesh.quad_count(),
        face_corners,
        "{name}"
    );
    // Face halfedges come first.
    for h in mesh.halfedges() {
        assert_eq!(
            h.idx() < face_corners,
            !mesh.is_boundary_halfedge(h),
            "{name}: {h:?}"
        );
    }

    let mut boundary_halfedges = 0usize;
    for b in mesh.boundary_loops() {
        let start = mesh.loop_halfedge(b);
        assert!(mesh.is_boundary_halfedge(start), "{name}");
        let mut h = start;
        let mut steps = 0usize;
        loop {
            assert!(mesh.is_boundary_halfedge(h), "{name}: {h:?} in loop {b:?}");
            assert_eq!(mesh.boundary_loop(h), Some(b), "{name}");
            assert_eq!(mesh.face(h), None, "{name}");
            visits[h.idx()] += 1;
            steps += 1;
            assert!(steps <= nh, "{name}: loop {b:?} does not close");
            h = mesh.next(h);
            if h == start {
                break;
            }
        }
        let listed: Vec<HalfedgeId> = mesh.loop_halfedges(b).collect();
        assert_eq!(listed.len(), steps, "{name}");
        assert_eq!(listed[0], start, "{name}");
        let lv: Vec<VertexId> = mesh.loop_vertices(b).collect();
        assert_eq!(
            lv,
            listed.iter().map(|&h| mesh.origin(h)).collect::<Vec<_>>()
        );
        for &v in &lv {
            assert!(
                mesh.is_boundary_vertex(v),
                "{name}: loop vertex {v:?} not boundary"
            );
        }
        let mut distinct = lv.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(
            distinct.len(),
            lv.len(),
            "{name}: loop {b:?} repeats a vertex"
        );
        boundary_halfedges += steps;
    }
    assert!(
        visits.iter().all(|&c| c == 1),
        "{name}: halfedges not in exactly one cycle: {:?}",
        visits
            .iter()
            .enumerate()
            .filter(|&(_, &c)| c != 1)
            .take(5)
            .collect::<Vec<_>>()
    );
    assert_eq!(face_corners + boundary_halfedges, nh, "{name}");

    // Edges: exactly two halfedges each.
    let mut per_edge = vec![0u32; ne];
    for h in mesh.halfedges() {
        per_edge[mesh.edge(h).idx()] += 1;
    }
    assert!(
        per_edge.iter().all(|&c| c == 2),
        "{name}: edge multiplicity"
    );
    assert_eq!(nh, 2 * ne, "{name}");
    let mut boundary_edges = 0;
    for e in mesh.edges() {
        let h = mesh.edge_halfedge(e);
        assert_eq!(mesh.edge(h), e, "{name}");
        assert!(
            !mesh.is_boundary_halfedge(h),
            "{name}: edge_halfedge({e:?}) is boundary"
        );
        let [a, b] = mesh.edge_vertices(e);
        assert_eq!([a, b], [mesh.origin(h), mesh.target(h)], "{name}");
        let [f0, f1] = mesh.edge_faces(e);
        assert_eq!(f0, mesh.face(h), "{name}");
        assert!(f0.is_some(), "{name}");
        assert_eq!(f1, mesh.face(mesh.twin(h)), "{name}");
        assert_eq!(mesh.is_boundary_edge(e), f1.is_none(), "{name}");
        if f1.is_none() {
            boundary_edges += 1;
        }
        assert!(mesh.edge_length(e) > 0.0, "{name}");
    }
    assert_eq!(boundary_edges, boundary_halfedges, "{name}");

    // No two edges join the same pair of vertices.
    let mut pairs: Vec<(VertexId, VertexId)> = mesh
        .edges()
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            (a.min(b), a.max(b))
        })
        .collect();
    pairs.sort();
    pairs.dedup();
    assert_eq!(pairs.len(), ne, "{name}: two edges on one vertex pair");

    // Vertices and circulators.
    let mut outgoing_count = vec![0usize; nv];
    for h in mesh.halfedges() {
        outgoing_count[mesh.origin(h).idx()] += 1;
    }
    let mut degree_sum = 0;
    for v in mesh.vertices() {
        assert_eq!(mesh.origin(mesh.vertex_halfedge(v)), v, "{name}");
        let out: Vec<HalfedgeId> = mesh.outgoing_halfedges(v).collect();
        assert_eq!(out[0], mesh.vertex_halfedge(v), "{name}");
        for &h in &out {
            assert_eq!(mesh.origin(h), v, "{name}: outgoing {h:?} of {v:?}");
        }
        assert_eq!(
            out.len(),
            outgoing_count[v.idx()],
            "{name}: outgoing count of {v:?}"
        );
        let mut distinct = out.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(
            distinct.len(),
            out.len(),
            "{name}: {v:?} circulator repeats"
        );
        assert_eq!(mesh.vertex_degree(v), out.len(), "{name}");
        degree_sum += out.len();

        let neighbors: Vec<VertexId> = mesh.vertex_neighbors(v).collect();
        assert_eq!(neighbors.len(), mesh.vertex_degree(v), "{name}");
        let mut distinct = neighbors.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(
            distinct.len(),
            neighbors.len(),
            "{name}: neighbours of {v:?}"
        );
        assert!(!neighbors.contains(&v), "{name}");

        let boundary_out = out
            .iter()
            .filter(|&&h| mesh.is_boundary_halfedge(h))
            .count();
        assert!(
            boundary_out <= 1,
            "{name}: {v:?} has {boundary_out} boundary halfedges"
        );
        let on_boundary = boundary_out == 1;
        assert_eq!(mesh.is_boundary_vertex(v), on_boundary, "{name}: {v:?}");

        let faces: Vec<FaceId> = mesh.vertex_faces(v).collect();
        assert!(!faces.is_empty(), "{name}");
        for &f in &faces {
            assert!(
                mesh.face_vertices(f).any(|w| w == v),
                "{name}: {f:?} not at {v:?}"
            );
        }
        let mut distinct = faces.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct.len(), faces.len(), "{name}: fan of {v:?} repeats");
        for w in faces.windows(2) {
            assert!(
                share_edge_at(mesh, w[0], w[1], v),
                "{name}: consecutive faces {:?}, {:?} at {v:?} share no edge",
                w[0],
                w[1]
            );
        }
        if on_boundary {
            assert!(
                mesh.is_boundary_halfedge(out[0]),
                "{name}: boundary halfedge not first"
            );
            assert_eq!(faces.len(), out.len() - 1, "{name}");
            // The first face contains the boundary edge entering v, the last one the
            // boundary edge leaving v (out[0]).
            let entering = mesh.edge(mesh.prev(out[0]));
            let leaving = mesh.edge(out[0]);
            assert!(mesh.is_boundary_edge(entering) && mesh.is_boundary_edge(leaving));
            assert!(
                face_edges(mesh, faces[0]).contains(&entering),
                "{name}: first face of {v:?} lacks the boundary edge"
            );
            assert!(
                face_edges(mesh, *faces.last().unwrap()).contains(&leaving),
                "{name}: last face of {v:?} lacks the boundary edge"
            );
        } else {
            assert_eq!(faces.len(), out.len(), "{name}");
            assert!(
                share_edge_at(mesh, *faces.last().unwrap(), faces[0], v),
                "{name}: fan of interior {v:?} does not close"
            );
        }
    }
    assert_eq!(degree_sum, nh, "{name}");
}

fn check_topology(mesh: &Mesh, e: &Expect, name: &str) {
    assert_eq!(mesh.vertex_count(), e.vertices, "{name}: V");
    assert_eq!(mesh.edge_count(), e.edges, "{name}: E");
    assert_eq!(mesh.face_count(), e.faces, "{name}: F");
    assert_eq!(mesh.triangle_count(), e.triangles, "{name}: triangles");
    assert_eq!(mesh.quad_count(), e.quads, "{name}: quads");
    assert_eq!(mesh.euler_characteristic(), e.chi, "{name}: chi");
    assert_eq!(
        e.vertices as i64 - e.edges as i64 + e.faces as i64,
        e.chi,
        "{name}: expectation inconsistent"
    );
    assert_eq!(mesh.component_count(), e.components, "{name}: components");
    assert_eq!(mesh.genus(), e.genus, "{name}: genus");
    assert_eq!(mesh.is_disk(), e.is_disk, "{name}: is_disk");
    assert_eq!(mesh.is_closed(), e.is_closed, "{name}: is_closed");
    assert_eq!(
        mesh.boundary_loop_count(),
        e.loop_sizes.len(),
        "{name}: loops"
    );
    let mut sizes = mesh.boundary_loop_sizes();
    sizes.sort_unstable();
    assert_eq!(sizes, e.loop_sizes, "{name}: loop sizes");

    let loops = mesh.boundary_loop_list();
    assert_eq!(loops.len(), e.loop_sizes.len(), "{name}");
    for l in &loops {
        let lv: Vec<VertexId> = mesh.loop_vertices(l.id).collect();
        assert_eq!(l.vertices, lv, "{name}");
        let n = lv.len();
        let length: f64 = (0..n)
            .map(|k| (mesh.position(lv[(k + 1) % n]) - mesh.position(lv[k])).norm())
            .sum();
        assert!((l.length - length).abs() < 1e-12, "{name}");
    }

    // Components: counts add up, each has a consistent chi and genus.
    let comps = mesh.components();
    assert_eq!(comps.len(), e.components, "{name}");
    let sum = |f: fn(&beltrami_mesh::Component) -> usize| comps.iter().map(f).sum::<usize>();
    assert_eq!(sum(|c| c.vertices), mesh.vertex_count(), "{name}");
    assert_eq!(sum(|c| c.edges), mesh.edge_count(), "{name}");
    assert_eq!(sum(|c| c.faces), mesh.face_count(), "{name}");
    assert_eq!(
        sum(|c| c.boundary_loops),
        mesh.boundary_loop_count(),
        "{name}"
    );
    for (k, c) in comps.iter().enumerate() {
        assert_eq!(c.id.idx(), k, "{name}");
        assert_eq!(
            c.euler_characteristic,
            c.vertices as i64 - c.edges as i64 + c.faces as i64,
            "{name}"
        );
        assert_eq!(
            c.euler_characteristic,
            2 - 2 * c.genus - c.boundary_loops as i64,
            "{name}"
        );
        assert!(c.genus >= 0, "{name}");
        assert_eq!(c.is_closed(), c.boundary_loops == 0, "{name}");
    }
    // Faces sharing an edge are in the same component.
    for ed in mesh.edges() {
        if let [Some(f), Some(g)] = mesh.edge_faces(ed) {
            assert_eq!(mesh.face_component(f), mesh.face_component(g), "{name}");
        }
    }
}

/// Face normals point the expected way; for planar meshes the circulators turn
/// counter-clockwise and boundary loops have the surface on their right.
fn check_orientation(mesh: &Mesh, shape: Shape, name: &str) {
    for f in mesh.faces() {
        let n = mesh.face_normal(f);
        let c = mesh.face_centroid(f);
        match shape {
            Shape::Planar => assert!(
                (n - Vector3::z()).norm() < 1e-12,
                "{name}: normal of {f:?} is {n:?}"
            ),
            Shape::Sphere => assert!(n.dot(&c.coords) > 0.0, "{name}: {f:?} points inward"),
            Shape::Torus => {
                // The matching point of the core polygon: the average of the centres of
                // the tube cross-sections through the face's vertices.
                let (vs, k) = mesh.face_vertex_array(f);
                let core: Vector3<f64> = vs[..k]
                    .iter()
                    .map(|&v| {
                        let p = mesh.position(v);
                        Vector3::new(p.x, p.y, 0.0).normalize() * TORUS_R
                    })
                    .sum::<Vector3<f64>>()
                    / k as f64;
                assert!(
                    n.dot(&(c.coords - core)) > 0.0,
                    "{name}: {f:?} points inward"
                );
            }
            Shape::Any => {}
        }
    }
    if shape != Shape::Planar {
        return;
    }
    for v in mesh.vertices() {
        let p = mesh.position(v);
        let dirs: Vec<Vector3<f64>> = mesh
            .vertex_neighbors(v)
            .map(|w| mesh.position(w) - p)
            .collect();
        let k = dirs.len();
        // On the boundary the walk starts at the boundary halfedge and its first step
        // crosses the outside; every other step turns counter-clockwise across one face
        // (by less than pi), back to the boundary halfedge at the end.
        let first = usize::from(mesh.is_boundary_vertex(v));
        for i in first..k {
            let z = dirs[i].cross(&dirs[(i + 1) % k]).z;
            assert!(z > 0.0, "{name}: neighbours of {v:?} not counter-clockwise");
        }
    }
    // Signed area of each loop: negative (clockwise) for the outer boundary, positive for
    // the inner ones; in every case the faces lie on the loop's right.
    let mut signed: Vec<f64> = mesh
        .boundary_loop_list()
        .iter()
        .map(|l| {
            let n = l.vertices.len();
            0.5 * (0..n)
                .map(|k| {
                    let a = mesh.position(l.vertices[k]);
                    let b = mesh.position(l.vertices[(k + 1) % n]);
                    a.x * b.y - a.y * b.x
                })
                .sum::<f64>()
        })
        .collect();
    signed.sort_by(f64::total_cmp);
    assert!(signed[0] < 0.0, "{name}: outer loop is not clockwise");
    let outer_area = -signed[0];
    let holes: f64 = signed[1..].iter().sum();
    assert!(signed[1..].iter().all(|&a| a > 0.0), "{name}");
    assert!(
        (outer_area - holes - mesh.total_area()).abs() < 1e-12,
        "{name}: loop areas {signed:?} vs total area {}",
        mesh.total_area()
    );
}

/// Each mesh face is its input face (through the vertex map), unchanged or reversed
/// keeping its first vertex; returns the number of reversed faces.
fn check_faces_match_soup(mesh: &Mesh, soup: &PolygonSoup, name: &str) -> usize {
    let map = mesh.vertex_map();
    let mut reversed = 0;
    let mut seen = vec![false; soup.face_count()];
    for f in mesh.faces() {
        let input = mesh.face_to_input(f);
        assert!(!seen[input], "{name}: input face {input} twice");
        seen[input] = true;
        let expected: Vec<VertexId> = soup
            .face(input)
            .iter()
            .map(|&i| map.from_input(i as usize).expect("referenced vertex"))
            .collect();
        let got: Vec<VertexId> = mesh.face_vertices(f).collect();
        if got != expected {
            let mut rev = expected.clone();
            rev[1..].reverse();
            assert_eq!(got, rev, "{name}: {f:?} is not input face {input}");
            reversed += 1;
        }
        for (&v, &i) in expected.iter().zip(soup.face(input)) {
            assert_eq!(mesh.position(v), soup.positions[i as usize], "{name}");
        }
    }
    assert!(seen.iter().all(|&s| s), "{name}: a face went missing");
    reversed
}

fn check_all(mesh: &Mesh, soup: &PolygonSoup, e: &Expect, name: &str) -> usize {
    check_connectivity(mesh, name);
    check_topology(mesh, e, name);
    check_orientation(mesh, e.shape, name);
    check_faces_match_soup(mesh, soup, name)
}

// ---------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------

#[test]
fn generated_meshes_satisfy_invariants() {
    for case in all_cases() {
        let (mesh, report) = build(&case.soup, &case.name);
        let reversed = check_all(&mesh, &case.soup, &case.expect, &case.name);
        assert_eq!(reversed, 0, "{}", case.name);
        assert_eq!(report.faces_reoriented, 0, "{}", case.name);
        assert!(!report.repaired(), "{}", case.name);
        assert!(report.dropped_degenerate_faces.is_empty());
        assert!(report.dropped_duplicate_faces.is_empty());
        assert!(report.merged_vertices.is_empty());
    }
}

#[test]
fn generated_meshes_keep_input_numbering() {
    for case in all_cases() {
        let (mesh, _) = build(&case.soup, &case.name);
        // Face order is the input order.
        for f in mesh.faces() {
            assert_eq!(mesh.face_to_input(f), f.idx(), "{}", case.name);
        }
        let map = mesh.vertex_map();
        if case.name.starts_with("annulus") {
            // The hole's centre vertex (2, 2) of the 6x6 vertex grid is unreferenced.
            assert!(!map.is_identity(), "{}", case.name);
            assert!(map.is_order_preserving(), "{}", case.name);
            continue;
        }
        assert!(map.is_identity(), "{}", case.name);
        assert!(map.is_order_preserving(), "{}", case.name);
        assert_eq!(map.input_len(), case.soup.vertex_count(), "{}", case.name);
        assert!(map.unreferenced().is_empty(), "{}", case.name);
        for i in 0..case.soup.vertex_count() {
            assert_eq!(map.from_input(i), Some(VertexId(i as u32)), "{}", case.name);
            assert_eq!(map.to_input(VertexId(i as u32)), i, "{}", case.name);
            assert_eq!(mesh.position(VertexId(i as u32)), case.soup.positions[i]);
        }
        assert_eq!(
            map.from_input(case.soup.vertex_count()),
            None,
            "{}",
            case.name
        );
        assert_eq!(mesh.positions(), &case.soup.positions[..], "{}", case.name);
    }
}

#[test]
fn annulus_leaves_out_the_hole_centre() {
    let soup = annulus(5, 1, 3, Cells::Quads);
    let (mesh, report) = build(&soup, "annulus");
    let centre = 2 + 6 * 2;
    assert_eq!(report.unreferenced_vertices, vec![centre]);
    let map = mesh.vertex_map();
    assert_eq!(map.from_input(centre), None);
    assert_eq!(
        map.unreferenced(),
        &[(centre as u32, soup.positions[centre])]
    );
    for i in 0..soup.vertex_count() {
        if i == centre {
            continue;
        }
        let v = map.from_input(i).unwrap();
        assert_eq!(v.idx(), if i < centre { i } else { i - 1 });
        assert_eq!(map.to_input(v), i);
    }
}

#[test]
fn randomly_reindexed_meshes_satisfy_invariants() {
    let mut rng = Rng::new(1);
    for case in all_cases() {
        for round in 0..3 {
            let name = format!("{} reindexed #{round}", case.name);
            let re = reindex(&case.soup, &mut rng);
            let (mesh, report) = build(&re.soup, &name);
            let reversed = check_all(&mesh, &re.soup, &case.expect, &name);
            assert_eq!(reversed, 0, "{name}");
            assert_eq!(report.faces_reoriented, 0, "{name}");
            // Face order follows the (permuted) input.
            for f in mesh.faces() {
                assert_eq!(mesh.face_to_input(f), f.idx(), "{name}");
            }
            // Areas are preserved face by face.
            let (orig, _) = build(&case.soup, &case.name);
            for f in mesh.faces() {
                let g = FaceId(re.face_old[f.idx()] as u32);
                let (a, b) = (mesh.face_area(f), orig.face_area(g));
                assert!((a - b).abs() <= 1e-12 * b.max(1.0), "{name}: {a} vs {b}");
            }
        }
    }
}

#[test]
fn flipped_faces_are_reoriented() {
    let mut rng = Rng::new(7);
    let mut tested_with_flips = 0;
    for case in all_cases() {
        for round in 0..3 {
            let base = if round == 0 {
                case.soup.clone()
            } else {
                reindex(&case.soup, &mut rng).soup
            };
            let (soup, flipped) = flip_some(&base, 0.1, &mut rng);
            let name = format!("{} flipped {} #{round}", case.name, flipped.len());
            // Every component must keep a strict majority of unflipped faces.
            let (plain, _) = build(&base, &name);
            let mut per_comp = vec![(0usize, 0usize); plain.component_count()];
            for f in plain.faces() {
                let c = plain.face_component(f).idx();
                per_comp[c].0 += 1;
                if flipped.contains(&plain.face_to_input(f)) {
                    per_comp[c].1 += 1;
                }
            }
            if per_comp.iter().any(|&(n, k)| 2 * k >= n) {
                continue;
            }
            if !flipped.is_empty() {
                tested_with_flips += 1;
            }
            let (mesh, report) = build(&soup, &name);
            assert_eq!(report.faces_reoriented, flipped.len(), "{name}");
            let reversed = check_all(&mesh, &soup, &case.expect, &name);
            assert_eq!(reversed, flipped.len(), "{name}");
            // Exactly the flipped faces were reversed.
            for f in mesh.faces() {
                let input = mesh.face_to_input(f);
                let first_same = mesh
                    .vertex_map()
                    .to_input(mesh.face_vertices(f).next().unwrap())
                    == soup.face(input)[0] as usize;
                assert!(first_same, "{name}: first vertex of {f:?} changed");
            }
        }
    }
    assert!(
        tested_with_flips >= 20,
        "only {tested_with_flips} rounds had flips"
    );
}

#[test]
fn flips_on_larger_meshes_are_counted_exactly() {
    // Enough faces that 10% is a real count, with re-indexing.
    let mut rng = Rng::new(99);
    let cases = [
        grid_case(20, 15, Cells::Triangles),
        sphere_case(3),
        torus_case(24, 12, Cells::Quads),
    ];
    for case in &cases {
        let re = reindex(&case.soup, &mut rng);
        let (soup, flipped) = flip_some(&re.soup, 0.1, &mut rng);
        assert!(!flipped.is_empty() && 2 * flipped.len() < soup.face_count());
        let name = format!("{} flipped {}", case.name, flipped.len());
        let (mesh, report) = build(&soup, &name);
        assert_eq!(report.faces_reoriented, flipped.len(), "{name}");
        check_orientation(&mesh, case.expect.shape, &name);
        check_connectivity(&mesh, &name);
    }
}

#[test]
fn majority_orientation_wins() {
    // Flip 90% of a grid: the builder keeps the majority, so every normal is -z and only
    // the unflipped 10% are reported as re-oriented.
    let mut rng = Rng::new(3);
    let base = primitives::grid(12, 10, Cells::Triangles);
    let (soup, flipped) = flip_some(&base, 0.9, &mut rng);
    let kept = soup.face_count() - flipped.len();
    assert!(kept > 0 && 2 * kept < soup.face_count());
    let (mesh, report) = build(&soup, "grid 90% flipped");
    assert_eq!(report.faces_reoriented, kept);
    for f in mesh.faces() {
        assert!((mesh.face_normal(f) + Vector3::z()).norm() < 1e-12);
    }
    check_connectivity(&mesh, "grid 90% flipped");
    assert!(mesh.is_disk());
}

#[test]
fn each_component_is_oriented_separately() {
    // A grid with 10% flipped and a sphere with 90% flipped in one soup: the grid comes
    // out +z; the sphere keeps its majority (inward) orientation.
    let mut rng = Rng::new(11);
    let (grid, grid_flipped) = flip_some(&primitives::grid(8, 8, Cells::Quads), 0.1, &mut rng);
    let (sphere, sphere_flipped) = flip_some(&primitives::icosphere(2), 0.9, &mut rng);
    assert!(2 * grid_flipped.len() < grid.face_count());
    let sphere_kept = sphere.face_count() - sphere_flipped.len();
    assert!(2 * sphere_kept < sphere.face_count());
    let offset = Vector3::new(4.0, 0.0, 0.0);
    let soup = disjoint_union(&grid, &sphere, offset);
    let (mesh, report) = build(&soup, "grid + sphere");
    assert_eq!(report.faces_reoriented, grid_flipped.len() + sphere_kept);
    assert_eq!(mesh.component_count(), 2);
    let nq = grid.face_count();
    for f in mesh.faces() {
        let n = mesh.face_normal(f);
        if mesh.face_to_input(f) < nq {
            assert!((n - Vector3::z()).norm() < 1e-12);
        } else {
            let c = mesh.face_centroid(f).coords - offset;
            assert!(n.dot(&c) < 0.0, "sphere face {f:?} should point inward");
        }
    }
    check_connectivity(&mesh, "grid + sphere");
}

#[test]
fn vertex_map_with_unreferenced_vertices() {
    let mut rng = Rng::new(5);
    for case in all_cases() {
        for round in 0..2 {
            let base = if round == 0 {
                case.soup.clone()
            } else {
                reindex(&case.soup, &mut rng).soup
            };
            let count = 1 + rng.below(6);
            let (soup, inserted) = insert_unreferenced(&base, count, &mut rng);
            let name = format!("{} +{count} unreferenced #{round}", case.name);
            let (mesh, report) = build(&soup, &name);
            // The annulus already has one unreferenced vertex (the hole's centre).
            let mut expected_unref = inserted.clone();
            for i in 0..soup.vertex_count() {
                if !inserted.contains(&i) && !soup.faces().any(|f| f.contains(&(i as u32))) {
                    expected_unref.push(i);
                }
            }
            expected_unref.sort_unstable();
            assert_eq!(report.unreferenced_vertices, expected_unref, "{name}");
            assert_eq!(
                mesh.vertex_count(),
                soup.vertex_count() - expected_unref.len(),
                "{name}"
            );
            let map = mesh.vertex_map();
            assert_eq!(map.input_len(), soup.vertex_count(), "{name}");
            assert!(!map.is_identity(), "{name}");
            assert!(map.is_order_preserving(), "{name}");
            let unref: Vec<(u32, Point3<f64>)> = expected_unref
                .iter()
                .map(|&i| (i as u32, soup.positions[i]))
                .collect();
            assert_eq!(map.unreferenced(), &unref[..], "{name}");
            for i in 0..soup.vertex_count() {
                match map.from_input(i) {
                    None => assert!(expected_unref.contains(&i), "{name}: {i} lost"),
                    Some(v) => {
                        assert!(!expected_unref.contains(&i), "{name}: {i} should be None");
                        assert_eq!(mesh.position(v), soup.positions[i], "{name}: input {i}");
                        assert_eq!(map.to_input(v), i, "{name}");
                    }
                }
            }
            assert_eq!(map.from_input(soup.vertex_count()), None, "{name}");
            let mut last = None;
            for v in mesh.vertices() {
                let i = map.to_input(v);
                assert_eq!(map.from_input(i), Some(v), "{name}");
                // Relative input order is kept.
                assert!(last.is_none_or(|l| l < i), "{name}: order not kept");
                last = Some(i);
            }
            check_all(&mesh, &soup, &case.expect, &name);
        }
    }
}

#[test]
fn grid_boundary_loop_is_the_square_outline() {
    for &(nx, ny) in &[(1, 1), (2, 3), (5, 4), (10, 1)] {
        for cells in [Cells::Triangles, Cells::Quads] {
            let (mesh, _) = build(&primitives::grid(nx, ny, cells), "grid");
            assert_eq!(mesh.boundary_loop_count(), 1);
            let l = &mesh.boundary_loop_list()[0];
            assert_eq!(l.vertices.len(), 2 * (nx + ny));
            assert!((l.length - 4.0).abs() < 1e-12);
            // Exactly the vertices on the square's outline, each once.
            let on_outline = mesh
                .vertices()
                .filter(|&v| {
                    let p = mesh.position(v);
                    p.x == 0.0 || p.x == 1.0 || p.y == 0.0 || p.y == 1.0
                })
                .count();
            assert_eq!(on_outline, l.vertices.len());
            for v in mesh.vertices() {
                let p = mesh.position(v);
                let outline = p.x == 0.0 || p.x == 1.0 || p.y == 0.0 || p.y == 1.0;
                assert_eq!(mesh.is_boundary_vertex(v), outline);
                assert_eq!(l.vertices.contains(&v), outline);
            }
        }
    }
}

#[test]
fn interior_grid_vertex_degrees() {
    // Quad grid: interior degree 4, edge 3, corner 2. Triangle grid (diagonal (0,0)-(1,1)):
    // interior 6, corners (0,0),(1,1) 3 and the other two corners 2.
    let (mesh, _) = build(&primitives::grid(4, 4, Cells::Quads), "quads");
    for v in mesh.vertices() {
        let p = mesh.position(v);
        let on_x = p.x == 0.0 || p.x == 1.0;
        let on_y = p.y == 0.0 || p.y == 1.0;
        let expected = 4 - usize::from(on_x) - usize::from(on_y);
        assert_eq!(mesh.vertex_degree(v), expected, "{p:?}");
        assert_eq!(
            mesh.vertex_faces(v).count(),
            [1, 2, 4][2 - usize::from(on_x) - usize::from(on_y)]
        );
    }
    let (mesh, _) = build(&primitives::grid(4, 4, Cells::Triangles), "tris");
    let corner = |x: f64, y: f64| {
        mesh.vertices()
            .find(|&v| mesh.position(v) == Point3::new(x, y, 0.0))
            .unwrap()
    };
    assert_eq!(mesh.vertex_degree(corner(0.0, 0.0)), 3);
    assert_eq!(mesh.vertex_degree(corner(1.0, 1.0)), 3);
    assert_eq!(mesh.vertex_degree(corner(1.0, 0.0)), 2);
    assert_eq!(mesh.vertex_degree(corner(0.0, 1.0)), 2);
    assert_eq!(mesh.vertex_degree(corner(0.5, 0.5)), 6);
    assert_eq!(mesh.vertex_faces(corner(0.5, 0.5)).count(), 6);
    assert_eq!(mesh.vertex_faces(corner(0.0, 0.0)).count(), 2);
}

#[test]
fn icosphere_valences() {
    // Twelve valence-5 vertices (the icosahedron's), all others valence 6.
    for s in 0..4 {
        let (mesh, _) = build(&primitives::icosphere(s), "icosphere");
        let fives = mesh
            .vertices()
            .filter(|&v| mesh.vertex_degree(v) == 5)
            .count();
        let sixes = mesh
            .vertices()
            .filter(|&v| mesh.vertex_degree(v) == 6)
            .count();
        assert_eq!(fives, 12);
        assert_eq!(fives + sixes, mesh.vertex_count());
    }
}
