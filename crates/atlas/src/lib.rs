#![warn(missing_docs)]
//! # beltrami-atlas
//!
//! Texture atlases of any triangle mesh (closed or open, any genus, several pieces):
//! per-corner UVs in `[0, 1]^2`, charts that are counter-clockwise, one-to-one and packed
//! without overlap.
//!
//! 1. **Charts**: each connected component starts as one chart.
//! 2. **Cones** ([`cones`]): a conformal flattening of a chart distorts area by `e^{2u}`
//!    with `u` the solution of the discrete Yamabe equation; cone singularities are
//!    added greedily where `|u|` is largest (Ben-Chen, Gotsman and Bunin 2008) until the
//!    predicted stretch meets the goal.
//! 3. **Cut** ([`cone_cut`]): the chart is cut open along its cut graph (handles,
//!    boundary loops) and shortest paths to every cone, leaving a disk.
//! 4. **Flattening** ([`boundary_first`]): the disk is laid flat by boundary first
//!    flattening (Sawhney and Crane 2017) with the cones' scale factors, so that the
//!    cut's two sides have the same length in the plane (the map is seamless up to a
//!    rotation at every seam).
//! 5. **Checks and splits** ([`overlap`], [`split`]): a chart whose flat image has a
//!    flipped face, crosses itself, or is stretched beyond the limit is split in two and
//!    each half goes back to step 2.
//! 6. **Packing** ([`pack`]): charts turned to their least bounding rectangles and
//!    packed by a skyline into the unit square.
//!
//! The quality is measured by Sander et al.'s texture stretch ([`stretch`](mod@stretch)).
//!
//! ```
//! use beltrami_atlas::{AtlasOptions, atlas};
//! use beltrami_mesh::{Mesh, primitives::icosphere};
//!
//! let sphere = Mesh::from_soup(&icosphere(3)).unwrap();
//! let result = atlas(&sphere, &AtlasOptions::default()).unwrap();
//! assert_eq!(result.stretch.flipped_faces, 0);
//! assert!(result.stretch.l2 <= 1.1);
//! ```

pub mod boundary_first;
pub mod chart;
pub mod cone_cut;
pub mod cones;
mod error;
mod held;
pub mod options;
pub mod overlap;
pub mod pack;
mod seamed;
pub mod shortest_paths;
pub mod split;
pub mod stretch;
pub mod unit_disk;

use beltrami_core::components::parts;
use beltrami_mesh::{EdgeId, FaceId, Mesh, VertexId, cut_along};

pub use chart::{ChartFailure, FlatChart, flatten_chart};
pub use error::AtlasError;
pub use options::{AtlasOptions, ChartCount, ConeCount};
pub use seamed::SeamedUv;
pub use stretch::{Stretch, stretch};

/// How often a piece of a chart may be split in two before the atlas gives up.
const MAX_SPLITS: usize = 24;

/// A texture atlas of a mesh.
#[derive(Debug, Clone)]
pub struct Atlas {
    /// The per-corner UVs, in `[0, 1]^2`.
    pub uv: SeamedUv,
    /// The chart of every face.
    pub face_chart: Vec<u32>,
    /// Every chart.
    pub charts: Vec<ChartSummary>,
    /// The stretch of the whole atlas.
    pub stretch: Stretch,
    /// How often a chart was split, by reason.
    pub splits: Splits,
}

/// How often charts were split in two, by reason.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Splits {
    /// The flat chart's boundary crossed itself.
    pub overlap: usize,
    /// The flat chart had faces with a non-positive area, or could not be built.
    pub flipped: usize,
    /// The flat chart's L2 stretch was above the limit.
    pub stretch: usize,
    /// The chart was split to reach the asked number of charts
    /// ([`ChartCount::AtLeast`]).
    pub charts: usize,
}

/// One chart of an [`Atlas`].
#[derive(Debug, Clone, PartialEq)]
pub struct ChartSummary {
    /// Its number of faces.
    pub faces: usize,
    /// Its cones, as vertices of the mesh.
    pub cones: Vec<VertexId>,
}

/// A piece of the mesh waiting to be laid flat.
struct Piece {
    mesh: Mesh,
    /// The face of the whole mesh each face of `mesh` is.
    faces: Vec<FaceId>,
    /// The vertex of the whole mesh each vertex of `mesh` is.
    vertices: Vec<VertexId>,
    splits: usize,
}

/// A chart laid flat: the chart, its piece of the mesh and its own L2 stretch.
type Laid = (FlatChart, Piece, f64);

/// The texture atlas of `mesh` (see the crate docs).
///
/// # Errors
/// [`AtlasError::InvalidOption`] for options out of range, or for more charts asked
/// than the mesh's faces can make (known after the work), [`AtlasError::NotTriangles`]
/// for a mesh with quads, [`AtlasError::Unflattenable`] if a piece cannot be laid flat
/// after `MAX_SPLITS` splits.
pub fn atlas(mesh: &Mesh, options: &AtlasOptions) -> Result<Atlas, AtlasError> {
    options.validate()?;
    if let Some(face) = mesh.faces().find(|&f| mesh.face_degree(f) != 3) {
        return Err(AtlasError::NotTriangles {
            face: mesh.face_to_input(face),
            corners: mesh.face_degree(face),
        });
    }
    if let ChartCount::AtLeast(n) = options.charts
        && n > mesh.face_count()
    {
        return Err(AtlasError::InvalidOption {
            option: "charts",
            message: format!(
                "{n} charts is more than the mesh's {} faces",
                mesh.face_count()
            ),
        });
    }
    let work: Vec<Piece> = parts(mesh)?
        .into_iter()
        .map(|p| Piece {
            mesh: p.mesh,
            faces: p.faces,
            vertices: p.vertices,
            splits: 0,
        })
        .collect();
    let mut flat: Vec<Laid> = Vec::new();
    let mut splits = Splits::default();
    lay_flat(mesh, work, options, &mut flat, &mut splits)?;
    if let ChartCount::AtLeast(n) = options.charts {
        while flat.len() < n {
            let share = |(chart, _, l2): &Laid| chart.disk.total_area() * l2 * l2;
            let Some(k) = (0..flat.len())
                .filter(|&k| flat[k].1.mesh.face_count() > 2)
                .max_by(|&a, &b| share(&flat[a]).total_cmp(&share(&flat[b])))
            else {
                return Err(AtlasError::InvalidOption {
                    option: "charts",
                    message: format!(
                        "{n} charts is more than this mesh makes: its {} charts have at most 2 faces each",
                        flat.len()
                    ),
                });
            };
            let (_, piece, _) = flat.swap_remove(k);
            splits.charts += 1;
            lay_flat(
                mesh,
                split_piece(mesh, piece)?,
                options,
                &mut flat,
                &mut splits,
            )?;
        }
    }
    Ok(assemble(mesh, flat, options.padding, splits))
}

