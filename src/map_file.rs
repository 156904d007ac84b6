//! A solution's map written as a mesh file on the source's connectivity.
//!
//! # What the file holds
//!
//! The source mesh's faces (in their input order, and its vertices in their input order,
//! [`beltrami_mesh::io`]) with, per vertex, the image of the map ([`image`]):
//!
//! - a planar map ([`Map::Planar`]) `x + i y` as the texture coordinate `(x, y)`
//!   (OBJ: one `vt` per vertex and faces `f a/a b/b c/c`; glTF: `TEXCOORD_0`; PLY: `s t`;
//!   OFF: `STOFF`), the positions staying the source's (STL holds no texture coordinates
//!   and is refused);
//! - a map into R^3 ([`Map::Spatial`]) as the positions;
//! - a map onto a target mesh ([`Map::OnMesh`]) as the positions of its surface points
//!   on that target, which must be given.
//!
//! glTF, GLB, PLY and OFF files also get, when the solution measured `mu`
//! ([`Metrics::mu`]), one color per vertex (glTF `COLOR_0`, PLY `red green blue`, COFF):
//! the viridis color ([`beltrami_render::viridis`], dark at 0, yellow at 1 and above) of
//! the vertex's `|mu|`, the mean of `|mu|` over its incident faces ([`vertex_mu`]). OBJ
//! and STL files get no colors.
//!
//! Every file is written atomically (complete or absent,
//! [`beltrami_mesh::io::write_atomically`]).
//!
//! [`Metrics::mu`]: beltrami_core::Metrics::mu

use std::path::Path;

use beltrami_core::{Map, Solution};
use beltrami_fem::BeltramiField;
use beltrami_mesh::io::{self, Format, VertexAttributes, WriteError};
use beltrami_mesh::{Mesh, Point3, SurfacePointError, Vector2, VertexId};
use beltrami_render::viridis;
use thiserror::Error;

