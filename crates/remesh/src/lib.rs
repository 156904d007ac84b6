#![warn(missing_docs)]
//! # beltrami-remesh
//!
//! Remeshing through a parameterization: open the surface into a chart, map it into the
//! plane with any registered solver, triangulate the parameter domain with spade's
//! constrained Delaunay triangulation and refinement, and lift the new vertices back.
//!
//! 1. **Chart** ([`chart`]): a disk as it is; a closed genus-0 surface slit along one
//!    path; every other surface cut along its cut graph
//!    ([`beltrami_mesh::cut_to_disk`]), or, for a circle-domain parameterizer, a genus-0
//!    surface with several boundary loops as it is.
//! 2. **Parameterization** ([`param`]): the solver's map of the chart into the plane
//!    (free boundary, circle, disk, circle domain or square, whichever it accepts
//!    first); a face with non-positive image area is refused. A mesh that lies in a
//!    plane is its own parameterization, uncut.
//! 3. **Boundary** ([`boundary`]): every surface curve on the boundary of the domain
//!    (boundary loops, both copies of each cut curve) is sampled once at the asked
//!    spacing on the surface; copies of one seam point become one vertex.
//! 4. **Refinement** ([`refine`]): the constrained Delaunay triangulation of the samples,
//!    refined until every edge lifted onto the surface has about the asked length (this
//!    compensates the area distortion of the map) and the smallest angle meets the
//!    limit.
//! 5. **Lift** ([`domain`]): every vertex goes to the surface point with the same face
//!    and barycentric coordinates as its parameter point in the image of the chart:
//!    exact on the input surface.
//!
//! The result is a [`Remeshed`] mesh with each vertex's point on the input, and
//! [`quality::measure`] reports angles, edge lengths and distances.
//!
//! ```
//! use beltrami_core::Context;
//! use beltrami_init::Lscm;
//! use beltrami_mesh::{Mesh, primitives::{grid, Cells}};
//! use beltrami_remesh::{RemeshOptions, quality, remesh};
//!
//! let square = Mesh::from_soup(&grid(10, 10, Cells::Triangles)).unwrap();
//! let result = remesh(&square, &[&Lscm], &RemeshOptions::with_edge_length(0.05),
//!     &mut Context::new()).unwrap();
//! let q = quality::measure(&square, &result.remeshed.mesh).unwrap();
//! assert!(q.min_angle > 20.0);
//! assert!(result.remeshed.mesh.positions().iter().all(|p| p.z == 0.0));
//! ```

pub mod boundary;
pub mod chart;
pub mod circle_domain;
pub mod components;
pub mod domain;
mod error;
pub mod in_place;
mod options;
pub mod param;
pub mod quality;
pub mod reference_angles;
pub mod refine;
pub mod scaffold;
mod seam_flips;
pub mod size;
mod star_relaxation;
pub mod two_charts;

use std::time::Instant;

use beltrami_core::{Context, Remeshed, Solver, topology::describe};
use beltrami_mesh::{Mesh, PolygonSoup, SurfacePoint};

pub use chart::Opening;
pub use error::{COARSE_FACES, RemeshError};
pub use options::{FEATURE_TOLERANCE, MAX_MIN_ANGLE, RemeshOptions, Resolution, SizeField};
pub use quality::Quality;

