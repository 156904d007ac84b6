//! What `render` and `histogram` share: loading a mesh and, when given, the map on it
//! (MAPPED's texture coordinates or positions, else MESH's own texture coordinates).

use std::path::Path;

use beltrami_mesh::Vector2;
use beltrami_mesh::io::LoadedMesh;
use beltrami_render::Layout;

use super::distortion::{correspondence, read_mapped};
use super::load::load_mesh;

/// MESH and the image of the map on it, if there is one: MAPPED's texture coordinates
/// (per corner, seams allowed) or, without them, MAPPED's positions; without MAPPED,
/// MESH's own texture coordinates.
pub fn load_map(
    mesh_path: &Path,
    map_path: Option<&Path>,
    repair: bool,
    quiet: bool,
) -> anyhow::Result<(LoadedMesh, Option<Layout>)> {
    let loaded = load_mesh(mesh_path, repair, quiet)?.mesh;
    let mesh = &loaded.mesh;
    let image = match map_path {
        Some(path) => {
            let mapped = read_mapped(path, repair)?;
            let to_mapped = correspondence(mesh, &mapped.mesh, mesh_path, path)?;
            match &mapped.corner_uvs {
                Some(uv) => {
                    // Same faces, same corner order (checked by `correspondence`).
                    let mut corners = vec![Vector2::zeros(); beltrami_render::corner_count(mesh)];
                    for f in mesh.faces() {
                        let theirs = mapped.mesh.face_halfedges(f);
                        for (h, g) in mesh.face_halfedges(f).zip(theirs) {
                            corners[h.idx()] = uv[g.idx()];
                        }
                    }
                    Some(Layout::plane(mesh, corners)?)
                }
                None => {
                    let points = beltrami::mapped::spatial_images(&mapped.mesh, &to_mapped);
                    Some(Layout::space(mesh, points)?)
                }
            }
        }
        None => match &loaded.corner_uvs {
            Some(uv) => Some(Layout::plane(mesh, uv.clone())?),
            None => None,
        },
    };
    Ok((loaded, image))
}
