//! Constrained Delaunay triangulation of the parameter domain and its refinement by a
//! size field measured on the surface (spade).
//!
//! 1. The boundary samples and their constraint edges are bulk-loaded into spade's
//!    constrained Delaunay triangulation; a crossing constraint means the map overlaps.
//! 2. Size passes: every inner face whose longest edge, *lifted onto the surface*, is
//!    longer than `ALPHA h` (`h` the asked length there), or whose smallest lifted angle
//!    is below the angle limit while its edges are not already short, gets a new vertex
//!    at its circumcenter (its centroid when the circumcenter falls outside the domain),
//!    as in Delaunay refinement (J. Ruppert, "A Delaunay refinement algorithm for
//!    quality 2-dimensional mesh generation", J. Algorithms 18, 1995; L. P. Chew,
//!    "Guaranteed-quality mesh generation for curved surfaces", SoCG 1993). Measuring on
//!    the surface is what compensates the map's area distortion: where the map shrinks
//!    the surface by `s`, the parameter edges come out `s` times shorter.
//! 3. spade's refinement with the angle limit, constraint edges kept (a seam must not be
//!    split on one side only) and outer faces excluded (holes by crossing parity).
//!
//! `ALPHA` sets where edges stop being split; a Delaunay refinement that stops when no
//! edge is longer than `ALPHA h` leaves edges between about `ALPHA h / 2` and
//! `ALPHA h`, whose mean is near `h` for the value below (measured on the test meshes).

use beltrami_core::Context;
use beltrami_mesh::{Point3, SurfacePoint};
use num_complex::Complex64;
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation as _,
};

use crate::RemeshError;
use crate::boundary::BoundarySamples;
use crate::domain::Domain;

/// Longest lifted edge, relative to the asked length, that is not split.
const ALPHA: f64 = 1.35;

/// Size passes at most (each splits every face that is too large).
const MAX_PASSES: usize = 40;

