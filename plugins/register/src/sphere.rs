//! Closed genus 0: both meshes onto the unit sphere with the `sphere` initialization of
//! `beltrami-init` (its `conformal` start with landmarks or a shape or feature match,
//! else its `tutte` start, which the flow was tuned from), the source's sphere aligned with the target's, and
//! the source's images located radially in the target's sphere polyhedron
//! ([`crate::compose::locate_radial`]).
//!
//! Alignment (applied to the source's sphere positions):
//!
//! - no landmark: the Moebius transformation `M` (a rotation from the Tutte start)
//!   minimizing `sum_i |M S_i - T(q_i)|^2`
//!   over (up to 4096 evenly picked) source vertices ([`crate::sphere_alignment`]),
//!   `S_i` a source vertex's sphere position and `T(q_i)` the target's sphere position
//!   at the spatial partner `q_i` of that vertex (the closest point of the target after
//!   centring and scaling, no rotation in space);
//! - one landmark: that transformation, then the smallest rotation taking the landmark's image
//!   onto its target's sphere position (exact);
//! - two or more: the Moebius transformation taking the first three landmarks' images
//!   onto their targets' (exact); with two, the third pair is the poles of the great
//!   circles through the two, so the transformation fixes the pole and slides along
//!   the circle.
//!
//! With landmarks, every landmark is matched on the sphere itself ([`match_on_sphere`]): after the
//! Moebius transformation of the three landmarks that brings all of them nearest their
//! targets, the source minus the face farthest from every landmark is mapped into the
//! stereographic chart from that face's direction by the landmark-matching
//! quasiconformal map of [`crate::landmark_match`] (the face's corners held where the
//! transformation put them, each landmark at its target's chart point), and lifted back
//! onto the sphere. The map is exact at every landmark and, with no flipped face in the
//! chart, a bijection of the sphere.
//!
//! Fields (features, the shape's coordinates) are matched in the same chart. The cap
//! about the pole within half its clearance from the landmarks is held there; when that
//! cap is large (a chordal radius above `LARGE_CAP`: few landmarks or none), the match
//! is run again in a second chart whose pole is the face farthest from the first pole
//! and the landmarks, so that the first cap is matched too (fsaverage5 pial onto white
//! with the sulcal depth and no landmarks: 1.96 -> 0.70 mm mean distance to the truth).

use beltrami_core::{Context, FeatureMismatch, Map, Problem, Solver, SolverError, Target};
use beltrami_fem::Frame;
use beltrami_init::Sphere;
use beltrami_mesh::{FaceId, Mesh, Point3, SurfacePoint, Vector3};
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::Routed;
use crate::compose;
use crate::error::{RegisterError, Side};
use crate::feature_match::{Channel, match_features};
use crate::landmark_match::match_landmarks;
use crate::landmarks::{
    Moebius, Resolved, SpatialMatch, best_rotation, interpolate, rotation_between,
};
use crate::param::{domain_mesh, each_mesh, planar_points};
use crate::sphere_alignment::{SphereMoebius, fitted_moebius};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// Source vertices used by the rotation fit at most.
const FIT_SAMPLES: usize = 4096;

/// A held cap about the pole of a chordal radius above this is matched again in a
/// second chart (module docs).
const LARGE_CAP: f64 = 0.25;

/// Triples of landmarks tried for the Moebius transformation at most.
const MOEBIUS_TRIALS: usize = 200;

