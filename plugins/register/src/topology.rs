//! The topology check that comes before any work.

use std::fmt;

use beltrami_mesh::Mesh;

use crate::error::{RegisterError, Side};

/// The topologies the initial map handles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topology {
    /// One component of genus 0 with one boundary loop: both meshes go onto the unit
    /// disk.
    Disk,
    /// One closed component of genus 0: both meshes go onto the unit sphere.
    Sphere,
    /// One closed component of genus 1: both meshes are cut into squares `[0, 1]^2` whose
    /// opposite sides are glued.
    Torus,
    /// One component of genus 0 with two or more boundary loops: both meshes are cut into
    /// disks along matched cut graphs, onto one polygon.
    MultiplyConnected,
    /// One component of genus 2 or more, or of genus 1 with boundary: cut along matched
    /// cut graphs as [`Topology::MultiplyConnected`].
    HigherGenus,
}

impl fmt::Display for Topology {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Topology::Disk => "disk",
            Topology::Sphere => "closed genus 0",
            Topology::Torus => "closed genus 1",
            Topology::MultiplyConnected => "genus 0 with several boundary loops",
            Topology::HigherGenus => "genus 1 with boundary, or genus 2 or more",
        })
    }
}

/// The counts that decide the topology of a mesh: connected components, and for a single
/// component its genus and number of boundary loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shape {
    /// Number of connected components.
    pub components: usize,
    /// Genus (of the first component when there are several).
    pub genus: i64,
    /// Number of boundary loops (of the whole mesh).
    pub boundary_loops: usize,
}

impl Shape {
    /// The counts of `mesh` (one pass over its elements).
    pub fn of(mesh: &Mesh) -> Self {
        let components = mesh.components();
        Self {
            components: components.len(),
            genus: components.first().map_or(0, |c| c.genus),
            boundary_loops: mesh.boundary_loop_count(),
        }
    }

    /// The supported topology these counts describe, if any.
    pub fn topology(&self) -> Option<Topology> {
        match (self.components, self.genus, self.boundary_loops) {
            (1, 0, 1) => Some(Topology::Disk),
            (1, 0, 0) => Some(Topology::Sphere),
            (1, 1, 0) => Some(Topology::Torus),
            (1, 0, _) => Some(Topology::MultiplyConnected),
            (1, _, _) => Some(Topology::HigherGenus),
            _ => None,
        }
    }
}

impl fmt::Display for Shape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.components != 1 {
            return write!(
                f,
                "a mesh of {} connected components with {} boundary loops",
                self.components, self.boundary_loops
            );
        }
        write!(
            f,
            "genus {} with {} boundary loop{}",
            self.genus,
            self.boundary_loops,
            if self.boundary_loops == 1 { "" } else { "s" }
        )
    }
}

/// Checks that `source` and `target` have the same topology and that it is one the
/// initial map supports: one connected component of any genus with any number of
/// boundary loops. Linear in the mesh sizes; no parameterization is computed.
///
/// # Errors
/// [`RegisterError::TopologyMismatch`] when the genus, the number of boundary loops or
/// the number of components differ (checked first, naming both), and
/// [`RegisterError::Unsupported`] for meshes of several components.
pub fn check_topology(source: &Mesh, target: &Mesh) -> Result<Topology, RegisterError> {
    let source_shape = Shape::of(source);
    let target_shape = Shape::of(target);
    if source_shape != target_shape {
        return Err(RegisterError::TopologyMismatch {
            source_shape,
            target_shape,
        });
    }
    source_shape.topology().ok_or(RegisterError::Unsupported {
        side: Side::Source,
        shape: source_shape,
    })
}
