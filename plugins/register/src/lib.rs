#![warn(missing_docs)]
//! # beltrami-register
//!
//! Surface registration: [`Register`] maps a source mesh onto a target mesh of the same
//! topology, bijectively and as conformally as the constraints allow (or with a
//! prescribed mu): the initial bijection below, then the discrete Beltrami flow on the
//! target mesh (the engine of `beltrami-flow-engine`, Wong-Zhao 2014, sections 4.5 and
//! 5.4).
//!
//! The initial bijection of surface registration (Wong-Zhao 2014, section 5.4): a map
//! from every vertex of a source mesh onto a target mesh of the same topology, built by
//! mapping both onto a common parameter domain and locating the source's images in the
//! target's parameterization.
//!
//! | topology | common domain | alignment |
//! |---|---|---|
//! | disk (one boundary loop) | the target's Tutte disk (module `disk`) | boundary rotation |
//! | closed genus 0 | the unit sphere (module `sphere`) | rotation or Moebius transformation |
//! | closed genus 1 | the square `[0, 1]^2` glued periodically (module `torus`) | symmetry of the square |
//! | any other (several boundary loops, genus 2 and more, genus 1 with boundary) | a polygon whose sides are the arcs of matched cut graphs (module `polygon`) | placement by landmarks or in space |
//!
//! Meshes of several components are refused by [`check_topology`] before any work, as
//! are meshes of different topologies.
//!
//! ```
//! use beltrami_mesh::{Mesh, primitives};
//! use beltrami_register::{Topology, initial_map};
//!
//! let source = Mesh::from_soup(&primitives::icosphere(2)).unwrap();
//! let target = Mesh::from_soup(&primitives::octahedral_sphere(3)).unwrap();
//! let map = initial_map(&source, &target, &[]).unwrap();
//! assert_eq!(map.topology, Topology::Sphere);
//! assert_eq!(map.points.len(), source.vertex_count());
//! assert_eq!(map.flipped(), 0);
//! ```
//!
//! See `docs/register.md` for the conventions, the choice of loops and the timings.

mod affine_alignment;
mod anderson;
mod compose;
mod consistency;
mod disk;
mod error;
mod feature_match;
mod inverse_consistency;
mod landmark_match;
mod landmarks;
mod modulus;
mod nonrigid_icp;
mod param;
mod polygon;
mod projection;
mod routing;
mod shape;
mod skeleton;
mod solver;
mod sphere;
mod sphere_alignment;
mod square_map;
mod topology;
mod torus;

use beltrami_core::{Features, Landmark};
use beltrami_fem::DistortionStats;
use beltrami_mesh::{Mesh, Point3, SurfacePoint};
use beltrami_spatial::SurfaceIndex;

use crate::feature_match::Channel;
use crate::landmarks::Resolved;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

pub use error::{RegisterError, Side};
pub use inverse_consistency::{InverseConsistency, inverse_consistency};
pub use modulus::{TorusPeriods, teichmueller_bound};
pub use solver::Register;
pub use topology::{Shape, Topology, check_topology};

/// An initial map from a source mesh onto a target mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialMap {
    /// The image of every source vertex (by source vertex id) as a point of the target
    /// mesh: a target face and its coordinates ([`SurfacePoint`] conventions).
    pub points: Vec<SurfacePoint>,
    /// The same images as positions: `points[i].position(target)`.
    pub positions: Vec<Point3<f64>>,
    /// Where each landmark goes, in the order given: its target vertex, or the closest
    /// point of the target to its point.
    pub landmark_targets: Vec<Point3<f64>>,
    /// The shared topology.
    pub topology: Topology,
    /// What was done, in words: the loops cut along (per mesh, lengths and input vertex
    /// indices), the alignment and the landmarks it honours, the flips.
    pub notes: Vec<String>,
    /// The map's distortion on the target: `|mu|` statistics and flipped faces, judged
    /// against the sum of the target's interpolated vertex normals at the images of each
    /// face's corners ([`SurfaceIndex::face_reference_normals`] with the fem kernel; a
    /// face is flipped where, at a quadrature point, the image's area element points
    /// against or orthogonal to it). No flips for a bijective map between well-shaped
    /// meshes.
    pub distortion: DistortionStats,
    /// The road to this map, in words: the common domain, where the landmarks are
    /// matched (a registration's report adds what followed).
    pub route: String,
    /// The smallest `sup |mu|` of any map homotopic to this one, when known: between
    /// two tori, from their conformal moduli in the markings the map pairs
    /// ([`teichmueller_bound`]).
    pub teichmueller_bound: Option<f64>,
    /// The target's parameterization, for a feature match after the flow.
    pub(crate) domain: TargetDomain,
    /// The landmarks as resolved on the target.
    pub(crate) marks: Vec<Resolved>,
}