/// The refined triangulation of the parameter domain, lifted.
#[derive(Debug, Clone)]
pub struct Triangulation {
    /// Vertex positions in the parameter domain: the boundary samples first, in order.
    pub uv: Vec<Complex64>,
    /// Per vertex, its point on the chart.
    pub on_chart: Vec<SurfacePoint>,
    /// Per vertex, its position on the surface.
    pub position: Vec<Point3<f64>>,
    /// The inner faces, counter-clockwise in the parameter domain.
    pub faces: Vec<[u32; 3]>,
    /// Size passes done.
    pub passes: usize,
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Triangulates and refines the domain (module docs). `size(p)` is the asked edge
/// length at surface point `p` of the chart; `min_angle` in degrees.
pub fn triangulate(
    domain: &Domain<'_>,
    samples: &BoundarySamples,
    size: &impl Fn(&SurfacePoint) -> f64,
    min_angle: f64,
    max_vertices: usize,
    solver: &'static str,
    context: &mut Context<'_>,
) -> Result<Triangulation, RemeshError> {
    let vertices: Vec<Point2<f64>> = samples
        .points
        .iter()
        .map(|z| Point2::new(z.re, z.im))
        .collect();
    let mut crossing = false;
    let mut cdt = Cdt::try_bulk_load_cdt(vertices, samples.edges.clone(), |_| crossing = true)
        .map_err(|_| RemeshError::Overlap { solver })?;
    if crossing || cdt.num_vertices() != samples.points.len() {
        return Err(RemeshError::Overlap { solver });
    }
    let mut tri = Triangulation {
        uv: Vec::with_capacity(samples.points.len()),
        on_chart: Vec::new(),
        position: Vec::new(),
        faces: Vec::new(),
        passes: 0,
    };
    for &z in &samples.points {
        let (point, position) = domain.lift(z)?.ok_or(RemeshError::Overlap { solver })?;
        tri.uv.push(z);
        tri.on_chart.push(point);
        tri.position.push(position);
    }
    let sin_limit = min_angle.to_radians().sin();

    for pass in 0..MAX_PASSES {
        if context.is_cancelled() {
            return Err(RemeshError::Cancelled);
        }
        tri.passes = pass + 1;
        // (circumradius in the plane, point to insert)
        let mut wanted: Vec<(f64, Complex64)> = Vec::new();
        for face in cdt.inner_faces() {
            let idx = face.vertices().map(|v| v.fix().index());
            let centroid = face.center();
            let centroid = Complex64::new(centroid.x, centroid.y);
            let Some((at, _)) = domain.lift(centroid)? else {
                continue;
            };
            let h = size(&at);
            let p = idx.map(|i| tri.position[i]);
            let len = [
                (p[1] - p[0]).norm(),
                (p[2] - p[1]).norm(),
                (p[0] - p[2]).norm(),
            ];
            let longest = len.iter().copied().fold(0.0, f64::max);
            let too_long = longest > ALPHA * h;
            let skinny = longest > 0.5 * h && smallest_sine(&p) < sin_limit;
            if !(too_long || skinny) {
                continue;
            }
            let c = face.circumcenter();
            let c = Complex64::new(c.x, c.y);
            let r = (c - tri.uv[idx[0]]).norm();
            let inside = c.is_finite() && domain.lift(c)?.is_some();
            wanted.push((r, if inside { c } else { centroid }));
        }
        if wanted.is_empty() {
            break;
        }
        wanted.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (r, q) in wanted {
            if too_close(&cdt, q, 0.5 * r) {
                continue;
            }
            insert(&mut cdt, &mut tri, domain, q)?;
            if tri.uv.len() > max_vertices {
                return Err(RemeshError::TooManyVertices {
                    limit: max_vertices,
                });
            }
        }
    }

    let before = cdt.num_vertices();
    let result = cdt.refine(
        RefinementParameters::<f64>::new()
            .with_angle_limit(AngleLimit::from_deg(min_angle))
            .keep_constraint_edges()
            .exclude_outer_faces(true)
            .with_max_additional_vertices(max_vertices.saturating_sub(before).max(1)),
    );
    for i in before..cdt.num_vertices() {
        let p = cdt.vertex(FixedVertexHandle::from_index(i)).position();
        let q = Complex64::new(p.x, p.y);
        // spade's new vertices lie inside the domain (no constraint edge is split); a
        // vertex on its boundary up to rounding lifts to the closest domain point.
        let (point, position) = domain.lift_closest(q)?;
        tri.uv.push(q);
        tri.on_chart.push(point);
        tri.position.push(position);
    }
    if tri.uv.len() > max_vertices {
        return Err(RemeshError::TooManyVertices {
            limit: max_vertices,
        });
    }
    let excluded: std::collections::HashSet<usize> =
        result.excluded_faces.iter().map(|f| f.index()).collect();
    tri.faces = cdt
        .inner_faces()
        .filter(|f| !excluded.contains(&f.fix().index()))
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    Ok(tri)
}

/// The smallest sine of the three angles of a triangle in R^3:
/// `sin A = 2 area / (|b| |c|)` at each corner.
fn smallest_sine(p: &[Point3<f64>; 3]) -> f64 {
    let twice_area = (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
    let l = [
        (p[1] - p[2]).norm(),
        (p[2] - p[0]).norm(),
        (p[0] - p[1]).norm(),
    ];
    let products = [l[1] * l[2], l[2] * l[0], l[0] * l[1]];
    products
        .iter()
        .map(|&m| if m > 0.0 { twice_area / m } else { 0.0 })
        .fold(f64::INFINITY, f64::min)
}

/// True if a vertex of the face containing `q` lies within `radius` of it (a point
/// inserted earlier in the same pass, typically).
fn too_close(cdt: &Cdt, q: Complex64, radius: f64) -> bool {
    use spade::PositionInTriangulation as P;
    let near = |p: Point2<f64>| (Complex64::new(p.x, p.y) - q).norm() < radius;
    match cdt.locate(Point2::new(q.re, q.im)) {
        P::OnFace(f) => cdt.face(f).vertices().iter().any(|v| near(v.position())),
        P::OnVertex(_) | P::OnEdge(_) => true,
        P::OutsideOfConvexHull(_) | P::NoTriangulation => true,
    }
}

/// Inserts `q` (inside the domain) and lifts it.
fn insert(
    cdt: &mut Cdt,
    tri: &mut Triangulation,
    domain: &Domain<'_>,
    q: Complex64,
) -> Result<(), RemeshError> {
    let Some((point, position)) = domain.lift(q)? else {
        return Ok(());
    };
    let Ok(handle) = cdt.insert(Point2::new(q.re, q.im)) else {
        return Ok(());
    };
    if handle.index() == tri.uv.len() {
        tri.uv.push(q);
        tri.on_chart.push(point);
        tri.position.push(position);
    }
    Ok(())
}