/// The source's images on the target, the landmarks honoured exactly (indices into
/// `marks`) and the target's sphere map (per target vertex).
pub(crate) fn map(
    source: &Mesh,
    target: &Mesh,
    target_index: &SurfaceIndex<'_>,
    marks: &[Resolved],
    conformal: bool,
    cancel: &Arc<AtomicBool>,
    notes: &mut Vec<String>,
) -> Result<Routed<Vec<Vector3<f64>>>, RegisterError> {
    // The Tutte start, which the flow from a map without landmarks was tuned from;
    // conformal sphere maps with landmarks or when asked (a shape or feature match):
    // composed through a Moebius transformation they make a nearly conformal map by
    // themselves, and the alignment by geometry chooses among exactly those.
    let conformal = conformal || !marks.is_empty();
    // The two sphere maps are independent: computed at once, on two cores.
    let (source_sphere, target_sphere) = each_mesh(source, target, notes, |mesh, side, notes| {
        sphere(mesh, side, conformal, cancel, notes)
    })?;
    let target_at =
        |p: &SurfacePoint| -> Vector3<f64> { interpolate(target, &target_sphere, p).normalize() };

    let fit = || -> Result<SphereMoebius, RegisterError> {
        let spatial = SpatialMatch::new(source, target);
        let step = source.vertex_count().div_ceil(FIT_SAMPLES).max(1);
        let mut pairs = Vec::new();
        for v in source.vertices().step_by(step) {
            let partner = target_index.locate(&spatial.to_target(&source.position(v)))?;
            pairs.push((source_sphere[v.idx()], target_at(&partner.point)));
        }
        // A Moebius transformation of Tutte sphere maps is no nearer conformal than a
        // rotation: they are only turned.
        Ok(if conformal {
            fitted_moebius(&pairs).0
        } else {
            SphereMoebius::rotation(best_rotation(&pairs))
        })
    };

    let s: Vec<Vector3<f64>> = marks
        .iter()
        .map(|m| source_sphere[m.source.idx()])
        .collect();
    let t: Vec<Vector3<f64>> = marks.iter().map(|m| target_at(&m.target)).collect();
    let aligned: Vec<Vector3<f64>> = match marks {
        [] => {
            let m = fit()?;
            let how = if conformal {
                "the Moebius transformation"
            } else {
                "the rotation"
            };
            notes.push(format!(
                "sphere: no landmark; source sphere moved by {how} that best matches a rough spatial correspondence (centroids and sizes)"
            ));
            source_sphere.iter().map(|s| m.apply(s)).collect()
        }
        [mark] => {
            let m = fit()?;
            let r = rotation_between(&m.apply(&s[0]), &t[0]);
            notes.push(format!(
                "sphere: moved so that landmark {} lands on its target, the rest by a rough spatial correspondence",
                mark.index
            ));
            source_sphere.iter().map(|s| r * m.apply(s)).collect()
        }
        _ => {
            let (moebius, used) = best_moebius(marks, &s, &t)?;
            notes.push(format!(
                "sphere: Moebius transformation taking landmarks {} onto their targets",
                used.iter()
                    .map(|&k| marks[k].index.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
            source_sphere
                .iter()
                .map(|p| moebius.apply(p).normalize())
                .collect()
        }
    };
    let images = if marks.is_empty() {
        aligned
    } else {
        match_on_sphere(source, &aligned, marks, &t, None, &[], notes)?.images
    };

    let domain = domain_mesh(
        target,
        target_sphere.iter().map(|v| Point3::from(*v)).collect(),
        Side::Target,
    )?;
    let points: Vec<Point3<f64>> = images.iter().map(|v| Point3::from(*v)).collect();
    let index = SurfaceIndex::new(&domain)?.with_threads(0);
    let (located, fallbacks) = compose::locate_radial(&index, &points)?;
    if fallbacks > 0 {
        notes.push(format!(
            "sphere: {fallbacks} source images were located by closest point instead of along the ray (quads or a target sphere map with inward faces)"
        ));
    }
    Ok(Routed {
        points: located,
        honoured: (0..marks.len()).collect(),
        domain: target_sphere,
    })
}

/// The registration `points` (a bijection of the spheres, the landmarks exact) bent on
/// the sphere so that `features` match (module `feature_match`): in the stereographic
/// chart of [`match_on_sphere`], with the landmarks held; `target_sphere` is the
/// target's sphere map.
pub(crate) fn match_features_after(
    source: &Mesh,
    target: &Mesh,
    target_sphere: &[Vector3<f64>],
    points: &[SurfacePoint],
    marks: &[Resolved],
    channels: &[Channel],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, FeatureMismatch), RegisterError> {
    let on_sphere = |p: &SurfacePoint| interpolate(target, target_sphere, p).normalize();
    let aligned: Vec<Vector3<f64>> = points.iter().map(on_sphere).collect();
    let targets: Vec<Vector3<f64>> = marks.iter().map(|m| on_sphere(&m.target)).collect();
    let domain = domain_mesh(
        target,
        target_sphere.iter().map(|v| Point3::from(*v)).collect(),
        Side::Target,
    )?;
    let index = SurfaceIndex::new(&domain)?.with_threads(0);
    let fields = || SphereFields {
        channels,
        target,
        target_sphere,
        sphere_index: &index,
    };
    let SphereMatch {
        mut images,
        mismatch: first,
        pole,
    } = match_on_sphere(
        source,
        &aligned,
        marks,
        &targets,
        Some(fields()),
        &[],
        notes,
    )?;
    let missing = || RegisterError::Features {
        reason: "the match on the sphere gave no mismatch".to_string(),
    };
    let mut mismatch = first.ok_or_else(missing)?;
    // A large held cap (few landmarks or none) is matched in a second chart, from the
    // face farthest from the first pole and the landmarks.
    if 0.5 * pole.clearance > LARGE_CAP {
        let again = match_on_sphere(
            source,
            &images,
            marks,
            &targets,
            Some(fields()),
            &[pole.centre],
            notes,
        )?;
        let second = again.mismatch.ok_or_else(missing)?;
        mismatch.after = second.after;
        mismatch.steps += second.steps;
        images = again.images;
    }
    let images: Vec<Point3<f64>> = images.iter().map(|v| Point3::from(*v)).collect();
    let (located, _) = compose::locate_radial(&index, &images)?;
    Ok((located, mismatch))
}

/// The Moebius transformation through three of the landmarks (from their source
/// sphere positions `s` to their targets' `t`) that brings all of them nearest their
/// targets (least sum of squared chordal distances), and the three (indices into
/// `marks`). With two landmarks the third pair is the poles of the great circles through
/// them, so the transformation fixes the pole and slides along the circle. Triples are
/// tried in order (all of them for up to 11 landmarks, else [`MOEBIUS_TRIALS`] spread
/// ones).
fn best_moebius(
    marks: &[Resolved],
    s: &[Vector3<f64>],
    t: &[Vector3<f64>],
) -> Result<(Moebius, Vec<usize>), RegisterError> {
    if let [_, _] = marks {
        let pole = |a: &Vector3<f64>, b: &Vector3<f64>| {
            let c = a.cross(b);
            if c.norm() > 0.0 { c.normalize() } else { c }
        };
        let moebius = Moebius::through(
            [s[0], s[1], pole(&s[0], &s[1])],
            [t[0], t[1], pole(&t[0], &t[1])],
        )
        .ok_or_else(|| coincident(&marks[1]))?;
        return Ok((moebius, vec![0, 1]));
    }
    let n = marks.len();
    let total = n * (n - 1) * (n - 2) / 6;
    let stride = total.div_ceil(MOEBIUS_TRIALS).max(1);
    let mut best: Option<(f64, Moebius, [usize; 3])> = None;
    let mut counter = 0usize;
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                counter += 1;
                if !(counter - 1).is_multiple_of(stride) {
                    continue;
                }
                let Some(m) = Moebius::through([s[a], s[b], s[c]], [t[a], t[b], t[c]]) else {
                    continue;
                };
                let cost: f64 = s
                    .iter()
                    .zip(t)
                    .map(|(p, q)| (m.apply(p).normalize() - q).norm_squared())
                    .sum();
                if cost.is_finite() && best.as_ref().is_none_or(|(c0, _, _)| cost < *c0) {
                    best = Some((cost, m, [a, b, c]));
                }
            }
        }
    }
    best.map(|(_, m, used)| (m, used.to_vec()))
        .ok_or_else(|| coincident(&marks[1]))
}

