//! Closed genus 1: both meshes cut into squares with matched sides, composed on the
//! torus `R^2 / Z^2`.
//!
//! [`beltrami_mesh::cut_to_disk`] cuts a torus along a figure-eight through one vertex:
//! `a`, the shortest loop of the greedy shortest homotopy basis (Erickson-Whittlesey
//! weights of the tree-cotree decomposition), and `b`, the shortest loop that crosses
//! `a` once. The cut mesh is a disk whose boundary (surface on its right) reads
//! `a, b, a^-1, b^-1`. It goes onto the unit square clockwise:
//!
//! ```text
//! a:     (0, s)      s from 0 to 1      (u = 0, upwards)
//! b:     (s, 1)      s from 0 to 1      (v = 1, rightwards)
//! a^-1:  (1, 1 - s)                     (u = 1, downwards)
//! b^-1:  (1 - s, 0)                     (v = 0, leftwards)
//! ```
//!
//! with `s` the arc-length fraction along the side, computed once for `a` and `b` and
//! reused for the copies on `a^-1` and `b^-1`, so that the two copies of every seam
//! vertex differ by exactly `(1, 0)` or `(0, 1)`: the map is continuous on the torus.
//! The interior follows by Tutte's embedding (a bijection onto the square), so each
//! mesh's square, glued periodically, is a homeomorphism of the torus onto
//! `R^2 / Z^2` taking `a` to the first and `b` to the second lattice direction.
//!
//! The composed map is `z -> L z + s (mod 1)` on the squares ([`SquareMap`]), with `L` an
//! integer matrix of determinant 1 (module `square_map`): `L` fixes the homotopy class
//! (which target loops the source's `a` and `b` go to), and both squares run in the same
//! rotational sense, so the map preserves orientation.
//!
//! - Without landmarks, the class is the one of least Teichmueller bound (module
//!   `modulus`: the conformal moduli of both meshes, every `L` with entries up to 2),
//!   so that the flow starts in the class where the least distorted map lives. When
//!   pairing `a` with `a` and `b` with `b` is within 0.01 of the least it is kept (with
//!   its half turn); otherwise every class within 0.01 of the least is a candidate. The
//!   candidate and one of 8 x 8 translations that best match the two meshes in space
//!   (sum of squared distances, over up to 512 source vertices, between a vertex moved
//!   by the rough spatial match and its image) are taken. Two meshes of one surface
//!   have a class of bound near 0; a shortest loop that is conformally the long way
//!   round (the kitten's `a` against Bob's) is paired with the other mesh's other loop.
//! - With one landmark: `L` the identity and the translation that takes the landmark
//!   onto its target; with more, the quarter turn (any of four, so a landmark set may
//!   pair `a` with the target's `b`) with the smallest periodic distances of the other
//!   landmarks to their targets.
//!
//! The notes give the pairing, both moduli and the bound of the class taken.

use beltrami_fem::{BoundaryMap, Frame};
use beltrami_mesh::{CutMesh, Mesh, Point3, SurfacePoint, VertexId, cut_to_disk, parallel};
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::compose;
use crate::error::{RegisterError, Side};
use crate::landmark_match::{Glue, Matched, match_landmarks};
use crate::landmarks::{Resolved, SpatialMatch, interpolate};
use crate::modulus::{TorusPeriods, periods, teichmueller_bound};
use crate::param::{domain_mesh, each_mesh, input_indices, path_fractions, planar_points, tutte};
use crate::square_map::{LatticeMap, SquareMap, periodic_distance};

/// Translations per direction tried without landmarks.
const SHIFTS: usize = 8;

/// Homotopy classes tried without landmarks: lattice maps with entries of at most this
/// size (module `square_map`).
const CLASS_ENTRIES: i32 = 2;

/// Classes whose Teichmueller bounds differ by less than this are told apart by the
/// spatial match; pairing `a` with `a` is kept when it is that close to the least.
const CLASS_TIE: f64 = 0.01;

/// Source vertices used to score the translations at most.
const SCORE_SAMPLES: usize = 512;

/// A landmark whose image is this close to its target (in the square) counts as honoured.
const HONOURED: f64 = 1e-9;

