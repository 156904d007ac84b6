//! Constrained Delaunay triangulation of the parameter domain and its refinement by a
//! size field measured on the surface (spade).
//!
//! 1. The boundary samples and their constraint edges are bulk-loaded into spade's
//!    constrained Delaunay triangulation; a crossing constraint means the map overlaps.
//! 2. Size passes: every inner face whose longest edge, *lifted onto the surface*, is
//!    longer than `ALPHA h` (`h` the asked length there), or whose smallest lifted angle
//!    is below the angle limit while its longest edge is still longer than `h` (so that
//!    an anisotropic map cannot drive it on forever), gets a new vertex
//!    at a frontal point towards its circumcenter (`frontal_point`; its centroid when
//!    that point falls outside the domain), as in Delaunay refinement (J. Ruppert, "A Delaunay refinement algorithm for
//!    quality 2-dimensional mesh generation", J. Algorithms 18, 1995; L. P. Chew,
//!    "Guaranteed-quality mesh generation for curved surfaces", SoCG 1993). Measuring on
//!    the surface is what compensates the map's area distortion: where the map shrinks
//!    the surface by `s`, the parameter edges come out `s` times shorter.
//!    Then every vertex of the input whose distance to the piecewise linear
//!    interpolation of the lifted triangulation at its parameter point exceeds
//!    `t h` (`t` the feature tolerance, default 0.2) is inserted itself (both surfaces
//!    are piecewise linear over the parameter domain, so their distance is largest at a
//!    vertex of either or at a crossing of their edges): a spike or crease thinner than the edge length is kept
//!    instead of cut off, which bounds the Hausdorff distance. Such vertices are not
//!    moved by the smoothing.
//! 3. spade's refinement with the angle limit, constraint edges kept (a seam must not be
//!    split on one side only) and outer faces excluded (holes by crossing parity).
//! 4. Smoothing: a few rounds that move every inner vertex to the mean of the
//!    parameter centroids of its faces weighted by their *lifted* areas (a Lloyd-type
//!    relaxation with the surface's area as density, which evens out the lifted
//!    triangle areas), each followed by a new constrained Delaunay triangulation of the
//!    moved vertices. A move that would leave the domain is not made.
//!
//! 5. Edge flips: an inner edge is flipped when that raises the smallest lifted angle of
//!    its two faces and keeps both faces positively oriented in the plane.
//!
//! Faces of the domain are found by crossing parity: a face is inside when a walk from
//! the outside to it crosses an odd number of constraint edges.
//!
//! `ALPHA` sets where edges stop being split. With frontal points the mean lifted edge
//! follows it smoothly (measured on a flat disk, a square, a torus and a sphere: mean
//! `0.95`-`1.02 h` at `ALPHA = 1.6`, `1.02`-`1.05 h` at 1.72); the value below puts
//! the mean at about `h`.

use beltrami_core::Context;
use beltrami_mesh::{Point3, SurfacePoint};
use num_complex::Complex64;
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation as _,
};

use crate::boundary::BoundarySamples;
use crate::domain::{Domain, cross};
use crate::{RemeshError, RemeshOptions};

/// Longest lifted edge, relative to the asked length, that is not split.
const ALPHA: f64 = 1.65;

/// Size passes at most (each splits every face that is too large).
const MAX_PASSES: usize = 40;

/// Smoothing rounds.
const SMOOTHING_ROUNDS: usize = 3;

