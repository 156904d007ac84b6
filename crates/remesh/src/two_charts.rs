//! Closed genus-0 surfaces remeshed through their spherical map, in two charts.
//!
//! A map onto the sphere (`sphere`) has no planar domain to triangulate, and a single
//! stereographic projection sends one pole to infinity. So the surface is split into two
//! disks along a loop of its edges near the map's equator: the *north* disk is the
//! connected set of faces reached from the northernmost face through faces whose image
//! centroid has `z >= 0`, together with every other part of the surface that it encloses;
//! the *south* disk is the rest. Each disk goes to the plane by the stereographic
//! projection from the opposite pole, `w = (x + i y) / (1 + z)` for the north and
//! `w = (x - i y) / (1 - z)` for the south (conjugated so that both keep the surface's
//! orientation); both images lie in a disk of radius about 1, and the projection is
//! conformal, so the remesh inherits the spherical map's low distortion without a pole.
//! Both charts sample the shared loop from the same vertex with the same spacing, so
//! their samples coincide; the two results are welded there.

use std::collections::VecDeque;

use beltrami_core::{Context, Problem, Remeshed, Solver, Target, topology::describe};
use beltrami_mesh::{FaceId, Mesh, Point3, PolygonSoup, SurfacePoint, VertexId};
use num_complex::Complex64;

use crate::chart::{Chart, Opening};
use crate::{RemeshError, RemeshOptions, Remeshing, param};

/// Remeshes the closed genus-0 `mesh` through the spherical map of `solver` (module
/// docs); `sizes` is the asked edge length per vertex of `mesh`.
pub fn remesh(
    mesh: &Mesh,
    solver: &dyn Solver,
    options: &RemeshOptions,
    sizes: &[f64],
    context: &mut Context<'_>,
) -> Result<Remeshing, RemeshError> {
    let refuse = |message: String| RemeshError::Parameterizer {
        solver: solver.name(),
        message,
    };
    let topology = describe(mesh);
    if topology != "genus 0 and no boundary" {
        return Err(refuse(format!(
            "it maps closed genus-0 surfaces onto the sphere, and this one is {topology}"
        )));
    }
    let solution = solver
        .solve(&Problem::new(mesh, Target::Sphere), context)
        .map_err(|error| RemeshError::Solve {
            solver: solver.name(),
            error,
        })?;
    let Some(beltrami_core::Map::Spatial(sphere)) = solution.map() else {
        return Err(refuse("it returned no map onto the sphere".to_string()));
    };
    let north = north_faces(mesh, sphere);
    let mut halves = Vec::with_capacity(2);
    for (side, pole) in [(true, 1.0), (false, -1.0)] {
        let (half, to_original, faces) = part(mesh, &north, side)?;
        if describe(&half) != "genus 0 and one boundary loop" {
            return Err(refuse(format!(
                "the split of its spherical map along the equator is not two disks ({})",
                describe(&half)
            )));
        }
        let mut uv: Vec<Complex64> = to_original
            .iter()
            .map(|v| {
                let p = sphere[v.idx()];
                Complex64::new(p.x, pole * p.y) / (1.0 + pole * p.z)
            })
            .collect();
        // A sliver of the spherical map can turn over under the projection of its
        // chords; local Tutte steps repair it as for any parameterizer. The samples of
        // the shared loop stay where they were on the surface (the lift keeps an edge's
        // parameter), so the two disks still meet.
        param::one_to_one(&half, &mut uv, solver.name()).map_err(|error| match error {
            RemeshError::Flipped {
                solver,
                flipped,
                first,
            } => RemeshError::Flipped {
                solver,
                flipped,
                first: faces[first.idx()],
            },
            other => other,
        })?;
        let chart = Chart {
            mesh: half,
            to_original,
            opening: Opening::TwoCharts,
        };
        let result = crate::triangulate_chart(
            &chart.mesh,
            &chart,
            &uv,
            solver.name(),
            options,
            sizes,
            context,
        )?;
        halves.push((result, faces));
    }
    weld(mesh, halves)
}