/// A remeshed surface and how it was made.
#[derive(Debug, Clone)]
pub struct Remeshing {
    /// The new mesh and each of its vertices' point on the input.
    pub remeshed: Remeshed,
    /// The parameterizer that was used, or `plane` for a planar mesh, which is its own
    /// parameterization ([`param::in_plane`]).
    pub parameterizer: &'static str,
    /// How the surface was opened for it.
    pub opening: Opening,
    /// The asked edge length (from [`Resolution`]).
    pub edge_length: f64,
    /// Size passes of the refinement.
    pub size_passes: usize,
    /// Seconds per stage: `chart`, `parameterize`, `triangulate`, `assemble`.
    pub timings: Vec<(&'static str, f64)>,
    /// Why earlier parameterizers of the list were passed over.
    pub notes: Vec<String>,
}

/// How a remeshing was made, for reports: one [`Remeshing`]'s, or the joined
/// remeshing of several components' ([`components::Joined::summary`]).
#[derive(Debug, Clone)]
pub struct Summary {
    /// The parameterizer's name, `per component` when the components used different ones.
    pub parameterizer: &'static str,
    /// [`Opening::name`], `per component` when the components were opened differently.
    pub opening: &'static str,
    /// The asked edge length; for components remeshed to a shared vertex count, the
    /// mean of their edge lengths weighted by area.
    pub edge_length: f64,
    /// Size passes of the refinement (the most of any component).
    pub size_passes: usize,
    /// Seconds per stage (summed over components).
    pub timings: Vec<(&'static str, f64)>,
    /// Notes (a component's prefixed with its index).
    pub notes: Vec<String>,
}

impl Remeshing {
    /// This remeshing's [`Summary`].
    pub fn summary(&self) -> Summary {
        Summary {
            parameterizer: self.parameterizer,
            opening: self.opening.name(),
            edge_length: self.edge_length,
            size_passes: self.size_passes,
            timings: self.timings.clone(),
            notes: self.notes.clone(),
        }
    }
}

/// Remeshes `mesh` through the first of `parameterizers` whose map is one-to-one (a
/// later one is tried only when an earlier one folds or overlaps; see the crate docs).
/// For [`Resolution::Vertices`] it remeshes twice: at the edge length of the
/// equilateral estimate, then at that length scaled by `sqrt(n / N)` for the `n`
/// vertices the first run gave.
///
/// # Errors
/// [`RemeshError::InvalidOption`] for bad options (before any work), and the errors of
/// the steps, naming the solver, face or option at fault.
pub fn remesh(
    mesh: &Mesh,
    parameterizers: &[&dyn Solver],
    options: &RemeshOptions,
    context: &mut Context<'_>,
) -> Result<Remeshing, RemeshError> {
    options.validate()?;
    let components = mesh.components();
    if components.len() != 1 {
        return Err(RemeshError::Components {
            components: components.len(),
        });
    }
    options.check_size(mesh.total_area())?;
    let edge_length = options.edge_length(mesh.total_area());
    let first = remesh_at(mesh, parameterizers, options, edge_length, context)
        .map_err(|error| too_coarse(mesh, edge_length, error))?;
    let Resolution::Vertices(asked) = options.resolution else {
        return Ok(first);
    };
    // The refined mesh is not equilateral, so the first edge length gives another vertex
    // count `n`; vertex counts scale like `1 / L^2`, so one correction lands close.
    let n = first.remeshed.mesh.vertex_count() as f64;
    let corrected = edge_length * (n / asked as f64).sqrt();
    remesh_at(mesh, parameterizers, options, corrected, context)
        .map_err(|error| too_coarse(mesh, corrected, error))
}

/// `error` of remeshing `mesh` at `edge_length`, as [`RemeshError::TooCoarse`] when the
/// remeshed surface could not be built (or came out with another topology) and fewer
/// than [`COARSE_FACES`] equilateral triangles of that side cover the surface: the
/// asked size, not the surface, is at fault.
fn too_coarse(mesh: &Mesh, edge_length: f64, error: RemeshError) -> RemeshError {
    let area = mesh.total_area();
    let triangle = |side: f64| 3f64.sqrt() / 4.0 * side * side;
    let faces = area / triangle(edge_length);
    let collapsed = matches!(
        error,
        RemeshError::Build {
            what: "remeshed surface",
            ..
        } | RemeshError::TopologyChanged { .. }
    );
    if collapsed && faces < COARSE_FACES as f64 {
        RemeshError::TooCoarse {
            edge_length,
            area,
            faces,
            suggested: (area / triangle(1.0) / COARSE_FACES as f64).sqrt(),
            error: Box::new(error),
        }
    } else {
        error
    }
}

/// [`remesh`] at a given edge length.
fn remesh_at(
    mesh: &Mesh,
    parameterizers: &[&dyn Solver],
    options: &RemeshOptions,
    edge_length: f64,
    context: &mut Context<'_>,
) -> Result<Remeshing, RemeshError> {
    let sizes = size::vertex_sizes(mesh, options.size_field, edge_length);
    if let Some(uv) = param::in_plane(mesh) {
        let chart = chart::Chart {
            mesh: mesh.clone(),
            to_original: mesh.vertices().collect(),
            opening: Opening::Uncut,
        };
        let mut out = triangulate_chart(mesh, &chart, &uv, "plane", options, &sizes, context)?;
        out.edge_length = edge_length;
        return Ok(out);
    }
    let mut notes = Vec::new();
    for (i, solver) in parameterizers.iter().enumerate() {
        match remesh_with(mesh, *solver, options, &sizes, context) {
            Ok(mut out) => {
                out.edge_length = edge_length;
                out.notes = notes;
                return Ok(out);
            }
            Err(e @ (RemeshError::Flipped { .. } | RemeshError::Overlap { .. }))
                if i + 1 < parameterizers.len() =>
            {
                notes.push(e.to_string());
            }
            Err(e) => return Err(e),
        }
    }
    Err(RemeshError::InvalidOption {
        option: "param",
        message: "no parameterizer given".to_string(),
    })
}

/// Seconds per stage, each measured from the end of the previous one.
struct Stopwatch {
    laps: Vec<(&'static str, f64)>,
    since: Instant,
}

impl Default for Stopwatch {
    fn default() -> Self {
        Self {
            laps: Vec::new(),
            since: Instant::now(),
        }
    }
}

impl Stopwatch {
    fn lap(&mut self, name: &'static str) {
        self.laps.push((name, self.since.elapsed().as_secs_f64()));
        self.since = Instant::now();
    }
}

fn remesh_with(
    mesh: &Mesh,
    solver: &dyn Solver,
    options: &RemeshOptions,
    sizes: &[f64],
    context: &mut Context<'_>,
) -> Result<Remeshing, RemeshError> {
    let mut timings = Stopwatch::default();
    if param::maps_onto_sphere(solver) {
        return two_charts::remesh(mesh, solver, options, sizes, context);
    }
    param::planar_target(solver)?;
    let chart = chart::open(mesh, param::keeps_loops(solver))?;
    timings.lap("chart");
    let uv = if let Opening::Filled { .. } = chart.opening {
        let closed = scaffold::close_holes(&chart.mesh)?;
        let mut uv = param::parameterize(&closed, solver, context)?;
        uv.truncate(chart.mesh.vertex_count());
        uv
    } else {
        param::parameterize(&chart.mesh, solver, context)?
    };
    timings.lap("parameterize");
    let mut out = triangulate_chart(mesh, &chart, &uv, solver.name(), options, sizes, context)?;
    timings.laps.append(&mut out.timings);
    out.timings = timings.laps;
    Ok(out)
}

/// The remeshed surface built from `soup`, refused unless it has the topology of `mesh`.
pub(crate) fn assemble(mesh: &Mesh, soup: &PolygonSoup) -> Result<Mesh, RemeshError> {
    let result = Mesh::from_soup(soup).map_err(|error| RemeshError::Build {
        what: "remeshed surface",
        error,
    })?;
    let (expected, found) = (describe(mesh), describe(&result));
    if expected != found {
        return Err(RemeshError::TopologyChanged { expected, found });
    }
    Ok(result)
}

/// Triangulates the parameter domain of `chart` (positions `uv`), lifts it onto `mesh`
/// and builds the result.
pub(crate) fn triangulate_chart(
    mesh: &Mesh,
    chart: &chart::Chart,
    uv: &[num_complex::Complex64],
    parameterizer: &'static str,
    options: &RemeshOptions,
    sizes: &[f64],
    context: &mut Context<'_>,
) -> Result<Remeshing, RemeshError> {
    let mut timings = Stopwatch::default();
    let planar = domain::planar_mesh(&chart.mesh, uv)?;
    let domain = domain::Domain::new(&chart.mesh, &planar)?;
    let corner_tolerance = if chart.opening == Opening::TwoCharts {
        f64::INFINITY
    } else {
        options.feature_tolerance
    };
    let samples = boundary::sample(
        &chart.mesh,
        uv,
        &chart.to_original,
        |v| sizes[v.idx()],
        corner_tolerance,
    );
    let size_at = |p: &SurfacePoint| {
        let (v, n) = chart.mesh.face_vertex_array(p.face);
        (0..n)
            .map(|i| p.coords[i] * sizes[chart.to_original[v[i].idx()].idx()])
            .sum::<f64>()
    };
    let mut inner: Vec<_> = chart
        .mesh
        .vertices()
        .filter(|&v| !chart.mesh.is_boundary_vertex(v))
        .map(|v| (uv[v.idx()], chart.mesh.position(v)))
        .collect();
    // In Morton order of their parameter points, each point location in the
    // triangulation starts next to the previous one.
    let planar_points: Vec<_> = inner
        .iter()
        .map(|(z, _)| beltrami_mesh::Point3::new(z.re, z.im, 0.0))
        .collect();
    inner = beltrami_spatial::morton::order(&planar_points)
        .into_iter()
        .map(|i| inner[i as usize])
        .collect();
    let tri = refine::triangulate(
        &domain,
        &samples,
        &inner,
        &size_at,
        options,
        parameterizer,
        context,
    )?;
    timings.lap("triangulate");

    // Result vertices: the boundary samples by their seam identity, then the rest.
    let boundary = samples.points.len();
    let id = |i: usize| {
        if i < boundary {
            samples.vertex[i] as usize
        } else {
            samples.vertex_count + (i - boundary)
        }
    };
    let slots = samples.vertex_count + tri.uv.len() - boundary;
    let mut compact = vec![u32::MAX; slots];
    let mut positions = Vec::new();
    let mut on_source: Vec<SurfacePoint> = Vec::new();
    let mut sizes_out = Vec::new();
    let mut faces = Vec::with_capacity(tri.faces.len());
    for face in &tri.faces {
        let mut out = [0u32; 3];
        for (slot, &i) in out.iter_mut().zip(face) {
            let j = id(i as usize);
            if compact[j] == u32::MAX {
                compact[j] = positions.len() as u32;
                positions.push(tri.position[i as usize]);
                on_source.push(tri.on_chart[i as usize]);
                sizes_out.push(tri.size[i as usize]);
            }
            *slot = compact[j];
        }
        faces.push(out);
    }
    let surface = beltrami_spatial::SurfaceIndex::new(mesh)?;
    seam_flips::flip_for_angles(&mut faces, &positions, &sizes_out, &surface)?;
    star_relaxation::relax_worst_stars(
        &faces,
        &mut positions,
        &mut on_source,
        &sizes_out,
        options.feature_tolerance,
        &surface,
    )?;
    seam_flips::flip_for_angles(&mut faces, &positions, &sizes_out, &surface)?;
    let result = assemble(mesh, &PolygonSoup::from_triangles(positions, &faces))?;
    timings.lap("assemble");
    Ok(Remeshing {
        remeshed: Remeshed {
            mesh: result,
            on_source,
        },
        parameterizer,
        opening: chart.opening,
        edge_length: 0.0,
        size_passes: tri.passes,
        timings: timings.laps,
        notes: Vec::new(),
    })
}