/// The refined triangulation of the parameter domain, lifted.
#[derive(Debug, Clone)]
pub struct Triangulation {
    /// Vertex positions in the parameter domain: the boundary samples first, in order.
    pub uv: Vec<Complex64>,
    /// Per vertex, its point on the chart.
    pub on_chart: Vec<SurfacePoint>,
    /// Per vertex, its position on the surface.
    pub position: Vec<Point3<f64>>,
    /// Per vertex, the asked edge length there.
    pub size: Vec<f64>,
    /// The inner faces, counter-clockwise in the parameter domain.
    pub faces: Vec<[u32; 3]>,
    /// Size passes done.
    pub passes: usize,
    /// Per vertex, whether it is an input vertex inserted to keep a feature.
    pub pinned: Vec<bool>,
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Triangulates and refines the domain (module docs). `size(p)` is the asked edge
/// length at surface point `p` of the chart. `inner` lists the interior vertices of the
/// chart as their parameter point and surface position. Of `options`, three count:
/// [`RemeshOptions::min_angle`] (degrees), [`RemeshOptions::max_vertices`] and
/// [`RemeshOptions::feature_tolerance`] (relative to the asked length, the module docs'
/// `0.2`).
pub fn triangulate(
    domain: &Domain<'_>,
    samples: &BoundarySamples,
    inner: &[(Complex64, Point3<f64>)],
    size: &impl Fn(&SurfacePoint) -> f64,
    options: &RemeshOptions,
    solver: &'static str,
    context: &mut Context<'_>,
) -> Result<Triangulation, RemeshError> {
    let (min_angle, max_vertices) = (options.min_angle, options.max_vertices);
    let tolerance = options.feature_tolerance;
    let mut cdt = load(&samples.points, &samples.edges, solver)?;
    let mut tri = Triangulation {
        uv: Vec::with_capacity(samples.points.len()),
        on_chart: Vec::new(),
        position: Vec::new(),
        size: Vec::new(),
        faces: Vec::new(),
        passes: 0,
        pinned: Vec::new(),
    };
    for &z in &samples.points {
        // Consecutive samples of a loop are neighbours on the surface.
        let hint = tri.on_chart.last().map(|p| p.face);
        let (point, position) = domain
            .lift(z, hint)?
            .ok_or(RemeshError::Overlap { solver })?;
        tri.push(z, point, position, size(&point));
    }
    let sin_limit = min_angle.to_radians().sin();

    for pass in 0..MAX_PASSES {
        if context.is_cancelled() {
            return Err(RemeshError::Cancelled);
        }
        tri.passes = pass + 1;
        let mut wanted = oversized_faces(&cdt, &tri, domain, sin_limit)?;
        wanted.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut inserted = insert_all(&mut cdt, &mut tri, domain, size, wanted, false)?;
        if inserted == 0 {
            let features = deviating(&cdt, &tri, inner, tolerance);
            inserted = insert_all(&mut cdt, &mut tri, domain, size, features, true)?;
        }
        if tri.uv.len() > max_vertices {
            return Err(RemeshError::TooManyVertices {
                limit: max_vertices,
            });
        }
        if inserted == 0 {
            break;
        }
    }

    refine_angles(&mut cdt, &mut tri, domain, size, min_angle, max_vertices)?;

    let smooth_round = |cdt: &Cdt, tri: &mut Triangulation| {
        if context.is_cancelled() {
            return Err(RemeshError::Cancelled);
        }
        tri.faces = faces_of(cdt);
        smooth(tri, samples.points.len(), domain, size)?;
        load(&tri.uv, &samples.edges, solver)
    };
    for _ in 0..SMOOTHING_ROUNDS {
        cdt = smooth_round(&cdt, &mut tri)?;
    }
    // The smoothing moves the neighbours of the feature vertices chosen during the size
    // passes, so the interpolation between them can leave the input again: check anew,
    // insert what deviates, restore the angles and smooth once more.
    for _ in 0..FEATURE_ROUNDS {
        let features = deviating(&cdt, &tri, inner, tolerance);
        if insert_all(&mut cdt, &mut tri, domain, size, features, true)? == 0 {
            break;
        }
        refine_angles(&mut cdt, &mut tri, domain, size, min_angle, max_vertices)?;
        cdt = smooth_round(&cdt, &mut tri)?;
    }
    tri.faces = faces_of(&cdt);
    for _ in 0..FLIP_SWEEPS {
        if flip_for_angles(&mut tri, domain)? == 0 {
            break;
        }
    }
    Ok(tri)
}

/// The points a size pass inserts, as `(circumradius in the plane, point)`, in face
/// order: one per inner face that is too long (its longest edge on the surface over
/// `ALPHA` times the mean asked length `h` at its corners) or skinny (longer than `h`,
/// the sine of its smallest angle below `sin_limit`). The point is the frontal point of
/// the face when it is finite and lifts onto the chart, else the face's center.
fn oversized_faces(
    cdt: &Cdt,
    tri: &Triangulation,
    domain: &Domain<'_>,
    sin_limit: f64,
) -> Result<Vec<(f64, Complex64)>, RemeshError> {
    let inside = inside_faces(cdt);
    let mut wanted: Vec<(f64, Complex64)> = Vec::new();
    for face in cdt.inner_faces() {
        if !inside[face.fix().index()] {
            continue;
        }
        let idx = face.vertices().map(|v| v.fix().index());
        let h = idx.iter().map(|&i| tri.size[i]).sum::<f64>() / 3.0;
        let p = idx.map(|i| tri.position[i]);
        let longest = (0..3)
            .map(|k| (p[(k + 1) % 3] - p[k]).norm())
            .fold(0.0, f64::max);
        let too_long = longest > ALPHA * h;
        let skinny = longest > h && smallest_sine(&p) < sin_limit;
        if !(too_long || skinny) {
            continue;
        }
        let z = idx.map(|i| tri.uv[i]);
        let (c, r) = frontal_point(&z, &p, h);
        let hint = Some(tri.on_chart[idx[0]].face);
        let q = if c.is_finite() && domain.lift(c, hint)?.is_some() {
            c
        } else {
            let m = face.center();
            Complex64::new(m.x, m.y)
        };
        wanted.push((r, q));
    }
    Ok(wanted)
}

/// Rounds of the feature check after the smoothing at most (each inserts the input
/// vertices that deviate, refines and smooths once).
const FEATURE_ROUNDS: usize = 3;

/// spade's refinement of `cdt` to the angle limit `min_angle` (degrees), constraint
/// edges kept and outer faces excluded; its new vertices are lifted into `tri`.
fn refine_angles(
    cdt: &mut Cdt,
    tri: &mut Triangulation,
    domain: &Domain<'_>,
    size: &impl Fn(&SurfacePoint) -> f64,
    min_angle: f64,
    max_vertices: usize,
) -> Result<(), RemeshError> {
    let before = cdt.num_vertices();
    cdt.refine(
        RefinementParameters::<f64>::new()
            .with_angle_limit(AngleLimit::from_deg(min_angle))
            .keep_constraint_edges()
            .exclude_outer_faces(true)
            .with_max_additional_vertices(max_vertices.saturating_sub(before).max(1)),
    );
    for i in before..cdt.num_vertices() {
        let vertex = cdt.vertex(FixedVertexHandle::from_index(i));
        let p = vertex.position();
        let q = Complex64::new(p.x, p.y);
        let hint = vertex
            .out_edges()
            .map(|e| e.to().fix().index())
            .find(|&j| j < i)
            .map(|j| tri.on_chart[j].face);
        // spade's new vertices lie inside the domain (no constraint edge is split); a
        // vertex on its boundary up to rounding lifts to the closest domain point.
        let (point, position) = domain.lift_closest(q, hint)?;
        tri.push(q, point, position, size(&point));
    }
    if tri.uv.len() > max_vertices {
        return Err(RemeshError::TooManyVertices {
            limit: max_vertices,
        });
    }
    Ok(())
}

/// Sweeps of [`flip_for_angles`] at most.
const FLIP_SWEEPS: usize = 8;

/// One sweep of edge flips for the lifted angles: an inner edge shared by faces `abc`
/// and `bad` becomes `cd` when that raises the smallest lifted angle of the two faces,
/// both new faces keep a positive orientation in the plane (so the parameter
/// triangulation stays a triangulation and no seam or boundary edge moves: those have
/// one face in the domain), and the new edge's midpoint is no farther from the surface
/// than the old one's or `FLIP_DEVIATION h` (a flip across a crease would cut it).
/// Each flip raises the sorted angle vector of the mesh, so sweeps end; returns the
/// flips made. Faces changed in this sweep wait for the next.
fn flip_for_angles(tri: &mut Triangulation, domain: &Domain<'_>) -> Result<usize, RemeshError> {
    use std::collections::HashMap;
    let mut across: HashMap<(u32, u32), (usize, u32)> = HashMap::new();
    for (f, face) in tri.faces.iter().enumerate() {
        for k in 0..3 {
            across.insert((face[k], face[(k + 1) % 3]), (f, face[(k + 2) % 3]));
        }
    }
    let angle = |a: u32, b: u32, c: u32| {
        smallest_sine(&[
            tri.position[a as usize],
            tri.position[b as usize],
            tri.position[c as usize],
        ])
    };
    let orientation = |a: u32, b: u32, c: u32| {
        let z = [a, b, c].map(|i| tri.uv[i as usize]);
        cross(z[1] - z[0], z[2] - z[0])
    };
    let mut changed = vec![false; tri.faces.len()];
    let mut flips = Vec::new();
    for (f, face) in tri.faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b, c) = (face[k], face[(k + 1) % 3], face[(k + 2) % 3]);
            let Some(&(g, d)) = across.get(&(b, a)) else {
                continue;
            };
            if g < f || changed[f] || changed[g] || across.contains_key(&(c, d)) {
                continue;
            }
            let before = angle(a, b, c).min(angle(b, a, d));
            let after = angle(a, d, c).min(angle(d, b, c));
            if after > before * (1.0 + 1e-9)
                && orientation(a, d, c) > 0.0
                && orientation(d, b, c) > 0.0
                && chord_gap(tri, domain, c, d)?
                    <= chord_gap(tri, domain, a, b)?.max(FLIP_DEVIATION * tri.size[a as usize])
            {
                changed[f] = true;
                changed[g] = true;
                flips.push((f, g, [a, d, c], [d, b, c]));
            }
        }
    }
    for &(f, g, new_f, new_g) in &flips {
        tri.faces[f] = new_f;
        tri.faces[g] = new_g;
    }
    Ok(flips.len())
}

