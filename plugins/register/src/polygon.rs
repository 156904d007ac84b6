//! Every other topology (genus 0 with several boundary loops, genus 1 with boundary,
//! genus 2 and more, closed or not): both meshes cut into disks along matched cut
//! graphs, and both disks onto one convex polygon with matched sides.
//!
//! The source is cut along its tree-cotree cut graph ([`beltrami_mesh::cut_graph`]:
//! the greedy shortest system of loops with the paths that join them and every
//! boundary loop), split into nodes and arcs ([`crate::skeleton`]); the target's cut
//! graph is drawn after it with the same nodes and arcs ([`crate::routing`]). Both cuts
//! are disks; when their boundaries read the same word (the same arcs in the same order
//! and directions, up to a cyclic shift) the gluing is the same, and otherwise the
//! registration is refused before any map is built ([`RegisterError::Seams`]).
//!
//! The target's disk boundary goes onto the unit circle by arc length, clockwise in
//! boundary order (`v_j -> exp(-2 pi i t_j)`), its interior by Tutte's embedding with
//! mean-value weights: a bijection onto the inscribed polygon `P`. Each side of the
//! source's disk (a copy of an arc, between two copies of nodes) goes onto the
//! matching side of `P` by the arc-length fraction along it: the source vertex at
//! fraction `phi` of its side lands where the target's side has fraction `phi`, linear
//! between the target's vertices there. The two copies of an arc are read with the same
//! fractions (`phi` and `1 - phi` the other way), so both copies of a seam vertex land
//! on the same target point, and the source's interior follows by Tutte's embedding
//! onto the same `P`. Locating the source's images in the target's embedding composes a
//! bijection with the inverse of another: a bijection of the surfaces, continuous
//! across the seams, orientation-preserving since both words are read with the surface
//! on the right.
//!
//! Landmarks pick the placement, the pairing of the boundary loops and the anchors
//! along them (see [`crate::routing`]). Every landmark is made a node of the cut graph
//! (one inside the surface at the tip of a slit, the shortest path joining it to the
//! cut graph), drawn on the other mesh at its partner's vertex: a corner of the
//! polygon, mapped exactly.

use std::f64::consts::TAU;

use beltrami_fem::BoundaryMap;
use beltrami_mesh::{Mesh, SurfacePoint, VertexId, cut_along, cut_graph, parallel};
use beltrami_spatial::SurfaceIndex;
use num_complex::Complex64;

use crate::compose;
use crate::error::{RegisterError, Side};
use crate::landmarks::Resolved;
use crate::param::{arc_fractions, domain_mesh, path_fractions, planar_points, tutte};
use crate::routing::{Drawing, Loops, Pin, forward_pins, pair_loops, refined_placement};
use crate::skeleton::{Skeleton, Word, with_slits};

/// [`map`] with every landmark's target point inside a target face made a vertex of
/// the target first ([`Mesh::with_points_inserted`]): the cut graphs are drawn through
/// it, so the landmark is a corner of the polygon at its very target; the images are
/// then read back on the target as given.
pub(crate) fn map_with_points(
    source: &Mesh,
    target: &Mesh,
    target_index: &SurfaceIndex<'_>,
    marks: &[Resolved],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, Vec<usize>), RegisterError> {
    let inside: Vec<SurfacePoint> = marks
        .iter()
        .filter(|m| m.vertex.is_none())
        .map(|m| m.target)
        .collect();
    if inside.is_empty() {
        return map(source, target, target_index, marks, notes);
    }
    let refined = target
        .with_points_inserted(&inside)
        .map_err(|error| RegisterError::Mesh {
            side: Side::Target,
            error,
        })?;
    let original = marks;
    let mut inserted = refined.vertices.iter();
    let marks: Vec<Resolved> = marks
        .iter()
        .map(|m| {
            let vertex = if m.vertex.is_none() {
                inserted.next().copied().flatten()
            } else {
                m.vertex
            };
            match vertex {
                Some(v) if m.vertex.is_none() => Resolved {
                    target: SurfacePoint::at_vertex(&refined.mesh, v),
                    vertex: Some(v),
                    ..*m
                },
                _ => *m,
            }
        })
        .collect();
    let added = refined.mesh.vertex_count() - target.vertex_count();
    let index = SurfaceIndex::new(&refined.mesh)?;
    let mut tried = Vec::new();
    match map(source, &refined.mesh, &index, &marks, &mut tried) {
        Ok((points, honoured)) => {
            notes.push(format!(
                "cut graphs: {added} landmark target points inside target faces made vertices of the target for the cuts"
            ));
            notes.append(&mut tried);
            let points = points.iter().map(|p| refined.to_original(p)).collect();
            Ok((points, honoured))
        }
        // An inserted vertex has three neighbours: a cut graph with a node of more arcs
        // there cannot be drawn; the nearest vertices take the points instead.
        Err(RegisterError::Seams { reason }) => {
            notes.push(format!(
                "cut graphs: drawn through the landmark target points made vertices, {reason}; drawn through the target vertices nearest to them instead"
            ));
            map(source, target, target_index, original, notes)
        }
        Err(error) => Err(error),
    }
}