/// Why a map could not be written. The destination is left untouched.
#[derive(Debug, Error)]
pub enum MapFileError {
    /// The solution made a new mesh, not a map of the source's vertices.
    #[error("the solution is a new mesh, not a map of the source's vertices")]
    NoMap,
    /// The map is onto a target mesh, and no target was given.
    #[error("the map is onto a target mesh: give the target mesh to write its positions")]
    NoTarget,
    /// The map does not have one image per source vertex.
    #[error("the map has {got} images but the mesh has {expected} vertices")]
    Length {
        /// Number of source vertices.
        expected: usize,
        /// Number of images.
        got: usize,
    },
    /// The measured `mu` does not have one value per source face.
    #[error("the measured mu has {got} values but the mesh has {expected} faces")]
    MuLength {
        /// Number of source faces.
        expected: usize,
        /// Number of values.
        got: usize,
    },
    /// An image of a map onto a target mesh is not a point of the target.
    #[error("the image of source vertex {vertex} (input index) is not on the target mesh: {error}")]
    OffTarget {
        /// The input index of the source vertex.
        vertex: usize,
        /// What is wrong with the surface point.
        #[source]
        error: SurfacePointError,
    },
    /// Writing the file failed (unknown format, non-finite values, IO).
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// The per-vertex data a map file holds (module docs), indexed by [`VertexId`].
#[derive(Debug, Clone, PartialEq)]
pub enum Image {
    /// Texture coordinates `(x, y)` of a planar map `x + i y`.
    Uv(Vec<Vector2<f64>>),
    /// Positions in R^3: a spatial map, or a map onto a target mesh.
    Positions(Vec<Point3<f64>>),
}

/// The image of `map`, a map of `mesh`'s vertices, as written to a file: texture
/// coordinates for a planar map, positions otherwise. A map onto a target mesh needs
/// `target` (its points are checked with [`beltrami_mesh::SurfacePoint::validate`]);
/// `target` is not read for other maps.
pub fn image(mesh: &Mesh, map: &Map, target: Option<&Mesh>) -> Result<Image, MapFileError> {
    if map.len() != mesh.vertex_count() {
        return Err(MapFileError::Length {
            expected: mesh.vertex_count(),
            got: map.len(),
        });
    }
    Ok(match map {
        Map::Planar(z) => Image::Uv(z.iter().map(|z| Vector2::new(z.re, z.im)).collect()),
        Map::Spatial(p) => Image::Positions(p.clone()),
        Map::OnMesh(points) => {
            let target = target.ok_or(MapFileError::NoTarget)?;
            let positions = points
                .iter()
                .enumerate()
                .map(|(v, p)| {
                    p.validate(target)
                        .map_err(|error| MapFileError::OffTarget {
                            vertex: mesh.vertex_map().to_input(VertexId(v as u32)),
                            error,
                        })?;
                    Ok(p.position(target))
                })
                .collect::<Result<Vec<_>, MapFileError>>()?;
            Image::Positions(positions)
        }
    })
}

/// Per vertex of `mesh` (by [`VertexId`]), the mean of `|mu|` over its incident faces
/// (0 for a vertex without faces). `field` has one value per face of `mesh`.
pub fn vertex_mu(mesh: &Mesh, field: &BeltramiField) -> Result<Vec<f64>, MapFileError> {
    if field.mu.len() != mesh.face_count() {
        return Err(MapFileError::MuLength {
            expected: mesh.face_count(),
            got: field.mu.len(),
        });
    }
    Ok(mesh
        .vertices()
        .map(|v| {
            let (sum, n) = mesh.vertex_faces(v).fold((0.0, 0usize), |(s, n), f| {
                (s + field.mu[f.idx()].norm(), n + 1)
            });
            if n > 0 { sum / n as f64 } else { 0.0 }
        })
        .collect())
}

/// Writes the map of `solution` (a map of `mesh`'s vertices) to `path` (any mesh format
/// but STL for a planar map) as described in the module docs; `target` is the target
/// mesh of a map onto one. An OBJ file takes the text of the lines that do not depend on
/// the map from `sections` where they fit ([`io::obj::write_with_sections`]) and the
/// input's grouping lines `obj_groups` ([`io::LoadedMesh::obj_groups`]).
pub fn write(
    path: &Path,
    mesh: &Mesh,
    solution: &Solution,
    target: Option<&Mesh>,
    sections: Option<&io::obj::MeshSections>,
    obj_groups: &[(u32, String)],
) -> Result<(), MapFileError> {
    let format = Format::from_path(path).ok_or_else(|| WriteError::UnknownFormat {
        path: path.to_path_buf(),
    })?;
    let map = solution.map().ok_or(MapFileError::NoMap)?;
    let image = image(mesh, map, target)?;
    let colors: Option<Vec<[f32; 3]>> = match &solution.metrics.mu {
        Some(field) if format.holds_colors() => {
            Some(vertex_mu(mesh, field)?.into_iter().map(viridis).collect())
        }
        _ => None,
    };
    let mut attributes = VertexAttributes {
        colors: colors.as_deref(),
        obj_groups,
        ..Default::default()
    };
    match &image {
        Image::Uv(uv) => attributes.uvs = Some(uv),
        Image::Positions(p) => attributes.positions = Some(p),
    }
    match format {
        Format::Obj => io::obj::write_with_sections(path, mesh, &attributes, sections)?,
        _ => io::write(path, mesh, &attributes)?,
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_core::{Output, Remeshed, Report};
    use beltrami_fem::Frame;
    use beltrami_mesh::primitives::{Cells, grid};
    use beltrami_mesh::{BuildOptions, SurfacePoint};
    use num_complex::Complex64;

    use crate::report::tests::lsqc_solution;

    fn read(path: &Path) -> beltrami_mesh::io::LoadedMesh {
        io::read(path, &BuildOptions::default()).unwrap()
    }

    /// The `COLOR_0` of the first primitive of a GLB file, through the gltf crate.
    fn glb_colors(path: &Path) -> Option<Vec<[f32; 3]>> {
        let doc = ::gltf::Gltf::from_slice(&std::fs::read(path).unwrap()).unwrap();
        let blob = doc.blob.as_deref().unwrap();
        let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
        let colors = prim.reader(|_| Some(blob)).read_colors(0)?;
        Some(colors.into_rgb_f32().collect())
    }

    #[test]
    fn a_planar_map_reads_back_from_obj_and_glb() {
        let (mesh, solution) = lsqc_solution();
        let z = solution.planar().unwrap().to_vec();
        let dir = tempfile::tempdir().unwrap();

        let obj = dir.path().join("map.obj");
        write(&obj, &mesh, &solution, None, None, &[]).unwrap();
        let back = read(&obj);
        assert_eq!(back.mesh.positions(), mesh.positions());
        let uv = back.vertex_uvs().unwrap();
        for (t, z) in uv.iter().zip(&z) {
            assert_eq!((t.x, t.y), (z.re, z.im), "OBJ keeps every digit");
        }

        let glb = dir.path().join("map.glb");
        write(&glb, &mesh, &solution, None, None, &[]).unwrap();
        let back = read(&glb);
        for (p, q) in back.mesh.positions().iter().zip(mesh.positions()) {
            assert!((p - q).norm() < 1e-6);
        }
        for (t, z) in back.vertex_uvs().unwrap().iter().zip(&z) {
            assert!((t.x - z.re).abs() < 1e-6 && (t.y - z.im).abs() < 1e-6);
        }
        let field = solution.metrics.mu.as_ref().unwrap();
        let expected: Vec<[f32; 3]> = vertex_mu(&mesh, field)
            .unwrap()
            .into_iter()
            .map(viridis)
            .collect();
        assert_eq!(glb_colors(&glb).unwrap(), expected);
    }

    #[test]
    fn vertex_mu_is_the_mean_over_the_incident_faces() {
        let mesh = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
        let constant = BeltramiField::new(Frame::Global, vec![Complex64::new(0.3, 0.4); 18]);
        for m in vertex_mu(&mesh, &constant).unwrap() {
            assert!((m - 0.5).abs() < 1e-15);
        }
        // |mu| = face index: each vertex gets the mean of its faces' indices.
        let ramp: Vec<Complex64> = (0..18).map(|f| Complex64::new(0.0, f as f64)).collect();
        let means = vertex_mu(&mesh, &BeltramiField::new(Frame::Face, ramp)).unwrap();
        for v in mesh.vertices() {
            let faces: Vec<f64> = mesh.vertex_faces(v).map(|f| f.idx() as f64).collect();
            assert!(!faces.is_empty());
            let mean = faces.iter().sum::<f64>() / faces.len() as f64;
            assert!((means[v.idx()] - mean).abs() < 1e-12);
        }
        let short = BeltramiField::new(Frame::Global, vec![Complex64::new(0.0, 0.0); 17]);
        assert!(matches!(
            vertex_mu(&mesh, &short),
            Err(MapFileError::MuLength {
                expected: 18,
                got: 17
            })
        ));
    }

    /// A 3x3 grid as the source, and as the target the same grid lifted onto the
    /// saddle z = x y.
    fn source_and_target() -> (Mesh, Mesh) {
        let source = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
        let mut soup = grid(3, 3, Cells::Triangles);
        for p in &mut soup.positions {
            p.z = p.x * p.y;
        }
        (source, Mesh::from_soup(&soup).unwrap())
    }

    #[test]
    fn a_map_onto_a_target_mesh_writes_the_positions_of_its_points() {
        let (source, target) = source_and_target();
        // Every vertex onto its twin, but vertex 5 onto the centroid of target face 3.
        let mut points: Vec<SurfacePoint> = target
            .vertices()
            .map(|v| SurfacePoint::at_vertex(&target, v))
            .collect();
        points[5] = SurfacePoint::in_triangle(beltrami_mesh::FaceId(3), [1.0 / 3.0; 3]);
        let solution = Solution::from_map(Map::OnMesh(points.clone()), Report::new("test"));
        let dir = tempfile::tempdir().unwrap();
        let obj = dir.path().join("on_target.obj");

        let err = write(&obj, &source, &solution, None, None, &[]).unwrap_err();
        assert!(matches!(err, MapFileError::NoTarget), "{err}");
        assert!(!obj.exists());

        write(&obj, &source, &solution, Some(&target), None, &[]).unwrap();
        let back = read(&obj);
        assert!(back.vertex_uvs().is_none());
        for (v, (p, q)) in back.mesh.positions().iter().zip(&points).enumerate() {
            assert_eq!(*p, q.position(&target), "vertex {v}");
        }
        assert_eq!(back.mesh.positions()[0], target.positions()[0]);

        // A point outside its face is refused, naming the vertex; nothing is written.
        let glb = dir.path().join("bad.glb");
        points[7].coords = [0.7, 0.7, -0.4, 0.0];
        let bad = Solution::from_map(Map::OnMesh(points), Report::new("test"));
        let err = write(&glb, &source, &bad, Some(&target), None, &[]).unwrap_err();
        assert!(
            matches!(err, MapFileError::OffTarget { vertex: 7, .. }),
            "{err}"
        );
        assert!(!glb.exists());
    }

    #[test]
    fn a_spatial_map_goes_into_the_positions_without_colors_when_mu_is_unknown() {
        let (source, target) = source_and_target();
        let solution = Solution::from_map(
            Map::Spatial(target.positions().to_vec()),
            Report::new("test"),
        );
        let dir = tempfile::tempdir().unwrap();
        let glb = dir.path().join("spatial.glb");
        write(&glb, &source, &solution, None, None, &[]).unwrap();
        let back = read(&glb);
        for (p, q) in back.mesh.positions().iter().zip(target.positions()) {
            assert!((p - q).norm() < 1e-6);
        }
        assert_eq!(glb_colors(&glb), None);
    }

    #[test]
    fn what_cannot_be_written_is_refused_before_any_output() {
        let (source, target) = source_and_target();
        let dir = tempfile::tempdir().unwrap();
        let obj = dir.path().join("out.obj");
        let short = Solution::from_map(
            Map::Planar(vec![Complex64::new(0.0, 0.0); 3]),
            Report::new("test"),
        );
        let err = write(&obj, &source, &short, None, None, &[]).unwrap_err();
        assert!(
            matches!(
                err,
                MapFileError::Length {
                    expected: 16,
                    got: 3
                }
            ),
            "{err}"
        );
        let remeshed = Solution {
            output: Output::Mesh(Box::new(Remeshed {
                mesh: target.clone(),
                on_source: Vec::new(),
            })),
            ..short
        };
        assert!(matches!(
            write(&obj, &source, &remeshed, None, None, &[]),
            Err(MapFileError::NoMap)
        ));
        let xyz = dir.path().join("out.xyz");
        let spatial = Solution::from_map(
            Map::Spatial(target.positions().to_vec()),
            Report::new("test"),
        );
        assert!(matches!(
            write(&xyz, &source, &spatial, None, None, &[]),
            Err(MapFileError::Write(WriteError::UnknownFormat { .. }))
        ));
        let mut nan = target.positions().to_vec();
        nan[2].x = f64::NAN;
        let nan = Solution::from_map(Map::Spatial(nan), Report::new("test"));
        assert!(matches!(
            write(&obj, &source, &nan, None, None, &[]),
            Err(MapFileError::Write(WriteError::NonFinite { vertex: 2, .. }))
        ));
        assert!(!obj.exists() && !xyz.exists());
    }
}