/// Largest distance from the surface of a flipped edge's midpoint, relative to the
/// asked length, that is accepted whatever the old edge's.
pub(crate) const FLIP_DEVIATION: f64 = 0.05;

/// The distance between the midpoint of the chord `ab` and the surface point over the
/// midpoint of `ab` in the plane.
fn chord_gap(tri: &Triangulation, domain: &Domain<'_>, a: u32, b: u32) -> Result<f64, RemeshError> {
    let (a, b) = (a as usize, b as usize);
    let hint = Some(tri.on_chart[a].face);
    let (_, on_surface) = domain.lift_closest((tri.uv[a] + tri.uv[b]) / 2.0, hint)?;
    let chord = (tri.position[a].coords + tri.position[b].coords) / 2.0;
    Ok((on_surface.coords - chord).norm())
}

impl Triangulation {
    fn push(&mut self, q: Complex64, point: SurfacePoint, position: Point3<f64>, size: f64) {
        self.uv.push(q);
        self.on_chart.push(point);
        self.position.push(position);
        self.size.push(size);
        self.pinned.push(false);
    }
}

/// Where to split a face that is too large or skinny, and the radius of its closeness
/// test in [`insert_all`]: the point on the perpendicular bisector of the face's shortest lifted edge
/// `pq` that would make `pq` the base of an equilateral triangle of the asked size `h`
/// (D. Rebay, "Efficient unstructured mesh generation by means of Delaunay
/// triangulation and Bowyer-Watson algorithm", J. Comput. Phys. 106, 1993), but no
/// farther from `pq` than the circumcenter (which Delaunay refinement would insert).
/// The size is carried into the plane by the edge's own length ratio. Inserting at the
/// circumcenter only, sizes come out anywhere between `ALPHA h / 2` and `ALPHA h`
/// depending on how the splits cascade; the frontal point builds on edges that are
/// already of the right size. A frontal point is dropped when a vertex lies within
/// `0.75 h` of it (in the plane): fronts that advance into a narrowing region, e.g.
/// rings towards the centre of a disk, would otherwise keep their number of points and
/// grow denser; a circumcenter is dropped within half the circumradius.
fn frontal_point(z: &[Complex64; 3], p: &[Point3<f64>; 3], h: f64) -> (Complex64, f64) {
    let k = (0..3)
        .min_by(|&a, &b| {
            let la = (p[(a + 1) % 3] - p[a]).norm();
            let lb = (p[(b + 1) % 3] - p[b]).norm();
            la.total_cmp(&lb)
        })
        .unwrap_or(0);
    let (a, b, c) = (z[k], z[(k + 1) % 3], z[(k + 2) % 3]);
    let base = (b - a).norm();
    let lifted = (p[(k + 1) % 3] - p[k]).norm();
    let circumcenter = circumcenter(a, b, c);
    let radius = 0.5 * (circumcenter - a).norm();
    if !(base > 0.0 && lifted > 0.0) {
        return (circumcenter, radius);
    }
    let m = (a + b) / 2.0;
    // Unit normal of ab towards c (the face is counter-clockwise: to the left of ab).
    let normal = Complex64::new(0.0, 1.0) * (b - a) / base;
    let to_circumcenter = ((circumcenter - m) * normal.conj()).re;
    let h_plane = h * base / lifted;
    let height = 3f64.sqrt() / 2.0 * h_plane;
    if to_circumcenter <= 0.0 || height >= to_circumcenter || h_plane <= 0.5 * base {
        return (circumcenter, radius);
    }
    (m + normal * height, 0.75 * h_plane)
}