/// Lays every piece of `work` flat into `flat`, splitting the pieces that overlap,
/// fold or stretch beyond the limit (counted in `splits`).
fn lay_flat(
    mesh: &Mesh,
    mut work: Vec<Piece>,
    options: &AtlasOptions,
    flat: &mut Vec<Laid>,
    splits: &mut Splits,
) -> Result<(), AtlasError> {
    let goal = options.cone_goal();
    while let Some(piece) = work.pop() {
        let laid = flatten_chart(&piece.mesh, goal)?;
        let accepted = match laid {
            Ok(chart) => {
                let l2 = stretch(&chart.disk, &disk_uv(&chart)).l2;
                if l2 <= options.max_stretch || piece.mesh.face_count() <= 2 {
                    flat.push((chart, piece, l2));
                    continue;
                }
                splits.stretch += 1;
                piece
            }
            Err(ChartFailure::Overlap) => {
                splits.overlap += 1;
                piece
            }
            Err(_) => {
                splits.flipped += 1;
                piece
            }
        };
        work.extend(split_piece(mesh, accepted)?);
    }
    Ok(())
}

/// The chart's flat positions as seamed UVs of its disk.
fn disk_uv(chart: &FlatChart) -> SeamedUv {
    SeamedUv {
        uvs: chart.uv.clone(),
        corners: chart
            .disk
            .faces()
            .map(|f| {
                let (v, _) = chart.disk.face_vertex_array(f);
                [v[0].0, v[1].0, v[2].0]
            })
            .collect(),
    }
}

/// The two halves of a piece of `mesh` (more pieces if a half falls apart).
fn split_piece(mesh: &Mesh, piece: Piece) -> Result<Vec<Piece>, AtlasError> {
    if piece.splits >= MAX_SPLITS {
        return Err(AtlasError::Unflattenable {
            face: mesh.face_to_input(piece.faces[0]),
            faces: piece.faces.len(),
            splits: piece.splits,
        });
    }
    let half = split::split_in_two(&piece.mesh)?;
    let border: Vec<EdgeId> = piece
        .mesh
        .edges()
        .filter(|&e| match piece.mesh.edge_faces(e) {
            [Some(f), Some(g)] => half[f.idx()] != half[g.idx()],
            _ => false,
        })
        .collect();
    let (cut, to_piece) = cut_along(&piece.mesh, &border)?;
    Ok(parts(&cut)?
        .into_iter()
        .map(|p| Piece {
            faces: p.faces.iter().map(|f| piece.faces[f.idx()]).collect(),
            vertices: p
                .vertices
                .iter()
                .map(|v| piece.vertices[to_piece[v.idx()].idx()])
                .collect(),
            mesh: p.mesh,
            splits: piece.splits + 1,
        })
        .collect())
}

/// The atlas from the flat charts: UVs packed, corners indexed, stretch measured.
fn assemble(mesh: &Mesh, flat: Vec<Laid>, padding: f64, splits: Splits) -> Atlas {
    // Every chart at the surface's scale on average, so that the texture density is the
    // same on all of them.
    let mut positions: Vec<Vec<[f64; 2]>> = flat
        .iter()
        .map(|(c, _, _)| {
            let uv = disk_uv(c);
            let flat_area: f64 = c.disk.faces().map(|f| 0.5 * uv.signed_double_area(f)).sum();
            let scale = (c.disk.total_area() / flat_area).sqrt();
            c.uv.iter().map(|p| [p[0] * scale, p[1] * scale]).collect()
        })
        .collect();
    pack::pack(&mut positions, padding);
    let mut uvs = Vec::new();
    let mut corners = vec![[0u32; 3]; mesh.face_count()];
    let mut face_chart = vec![0u32; mesh.face_count()];
    let mut charts = Vec::with_capacity(flat.len());
    for (k, ((chart, piece, _), placed)) in flat.iter().zip(positions).enumerate() {
        let first = uvs.len() as u32;
        uvs.extend(placed);
        for f in chart.disk.faces() {
            let whole = piece.faces[f.idx()];
            let (v, _) = chart.disk.face_vertex_array(f);
            corners[whole.idx()] = [first + v[0].0, first + v[1].0, first + v[2].0];
            face_chart[whole.idx()] = k as u32;
        }
        charts.push(ChartSummary {
            faces: piece.faces.len(),
            cones: chart
                .cones
                .iter()
                .map(|c| piece.vertices[c.idx()])
                .collect(),
        });
    }
    let uv = SeamedUv { uvs, corners };
    let stretch = stretch(mesh, &uv);
    Atlas {
        uv,
        face_chart,
        charts,
        stretch,
        splits,
    }
}