fn coincident(mark: &Resolved) -> RegisterError {
    RegisterError::Landmark {
        index: mark.index,
        vertex: mark.source,
        reason: "its position on the sphere coincides with (or is opposite to) another landmark's, so no Moebius transformation takes the landmarks onto their targets".to_string(),
    }
}

/// Every landmark matched on the sphere (module docs): `aligned` the source's sphere
/// positions after the alignment, `targets` the landmarks' targets on the sphere. The
/// returned positions are on the unit sphere, each landmark exactly at its target; with
/// `fields`, the features are matched in the same chart after the landmarks, and how
/// far is returned too.
///
/// # Errors
/// [`RegisterError::LandmarkFolds`] when the landmark-matching map still folds faces
/// after its steps; the errors of [`match_landmarks`].
fn match_on_sphere(
    source: &Mesh,
    aligned: &[Vector3<f64>],
    marks: &[Resolved],
    targets: &[Vector3<f64>],
    fields: Option<SphereFields<'_>>,
    avoid: &[Vector3<f64>],
    notes: &mut Vec<String>,
) -> Result<SphereMatch, RegisterError> {
    let chosen = pole_face(source, aligned, marks, targets, avoid);
    let Pole {
        face: pole,
        centre,
        clearance,
    } = chosen;
    let (corners, degree) = source.face_vertex_array(pole);
    let r = rotation_between(&centre, &Vector3::z());
    // Stereographic projection from the north pole, conjugated so that a face turning
    // counter-clockwise about the outward normal turns counter-clockwise in the chart.
    let chart = |p: &Vector3<f64>| {
        let q = r * p;
        Complex64::new(q.x, -q.y) / (1.0 - q.z)
    };
    // The cap about the pole within half the pole's clearance from the landmarks stays
    // where the alignment put it: the chart is bounded there, and the punctured face's
    // neighbourhood (where a chart blows up) is not solved for.
    let mut fixed: Vec<_> = source
        .vertices()
        .filter(|v| (aligned[v.idx()] - centre).norm() <= 0.5 * clearance)
        .chain(corners[..degree].iter().copied())
        .map(|v| (v, chart(&aligned[v.idx()])))
        .collect();
    fixed.sort_by_key(|(v, _)| *v);
    fixed.dedup_by_key(|(v, _)| *v);
    fixed.extend(marks.iter().zip(targets).map(|(m, t)| (m.source, chart(t))));
    let punctured = source
        .punctured(pole)
        .map_err(|error| RegisterError::Mesh {
            side: Side::Source,
            error,
        })?;
    // Every vertex of a closed surface has other faces: the ids are kept.
    debug_assert!(punctured.vertex_map().is_identity());
    let initial: Vec<Complex64> = aligned.iter().map(chart).collect();
    let mut map = if marks.is_empty() {
        initial
    } else {
        let matched =
            match_landmarks(&punctured, Frame::Face, &initial, &fixed, &[], Side::Source)?;
        let matched = matched.without_folds("sphere")?;
        notes.push(format!(
            "sphere: every landmark matched on the sphere in the chart from source face {} (mean |mu| of the matching {:.4}, {} smoothing steps)",
            source.face_to_input(pole),
            matched.mean_mu,
            matched.steps
        ));
        matched.map
    };
    let mut mismatch = None;
    if let Some(fields) = fields {
        // The target in the same chart, punctured at the face the pole falls in.
        let (at_pole, _) = compose::locate_radial(fields.sphere_index, &[Point3::from(centre)])?;
        let pole_face = at_pole.first().map_or(FaceId(0), |p| p.face);
        let punctured_target =
            fields
                .target
                .punctured(pole_face)
                .map_err(|error| RegisterError::Mesh {
                    side: Side::Target,
                    error,
                })?;
        let chart_target: Vec<Complex64> = fields.target_sphere.iter().map(chart).collect();
        let domain = domain_mesh(
            &punctured_target,
            planar_points(&chart_target),
            Side::Target,
        )?;
        let matched = match_features(
            &punctured,
            &map,
            &fixed,
            fields.channels,
            &domain,
            Side::Source,
        )?;
        notes.push(format!(
            "sphere: features matched in the chart from source face {}: mismatch {:.4} -> {:.4} (mean squared difference of the fields) in {} steps",
            source.face_to_input(pole),
            matched.before,
            matched.after,
            matched.steps
        ));
        mismatch = Some(FeatureMismatch {
            before: matched.before,
            after: matched.after,
            steps: matched.steps,
        });
        map = matched.map;
    }
    let back = r.transpose();
    let images = map
        .iter()
        .map(|f| {
            let w = f.conj();
            let n = w.norm_sqr();
            back * Vector3::new(2.0 * w.re, 2.0 * w.im, n - 1.0) / (n + 1.0)
        })
        .collect();
    Ok(SphereMatch {
        images,
        mismatch,
        pole: chosen,
    })
}

