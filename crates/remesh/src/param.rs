//! The parameterization of a chart by a registered solver, and the choice of solver by
//! topology.

use beltrami_core::{
    Context, PlanarBoundary, Problem, Registry, Solver, Target, TargetKind, topology::describe,
};
use beltrami_mesh::{FaceId, Mesh};
use num_complex::Complex64;

use crate::RemeshError;

/// The planar targets a remeshing can use, in order of preference: a free boundary (the
/// least distortion), the unit circle, the unit disk, a circle domain, the unit square.
const PLANAR_TARGETS: [TargetKind; 5] = [
    TargetKind::PlaneFree,
    TargetKind::PlaneCircle,
    TargetKind::Disk,
    TargetKind::CircleDomain,
    TargetKind::PlaneSquare,
];

/// The first target of `PLANAR_TARGETS` that `solver` accepts, or an error saying it
/// does not map into the plane.
pub fn planar_target(solver: &dyn Solver) -> Result<Target<'static>, RemeshError> {
    let accepts = solver.accepts();
    let kind = PLANAR_TARGETS
        .iter()
        .find(|k| accepts.targets.contains(k))
        .ok_or_else(|| RemeshError::Parameterizer {
            solver: solver.name(),
            message: format!(
                "it maps onto {:?}, not into the plane; use `lscm`, `tutte`, `harmonic` or `auto` (a closed genus-0 surface is slit open and mapped to the plane)",
                accepts.targets
            ),
        })?;
    Ok(match kind {
        TargetKind::PlaneFree => Target::Plane(PlanarBoundary::Free),
        TargetKind::PlaneCircle => Target::Plane(PlanarBoundary::Circle),
        TargetKind::Disk => Target::Disk,
        TargetKind::CircleDomain => Target::CircleDomain,
        _ => Target::Plane(PlanarBoundary::Square { corners: None }),
    })
}

/// True if `solver` maps onto the sphere and into no planar domain: a closed genus-0
/// surface is then remeshed in two charts ([`crate::two_charts`]).
pub fn maps_onto_sphere(solver: &dyn Solver) -> bool {
    let targets = solver.accepts().targets;
    targets.contains(&TargetKind::Sphere) && !PLANAR_TARGETS.iter().any(|k| targets.contains(k))
}

/// True if `solver` maps several boundary loops onto a circle domain, so that a
/// multiply connected surface needs no cut.
pub fn keeps_loops(solver: &dyn Solver) -> bool {
    solver.accepts().targets.contains(&TargetKind::CircleDomain)
}

/// The parameterizers `auto` tries for `mesh`, in order: on a genus-0 surface with
/// several boundary loops `lscm` of the surface with its holes closed (the chart stays
/// uncut, [`crate::chart::Opening::Filled`]), then `qcmc` (its circle domain) when
/// registered; on every other surface `lscm` (on a disk as it is, on a closed genus-0
/// surface after a slit, otherwise after a cut to a disk); last `tutte`, whose convex
/// boundary makes the map one-to-one (Tutte's theorem). The next one is tried when a
/// map folds or overlaps. On the shared multiply connected meshes LSCM with closed holes
/// gives as good a remesh as the circle domain in a third of the time (`mc4_face_a`),
/// and a far better one where the circle domain nearly folds at a coarse hole
/// (`mc8_peaks`, docs/remesh.md); `mc2_sophie`'s LSCM folds a face and goes to `qcmc`.
pub fn auto<'r>(registry: &'r Registry, mesh: &Mesh) -> Result<Vec<&'r dyn Solver>, RemeshError> {
    let components = mesh.components();
    if components.len() != 1 {
        return Err(RemeshError::Components {
            components: components.len(),
        });
    }
    let c = components[0];
    let lscm = registry.get("lscm").map_err(|error| RemeshError::Solve {
        solver: "auto",
        error,
    })?;
    let mut order = vec![lscm];
    if c.genus == 0 && c.boundary_loops > 1 {
        order.extend(registry.get("qcmc").ok());
    }
    order.extend(registry.get("tutte").ok());
    Ok(order)
}

/// The parameterizers to try, in order, for the name `name`: `auto` gives [`auto`]'s
/// order, any other name the registered solver of that name alone.
pub fn chosen<'r>(
    registry: &'r Registry,
    mesh: &Mesh,
    name: &str,
) -> Result<Vec<&'r dyn Solver>, RemeshError> {
    if name != "auto" {
        let solver = registry.get(name).map_err(|error| RemeshError::Solve {
            solver: "remesh",
            error,
        })?;
        return Ok(vec![solver]);
    }
    auto(registry, mesh)
}

/// Maps `chart` into the plane with `solver` and checks that no face folds over
/// (non-positive signed area of its image, summed over the triangle fan of a quad).
pub fn parameterize(
    chart: &Mesh,
    solver: &dyn Solver,
    context: &mut Context<'_>,
) -> Result<Vec<Complex64>, RemeshError> {
    let problem = Problem::new(chart, planar_target(solver)?);
    let solution = solver
        .solve(&problem, context)
        .map_err(|error| RemeshError::Solve {
            solver: solver.name(),
            error,
        })?;
    let uv = solution
        .planar()
        .ok_or_else(|| RemeshError::Parameterizer {
            solver: solver.name(),
            message: format!(
                "it returned no planar map of the chart ({})",
                describe(chart)
            ),
        })?
        .to_vec();
    let mut uv = uv;
    one_to_one(chart, &mut uv, solver.name())?;
    Ok(uv)
}