/// The circumcenter of the triangle `a b c` of the plane.
fn circumcenter(a: Complex64, b: Complex64, c: Complex64) -> Complex64 {
    let (b, c) = (b - a, c - a);
    let d = 2.0 * cross(b, c);
    let (nb, nc) = (b.norm_sqr(), c.norm_sqr());
    a + Complex64::new(c.im * nb - b.im * nc, b.re * nc - c.re * nb) / d
}

/// Inserts the points `(r, q)` in order, each unless a vertex lies within `r` of it or
/// it falls outside the domain, and lifts them; returns how many were inserted.
fn insert_all(
    cdt: &mut Cdt,
    tri: &mut Triangulation,
    domain: &Domain<'_>,
    size: &impl Fn(&SurfacePoint) -> f64,
    points: Vec<(f64, Complex64)>,
    pinned: bool,
) -> Result<usize, RemeshError> {
    let mut inserted = 0;
    for (r, q) in points {
        let Some(near) = vertex_nearby(cdt, q, r) else {
            continue;
        };
        if let Some((point, position)) = domain.lift(q, Some(tri.on_chart[near].face))?
            && let Ok(handle) = cdt.insert(Point2::new(q.re, q.im))
            && handle.index() == tri.uv.len()
        {
            tri.push(q, point, position, size(&point));
            tri.pinned[handle.index()] = pinned;
            inserted += 1;
        }
    }
    Ok(inserted)
}

