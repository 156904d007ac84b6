//! Meshes in several connected pieces (a scan in parts): every component remeshed on its
//! own ([`remesh`] takes one connected surface), and the results joined.
//!
//! The components are those of [`beltrami_core::components::parts`], in the order of
//! their first face; the joined mesh holds component `k`'s new vertices and faces after
//! those of components `0..k`, and each new vertex's point on the input is read on the
//! whole input (the part's face is the whole mesh's face of the same corners, in the
//! same order). An edge length applies to every component as given; a vertex count `N`
//! is shared out by area, `N_k = round(N A_k / A)` (at least 3), so that the joined mesh
//! has about `N` vertices and one edge length throughout.

use beltrami_core::components::{Part, largest, parts};
use beltrami_core::{Context, Remeshed, Solver};
use beltrami_mesh::{Mesh, PolygonSoup, SurfacePoint};

use crate::{RemeshError, RemeshOptions, Remeshing, Resolution, Summary, remesh};

/// One component's remeshing within [`remesh_each`].
#[derive(Debug)]
pub struct ComponentRemeshing {
    /// The component's faces in the input.
    pub input_faces: usize,
    /// The component's area.
    pub area: f64,
    /// Its remeshing, on the component alone (vertices and faces numbered within it).
    pub remeshing: Remeshing,
}

/// [`remesh_each`]'s result: the joined mesh and what each component's remeshing did.
#[derive(Debug)]
pub struct Joined {
    /// The new mesh of every component, joined in component order, each vertex with its
    /// point on the whole input.
    pub remeshed: Remeshed,
    /// Per component, in order.
    pub components: Vec<ComponentRemeshing>,
}

