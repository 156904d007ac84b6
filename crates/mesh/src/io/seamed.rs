//! Writing a mesh with texture coordinates per face corner (UVs with seams, as a texture
//! atlas has them).
//!
//! OBJ keeps the mesh's vertices as they are (in input order, [`super::obj::write`]'s
//! numbering) and gives each face corner its own texture index (`f v/t`). PLY and glTF
//! hold one texture coordinate per vertex, so there a vertex is written once per distinct
//! coordinate among its corners (split along the seams). STL and OFF hold none.

use std::io::Write as _;
use std::path::Path;

use nalgebra::Vector2;

use super::obj::{push_decimal, vertex_line, write_lines};
use super::slots::OutputSlots;
use super::{Format, VertexAttributes, WriteError};
use crate::{FaceId, Mesh, split_corners};

/// Texture coordinates per face corner.
#[derive(Debug, Clone, Copy)]
pub struct CornerUvs<'a> {
    /// The coordinates.
    pub uvs: &'a [Vector2<f64>],
    /// For each face halfedge (by [`crate::HalfedgeId`]), the index in `uvs` of the
    /// coordinate of the corner at its origin; other halfedges' entries are not read.
    pub corners: &'a [u32],
}

impl CornerUvs<'_> {
    /// Checks that every face corner names a finite coordinate.
    fn check(&self, mesh: &Mesh) -> Result<(), WriteError> {
        for f in mesh.faces() {
            for h in mesh.face_halfedges(f) {
                let t = self.corners.get(h.idx()).map(|&t| t as usize);
                match t.and_then(|t| self.uvs.get(t)) {
                    Some(uv) if uv.iter().all(|x| x.is_finite()) => {}
                    _ => {
                        return Err(WriteError::AttributeLength {
                            what: "corner texture coordinates",
                            expected: mesh.halfedge_count(),
                            got: self.corners.len(),
                        });
                    }
                }
            }
        }
        Ok(())
    }
}

/// Writes `mesh` with `corner_uvs`, choosing the format by extension (see the module
/// docs); OBJ keeps `obj_groups` as [`VertexAttributes::obj_groups`] does.
pub fn write_seamed(
    path: &Path,
    mesh: &Mesh,
    corner_uvs: &CornerUvs<'_>,
    obj_groups: &[(u32, String)],
) -> Result<(), WriteError> {
    corner_uvs.check(mesh)?;
    match Format::from_path(path) {
        Some(Format::Obj) => write_obj(path, mesh, corner_uvs, obj_groups),
        Some(format @ (Format::Stl | Format::Off)) => Err(WriteError::Unsupported {
            path: path.to_path_buf(),
            format,
            what: "texture coordinates with seams",
        }),
        Some(_) => {
            let (split, uvs) = split_at_seams(mesh, corner_uvs)?;
            let attributes = VertexAttributes {
                uvs: Some(&uvs),
                ..VertexAttributes::default()
            };
            super::write(path, &split, &attributes)
        }
        None => Err(WriteError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// The OBJ file: `v` lines as [`super::obj::write`] writes them, one `vt` per
/// coordinate, `f v/t` lines.
fn write_obj(
    path: &Path,
    mesh: &Mesh,
    corner_uvs: &CornerUvs<'_>,
    obj_groups: &[(u32, String)],
) -> Result<(), WriteError> {
    let slots = OutputSlots::new(mesh);
    let position = slots.positions(mesh, &VertexAttributes::default());
    let groups = super::obj::groups_before_faces(mesh, obj_groups);
    super::write_atomically(path, |w| {
        writeln!(
            w,
            "# beltrami: {} vertices, {} texture coordinates, {} faces",
            slots.len(),
            corner_uvs.uvs.len(),
            mesh.face_count()
        )?;
        write_lines(w, position.len(), |i, line| vertex_line(&position[i], line))?;
        write_lines(w, corner_uvs.uvs.len(), |i, line| {
            let uv = corner_uvs.uvs[i];
            writeln!(line, "vt {} {}", uv.x, uv.y)
        })?;
        write_lines(w, mesh.face_count(), |i, line| {
            if let Some(text) = &groups[i] {
                line.extend_from_slice(text.as_bytes());
            }
            line.push(b'f');
            for h in mesh.face_halfedges(FaceId::from_usize(i)) {
                line.push(b' ');
                push_decimal(line, slots.slot(mesh.origin(h)) + 1);
                line.push(b'/');
                push_decimal(line, corner_uvs.corners[h.idx()] as usize + 1);
            }
            line.push(b'\n');
            Ok(())
        })
    })
}

/// `mesh` with every vertex split once per distinct coordinate among its corners, and
/// the coordinate of every new vertex.
fn split_at_seams(
    mesh: &Mesh,
    corner_uvs: &CornerUvs<'_>,
) -> Result<(Mesh, Vec<Vector2<f64>>), WriteError> {
    let (split, origin) =
        split_corners(mesh, corner_uvs.corners).map_err(|error| WriteError::Seams {
            message: error.to_string(),
        })?;
    let uvs = origin
        .iter()
        .map(|&(_, t)| corner_uvs.uvs[t as usize])
        .collect();
    Ok((split, uvs))
}