/// Input vertices farther than `tolerance h` from the interpolated result at their
/// parameter point (module docs), as (the radius of the closeness test of
/// [`insert_all`], point), farthest first.
fn deviating(
    cdt: &Cdt,
    tri: &Triangulation,
    inner: &[(Complex64, Point3<f64>)],
    tolerance: f64,
) -> Vec<(f64, Complex64)> {
    use spade::PositionInTriangulation as P;
    let mut out: Vec<(f64, f64, Complex64)> = Vec::new();
    for &(q, p) in inner {
        let P::OnFace(f) = cdt.locate(Point2::new(q.re, q.im)) else {
            continue;
        };
        let idx = cdt.face(f).vertices().map(|v| v.fix().index());
        let z = idx.map(|i| tri.uv[i]);
        let det = cross(z[1] - z[0], z[2] - z[0]);
        if det <= 0.0 {
            continue;
        }
        let l1 = cross(q - z[0], z[2] - z[0]) / det;
        let l2 = cross(z[1] - z[0], q - z[0]) / det;
        let interpolated = tri.position[idx[0]].coords * (1.0 - l1 - l2)
            + tri.position[idx[1]].coords * l1
            + tri.position[idx[2]].coords * l2;
        let h = idx.iter().map(|&i| tri.size[i]).sum::<f64>() / 3.0;
        let deviation = (p.coords - interpolated).norm();
        if deviation > tolerance * h {
            let r = (0..3)
                .map(|k| (z[k] - q).norm())
                .fold(f64::INFINITY, f64::min);
            out.push((deviation / h, r, q));
        }
    }
    out.sort_by(|a, b| b.0.total_cmp(&a.0));
    out.into_iter().map(|(_, r, q)| (r, q)).collect()
}

