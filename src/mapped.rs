//! Maps given as mesh files: a mesh with the source's faces (same input vertex indices)
//! whose texture coordinates (a map into the plane) or, without them, whose positions (a
//! map into R^3) are the images of the source's vertices. This is what `beltrami
//! distortion`, `render` and `histogram` read, and what `param`, `qc` and `register`
//! write.
//!
//! Vertices correspond by their input index (the files' own order), face by face
//! ([`correspondence`]). A map into R^3 is judged against a reference normal
//! (`beltrami_fem::ReferenceNormal`); for a map onto another surface, [`target_normals`]
//! gives that surface's normals at the image, the rule `register` judges its maps by.

use std::collections::HashMap;
use std::path::Path;

use beltrami_atlas::SeamedUv;
use beltrami_fem::Frame;
use beltrami_fem::distortion::{Distortion, measure_planar};
use beltrami_mesh::io::{self, LoadedMesh, ReadError};
use beltrami_mesh::{
    BuildOptions, Mesh, Point3, Repair, SurfacePoint, Vector3, VertexId, split_corners,
};
use beltrami_spatial::{SpatialError, SurfaceIndex};
use num_complex::Complex64;
use thiserror::Error;

/// Why a mesh file is not a map of a source mesh.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MappedError {
    /// The face counts differ.
    #[error("it has {mapped} faces, the source has {source_faces}")]
    FaceCount {
        /// Faces of the map's mesh.
        mapped: usize,
        /// Faces of the source.
        source_faces: usize,
    },
    /// A face differs (input indices, 0-based).
    #[error(
        "face {source_face} has vertices {source_vertices:?} in the source but face {mapped_face} of the map has {mapped_vertices:?} (0-based input indices)"
    )]
    Face {
        /// The source face (input index).
        source_face: usize,
        /// Its vertices (input indices).
        source_vertices: Vec<usize>,
        /// The map's face at the same place (input index).
        mapped_face: usize,
        /// Its vertices (input indices).
        mapped_vertices: Vec<usize>,
    },
    /// A source vertex on no face (cannot happen for a built mesh; kept for safety).
    #[error("source vertex {vertex} lies on no face")]
    Unreferenced {
        /// The vertex.
        vertex: VertexId,
    },
    /// Texture coordinates with seams: a vertex with two different `vt`.
    #[error(
        "texture seams (vertex {vertex} has two different vt): a map into the plane needs one vt per vertex"
    )]
    Seam {
        /// The first vertex with two texture coordinates (input index).
        vertex: usize,
    },
}

