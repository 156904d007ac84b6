//! What a picture shows: a mesh, the image of a map on it (texture coordinates or
//! positions in R^3) and the map's distortion per face, measured once with the fem
//! crate.

use beltrami_fem::distortion::{self, Distortion, DistortionStats};
use beltrami_fem::{Frame, ReferenceNormal, element};
use beltrami_mesh::{HalfedgeId, Mesh, Point3, PolygonSoup, Vector2};

use crate::RenderError;

/// Where a mesh's corners go in a view.
#[derive(Debug, Clone, PartialEq)]
pub enum Layout {
    /// Points in the plane, one per face corner: entry `h` for the face halfedge `h`
    /// (the corner at `origin(h)` in face `face(h)`), so texture seams are kept. Drawn
    /// flat in the uv view (x to the right, y up).
    Plane(Vec<Vector2<f64>>),
    /// Points in R^3, one per vertex ([`beltrami_mesh::VertexId`] order). Drawn as a
    /// shaded surface in the 3D view.
    Space(Vec<Point3<f64>>),
}

/// The number of face corners of `mesh` (the face halfedges, whose ids come first).
pub fn corner_count(mesh: &Mesh) -> usize {
    3 * mesh.triangle_count() + 4 * mesh.quad_count()
}

impl Layout {
    /// A planar layout from one point per corner (see [`Layout::Plane`]), checked:
    /// length and finite values (an error names the face by its input index).
    pub fn plane(mesh: &Mesh, corners: Vec<Vector2<f64>>) -> Result<Self, RenderError> {
        check_length(
            "texture coordinates per corner",
            corner_count(mesh),
            corners.len(),
        )?;
        for f in mesh.faces() {
            if mesh
                .face_halfedges(f)
                .any(|h| !corners[h.idx()].iter().all(|c| c.is_finite()))
            {
                return Err(RenderError::NonFinite {
                    what: "a texture coordinate",
                    element: "face",
                    index: mesh.face_to_input(f),
                });
            }
        }
        Ok(Layout::Plane(corners))
    }

    /// A planar layout from one point per vertex, checked like [`Layout::plane`] (an
    /// error names the vertex).
    pub fn plane_from_vertices(mesh: &Mesh, points: &[Vector2<f64>]) -> Result<Self, RenderError> {
        check_length(
            "texture coordinates per vertex",
            mesh.vertex_count(),
            points.len(),
        )?;
        if let Some(v) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(non_finite_vertex(mesh, v, "the texture coordinate"));
        }
        let mut corners = vec![Vector2::zeros(); corner_count(mesh)];
        for f in mesh.faces() {
            for h in mesh.face_halfedges(f) {
                corners[h.idx()] = points[mesh.origin(h).idx()];
            }
        }
        Ok(Layout::Plane(corners))
    }

    /// A layout in R^3 from one point per vertex, checked: length and finite values
    /// (an error names the vertex by its input index).
    pub fn space(mesh: &Mesh, points: Vec<Point3<f64>>) -> Result<Self, RenderError> {
        check_length("positions", mesh.vertex_count(), points.len())?;
        if let Some(v) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(non_finite_vertex(mesh, v, "the position"));
        }
        Ok(Layout::Space(points))
    }

    /// One point per vertex when every vertex has a single one (a planar layout
    /// without seams), else `None`.
    fn plane_per_vertex(mesh: &Mesh, corners: &[Vector2<f64>]) -> Option<Vec<Vector2<f64>>> {
        let mut out: Vec<Option<Vector2<f64>>> = vec![None; mesh.vertex_count()];
        for f in mesh.faces() {
            for h in mesh.face_halfedges(f) {
                let slot = &mut out[mesh.origin(h).idx()];
                match slot {
                    None => *slot = Some(corners[h.idx()]),
                    Some(p) if *p != corners[h.idx()] => return None,
                    Some(_) => {}
                }
            }
        }
        out.into_iter().collect()
    }
}

fn check_length(what: &'static str, expected: usize, got: usize) -> Result<(), RenderError> {
    if expected == got {
        Ok(())
    } else {
        Err(RenderError::Length {
            what,
            expected,
            got,
        })
    }
}

fn non_finite_vertex(mesh: &Mesh, v: usize, what: &'static str) -> RenderError {
    RenderError::NonFinite {
        what,
        element: "vertex",
        index: mesh
            .vertex_map()
            .to_input(beltrami_mesh::VertexId::from_usize(v)),
    }
}

/// The distortion of a map, per face.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceDistortion {
    /// `|mu|` per face ([`beltrami_mesh::FaceId`] order).
    pub modulus: Vec<f64>,
    /// Per face: the map reverses its orientation there (a fold).
    pub flipped: Vec<bool>,
    /// Source face areas (the weights of an area-weighted histogram).
    pub areas: Vec<f64>,
    /// Statistics of `|mu|` (mean, max, flips, ...).
    pub stats: DistortionStats,
}

impl FaceDistortion {
    fn from_measured(mesh: &Mesh, d: Distortion) -> Self {
        Self {
            modulus: d.field.mu.iter().map(|m| m.norm()).collect(),
            flipped: d.flipped,
            areas: mesh.faces().map(|f| mesh.face_area(f)).collect(),
            stats: d.stats,
        }
    }
}

/// A mesh, optionally the image of a map on it, and the map's distortion.
#[derive(Debug, Clone)]
pub struct Scene<'a> {
    mesh: &'a Mesh,
    planar_source: bool,
    image: Option<Layout>,
    distortion: Option<FaceDistortion>,
    reference: Option<&'static str>,
}