/// Repairs the few folded faces of the map `uv` of `chart` ([`untangle`]) and refuses
/// it, naming `solver` and the first face, when some still fold.
pub(crate) fn one_to_one(
    chart: &Mesh,
    uv: &mut [Complex64],
    solver: &'static str,
) -> Result<(), RemeshError> {
    untangle(chart, uv);
    let mut flipped = chart.faces().filter(|&f| signed_area(chart, uv, f) <= 0.0);
    match flipped.next() {
        Some(first) => Err(RemeshError::Flipped {
            solver,
            flipped: 1 + flipped.count(),
            first,
        }),
        None => Ok(()),
    }
}

/// Rounds of [`untangle`] at most.
const UNTANGLE_ROUNDS: usize = 100;

/// Repairs a few folded faces of a map (LSCM folds slivers now and then, mostly along
/// a free boundary): each round moves every vertex of a folded face and its neighbours,
/// an interior one to the mean of its neighbours' images (a local Tutte step, which
/// unfolds where the neighbourhood's boundary is star-shaped around it), a boundary one
/// to the midpoint of its two boundary neighbours (straightening a folded boundary),
/// until no face folds or the rounds run out; the caller checks what is left.
fn untangle(chart: &Mesh, uv: &mut [Complex64]) {
    for _ in 0..UNTANGLE_ROUNDS {
        let mut moving: Vec<_> = chart
            .faces()
            .filter(|&f| signed_area(chart, uv, f) <= 0.0)
            .flat_map(|f| chart.face_vertices(f).collect::<Vec<_>>())
            .flat_map(|v| std::iter::once(v).chain(chart.vertex_neighbors(v)))
            .collect();
        if moving.is_empty() {
            return;
        }
        moving.sort_unstable();
        moving.dedup();
        for v in moving {
            if chart.is_boundary_vertex(v) {
                // Along the boundary: the midpoint of its two boundary neighbours.
                let h = chart.vertex_halfedge(v);
                let (a, b) = (chart.target(h), chart.origin(chart.prev(h)));
                uv[v.idx()] = (uv[a.idx()] + uv[b.idx()]) / 2.0;
                continue;
            }
            let (sum, n) = chart
                .vertex_neighbors(v)
                .fold((Complex64::new(0.0, 0.0), 0usize), |(s, n), w| {
                    (s + uv[w.idx()], n + 1)
                });
            if n > 0 {
                uv[v.idx()] = sum / n as f64;
            }
        }
    }
}

/// The in-plane coordinates of a mesh that lies in a plane (every vertex within
/// `1e-12` of the bounding-box diagonal from the plane through its first vertex normal
/// to the total vector area `n`), in an orthonormal basis `(e1, e2)` with
/// `e1 x e2 = n / |n|`, so that faces counter-clockwise about `n` stay so. A planar
/// region is its own conformal parameterization, uncut whatever its number of boundary
/// loops; `None` for a curved mesh, or one whose faces do not all turn the same way.
pub fn in_plane(mesh: &Mesh) -> Option<Vec<Complex64>> {
    let normal = mesh
        .faces()
        .map(|f| mesh.face_vector_area(f))
        .fold(beltrami_mesh::Vector3::zeros(), |s, a| s + a)
        .try_normalize(0.0)?;
    let origin = mesh.positions().first()?.coords;
    let tolerance = 1e-12 * mesh.bounding_box().diagonal();
    if mesh
        .positions()
        .iter()
        .any(|p| (p.coords - origin).dot(&normal).abs() > tolerance)
    {
        return None;
    }
    let helper = if normal.x.abs() < 0.9 {
        beltrami_mesh::Vector3::x()
    } else {
        beltrami_mesh::Vector3::y()
    };
    let e1 = normal.cross(&helper).normalize();
    let e2 = normal.cross(&e1);
    let uv: Vec<Complex64> = mesh
        .positions()
        .iter()
        .map(|p| Complex64::new((p.coords - origin).dot(&e1), (p.coords - origin).dot(&e2)))
        .collect();
    mesh.faces()
        .all(|f| signed_area(mesh, &uv, f) > 0.0)
        .then_some(uv)
}

/// Twice the signed area of the image of face `f`: `sum_i Im(conj(z_i) z_{i+1})` over
/// its corners (the shoelace formula; positive when counter-clockwise).
pub fn signed_area(mesh: &Mesh, uv: &[Complex64], f: FaceId) -> f64 {
    let (v, n) = mesh.face_vertex_array(f);
    (0..n)
        .map(|i| (uv[v[i].idx()].conj() * uv[v[(i + 1) % n].idx()]).im)
        .sum()
}