/// The constrained Delaunay triangulation of `points` with constraint edges `edges`
/// (between the first points), vertex `i` being `points[i]`; a crossing constraint or a
/// repeated point means the map overlaps.
fn load(
    points: &[Complex64],
    edges: &[[usize; 2]],
    solver: &'static str,
) -> Result<Cdt, RemeshError> {
    let vertices: Vec<Point2<f64>> = points.iter().map(|z| Point2::new(z.re, z.im)).collect();
    let mut crossing = false;
    let cdt = Cdt::try_bulk_load_cdt(vertices, edges.to_vec(), |_| crossing = true)
        .map_err(|_| RemeshError::Overlap { solver })?;
    if crossing || cdt.num_vertices() != points.len() {
        return Err(RemeshError::Overlap { solver });
    }
    Ok(cdt)
}

/// Per face index of `cdt`, whether the face is inside the domain: a depth-first walk
/// from the convex hull that flips a parity bit at every constraint edge it crosses.
fn inside_faces(cdt: &Cdt) -> Vec<bool> {
    let mut inside = vec![false; cdt.num_all_faces()];
    let mut seen = vec![false; cdt.num_all_faces()];
    // (edge with the face to visit on its left, inside-parity of the face across it)
    let mut stack: Vec<_> = cdt.convex_hull().map(|e| (e.rev(), false)).collect();
    while let Some((e, across)) = stack.pop() {
        let Some(face) = e.face().as_inner() else {
            continue;
        };
        let i = face.fix().index();
        if seen[i] {
            continue;
        }
        seen[i] = true;
        let parity = across ^ e.is_constraint_edge();
        inside[i] = parity;
        stack.push((e.next().rev(), parity));
        stack.push((e.prev().rev(), parity));
    }
    inside
}

/// The faces of `cdt` inside the domain, as vertex indices, counter-clockwise.
fn faces_of(cdt: &Cdt) -> Vec<[u32; 3]> {
    let inside = inside_faces(cdt);
    cdt.inner_faces()
        .filter(|f| inside[f.fix().index()])
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect()
}

/// One smoothing round (module docs): every vertex after the first `fixed` moves to the
/// mean of the parameter centroids of its faces weighted by their lifted areas.
fn smooth(
    tri: &mut Triangulation,
    fixed: usize,
    domain: &Domain<'_>,
    size: &impl Fn(&SurfacePoint) -> f64,
) -> Result<(), RemeshError> {
    let n = tri.uv.len();
    let mut sum = vec![Complex64::new(0.0, 0.0); n];
    let mut weight = vec![0.0f64; n];
    for face in &tri.faces {
        let [a, b, c] = face.map(|i| i as usize);
        let (pa, pb, pc) = (tri.position[a], tri.position[b], tri.position[c]);
        let area = (pb - pa).cross(&(pc - pa)).norm();
        let centroid = (tri.uv[a] + tri.uv[b] + tri.uv[c]) / 3.0;
        for i in [a, b, c] {
            sum[i] += centroid * area;
            weight[i] += area;
        }
    }
    for i in fixed..n {
        if weight[i] <= 0.0 || tri.pinned[i] {
            continue;
        }
        let q = sum[i] / weight[i];
        if let Some((point, position)) = domain.lift(q, Some(tri.on_chart[i].face))? {
            tri.uv[i] = q;
            tri.on_chart[i] = point;
            tri.position[i] = position;
            tri.size[i] = size(&point);
        }
    }
    Ok(())
}

/// The smallest sine of the three angles of a triangle in R^3:
/// `sin A = 2 area / (|b| |c|)` at each corner.
pub(crate) fn smallest_sine(p: &[Point3<f64>; 3]) -> f64 {
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

/// A vertex of the face of `cdt` containing `q`, or `None` when one of them lies within
/// `radius` of `q` (a point inserted earlier in the same pass, typically) or `q` is not
/// inside a face.
fn vertex_nearby(cdt: &Cdt, q: Complex64, radius: f64) -> Option<usize> {
    use spade::PositionInTriangulation as P;
    let near = |p: Point2<f64>| (Complex64::new(p.x, p.y) - q).norm() < radius;
    match cdt.locate(Point2::new(q.re, q.im)) {
        P::OnFace(f) => {
            let vertices = cdt.face(f).vertices();
            (!vertices.iter().any(|v| near(v.position()))).then(|| vertices[0].fix().index())
        }
        P::OnVertex(_) | P::OnEdge(_) | P::OutsideOfConvexHull(_) | P::NoTriangulation => None,
    }
}