impl<'a> Scene<'a> {
    /// A scene of `mesh` and, when given, the image of the map `vertex -> image`:
    /// texture coordinates ([`Layout::Plane`], a map into the plane) or positions
    /// ([`Layout::Space`], a map into R^3). The map is measured here (per-face `|mu|`
    /// and flips, in the global frame for a mesh in the plane z = 0, in the face frames
    /// otherwise), which costs about as much as loading the mesh. A map into R^3 is
    /// judged against the reference normal [`ReferenceNormal::for_image`] chooses from
    /// its image: `+z` in the plane z = 0, the radial direction on a sphere about the
    /// origin (the `sphere` solver's output), else the source normals, which suit only
    /// images close to the source: give a target's normals with
    /// [`Scene::with_reference`] otherwise.
    ///
    /// Fails for a mesh without faces and when the measure fails (a degenerate face).
    pub fn new(mesh: &'a Mesh, image: Option<Layout>) -> Result<Self, RenderError> {
        Self::with_reference(mesh, image, None)
    }

    /// [`Scene::new`] with the reference normal a map into R^3 is judged against
    /// (`None`: [`ReferenceNormal::for_image`]; a map into the plane is always judged
    /// in the plane, and `reference` is not used).
    ///
    /// Fails like [`Scene::new`], and for a [`ReferenceNormal::PerFace`] without one
    /// finite normal per face.
    pub fn with_reference(
        mesh: &'a Mesh,
        image: Option<Layout>,
        reference: Option<ReferenceNormal<'_>>,
    ) -> Result<Self, RenderError> {
        if mesh.face_count() == 0 {
            return Err(RenderError::EmptyMesh);
        }
        let planar_source = element::is_planar(mesh);
        let (distortion, reference) = match &image {
            None => (None, None),
            Some(Layout::Space(points)) => {
                let reference = reference.unwrap_or_else(|| ReferenceNormal::for_image(points));
                let measured = distortion::measure_surface(mesh, points, reference)?;
                (
                    Some(FaceDistortion::from_measured(mesh, measured)),
                    Some(reference.name()),
                )
            }
            Some(Layout::Plane(corners)) => {
                let frame = if planar_source {
                    Frame::Global
                } else {
                    Frame::Face
                };
                (
                    Some(measure_plane(mesh, corners, frame)?),
                    Some(ReferenceNormal::Plane.name()),
                )
            }
        };
        Ok(Self {
            mesh,
            planar_source,
            image,
            distortion,
            reference,
        })
    }

    /// The name of the reference normal the map's flips were judged against
    /// ([`ReferenceNormal::name`]: `plane` for a map into the plane), or `None` without
    /// a map.
    pub fn reference(&self) -> Option<&'static str> {
        self.reference
    }

    /// The mesh.
    pub fn mesh(&self) -> &'a Mesh {
        self.mesh
    }

    /// True when the mesh lies in the plane z = 0 (its source view is then flat).
    pub fn planar_source(&self) -> bool {
        self.planar_source
    }

    /// The image of the map, if any.
    pub fn image(&self) -> Option<&Layout> {
        self.image.as_ref()
    }

    /// The measured distortion of the map, if any.
    pub fn distortion(&self) -> Option<&FaceDistortion> {
        self.distortion.as_ref()
    }
}

/// Measures a map into the plane given per corner: through the vertices when there are
/// no seams, else on a copy of the mesh whose faces share no vertex (per-face values do
/// not depend on the neighbours).
fn measure_plane(
    mesh: &Mesh,
    corners: &[Vector2<f64>],
    frame: Frame,
) -> Result<FaceDistortion, RenderError> {
    let to_complex = |p: &Vector2<f64>| num_complex::Complex64::new(p.x, p.y);
    if let Some(points) = Layout::plane_per_vertex(mesh, corners) {
        let map: Vec<_> = points.iter().map(to_complex).collect();
        return Ok(FaceDistortion::from_measured(
            mesh,
            distortion::measure_planar(mesh, &map, frame)?,
        ));
    }
    let mut soup = PolygonSoup::new(Vec::with_capacity(corners.len()));
    let mut corner_of: Vec<HalfedgeId> = Vec::with_capacity(corners.len());
    let mut positions = Vec::with_capacity(corners.len());
    for f in mesh.faces() {
        let first = corner_of.len() as u32;
        let n = mesh.face_degree(f) as u32;
        for h in mesh.face_halfedges(f) {
            positions.push(mesh.position(mesh.origin(h)));
            corner_of.push(h);
        }
        let face: Vec<u32> = (first..first + n).collect();
        soup.push_face(&face);
    }
    soup.positions = positions;
    let split = Mesh::from_soup(&soup).map_err(|e| {
        RenderError::Missing(format!("cannot measure a map with texture seams: {e}"))
    })?;
    let map: Vec<_> = split
        .vertices()
        .map(|v| to_complex(&corners[corner_of[split.vertex_map().to_input(v)].idx()]))
        .collect();
    let measured = distortion::measure_planar(&split, &map, frame)?;
    // Faces of the copy follow the mesh's faces through their input order.
    let mut modulus = vec![0.0; mesh.face_count()];
    let mut flipped = vec![false; mesh.face_count()];
    for g in split.faces() {
        let f = split.face_to_input(g);
        modulus[f] = measured.field.mu[g.idx()].norm();
        flipped[f] = measured.flipped[g.idx()];
    }
    Ok(FaceDistortion {
        modulus,
        flipped,
        areas: mesh.faces().map(|f| mesh.face_area(f)).collect(),
        stats: measured.stats,
    })
}