/// Why a planar map could not be read from a mesh file.
#[derive(Debug, Error)]
pub enum ReadMapError {
    /// The file could not be read as a mesh.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// It is not a map of the source.
    #[error(transparent)]
    Map(#[from] MappedError),
}

/// The planar map in a mesh file with `source`'s faces: its texture coordinates, or,
/// without them, the `x + i y` of its positions (a planar map written as positions).
/// The file is read as [`read_mapped`] reads it and matched face by face
/// ([`correspondence`]).
pub fn read_planar(
    path: &Path,
    source: &Mesh,
    repair: bool,
) -> Result<Vec<Complex64>, ReadMapError> {
    let mapped = read_mapped(path, repair)?;
    let to_mapped = correspondence(source, &mapped.mesh)?;
    Ok(match planar_images(&mapped, &to_mapped)? {
        Some(map) => map,
        None => spatial_images(&mapped.mesh, &to_mapped)
            .iter()
            .map(|p| Complex64::new(p.x, p.y))
            .collect(),
    })
}

/// The map into R^3 in a mesh file with `source`'s faces: its positions, matched face
/// by face ([`correspondence`]).
pub fn read_spatial(
    path: &Path,
    source: &Mesh,
    repair: bool,
) -> Result<Vec<Point3<f64>>, ReadMapError> {
    let mapped = read_mapped(path, repair)?;
    let to_mapped = correspondence(source, &mapped.mesh)?;
    Ok(spatial_images(&mapped.mesh, &to_mapped))
}

/// Reads a map's mesh file. Its positions are the map's image (or do not matter, for a
/// map given by texture coordinates), so they must not change its connectivity: a face
/// collapsed by the map is a measurement (`|mu| = 1`, flipped), not a defect. So no face
/// counts as degenerate by its area and no vertices are merged; with `repair`, faces
/// with a repeated vertex and duplicate faces are dropped, as in the source.
pub fn read_mapped(path: &Path, repair: bool) -> Result<LoadedMesh, ReadError> {
    let options = BuildOptions {
        // The threshold `tolerance * diagonal^2` is then -inf: no area is below it.
        degenerate_area_tolerance: f64::NEG_INFINITY,
        repair: Repair {
            drop_degenerate_faces: repair,
            drop_duplicate_faces: repair,
            merge_coincident_vertices: false,
        },
    };
    io::read(path, &options)
}

/// For every source vertex, the vertex of `mapped` with the same input index, after
/// checking that both meshes have the same faces with the same input vertex indices, in
/// order (vertices a repair merged in the source are accepted).
pub fn correspondence(source: &Mesh, mapped: &Mesh) -> Result<Vec<VertexId>, MappedError> {
    if source.face_count() != mapped.face_count() {
        return Err(MappedError::FaceCount {
            mapped: mapped.face_count(),
            source_faces: source.face_count(),
        });
    }
    let (source_map, mapped_map) = (source.vertex_map(), mapped.vertex_map());
    let mut to_mapped = vec![None; source.vertex_count()];
    for f in source.faces() {
        let same = source.face_to_input(f) == mapped.face_to_input(f)
            && source.face_degree(f) == mapped.face_degree(f)
            && source
                .face_vertices(f)
                .zip(mapped.face_vertices(f))
                .all(|(v, w)| source_map.from_input(mapped_map.to_input(w)) == Some(v));
        if !same {
            return Err(MappedError::Face {
                source_face: source.face_to_input(f),
                source_vertices: source
                    .face_vertices(f)
                    .map(|v| source_map.to_input(v))
                    .collect(),
                mapped_face: mapped.face_to_input(f),
                mapped_vertices: mapped
                    .face_vertices(f)
                    .map(|v| mapped_map.to_input(v))
                    .collect(),
            });
        }
        for (v, w) in source.face_vertices(f).zip(mapped.face_vertices(f)) {
            to_mapped[v.idx()] = Some(w);
        }
    }
    to_mapped
        .into_iter()
        .enumerate()
        .map(|(v, w)| {
            w.ok_or(MappedError::Unreferenced {
                vertex: VertexId::from_usize(v),
            })
        })
        .collect()
}

/// The first vertex (in face order) whose corners carry two different texture
/// coordinates, if the file has texture coordinates with seams.
pub fn uv_seam(mapped: &LoadedMesh) -> Option<VertexId> {
    let mesh = &mapped.mesh;
    let corner = mapped.corner_uvs.as_ref()?;
    let mut first = vec![None; mesh.vertex_count()];
    mesh.faces()
        .flat_map(|f| mesh.face_halfedges(f))
        .find_map(|h| {
            let v = mesh.origin(h);
            match first[v.idx()] {
                None => {
                    first[v.idx()] = Some(corner[h.idx()]);
                    None
                }
                Some(uv) if uv != corner[h.idx()] => Some(v),
                Some(_) => None,
            }
        })
}

/// The planar map of a file with texture coordinates: per source vertex, the `vt` of its
/// vertex in `mapped` (`to_mapped` from [`correspondence`]). `None` when the file has no
/// texture coordinates; [`MappedError::Seam`] when a vertex has two.
pub fn planar_images(
    mapped: &LoadedMesh,
    to_mapped: &[VertexId],
) -> Result<Option<Vec<Complex64>>, MappedError> {
    if mapped.corner_uvs.is_none() {
        return Ok(None);
    }
    let Some(uv) = mapped.vertex_uvs() else {
        let vertex = uv_seam(mapped).map_or(0, |v| mapped.mesh.vertex_map().to_input(v));
        return Err(MappedError::Seam { vertex });
    };
    Ok(Some(
        to_mapped
            .iter()
            .map(|v| Complex64::new(uv[v.idx()].x, uv[v.idx()].y))
            .collect(),
    ))
}

/// The texture coordinates of a file per face corner of the source, seams allowed:
/// corner `k` of source face `f` takes the coordinate of corner `k` of the file's face
/// `f` (the faces agree, [`correspondence`]); equal coordinates at one vertex share an
/// index. `None` when the file has no texture coordinates or a face is not a triangle.
pub fn corner_images(source: &Mesh, mapped: &LoadedMesh) -> Option<SeamedUv> {
    let corner = mapped.corner_uvs.as_ref()?;
    let mesh = &mapped.mesh;
    if source.faces().any(|f| source.face_degree(f) != 3) {
        return None;
    }
    let mut index: HashMap<(VertexId, [u64; 2]), u32> = HashMap::new();
    let mut uvs = Vec::new();
    let corners = source
        .faces()
        .map(|f| {
            let mut out = [0u32; 3];
            for (k, (v, h)) in source
                .face_vertices(f)
                .zip(mesh.face_halfedges(f))
                .enumerate()
            {
                let uv = corner[h.idx()];
                // -0.0 and 0.0 are one coordinate.
                let key = (v, [(uv.x + 0.0).to_bits(), (uv.y + 0.0).to_bits()]);
                out[k] = *index.entry(key).or_insert_with(|| {
                    uvs.push([uv.x, uv.y]);
                    (uvs.len() - 1) as u32
                });
            }
            out
        })
        .collect();
    Some(SeamedUv { uvs, corners })
}

/// The distortion of a map into the plane given per face corner (with seams): every
/// face measured with its own corners' coordinates in `frame`, on a copy of the source
/// whose faces share no vertex ([`split_corners`] by corner; a face keeps its first
/// vertex, so its frame and `mu` are the source's, and the faces keep their order).
pub fn measure_seamed(mesh: &Mesh, uv: &SeamedUv, frame: Frame) -> Result<Distortion, SeamedError> {
    let corner: Vec<u32> = (0..mesh.halfedge_count() as u32).collect();
    let (split, origin) = split_corners(mesh, &corner)?;
    let mut at_corner = vec![Complex64::default(); mesh.halfedge_count()];
    for f in mesh.faces() {
        for (k, h) in mesh.face_halfedges(f).enumerate() {
            let t = uv.uvs[uv.corners[f.idx()][k] as usize];
            at_corner[h.idx()] = Complex64::new(t[0], t[1]);
        }
    }
    let map: Vec<Complex64> = origin.iter().map(|&(_, h)| at_corner[h as usize]).collect();
    Ok(measure_planar(&split, &map, frame)?)
}

/// Why a map with seams could not be measured.
#[derive(Debug, Error)]
pub enum SeamedError {
    /// The seams do not split the source into a valid mesh.
    #[error("splitting the mesh into separate faces: {0}")]
    Split(#[from] beltrami_mesh::MeshError),
    /// The measure failed (a degenerate face, a non-finite coordinate).
    #[error(transparent)]
    Measure(#[from] beltrami_fem::FemError),
}

/// The map into R^3 of a file's positions: per source vertex, the position of its vertex
/// in `mapped`.
pub fn spatial_images(mapped: &Mesh, to_mapped: &[VertexId]) -> Vec<Point3<f64>> {
    to_mapped.iter().map(|&v| mapped.position(v)).collect()
}

/// A target surface's normals at a map's image.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetNormals {
    /// Per source face, the reference normal (`ReferenceNormal::PerFace`).
    pub normals: Vec<Vector3<f64>>,
    /// Image vertices farther from the target than its mean face size
    /// `sqrt(area / faces)`.
    pub far: usize,
    /// The largest distance of an image vertex from the target.
    pub farthest: f64,
    /// The target's mean face size.
    pub face_size: f64,
}

/// Per face of `source`, the normal of `target` at its image: every image point located
/// on `target` by its exact closest point (`SurfaceIndex::locate_all`), then
/// `SurfaceIndex::face_reference_normals` (the sum of the target's interpolated vertex
/// normals at the corners' images), the rule `register` and the flow judge maps by. Also
/// how many image vertices lie off the target by more than a mean face size.
pub fn target_normals(
    target: &Mesh,
    source: &Mesh,
    image: &[Point3<f64>],
) -> Result<TargetNormals, SpatialError> {
    let index = SurfaceIndex::new(target)?;
    let located = index.locate_all(image)?;
    let face_size = (target.total_area() / target.face_count().max(1) as f64).sqrt();
    let far = located.iter().filter(|l| l.distance > face_size).count();
    let farthest = located.iter().map(|l| l.distance).fold(0.0, f64::max);
    let points: Vec<SurfacePoint> = located.into_iter().map(|l| l.point).collect();
    let normals = index.face_reference_normals(source, &points)?;
    Ok(TargetNormals {
        normals,
        far,
        farthest,
        face_size,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    fn square() -> Mesh {
        Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap()
    }

    #[test]
    fn the_same_mesh_corresponds_vertex_by_vertex() {
        let mesh = square();
        let to = correspondence(&mesh, &mesh).unwrap();
        assert!(to.iter().enumerate().all(|(v, w)| w.idx() == v));
    }

    #[test]
    fn other_connectivity_is_named() {
        let mesh = square();
        let coarse = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        assert!(matches!(
            correspondence(&mesh, &coarse),
            Err(MappedError::FaceCount {
                mapped: 8,
                source_faces: 18
            })
        ));
        let quads = Mesh::from_soup(&grid(3, 3, Cells::Quads)).unwrap();
        let tris = Mesh::from_soup(&grid(3, 3, Cells::Triangles)).unwrap();
        assert!(matches!(
            correspondence(&quads, &tris),
            Err(MappedError::FaceCount { .. })
        ));
        // Same counts, a face starting at another corner: named with both vertex lists.
        let soup = grid(3, 3, Cells::Triangles);
        let mut turned = beltrami_mesh::PolygonSoup::new(mesh.positions().to_vec());
        for i in 0..soup.face_count() {
            let mut f = soup.face(i).to_vec();
            if i == 4 {
                f.rotate_left(1);
            }
            turned.push_face(&f);
        }
        let turned = Mesh::from_soup(&turned).unwrap();
        let e = correspondence(&mesh, &turned).unwrap_err();
        assert!(matches!(e, MappedError::Face { source_face: 4, .. }), "{e}");
        assert!(e.to_string().contains("face 4 has vertices"), "{e}");
    }

    #[test]
    fn a_planar_map_reads_back_from_vt_and_from_positions() {
        use beltrami_mesh::Vector2;
        use beltrami_mesh::io::{VertexAttributes, write};
        let mesh = square();
        let f = |p: &Point3<f64>| Complex64::new(2.0 * p.x + 0.5 * p.y, -p.x + p.y);
        let map: Vec<Complex64> = mesh.positions().iter().map(f).collect();
        let dir = tempfile::tempdir().unwrap();
        let uv: Vec<Vector2<f64>> = map.iter().map(|z| Vector2::new(z.re, z.im)).collect();
        let with_vt = dir.path().join("vt.obj");
        let attributes = VertexAttributes {
            uvs: Some(&uv),
            ..Default::default()
        };
        write(&with_vt, &mesh, &attributes).unwrap();
        assert_eq!(read_planar(&with_vt, &mesh, false).unwrap(), map);
        let positions: Vec<Point3<f64>> =
            map.iter().map(|z| Point3::new(z.re, z.im, 0.0)).collect();
        let as_positions = dir.path().join("v.obj");
        let attributes = VertexAttributes {
            positions: Some(&positions),
            ..Default::default()
        };
        write(&as_positions, &mesh, &attributes).unwrap();
        assert_eq!(read_planar(&as_positions, &mesh, false).unwrap(), map);
        let coarse = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        assert!(matches!(
            read_planar(&as_positions, &coarse, false),
            Err(ReadMapError::Map(MappedError::FaceCount { .. }))
        ));
    }

    #[test]
    fn target_normals_of_the_identity_are_the_face_normals() {
        let mesh = square();
        let image = mesh.positions().to_vec();
        let found = target_normals(&mesh, &mesh, &image).unwrap();
        assert_eq!(found.far, 0);
        assert!(found.farthest < 1e-12);
        for n in &found.normals {
            assert!(n.z > 0.0 && n.x.abs() < 1e-12 && n.y.abs() < 1e-12, "{n}");
        }
    }

    /// The icosphere of `level` with `r = 1 + 0.1 cos(8x) cos(8y) cos(8z)`: bumps of
    /// wavelength 0.79, about 20 edges of level 5, even in each coordinate.
    fn bumpy_sphere(level: usize) -> Mesh {
        let mut soup = beltrami_mesh::primitives::icosphere(level);
        for p in &mut soup.positions {
            let r = 1.0 + 0.1 * (8.0 * p.x).cos() * (8.0 * p.y).cos() * (8.0 * p.z).cos();
            *p = Point3::from(p.coords * r);
        }
        Mesh::from_soup(&soup).unwrap()
    }

    /// The flip rule judged on coarse sources: the exact maps of a bumpy sphere of
    /// levels 2 to 4 (faces up to 16 times the target's edge) onto level 5 keep every
    /// face, and the mirror image `x -> -x` (onto the same surface, the bumps are even)
    /// turns every face over.
    #[test]
    fn exact_maps_of_coarse_sources_keep_every_face_and_a_mirror_turns_all() {
        use beltrami_fem::beltrami::ReferenceNormal;
        use beltrami_fem::distortion::measure_surface;
        let target = bumpy_sphere(5);
        for level in 2..5 {
            let source = bumpy_sphere(level);
            for mirrored in [false, true] {
                let image: Vec<Point3<f64>> = source
                    .positions()
                    .iter()
                    .map(|p| {
                        if mirrored {
                            Point3::new(-p.x, p.y, p.z)
                        } else {
                            *p
                        }
                    })
                    .collect();
                let found = target_normals(&target, &source, &image).unwrap();
                assert!(found.farthest < 1e-12, "level {level}: {}", found.farthest);
                let measured =
                    measure_surface(&source, &image, ReferenceNormal::PerFace(&found.normals))
                        .unwrap();
                let flipped = measured.flipped.iter().filter(|&&f| f).count();
                let expected = if mirrored { source.face_count() } else { 0 };
                assert_eq!(flipped, expected, "level {level}, mirrored {mirrored}");
            }
        }
    }
}