impl InitialMap {
    /// The number of source faces whose image is flipped (`distortion.flipped`).
    pub fn flipped(&self) -> usize {
        self.distortion.flipped
    }
}

/// The initial bijection from `source` onto `target` (crate docs): both meshes onto a
/// common parameter domain chosen by their topology, aligned by the `landmarks` (or by a
/// rough spatial match when none apply), and each source vertex's image located in the
/// target's parameterization.
///
/// Landmarks that the alignment makes exact land exactly on their targets (a vertex
/// target gives the surface point of that vertex); the others are listed in the notes,
/// for the flow to honour.
///
/// # Errors
/// Topology errors of [`check_topology`] (before any work), [`RegisterError::Landmark`]
/// for a bad landmark (naming its index and vertex), and the wrapped errors of the
/// cuts, Tutte embeddings, the sphere initialization and point location.
pub fn initial_map(
    source: &Mesh,
    target: &Mesh,
    landmarks: &[Landmark],
) -> Result<InitialMap, RegisterError> {
    initial_map_for(source, target, landmarks, false, &Arc::default())
}

/// [`initial_map`], with both sphere maps conformal when `conformal_sphere` (the
/// start of a shape or feature match on the sphere) even without landmarks; setting
/// `cancel` (the caller's cancellation flag) stops the sphere maps.
pub(crate) fn initial_map_for(
    source: &Mesh,
    target: &Mesh,
    landmarks: &[Landmark],
    conformal_sphere: bool,
    cancel: &Arc<AtomicBool>,
) -> Result<InitialMap, RegisterError> {
    let topology = check_topology(source, target)?;
    let target_index = SurfaceIndex::new(target)?;
    let marks = landmarks::resolve(source, target, &target_index, landmarks)?;
    let mut notes = Vec::new();
    let mut teichmueller_bound = None;
    let route = route(topology, marks.len());
    let mut domain = TargetDomain::Other;
    let (mut points, honoured) = match topology {
        Topology::Disk => {
            let routed = disk::map(source, target, &marks, &mut notes)?;
            domain = TargetDomain::Disk(routed.domain);
            (routed.points, routed.honoured)
        }
        Topology::Sphere => {
            let routed = sphere::map(
                source,
                target,
                &target_index,
                &marks,
                conformal_sphere,
                cancel,
                &mut notes,
            )?;
            domain = TargetDomain::Sphere(routed.domain);
            (routed.points, routed.honoured)
        }
        Topology::Torus => {
            let torus = torus::map(source, target, &marks, &mut notes)?;
            teichmueller_bound = Some(torus.teichmueller_bound);
            (torus.points, torus.honoured)
        }
        Topology::MultiplyConnected | Topology::HigherGenus => {
            let cut = polygon::map_with_points(source, target, &target_index, &marks, &mut notes);
            if marks.is_empty() && target.boundary_loop_count() == 0 {
                projection::better(source, target, &target_index, cut, &mut notes)?
            } else {
                cut?
            }
        }
    };
    let mut exact = vec![false; marks.len()];
    for &m in &honoured {
        points[marks[m].source.idx()] = marks[m].target;
        exact[m] = true;
    }
    let positions: Vec<Point3<f64>> = points.iter().map(|p| p.position(target)).collect();
    let landmark_targets: Vec<Point3<f64>> =
        marks.iter().map(|m| m.target.position(target)).collect();
    for ((mark, &exact), goal) in marks.iter().zip(&exact).zip(&landmark_targets) {
        if !exact {
            let distance = (positions[mark.source.idx()] - goal).norm();
            notes.push(format!(
                "landmark {} (source vertex {}) is not enforced by the initial map: its image is {distance:.4e} from its target (left to the flow)",
                mark.index,
                source.vertex_map().to_input(mark.source)
            ));
        }
    }
    let distortion = compose::distortion(source, &target_index, &points, &positions)?;
    let flipped = distortion.flipped;
    notes.push(format!(
        "{flipped} of {} source faces flipped on the target",
        source.face_count()
    ));
    if flipped * 2 > source.face_count() {
        notes.push(
            "most faces are flipped: the two meshes are probably oriented oppositely (one has its normals inward)"
                .to_string(),
        );
    }
    Ok(InitialMap {
        points,
        positions,
        landmark_targets,
        topology,
        notes,
        distortion,
        route,
        teichmueller_bound,
        domain,
        marks,
    })
}