/// A torus cut into its square.
pub(crate) struct Square {
    pub(crate) cut: CutMesh,
    /// Parameter of every cut-mesh vertex in `[0, 1]^2`.
    pub(crate) param: Vec<Complex64>,
}

/// The initial map between two tori.
pub(crate) struct TorusMap {
    /// The source's images on the target.
    pub(crate) points: Vec<SurfacePoint>,
    /// The landmarks honoured exactly (indices into `marks`).
    pub(crate) honoured: Vec<usize>,
    /// The Teichmueller bound of the map's homotopy class (module `modulus`).
    pub(crate) teichmueller_bound: f64,
}

/// The source's images on the target, the landmarks honoured exactly and the
/// Teichmueller bound of the map's homotopy class.
pub(crate) fn map(
    source: &Mesh,
    target: &Mesh,
    marks: &[Resolved],
    notes: &mut Vec<String>,
) -> Result<TorusMap, RegisterError> {
    // Each mesh's square and periods are its own: both meshes at once, on two cores.
    let (source_square, target_square) = each_mesh(source, target, notes, square)?;
    let domain = domain_mesh(
        &target_square.cut.mesh,
        planar_points(&target_square.param),
        Side::Target,
    )?;
    let s_param = &source_square.param[..source.vertex_count()];
    let (source_periods, target_periods) =
        both_periods(source, target, &source_square, &target_square)?;
    let tau = source_periods.tau();

    // Each landmark's target in the target's square.
    let t: Vec<Complex64> = marks
        .iter()
        .map(|m| interpolate(&target_square.cut.mesh, &target_square.param, &m.target))
        .collect();
    let (map, honoured) = if marks.is_empty() {
        let map = map_by_space(
            source,
            target,
            &domain,
            s_param,
            tau,
            &target_periods,
            notes,
        )?;
        (map, Vec::new())
    } else {
        map_by_landmarks(marks, s_param, &t, notes)?
    };
    let (images, honoured): (Vec<Complex64>, Vec<usize>) = if honoured.len() < marks.len() {
        let matched = match_on_torus(&source_square, source.vertex_count(), &map, marks, &t)?;
        notes.push(format!(
            "torus: {} landmarks not placed by the symmetry matched on the torus ({} smoothing steps)",
            marks.len() - honoured.len(),
            matched.steps
        ));
        let wrapped = matched.map[..source.vertex_count()]
            .iter()
            .map(|z| Complex64::new(z.re.rem_euclid(1.0), z.im.rem_euclid(1.0)))
            .collect();
        (wrapped, (0..marks.len()).collect())
    } else {
        (s_param.iter().map(|&x| map.apply(x)).collect(), honoured)
    };
    let (points, gap) = compose::locate(&domain, &planar_points(&images))?;
    if gap > 1e-12 {
        notes.push(format!(
            "torus: the farthest source image was {gap:.3e} outside the target's square and was moved onto it"
        ));
    }
    let tau_target = target_periods.tau_in(&map.linear);
    let bound = teichmueller_bound(tau, tau_target);
    notes.push(format!(
        "torus: conformal moduli (periods of a over b) {:.5}{:+.5}i (source) and {:.5}{:+.5}i (target, in the loops the map pairs with the source's): every map in this homotopy class has sup |mu| >= {bound:.5} (Teichmueller bound)",
        tau.re, tau.im, tau_target.re, tau_target.im
    ));
    Ok(TorusMap {
        points,
        honoured,
        teichmueller_bound: bound,
    })
}

/// The periods of both meshes' squares (module `modulus`): independent, so both at
/// once, on two cores.
fn both_periods(
    source: &Mesh,
    target: &Mesh,
    source_square: &Square,
    target_square: &Square,
) -> Result<(TorusPeriods, TorusPeriods), RegisterError> {
    let (source_periods, target_periods) = parallel::join(
        || {
            periods(
                source,
                &source_square.cut,
                &source_square.param,
                Side::Source,
            )
        },
        || {
            periods(
                target,
                &target_square.cut,
                &target_square.param,
                Side::Target,
            )
        },
    );
    Ok((source_periods?, target_periods?))
}