impl Joined {
    /// The joined remeshing's [`Summary`] (its fields say how components are merged).
    pub fn summary(&self) -> Summary {
        let first = self.components.first().map(|c| &c.remeshing);
        let common = |name: fn(&Remeshing) -> &'static str| -> &'static str {
            let mut names = self.components.iter().map(|c| name(&c.remeshing));
            let head = names.next().unwrap_or("none");
            if names.all(|n| n == head) {
                head
            } else {
                "per component"
            }
        };
        let area: f64 = self.components.iter().map(|c| c.area).sum();
        let edge_length = if area > 0.0 {
            self.components
                .iter()
                .map(|c| c.remeshing.edge_length * c.area)
                .sum::<f64>()
                / area
        } else {
            first.map_or(f64::NAN, |r| r.edge_length)
        };
        let mut timings: Vec<(&'static str, f64)> = Vec::new();
        for c in &self.components {
            for &(stage, s) in &c.remeshing.timings {
                match timings.iter_mut().find(|(name, _)| *name == stage) {
                    Some(entry) => entry.1 += s,
                    None => timings.push((stage, s)),
                }
            }
        }
        Summary {
            parameterizer: common(|r| r.parameterizer),
            opening: common(|r| r.opening.name()),
            edge_length,
            size_passes: self
                .components
                .iter()
                .map(|c| c.remeshing.size_passes)
                .max()
                .unwrap_or(0),
            timings,
            notes: self
                .components
                .iter()
                .enumerate()
                .flat_map(|(k, c)| {
                    c.remeshing
                        .notes
                        .iter()
                        .map(move |n| format!("component {k}: {n}"))
                })
                .collect(),
        }
    }
}

/// Remeshes every connected component of `mesh` on its own with the parameterizers
/// `choose` picks for it, and joins the results (module docs). A mesh of one component
/// gives one entry.
///
/// # Errors
/// [`RemeshError::InComponent`] naming the component (its index and first input face)
/// with the error of its remeshing; [`RemeshError::InvalidOption`] for bad options,
/// before any work.
pub fn remesh_each<'r>(
    mesh: &Mesh,
    choose: impl Fn(&Mesh) -> Result<Vec<&'r dyn Solver>, RemeshError>,
    options: &RemeshOptions,
    context: &mut Context<'_>,
) -> Result<Joined, RemeshError> {
    options.validate()?;
    let total = mesh.total_area();
    options.check_size(total)?;
    let pieces = parts(mesh).map_err(|error| RemeshError::Build {
        what: "component",
        error,
    })?;
    let in_component = |k: usize, part: &Part, error: RemeshError| RemeshError::InComponent {
        component: k,
        first_face: mesh.face_to_input(part.faces[0]),
        error: Box::new(error),
    };
    // Every component's parameterizers are chosen before any is remeshed.
    let chosen = pieces
        .iter()
        .enumerate()
        .map(|(k, part)| choose(&part.mesh).map_err(|error| in_component(k, part, error)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut components = Vec::with_capacity(pieces.len());
    for (k, (part, solvers)) in pieces.iter().zip(&chosen).enumerate() {
        let mut own = options.clone();
        if let Resolution::Vertices(n) = options.resolution {
            let share = n as f64 * part.mesh.total_area() / total;
            own.resolution = Resolution::Vertices((share.round() as usize).max(3));
        }
        let remeshing = remesh(&part.mesh, solvers, &own, context)
            .map_err(|error| in_component(k, part, error))?;
        components.push(ComponentRemeshing {
            input_faces: part.mesh.face_count(),
            area: part.mesh.total_area(),
            remeshing,
        });
    }
    let remeshed = join(&pieces, &components)?;
    Ok(Joined {
        remeshed,
        components,
    })
}

/// [`remesh_largest`]'s result: the largest component and its remeshing.
#[derive(Debug)]
pub struct Largest {
    /// The component with the most faces (the first of equals), as a mesh of its own.
    pub part: Part,
    /// Its index among the components, in the order of [`parts`].
    pub index: usize,
    /// How many components the mesh has.
    pub of: usize,
    /// Its remeshing, on the component alone.
    pub remeshing: Remeshing,
}

impl Largest {
    /// The note that says what was remeshed: `the largest of C components remeshed (F of
    /// T faces)`.
    pub fn note(&self, whole: &Mesh) -> String {
        format!(
            "the largest of {} components remeshed ({} of {} faces); the result holds it alone",
            self.of,
            self.part.mesh.face_count(),
            whole.face_count()
        )
    }
}

/// Remeshes only the connected component of `mesh` with the most faces, with the
/// parameterizers `choose` picks for it (a mesh of one component is remeshed whole).
///
/// # Errors
/// The errors of [`remesh`] on the component.
pub fn remesh_largest<'r>(
    mesh: &Mesh,
    choose: impl Fn(&Mesh) -> Result<Vec<&'r dyn Solver>, RemeshError>,
    options: &RemeshOptions,
    context: &mut Context<'_>,
) -> Result<Largest, RemeshError> {
    options.validate()?;
    let mut pieces = parts(mesh).map_err(|error| RemeshError::Build {
        what: "component",
        error,
    })?;
    let of = pieces.len();
    let k = largest(&pieces).ok_or(RemeshError::Components { components: 0 })?;
    let part = pieces.swap_remove(k);
    let solvers = choose(&part.mesh)?;
    let remeshing = remesh(&part.mesh, &solvers, options, context)?;
    Ok(Largest {
        part,
        index: k,
        of,
        remeshing,
    })
}

/// The components' new meshes in one, their points carried onto the whole input.
fn join(pieces: &[Part], components: &[ComponentRemeshing]) -> Result<Remeshed, RemeshError> {
    let mut positions = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut on_source = Vec::new();
    for (part, component) in pieces.iter().zip(components) {
        let new = &component.remeshing.remeshed;
        let offset = positions.len() as u32;
        positions.extend(new.mesh.positions().iter().copied());
        faces.extend(
            new.mesh
                .faces()
                .map(|f| new.mesh.face_vertices(f).map(|v| v.0 + offset).collect()),
        );
        on_source.extend(on_whole(part, &new.on_source));
    }
    let mut soup = PolygonSoup::new(positions);
    for face in &faces {
        soup.push_face(face);
    }
    let mesh = Mesh::from_soup(&soup).map_err(|error| RemeshError::Build {
        what: "joined result",
        error,
    })?;
    Ok(Remeshed { mesh, on_source })
}

/// `points` on the component `part`, as points on the whole mesh (the part's face is
/// the whole mesh's face of the same corners, in the same order).
fn on_whole<'a>(
    part: &'a Part,
    points: &'a [SurfacePoint],
) -> impl Iterator<Item = SurfacePoint> + 'a {
    points.iter().map(|p| SurfacePoint {
        face: part.faces[p.face.idx()],
        coords: p.coords,
    })
}