/// The source's images on the target and the landmarks honoured exactly (indices into
/// `marks`): each landmark is a corner of the polygon, drawn on the target at its
/// target vertex or at the vertex nearest to its target point; the image is then moved
/// onto a target point next to it.
pub(crate) fn map(
    source: &Mesh,
    target: &Mesh,
    target_index: &SurfaceIndex<'_>,
    marks: &[Resolved],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, Vec<usize>), RegisterError> {
    // The pairing of the loops is the registration's, source onto target.
    let forward = forward_pins(source, target, marks);
    let source_loops = Loops::of(source);
    let target_loops = Loops::of(target);
    let (place, fitted) = refined_placement(source, target, target_index, &forward)?;
    let paired = pair_loops(source, target, &source_loops, &target_loops, marks, &place)?;

    // The cut graph is the coarser mesh's, drawn onto the finer one.
    let swapped = target.vertex_count() < source.vertex_count();
    let cut = if swapped {
        target_cut_drawn_on_source(
            [source, target],
            &forward,
            [&source_loops, &target_loops],
            &paired,
        )?
    } else {
        matched_cuts(
            [source, target],
            target_index,
            &forward,
            &place,
            [&source_loops, &target_loops],
            &paired,
        )?
    };
    notes.push(cut_graphs_note(
        [source, target],
        &cut,
        swapped,
        fitted,
        &paired,
    ));
    let points = polygon_images(source.vertex_count(), &cut, notes)?;
    let honoured = honoured_landmarks(target, marks, &points);
    Ok((points, honoured))
}

/// The matched cuts with the target's cut graph drawn onto the source (the target is
/// the coarser mesh), the source's roles and the target's exchanged back: the
/// landmarks and the loops' pairing read backwards, the placement fitted the other way.
fn target_cut_drawn_on_source(
    [source, target]: [&Mesh; 2],
    forward: &[Pin],
    [source_loops, target_loops]: [&Loops; 2],
    paired: &[usize],
) -> Result<MatchedCuts, RegisterError> {
    let backward: Vec<Pin> = forward
        .iter()
        .map(|p| Pin {
            from: p.onto,
            from_vertex: p.onto_vertex,
            onto: p.from,
            onto_vertex: p.from_vertex,
            ..*p
        })
        .collect();
    let mut inverse = vec![usize::MAX; paired.len()];
    for (s, &t) in paired.iter().enumerate() {
        inverse[t] = s;
    }
    let source_index = SurfaceIndex::new(source)?;
    let (place, _) = refined_placement(target, source, &source_index, &backward)?;
    Ok(matched_cuts(
        [target, source],
        &source_index,
        &backward,
        &place,
        [target_loops, source_loops],
        &inverse,
    )?
    .reversed())
}