/// Per face of `mesh`, whether it belongs to the north disk (module docs).
fn north_faces(mesh: &Mesh, sphere: &[Point3<f64>]) -> Vec<bool> {
    let height = |f: FaceId| {
        let (v, n) = mesh.face_vertex_array(f);
        (0..n).map(|i| sphere[v[i].idx()].z).sum::<f64>() / n as f64
    };
    let neighbours = |f: FaceId| {
        mesh.face_halfedges(f)
            .filter_map(|h| mesh.face(mesh.twin(h)))
            .collect::<Vec<_>>()
    };
    let extreme = |sign: f64| {
        mesh.faces()
            .max_by(|&a, &b| (sign * height(a)).total_cmp(&(sign * height(b))))
    };
    let flood = |start: FaceId, inside: &dyn Fn(FaceId) -> bool| {
        let mut reached = vec![false; mesh.face_count()];
        let mut queue = VecDeque::from([start]);
        reached[start.idx()] = true;
        while let Some(f) = queue.pop_front() {
            for g in neighbours(f) {
                if !reached[g.idx()] && inside(g) {
                    reached[g.idx()] = true;
                    queue.push_back(g);
                }
            }
        }
        reached
    };
    let (Some(top), Some(bottom)) = (extreme(1.0), extreme(-1.0)) else {
        return vec![true; mesh.face_count()];
    };
    let upper = flood(top, &|g| height(g) >= 0.0);
    // The south disk: the faces outside the north set connected to the southernmost;
    // every other part (an island enclosed by the north set) joins the north.
    let south = flood(bottom, &|g| !upper[g.idx()]);
    south.iter().map(|&s| !s).collect()
}

/// The faces of `mesh` with `north[f] == side`, as a mesh of their own: its vertices'
/// vertices of `mesh`, and its faces' faces of `mesh` (same first vertex and order).
fn part(
    mesh: &Mesh,
    north: &[bool],
    side: bool,
) -> Result<(Mesh, Vec<VertexId>, Vec<FaceId>), RemeshError> {
    let mut new_id = vec![u32::MAX; mesh.vertex_count()];
    let mut to_original = Vec::new();
    let mut faces = Vec::new();
    let mut soup = PolygonSoup::new(Vec::new());
    let mut face = Vec::with_capacity(4);
    for f in mesh.faces().filter(|f| north[f.idx()] == side) {
        face.clear();
        for v in mesh.face_vertices(f) {
            if new_id[v.idx()] == u32::MAX {
                new_id[v.idx()] = to_original.len() as u32;
                to_original.push(v);
                soup.positions.push(mesh.position(v));
            }
            face.push(new_id[v.idx()]);
        }
        soup.push_face(&face);
        faces.push(f);
    }
    let half = Mesh::from_soup(&soup).map_err(|error| RemeshError::Build {
        what: "hemisphere chart",
        error,
    })?;
    Ok((half, to_original, faces))
}

/// The two remeshed disks joined along their common loop: the south disk's boundary
/// vertices are the north disk's at the same position (to `1e-9` of the diagonal).
fn weld(mesh: &Mesh, halves: Vec<(Remeshing, Vec<FaceId>)>) -> Result<Remeshing, RemeshError> {
    let tolerance = 1e-9 * mesh.bounding_box().diagonal();
    let mut positions: Vec<Point3<f64>> = Vec::new();
    let mut on_source: Vec<SurfacePoint> = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut seam: Vec<(Point3<f64>, u32)> = Vec::new();
    let mut timings = Vec::new();
    let mut passes = 0;
    for (k, (half, original_faces)) in halves.iter().enumerate() {
        let m = &half.remeshed.mesh;
        let mut id = vec![u32::MAX; m.vertex_count()];
        for v in m.vertices() {
            let p = m.position(v);
            if k > 0 && m.is_boundary_vertex(v) {
                let found = seam
                    .iter()
                    .find(|(q, _)| (q - p).norm() <= tolerance)
                    .map(|&(_, i)| i);
                if let Some(i) = found {
                    id[v.idx()] = i;
                    continue;
                }
            }
            id[v.idx()] = positions.len() as u32;
            if k == 0 && m.is_boundary_vertex(v) {
                seam.push((p, id[v.idx()]));
            }
            positions.push(p);
            let mut point = half.remeshed.on_source[v.idx()];
            point.face = original_faces[point.face.idx()];
            on_source.push(point);
        }
        faces.extend(
            m.faces()
                .map(|f| m.face_vertices(f).map(|v| id[v.idx()]).collect()),
        );
        timings.extend(half.timings.iter().copied());
        passes = passes.max(half.size_passes);
    }
    let mut soup = PolygonSoup::new(positions);
    for face in &faces {
        soup.push_face(face);
    }
    let result = crate::assemble(mesh, &soup)?;
    let first = &halves[0].0;
    Ok(Remeshing {
        remeshed: Remeshed {
            mesh: result,
            on_source,
        },
        parameterizer: first.parameterizer,
        opening: Opening::TwoCharts,
        edge_length: 0.0,
        size_passes: passes,
        timings,
        notes: Vec::new(),
    })
}