/// Which connected components a remeshing covers (`beltrami remesh --components`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coverage {
    /// The mesh as one surface: a mesh in several components is refused
    /// ([`RemeshError::Components`]).
    Whole,
    /// Every component on its own, the results joined ([`remesh_each`]).
    Each,
    /// The component with the most faces alone ([`remesh_largest`]); a mesh in one
    /// piece is remeshed whole.
    Largest,
}

/// What [`remesh_covering`] made.
#[derive(Debug)]
pub struct Covered {
    /// The new mesh.
    pub mesh: Mesh,
    /// Per vertex of the new mesh (by id), its point on the whole input (also when one
    /// component was remeshed alone).
    pub on_source: Vec<SurfacePoint>,
    /// The remeshing's summary; with [`Coverage::Largest`] of a mesh in pieces its notes
    /// say what was remeshed ([`Largest::note`]).
    pub summary: Summary,
    /// Per component, in order ([`Coverage::Each`]; empty otherwise).
    pub components: Vec<ComponentRemeshing>,
    /// The component remeshed alone ([`Coverage::Largest`] of a mesh in pieces), the
    /// input the new mesh is to be measured against; `None` when that is the whole.
    pub part: Option<Part>,
    /// That component's index in the order of [`parts`].
    pub component: Option<usize>,
}

impl Covered {
    /// The input the new mesh replaces: the remeshed component, or `whole`.
    pub fn input<'a>(&'a self, whole: &'a Mesh) -> &'a Mesh {
        self.part.as_ref().map_or(whole, |part| &part.mesh)
    }
}

/// Remeshes the components of `mesh` that `coverage` names, with the parameterizers
/// `choose` picks for each surface remeshed (the one dispatch of the command line and
/// the Python binding).
pub fn remesh_covering<'r>(
    mesh: &Mesh,
    coverage: Coverage,
    choose: impl Fn(&Mesh) -> Result<Vec<&'r dyn Solver>, RemeshError>,
    options: &RemeshOptions,
    context: &mut Context<'_>,
) -> Result<Covered, RemeshError> {
    match coverage {
        Coverage::Each => {
            let joined = remesh_each(mesh, choose, options, context)?;
            let summary = joined.summary();
            Ok(Covered {
                mesh: joined.remeshed.mesh,
                on_source: joined.remeshed.on_source,
                summary,
                components: joined.components,
                part: None,
                component: None,
            })
        }
        Coverage::Largest if mesh.component_count() > 1 => {
            let largest = remesh_largest(mesh, choose, options, context)?;
            let mut summary = largest.remeshing.summary();
            summary.notes.push(largest.note(mesh));
            let on_source =
                on_whole(&largest.part, &largest.remeshing.remeshed.on_source).collect();
            Ok(Covered {
                mesh: largest.remeshing.remeshed.mesh,
                on_source,
                summary,
                components: Vec::new(),
                part: Some(largest.part),
                component: Some(largest.index),
            })
        }
        Coverage::Whole | Coverage::Largest => {
            let solvers = choose(mesh)?;
            let result = remesh(mesh, &solvers, options, context)?;
            let summary = result.summary();
            Ok(Covered {
                mesh: result.remeshed.mesh,
                on_source: result.remeshed.on_source,
                summary,
                components: Vec::new(),
                part: None,
                component: None,
            })
        }
    }
}
