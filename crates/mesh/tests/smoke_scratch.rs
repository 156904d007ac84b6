use beltrami_mesh::primitives::*;
use beltrami_mesh::*;
#[test]
fn smoke() {
    for (soup, chi, b) in [(grid(3, 2, Cells::Triangles), 1, 1), (grid(3, 2, Cells::Quads), 1, 1), (torus(8, 6, 2.0, 0.5, Cells::Triangles), 0, 0), (icosphere(2), 2, 0)] {
        let (m, r) = Mesh::build(&soup, &BuildOptions::default()).unwrap();
        assert_eq!(m.euler_characteristic(), chi);
        assert_eq!(m.boundary_loop_count(), b);
        assert_eq!(r.faces_reoriented, 0);
        for v in m.vertices() { let fs: Vec<_> = m.vertex_faces(v).collect(); assert!(!fs.is_empty()); }
        println!("{:?} area {}", m.components(), m.total_area());
    }
}