/// The map of the squares without landmarks (module docs): of the classes of least
/// Teichmueller bound, the one and the translation that best match the meshes in
/// space; the choice is noted.
fn map_by_space(
    source: &Mesh,
    target: &Mesh,
    domain: &Mesh,
    s_param: &[Complex64],
    tau: Complex64,
    target_periods: &TorusPeriods,
    notes: &mut Vec<String>,
) -> Result<SquareMap, RegisterError> {
    let (candidates, identity) = least_distortion_classes(tau, target_periods);
    let map = best_by_space(source, target, domain, s_param, &candidates)?;
    notes.push(format!(
        "torus: no landmark; {} (the homotopy class of least Teichmueller bound{}), translation ({:.3}, {:.3}) of the square chosen by a rough spatial match",
        map.linear.describe(),
        if candidates.contains(&LatticeMap::IDENTITY) {
            String::new()
        } else {
            format!("; pairing a with a and b with b would have {identity:.4}")
        },
        map.shift.re,
        map.shift.im
    ));
    Ok(map)
}

/// The map of the squares from the landmarks (module docs), `s_param` the source's
/// square and `t` the landmarks' targets in the target's: the quarter turn and
/// translation with the smallest periodic distances, and the landmarks it honours
/// exactly; the choice is noted.
fn map_by_landmarks(
    marks: &[Resolved],
    s_param: &[Complex64],
    t: &[Complex64],
    notes: &mut Vec<String>,
) -> Result<(SquareMap, Vec<usize>), RegisterError> {
    let s: Vec<Complex64> = marks.iter().map(|m| s_param[m.source.idx()]).collect();
    let turns: &[u8] = if marks.len() == 1 {
        &[0]
    } else {
        &[0, 1, 2, 3]
    };
    let mut best: Option<(f64, SquareMap)> = None;
    for &quarter_turns in turns {
        let mut map = SquareMap {
            linear: LatticeMap::quarter_turns(quarter_turns),
            shift: Complex64::new(0.0, 0.0),
        };
        map.shift = t[0] - map.turn(s[0]);
        let residual: f64 = s
            .iter()
            .zip(t)
            .skip(1)
            .map(|(&a, &b)| periodic_distance(map.apply(a), b))
            .sum();
        if best.is_none_or(|(r, _)| residual < r - 1e-12) {
            best = Some((residual, map));
        }
    }
    let Some((_, map)) = best else {
        return Err(RegisterError::NoSquare { side: Side::Source });
    };
    let honoured: Vec<usize> = (0..marks.len())
        .filter(|&k| periodic_distance(map.apply(s[k]), t[k]) <= HONOURED)
        .collect();
    notes.push(format!(
        "torus: {} and translation ({:.4}, {:.4}) of the square from the landmarks ({} of {} honoured exactly)",
        map.linear.describe(),
        map.shift.re,
        map.shift.im,
        honoured.len(),
        marks.len(),
    ));
    Ok((map, honoured))
}

/// The source's square bent so that every landmark lands on its target `targets[k]`
/// (points of the target's square), on the torus itself: the map `x -> L x + s` of
/// `map` unwrapped on the source's cut mesh (no reduction mod 1), the two copies of
/// every seam vertex glued at their lattice offset, each landmark fixed at the lattice
/// translate of its target nearest to its image, and the landmark-matching map of
/// module `landmark_match` solved with these unknowns. The map returned is on the
/// cut mesh, unwrapped; `n` is the source's vertex count (the cut mesh's first `n`
/// vertices are the source's).
///
/// # Errors
/// [`RegisterError::LandmarkFolds`] when the matching leaves flipped faces; the errors
/// of [`match_landmarks`].
fn match_on_torus(
    square: &Square,
    n: usize,
    map: &SquareMap,
    marks: &[Resolved],
    targets: &[Complex64],
) -> Result<Matched, RegisterError> {
    let unwrapped: Vec<Complex64> = square
        .param
        .iter()
        .map(|&x| map.turn(x) + map.shift)
        .collect();
    let lattice = |z: Complex64| Complex64::new(z.re.round(), z.im.round());
    let glued: Vec<Glue> = square
        .cut
        .mesh
        .vertices()
        .skip(n)
        .map(|copy| {
            let original = square.cut.original_vertex(copy);
            Glue {
                a: original,
                b: copy,
                offset: lattice(unwrapped[copy.idx()] - unwrapped[original.idx()]),
            }
        })
        .collect();
    let fixed: Vec<(VertexId, Complex64)> = marks
        .iter()
        .zip(targets)
        .map(|(m, &t)| (m.source, t + lattice(unwrapped[m.source.idx()] - t)))
        .collect();
    let matched = match_landmarks(
        &square.cut.mesh,
        Frame::Face,
        &unwrapped,
        &fixed,
        &glued,
        Side::Source,
    )?;
    let matched = matched.without_folds("torus")?;
    Ok(matched)
}

