//! Scaffold faces that close the holes of a multiply connected chart, so that a
//! parameterizer of disks can map it.
//!
//! A genus-0 surface with several boundary loops becomes a disk when every loop but one
//! is closed: each closed loop `v_1 .. v_n` gets a vertex `c` at the mean of its vertices
//! and the fan of faces `(v_k, v_(k+1), c)`, which turn like the surface's faces across
//! the loop's edges. The parameterizer maps the closed disk; the chart keeps its holes
//! (their loops are constraint curves of the triangulation and the holes lie outside the
//! domain), so the scaffold only lets the holes take the shape the map gives them. A
//! circle-domain map fixes that shape to a circle instead, and on coarse holes a discrete
//! conformal map onto circles can squeeze a face nearly flat (docs/remesh.md, limits);
//! with a free boundary (LSCM) or a convex one (Tutte's theorem holds for the closed disk)
//! nothing forces that. The loop left open is the longest on the surface.

use beltrami_mesh::{Mesh, Point3, PolygonSoup};

use crate::RemeshError;

/// `chart` with every boundary loop but the longest closed by a fan of scaffold faces:
/// the chart's vertices and faces first, with their ids, then one vertex and the fan of
/// faces per closed loop.
pub fn close_holes(chart: &Mesh) -> Result<Mesh, RemeshError> {
    let length = |b| {
        chart
            .loop_halfedges(b)
            .map(|h| chart.halfedge_vector(h).norm())
            .sum::<f64>()
    };
    let open = chart
        .boundary_loops()
        .max_by(|&a, &b| length(a).total_cmp(&length(b)));
    let mut soup = PolygonSoup::new(chart.positions().to_vec());
    let mut face = Vec::with_capacity(4);
    for f in chart.faces() {
        face.clear();
        face.extend(chart.face_vertices(f).map(|v| v.0));
        soup.push_face(&face);
    }
    for b in chart.boundary_loops().filter(|&b| Some(b) != open) {
        let ring: Vec<_> = chart.loop_halfedges(b).collect();
        let centre = ring.iter().fold(Point3::origin(), |s, &h| {
            s + chart.position(chart.origin(h)).coords
        }) / ring.len() as f64;
        let c = soup.positions.len() as u32;
        soup.positions.push(centre);
        for h in ring {
            soup.push_face(&[chart.origin(h).0, chart.target(h).0, c]);
        }
    }
    Mesh::from_soup(&soup).map_err(|error| RemeshError::Build {
        what: "chart with its holes closed",
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_core::topology::describe;
    use beltrami_mesh::primitives::annulus;

    #[test]
    fn an_annulus_becomes_a_disk_with_its_own_vertices_and_faces_first() {
        let chart = Mesh::from_soup(&annulus(0.4, 6, 32)).unwrap();
        let closed = close_holes(&chart).unwrap();
        assert_eq!(describe(&closed), "genus 0 and one boundary loop");
        assert_eq!(closed.vertex_count(), chart.vertex_count() + 1);
        assert_eq!(
            closed.positions()[..chart.vertex_count()],
            *chart.positions()
        );
        for f in chart.faces() {
            let a: Vec<_> = chart.face_vertices(f).collect();
            let b: Vec<_> = closed.face_vertices(f).collect();
            assert_eq!(a, b, "face {f}");
        }
        // The outer loop (radius 1) stays open; the fan's centre is the inner circle's.
        let open = closed.boundary_loops().next().unwrap();
        for h in closed.loop_halfedges(open) {
            let r = closed.position(closed.origin(h)).coords.norm();
            assert!((r - 1.0).abs() < 1e-12, "an open loop vertex at radius {r}");
        }
        assert!(closed.positions()[chart.vertex_count()].coords.norm() < 1e-12);
    }
}
