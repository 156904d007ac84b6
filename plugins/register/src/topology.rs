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
}

impl fmt::Display for Topology {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Topology::Disk => "disk",
            Topology::Sphere => "closed genus 0",
            Topology::Torus => "closed genus 1",
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
/// initial map supports: a disk, a closed genus-0 or a closed genus-1 surface, each one
/// connected component. Linear in the mesh sizes; no parameterization is computed.
///
/// # Errors
/// [`RegisterError::TopologyMismatch`] when the genus, the number of boundary loops or
/// the number of components differ (checked first, naming both), and
/// [`RegisterError::Unsupported`] for a shared topology outside the three cases.
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