/// The homotopy classes a map without landmarks chooses from, and the Teichmueller
/// bound of pairing `a` with `a`: the classes (lattice maps with entries up to
/// `CLASS_ENTRIES`) whose bound is within `CLASS_TIE` of the least, or the identity and
/// its half turn when the identity is among them (the loops' own pairing is kept when it
/// costs nothing).
fn least_distortion_classes(tau: Complex64, target: &TorusPeriods) -> (Vec<LatticeMap>, f64) {
    let bound_of = |linear: &LatticeMap| teichmueller_bound(tau, target.tau_in(linear));
    let classes: Vec<(f64, LatticeMap)> = LatticeMap::all_within(CLASS_ENTRIES)
        .map(|linear| (bound_of(&linear), linear))
        .collect();
    let least = classes.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
    let identity = bound_of(&LatticeMap::IDENTITY);
    let candidates = if identity <= least + CLASS_TIE {
        vec![LatticeMap::IDENTITY, LatticeMap::quarter_turns(2)]
    } else {
        classes
            .iter()
            .filter(|c| c.0 <= least + CLASS_TIE)
            .map(|c| c.1)
            .collect()
    };
    (candidates, identity)
}

/// Cuts `mesh` and maps it onto the unit square (module docs), noting the loops.
pub(crate) fn square(
    mesh: &Mesh,
    side: Side,
    notes: &mut Vec<String>,
) -> Result<Square, RegisterError> {
    let cut = cut_to_disk(mesh).map_err(|error| RegisterError::Cut { side, error })?;
    let sides = cut
        .torus_sides
        .clone()
        .ok_or(RegisterError::NoSquare { side })?;
    for (name, generator) in ["a", "b"].iter().zip(&cut.cut.generators) {
        notes.push(format!(
            "torus: {side} loop {name}: length {:.6}, {} vertices (input indices) {:?}",
            generator.length,
            generator.halfedges.len(),
            input_indices(mesh, &generator.vertices(mesh))
        ));
    }
    let a = cut.path_vertices(sides.a.clone());
    let b = cut.path_vertices(sides.b.clone());
    let a_inv = cut.path_vertices(sides.a_inv.clone());
    let b_inv = cut.path_vertices(sides.b_inv.clone());
    let fa = path_fractions(&cut.mesh, &a);
    let fb = path_fractions(&cut.mesh, &b);
    let same = |x: &[VertexId], y: &[VertexId]| {
        x.len() == y.len()
            && x.iter()
                .zip(y.iter().rev())
                .all(|(&p, &q)| cut.original_vertex(p) == cut.original_vertex(q))
    };
    if !same(&a, &a_inv) || !same(&b, &b_inv) {
        return Err(RegisterError::NoSquare { side });
    }
    let mut vertices = Vec::with_capacity(cut.boundary.len());
    let mut positions = Vec::with_capacity(cut.boundary.len());
    let na = a.len() - 1;
    let nb = b.len() - 1;
    for k in 0..na {
        vertices.push(a[k]);
        positions.push(Complex64::new(0.0, fa[k]));
    }
    for k in 0..nb {
        vertices.push(b[k]);
        positions.push(Complex64::new(fb[k], 1.0));
    }
    for k in 0..na {
        vertices.push(a_inv[k]);
        positions.push(Complex64::new(1.0, fa[na - k]));
    }
    for k in 0..nb {
        vertices.push(b_inv[k]);
        positions.push(Complex64::new(fb[nb - k], 0.0));
    }
    let param = tutte(
        &cut.mesh,
        &BoundaryMap {
            vertices,
            positions,
        },
        side,
    )?;
    Ok(Square { cut, param })
}