/// What a road of [`initial_map`] gives: the source's images on the target, the
/// landmarks it honours exactly (indices into the resolved landmarks) and the target's
/// parameterization it composed with.
pub(crate) struct Routed<D> {
    pub points: Vec<SurfacePoint>,
    pub honoured: Vec<usize>,
    pub domain: D,
}

/// The target's parameterization an initial map composed with, kept for a later
/// feature match.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum TargetDomain {
    /// The target's disk, per target vertex.
    Disk(Vec<num_complex::Complex64>),
    /// The target's sphere map, per target vertex.
    Sphere(Vec<beltrami_mesh::Vector3<f64>>),
    /// A road that keeps none.
    Other,
}

/// The registration `points` bent in the common domain of `initial` so that `features`
/// match, the landmarks held: on the disk and the sphere (see [`check_features`]); and
/// the fields' mismatch before and after.
///
/// # Errors
/// [`RegisterError::Features`] on another road; the errors of the matching.
pub(crate) fn match_features_after(
    source: &Mesh,
    target: &Mesh,
    initial: &InitialMap,
    points: &[SurfacePoint],
    channels: &[Channel],
    notes: &mut Vec<String>,
) -> Result<(Vec<SurfacePoint>, beltrami_core::FeatureMismatch), RegisterError> {
    let marks = &initial.marks;
    match &initial.domain {
        TargetDomain::Disk(param) => {
            disk::match_features_after(source, target, param, points, marks, channels, notes)
        }
        TargetDomain::Sphere(sphere) => {
            sphere::match_features_after(source, target, sphere, points, marks, channels, notes)
        }
        TargetDomain::Other => Err(RegisterError::Features {
            reason: "they are matched on disks and closed genus-0 surfaces".to_string(),
        }),
    }
}

/// Refuses fields to match (`features`, and the shape when `shape`) on a topology whose
/// road does not match them, or features that do not fit the meshes
/// ([`Features::check`]).
pub(crate) fn check_features(
    topology: Topology,
    features: Option<&Features>,
    shape: bool,
    source: &Mesh,
    target: &Mesh,
) -> Result<(), RegisterError> {
    if (features.is_some() || shape) && !matches!(topology, Topology::Disk | Topology::Sphere) {
        let what = if features.is_some() {
            "they are"
        } else {
            "the shape (match-shape) is"
        };
        return Err(RegisterError::Features {
            reason: format!(
                "{what} matched on disks and closed genus-0 surfaces; these meshes are {topology}"
            ),
        });
    }
    match features {
        Some(features) => features
            .check(source, target)
            .map_err(|reason| RegisterError::Features { reason }),
        None => Ok(()),
    }
}

/// The road of [`initial_map`] for `topology` with `landmarks` landmarks, in words: the
/// common domain and where the landmarks are matched (the registration adds what
/// follows the initial map).
fn route(topology: Topology, landmarks: usize) -> String {
    let matched = "every landmark matched in the domain";
    match topology {
        Topology::Sphere if landmarks > 0 => format!(
            "sphere: both meshes conformally onto the unit sphere, {matched} (a landmark-matching quasiconformal map in a stereographic chart), composed with the target's sphere map"
        ),
        Topology::Sphere => "sphere: both meshes onto the unit sphere, aligned by the Moebius transformation that best matches a rough spatial correspondence, composed with the target's sphere map".to_string(),
        Topology::Disk if landmarks > 0 => format!(
            "disk: both meshes onto the target's Tutte disk, the boundary laid between the boundary landmarks, {matched} with the boundary held"
        ),
        Topology::Disk => "disk: both meshes onto the target's Tutte disk, the boundary turned by a rough spatial match".to_string(),
        Topology::Torus if landmarks > 0 => format!(
            "torus: both meshes onto the square glued periodically, a symmetry of the square and a translation chosen by the landmarks, {matched} (a landmark-matching quasiconformal map on the torus, the seams glued)"
        ),
        Topology::Torus => "torus: both meshes onto the square glued periodically, a symmetry of the square chosen by a rough spatial match".to_string(),
        Topology::MultiplyConnected | Topology::HigherGenus if landmarks > 0 => "polygon: both meshes cut along matched cut graphs into one polygon, every landmark a corner of it (drawn on the target at its vertex, or at the vertex nearest to its point and moved onto the point)".to_string(),
        Topology::MultiplyConnected | Topology::HigherGenus => "polygon: both meshes cut along matched cut graphs into one polygon, placed in space".to_string(),
    }
}

/// Adds [`Register`] to `registry`.
pub fn register(registry: &mut beltrami_core::Registry) {
    registry.register(Box::new(Register));
}
