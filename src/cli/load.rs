//! Loading a mesh from the command line: reading, validating, reporting repairs.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::anyhow;
use beltrami_mesh::io::{self, LoadedMesh, ReadError};
use beltrami_mesh::{BuildOptions, MeshError, Repair};

/// What `--components` does with a mesh of several connected components (a scan in
/// pieces).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ComponentsArg {
    /// Every component on its own, the results joined in the order of each
    /// component's first face.
    Each,
    /// Only the component with the most faces; OUT holds that component alone.
    Largest,
}

/// A loaded mesh and how long reading and building took.
pub struct Loaded {
    pub mesh: LoadedMesh,
    /// Time to read and parse the file.
    pub parse: Duration,
    /// Time to validate and build the halfedge mesh.
    pub build: Duration,
}

/// Reads and validates `path`; with `repair`, drops degenerate and duplicate faces and
/// merges coincident vertices, and says so on stderr unless `quiet`.
pub fn load_mesh(path: &Path, repair: bool, quiet: bool) -> anyhow::Result<Loaded> {
    let options = BuildOptions {
        repair: if repair { Repair::ALL } else { Repair::NONE },
        ..BuildOptions::default()
    };
    let start = Instant::now();
    let raw = io::read_raw(path)?;
    let parse = start.elapsed();
    let start = Instant::now();
    let one_based = raw.soup.looks_one_based();
    let mesh = io::build_raw(path, raw, &options).map_err(|e| {
        if one_based
            && matches!(&e, ReadError::Mesh { error: MeshError::VertexIndexOutOfRange { .. }, .. })
        {
            return anyhow!(
                "{e}\nhint: the faces look 1-based (no face uses vertex 0, and the largest index is the vertex count), but this format numbers vertices from 0"
            );
        }
        let repairable = matches!(
            &e,
            ReadError::Mesh {
                error: MeshError::DegenerateFace { .. }
                    | MeshError::RepeatedVertex { .. }
                    | MeshError::DuplicateFace { .. },
                ..
            }
        );
        if repairable && !repair {
            anyhow!("{e}\nhint: `--repair` drops degenerate and duplicate faces (and says which)")
        } else {
            anyhow!(e)
        }
    })?;
    let build = start.elapsed();
    if !quiet {
        let r = &mesh.report;
        let name = path.display();
        if let Some(weld) = mesh.weld {
            eprintln!(
                "note: {name}: STL: {} triangle corners welded into {} vertices by exact position (vertex indices follow first appearance)",
                weld.corners, weld.vertices
            );
        }
        if r.faces_reoriented > 0 {
            eprintln!(
                "note: {name}: {} faces were re-oriented to match their neighbours",
                r.faces_reoriented
            );
        }
        if !r.unreferenced_vertices.is_empty() {
            eprintln!(
                "note: {name}: {} unreferenced vertices left out (indices still follow the file)",
                r.unreferenced_vertices.len()
            );
        }
        if !r.dropped_degenerate_faces.is_empty() {
            eprintln!(
                "repair: {name}: dropped {} degenerate faces {:?}",
                r.dropped_degenerate_faces.len(),
                preview(&r.dropped_degenerate_faces)
            );
        }
        if !r.dropped_duplicate_faces.is_empty() {
            eprintln!(
                "repair: {name}: dropped {} duplicate faces {:?}",
                r.dropped_duplicate_faces.len(),
                preview(&r.dropped_duplicate_faces)
            );
        }
        if !r.merged_vertices.is_empty() {
            eprintln!(
                "repair: {name}: merged {} coincident vertices",
                r.merged_vertices.len()
            );
        }
    }
    Ok(Loaded { mesh, parse, build })
}

/// The first few indices of a list, for messages.
fn preview(list: &[usize]) -> &[usize] {
    &list[..list.len().min(10)]
}