/// The linear part (of `candidates`) and translation (of `SHIFTS^2`) whose images best
/// match the source in space (module docs).
fn best_by_space(
    source: &Mesh,
    target: &Mesh,
    domain: &Mesh,
    s_param: &[Complex64],
    candidates: &[LatticeMap],
) -> Result<SquareMap, RegisterError> {
    let spatial = SpatialMatch::new(source, target);
    let step = source.vertex_count().div_ceil(SCORE_SAMPLES).max(1);
    let samples: Vec<VertexId> = source.vertices().step_by(step).collect();
    let moved: Vec<Point3<f64>> = samples
        .iter()
        .map(|&v| spatial.to_target(&source.position(v)))
        .collect();
    let index = SurfaceIndex::new(domain)?;
    let mut best = (
        f64::INFINITY,
        SquareMap {
            linear: LatticeMap::IDENTITY,
            shift: Complex64::new(0.0, 0.0),
        },
    );
    for &linear in candidates {
        for i in 0..SHIFTS {
            for j in 0..SHIFTS {
                let map = SquareMap {
                    linear,
                    shift: Complex64::new(i as f64, j as f64) / SHIFTS as f64,
                };
                let images: Vec<Point3<f64>> = samples
                    .iter()
                    .map(|v| {
                        let z = map.apply(s_param[v.idx()]);
                        Point3::new(z.re, z.im, 0.0)
                    })
                    .collect();
                let located = index.locate_all(&images)?;
                let cost: f64 = located
                    .iter()
                    .zip(&moved)
                    .map(|(l, p)| (l.point.position(target) - p).norm_squared())
                    .sum();
                if cost < best.0 {
                    best = (cost, map);
                }
            }
        }
    }
    Ok(best.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn periods_of(tau: Complex64) -> TorusPeriods {
        TorusPeriods {
            a: tau,
            b: Complex64::new(1.0, 0.0),
        }
    }

    #[test]
    fn equal_moduli_keep_the_loops_own_pairing() {
        let tau = Complex64::new(0.01, 0.46);
        let (classes, identity) = least_distortion_classes(tau, &periods_of(tau));
        assert_eq!(
            classes,
            [LatticeMap::IDENTITY, LatticeMap::quarter_turns(2)]
        );
        assert!(identity < 1e-15);
    }

    #[test]
    fn a_target_whose_loop_a_is_conformally_long_is_turned() {
        // The kitten (tau = 0.458 i) onto Bob, whose shortest loop is the conformally
        // long one (tau = 1.794 i): pairing a with a has bound 0.593; a quarter turn
        // compares 0.458 i with -1 / 1.794 i = 0.557 i, bound 0.098.
        let (classes, identity) = least_distortion_classes(
            Complex64::new(0.0, 0.458),
            &periods_of(Complex64::new(0.0, 1.794)),
        );
        assert!((identity - 0.5932).abs() < 1e-3, "{identity}");
        assert_eq!(classes.len(), 2, "{classes:?}");
        assert!(classes.contains(&LatticeMap::quarter_turns(1)));
        assert!(classes.contains(&LatticeMap::quarter_turns(3)));
    }

    #[test]
    fn a_sheared_target_is_sheared_back() {
        // The same torus read in the loops a + b and b: the class a -> a - b undoes it.
        let tau = Complex64::new(0.1, 1.3);
        let sheared = periods_of(tau + 1.0);
        let (classes, identity) = least_distortion_classes(tau, &sheared);
        assert!(identity > 0.3, "{identity}");
        assert!(
            classes.contains(&LatticeMap([[1, -1], [0, 1]])),
            "{classes:?}"
        );
        for linear in &classes {
            assert!(teichmueller_bound(tau, sheared.tau_in(linear)) < 1e-12);
        }
    }
}