/// The note on the cut graphs: whose was drawn onto whose, their size and lengths, the
/// placement (`fitted` to the landmarks or not) and the loops' pairing.
fn cut_graphs_note(
    [source, target]: [&Mesh; 2],
    cut: &MatchedCuts,
    swapped: bool,
    fitted: bool,
    paired: &[usize],
) -> String {
    let [source_skeleton, target_skeleton] = &cut.skeletons;
    let length = |mesh: &Mesh, skeleton: &Skeleton| -> f64 {
        skeleton
            .edges(mesh)
            .iter()
            .map(|&e| mesh.edge_length(e))
            .sum()
    };
    format!(
        "cut graphs: the {}'s, drawn onto the {}: {} nodes and {} arcs on each mesh (source length {:.6}, target {:.6}), a disk whose boundary has {} sides; placed by {}; boundary loops paired {}",
        if swapped { "target" } else { "source" },
        if swapped { "source" } else { "target" },
        source_skeleton.nodes.len(),
        source_skeleton.arcs.len(),
        length(source, source_skeleton),
        length(target, target_skeleton),
        cut.words[0].letters.len(),
        if fitted {
            "the similarity fitted to the landmarks"
        } else {
            "closest points (an affine map fitted from the centroids and sizes)"
        },
        if paired.is_empty() {
            "(none)".to_string()
        } else {
            paired
                .iter()
                .enumerate()
                .map(|(s, t)| format!("{s}->{t}"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    )
}

/// The images of the source's `n` vertices on the target (module docs): both cut disks
/// onto the target's inscribed polygon by Tutte's embedding, sides matched, the
/// source's images located in the target's embedding; an image outside is moved onto
/// it and noted.
fn polygon_images(
    n: usize,
    cut: &MatchedCuts,
    notes: &mut Vec<String>,
) -> Result<Vec<SurfacePoint>, RegisterError> {
    let [source_cut, target_cut] = &cut.cuts;
    let [source_word, target_word] = &cut.words;
    let angles: Vec<f64> = arc_fractions(target_cut, &target_word.vertices)
        .iter()
        .map(|&t| -TAU * t)
        .collect();
    let target_boundary = BoundaryMap {
        vertices: target_word.vertices.clone(),
        positions: angles
            .iter()
            .map(|&a| Complex64::from_polar(1.0, a))
            .collect(),
    };
    let boundary = source_boundary(
        source_cut,
        source_word,
        target_cut,
        target_word,
        &angles,
        cut.shift,
    );
    // The two Tutte maps are independent: both at once, on two cores.
    let (target_param, source_param) = parallel::join(
        || tutte(target_cut, &target_boundary, Side::Target),
        || tutte(source_cut, &boundary, Side::Source),
    );
    let target_param = target_param?;
    let radial = Radial::new(&angles).ok_or_else(|| RegisterError::Seams {
        reason: "one side of the target's cut disk is longer than half its boundary".to_string(),
    })?;
    let source_param = source_param?;
    let images: Vec<Complex64> = source_param[..n].iter().map(|&z| radial.apply(z)).collect();
    let domain = domain_mesh(target_cut, planar_points(&target_param), Side::Target)?;
    let (points, gap) = compose::locate(&domain, &planar_points(&images))?;
    if gap > 1e-12 {
        notes.push(format!(
            "cut graphs: the farthest source image was {gap:.3e} outside the target's polygon and was moved onto it"
        ));
    }
    Ok(points)
}

/// The landmarks honoured exactly (indices into `marks`). Every landmark is a node of
/// the cut graphs: on the target at its own vertex, or for a point inside a face at
/// the nearest vertex. A point target is then taken exactly when the vertex is a
/// corner of a face next to the point's (the move stays within the image's star; the
/// flow mends a fold it makes); a landmark drawn elsewhere is left to the flow, and
/// the registration fails if it is missed.
fn honoured_landmarks(target: &Mesh, marks: &[Resolved], points: &[SurfacePoint]) -> Vec<usize> {
    let near = |a: &SurfacePoint, b: &SurfacePoint| {
        a.face == b.face
            || target
                .face_vertices(a.face)
                .any(|v| target.face_vertices(b.face).any(|w| w == v))
    };
    marks
        .iter()
        .enumerate()
        .filter(|(_, mark)| near(&points[mark.source.idx()], &mark.target))
        .map(|(k, _)| k)
        .collect()
}

/// Both meshes' skeletons (numbered alike), cuts, words, and the shift of the second
/// word against the first ([`Word::shift_onto`]).
struct MatchedCuts {
    skeletons: [Skeleton; 2],
    cuts: [Mesh; 2],
    words: [Word; 2],
    shift: usize,
}

impl MatchedCuts {
    /// The same cuts with the two meshes' roles exchanged.
    fn reversed(self) -> Self {
        let [a, b] = self.skeletons;
        let [ca, cb] = self.cuts;
        let [wa, wb] = self.words;
        let m = wa.letters.len();
        Self {
            skeletons: [b, a],
            cuts: [cb, ca],
            words: [wb, wa],
            shift: (m - self.shift) % m.max(1),
        }
    }
}

/// The cut graph of `meshes[0]` (landmarks on its boundary loops made nodes) drawn onto
/// `meshes[1]` ([`crate::routing`]), both cuts, and their words, refused unless they
/// agree.
fn matched_cuts(
    [from, onto]: [&Mesh; 2],
    onto_index: &SurfaceIndex<'_>,
    pins: &[Pin],
    place: &crate::landmarks::SpatialMatch,
    [from_loops, onto_loops]: [&Loops; 2],
    paired: &[usize],
) -> Result<MatchedCuts, RegisterError> {
    let side = |mesh: &Mesh| {
        if std::ptr::eq(mesh, from) {
            Side::Source
        } else {
            Side::Target
        }
    };
    let graph = cut_graph(from);
    // Landmarks become nodes, corners of the polygon mapped exactly: those off the cut
    // graph at the tip of a slit joining them to it.
    let tips: Vec<VertexId> = pins.iter().filter_map(|p| p.from_vertex).collect();
    let edges = with_slits(from, &graph.edges, &tips);
    let skeleton = Skeleton::of(from, &edges, &tips);
    let from_cut = cut_along(from, &edges).map_err(|error| RegisterError::Cut {
        side: side(from),
        error,
    })?;
    let from_word = skeleton
        .word(from, &from_cut.0, &from_cut.1)
        .ok_or_else(|| RegisterError::Seams {
            reason: "a mesh's own cut graph does not cut it into a disk (please report this mesh)"
                .to_string(),
        })?;
    let drawn = Drawing {
        from,
        from_side: side(from),
        skeleton: &skeleton,
        onto,
        onto_index,
        pins,
        place,
        from_loops,
        onto_loops,
        paired,
    }
    .draw()?;
    let onto_cut = cut_along(onto, &drawn.edges(onto)).map_err(|error| RegisterError::Cut {
        side: side(onto),
        error,
    })?;
    let mismatch = || RegisterError::Seams {
        reason: format!(
            "the cut graph drawn on one mesh after the other's ({} nodes, {} arcs) does not cut it in the same pattern",
            skeleton.nodes.len(),
            skeleton.arcs.len()
        ),
    };
    let onto_word = drawn
        .word(onto, &onto_cut.0, &onto_cut.1)
        .ok_or_else(mismatch)?;
    let shift = from_word.shift_onto(&onto_word).ok_or_else(mismatch)?;
    Ok(MatchedCuts {
        skeletons: [skeleton, drawn],
        cuts: [from_cut.0, onto_cut.0],
        words: [from_word, onto_word],
        shift,
    })
}

/// The source disk's boundary on the unit circle: side `k` of the source's word onto
/// side `k + shift` of the target's, by arc-length fraction, each fraction between two
/// target vertices taken linearly in angle between theirs (module docs).
fn source_boundary(
    source_cut: &Mesh,
    source_word: &Word,
    target_cut: &Mesh,
    target_word: &Word,
    angles: &[f64],
    shift: usize,
) -> BoundaryMap {
    let m = source_word.letters.len();
    let n = target_word.vertices.len();
    let mut vertices: Vec<VertexId> = Vec::with_capacity(source_word.vertices.len());
    let mut positions = Vec::with_capacity(source_word.vertices.len());
    for k in 0..m {
        let side = source_word.side(k);
        let phi = path_fractions(source_cut, &side);
        let t = (k + shift) % m;
        let target_side = target_word.side(t);
        let psi = path_fractions(target_cut, &target_side);
        let start = target_word.starts[t];
        // Unwrapped, so that the side's angles decrease without a jump.
        let side_angles: Vec<f64> = (0..target_side.len())
            .map(|j| angles[start] - (angles[start] - angles[(start + j) % n]).rem_euclid(TAU))
            .collect();
        // The last vertex of a side is the first of the next one.
        for (&v, &f) in side.iter().zip(&phi).take(side.len() - 1) {
            vertices.push(v);
            positions.push(Complex64::from_polar(1.0, along(&psi, &side_angles, f)));
        }
    }
    BoundaryMap {
        vertices,
        positions,
    }
}

/// The value at fraction `f` of a piecewise linear function with `values` at the
/// increasing fractions `psi` (from 0 to 1).
fn along(psi: &[f64], values: &[f64], f: f64) -> f64 {
    let j = psi
        .partition_point(|&x| x <= f)
        .saturating_sub(1)
        .min(values.len().saturating_sub(2));
    let span = psi[j + 1] - psi[j];
    let lambda = if span > 0.0 {
        ((f - psi[j]) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    values[j] + (values[j + 1] - values[j]) * lambda
}

/// The inscribed polygon with vertices on the unit circle at `angles` (clockwise, as
/// the target's boundary), as a map of the closed unit disk onto it: `z = r e^{i theta}`
/// goes to `r rho(theta) e^{i theta}`, `rho(theta)` the distance from the origin to the
/// polygon's side in direction `theta`. A homeomorphism when the origin is inside the
/// polygon (every angular gap below pi); it moves a point on the circle at angle
/// `theta` between two vertices onto their chord, in the same way for every pair of
/// vertices the same angle apart.
struct Radial {
    /// The vertices' angles in `[0, 2 pi)`, increasing.
    angles: Vec<f64>,
}

impl Radial {
    fn new(angles: &[f64]) -> Option<Self> {
        let mut sorted: Vec<f64> = angles.iter().map(|a| a.rem_euclid(TAU)).collect();
        sorted.sort_by(f64::total_cmp);
        let widest = sorted
            .windows(2)
            .map(|w| w[1] - w[0])
            .chain(sorted.first().zip(sorted.last()).map(|(a, b)| a + TAU - b))
            .fold(0.0, f64::max);
        (sorted.len() >= 3 && widest < std::f64::consts::PI).then_some(Self { angles: sorted })
    }

    fn apply(&self, z: Complex64) -> Complex64 {
        let (r, theta) = z.to_polar();
        let theta = theta.rem_euclid(TAU);
        let n = self.angles.len();
        let j = self.angles.partition_point(|&a| a <= theta);
        let (a, b) = if j == 0 || j == n {
            (self.angles[n - 1], self.angles[0] + TAU)
        } else {
            (self.angles[j - 1], self.angles[j])
        };
        let theta = if theta < a { theta + TAU } else { theta };
        // Distance to the chord between the unit vectors at a and b along theta.
        let rho = ((b - a) * 0.5).cos() / (theta - (a + b) * 0.5).cos();
        Complex64::from_polar(r * rho, theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn along_interpolates_between_the_enclosing_vertices() {
        let psi = [0.0, 0.25, 1.0];
        let values = [0.0, 1.0, 4.0];
        assert_eq!(along(&psi, &values, 0.0), 0.0);
        assert_eq!(along(&psi, &values, 1.0), 4.0);
        assert!((along(&psi, &values, 0.125) - 0.5).abs() < 1e-15);
        assert!((along(&psi, &values, 0.625) - 2.5).abs() < 1e-15);
    }

    #[test]
    fn the_radial_map_takes_the_circle_onto_the_inscribed_polygon() {
        let angles: Vec<f64> = [0.0, -1.0, -2.5, -4.0, -5.5].to_vec();
        let radial = Radial::new(&angles).unwrap();
        let corner = |a: f64| Complex64::from_polar(1.0, a);
        for w in angles.windows(2) {
            // Vertices stay; a point of the arc lands on the chord, symmetric about its middle.
            assert!((radial.apply(corner(w[0])) - corner(w[0])).norm() < 1e-12);
            for lambda in [0.1, 0.5, 0.8] {
                let z = radial.apply(corner(w[0] + (w[1] - w[0]) * lambda));
                let (p, q) = (corner(w[0]), corner(w[1]));
                let cross = ((q - p).conj() * (z - p)).im;
                assert!(cross.abs() < 1e-12, "on the chord");
                let mirrored = radial.apply(corner(w[1] + (w[0] - w[1]) * lambda));
                assert!(((z - p).norm() - (mirrored - q).norm()).abs() < 1e-12);
            }
            // The centre stays and radii scale.
            let z = radial.apply(corner(w[0] + 0.3 * (w[1] - w[0])) * 0.5);
            let on_chord = radial.apply(corner(w[0] + 0.3 * (w[1] - w[0])));
            assert!((z - on_chord * 0.5).norm() < 1e-12);
        }
        assert!(Radial::new(&[0.0, 0.5, 1.0]).is_none(), "origin outside");
    }
}