/// What [`match_on_sphere`] found: the images on the unit sphere, the fields' mismatch
/// (with fields) and the pole of its chart.
struct SphereMatch {
    images: Vec<Vector3<f64>>,
    mismatch: Option<FeatureMismatch>,
    pole: Pole,
}

/// The fields of a feature match on the sphere: the channels and the target with its
/// sphere map.
struct SphereFields<'a> {
    channels: &'a [Channel],
    target: &'a Mesh,
    target_sphere: &'a [Vector3<f64>],
    /// The index of the target's sphere polyhedron (its faces over `target_sphere`),
    /// made once for every chart's pole and the images at the end.
    sphere_index: &'a SurfaceIndex<'a>,
}

/// The face of a stereographic chart: its centroid direction on the sphere and the
/// chordal distance from there to the nearest landmark or landmark target.
#[derive(Debug, Clone, Copy)]
struct Pole {
    face: FaceId,
    centre: Vector3<f64>,
    clearance: f64,
}

/// The face whose sphere centroid is farthest from every landmark and every landmark
/// target (chordal distance), among the faces with no landmark corner (the last of
/// equals).
fn pole_face(
    source: &Mesh,
    aligned: &[Vector3<f64>],
    marks: &[Resolved],
    targets: &[Vector3<f64>],
    avoid: &[Vector3<f64>],
) -> Pole {
    let mut is_mark = vec![false; source.vertex_count()];
    for m in marks {
        is_mark[m.source.idx()] = true;
    }
    let points: Vec<Vector3<f64>> = marks
        .iter()
        .map(|m| aligned[m.source.idx()])
        .chain(targets.iter().copied())
        .chain(avoid.iter().copied())
        .collect();
    let mut best = (FaceId(0), Vector3::z(), f64::NEG_INFINITY);
    for f in source.faces() {
        let (vs, degree) = source.face_vertex_array(f);
        let c: Vector3<f64> = vs[..degree].iter().map(|v| aligned[v.idx()]).sum();
        let c = c.normalize();
        let squared = if vs[..degree].iter().any(|v| is_mark[v.idx()]) {
            f64::NEG_INFINITY
        } else {
            points
                .iter()
                .map(|p| (p - c).norm_squared())
                .fold(f64::INFINITY, f64::min)
        };
        if squared >= best.2 {
            best = (f, c, squared);
        }
    }
    Pole {
        face: best.0,
        centre: best.1,
        clearance: best.2.max(0.0).sqrt().min(2.0),
    }
}

/// The `sphere` initialization of `mesh` (its `conformal` start, or `tutte`) as unit
/// vectors, its notes added to `notes`; setting `cancel` stops it.
fn sphere(
    mesh: &Mesh,
    side: Side,
    conformal: bool,
    cancel: &Arc<AtomicBool>,
    notes: &mut Vec<String>,
) -> Result<Vec<Vector3<f64>>, RegisterError> {
    let mut problem = Problem::new(mesh, Target::Sphere);
    let start = if conformal { "conformal" } else { "tutte" };
    problem.options.set_text("start", start);
    let solution = Sphere
        .solve(
            &problem,
            &mut Context::new().with_cancel_flag(Arc::clone(cancel)),
        )
        .map_err(|error| RegisterError::Sphere { side, error })?;
    notes.extend(
        solution
            .report
            .notes
            .iter()
            .map(|n| format!("sphere map of the {side}: {n}")),
    );
    match solution.map() {
        Some(Map::Spatial(points)) => Ok(points.iter().map(|p| p.coords.normalize()).collect()),
        _ => Err(RegisterError::Sphere {
            side,
            error: SolverError::invalid(
                "sphere",
                "the sphere initialization returned no positions in space",
            ),
        }),
    }
}
