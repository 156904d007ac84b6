#![warn(missing_docs)]
//! # beltrami-mesh
//!
//! The halfedge mesh under every beltrami solver: triangle and quad faces (mixed
//! allowed), validated on construction, with explicit boundary halfedges, circulators,
//! topology and geometry queries, and mesh IO (OBJ, PLY, STL, OFF, glTF/GLB).
//!
//! ```
//! use beltrami_mesh::{Mesh, PolygonSoup};
//! use nalgebra::Point3;
//!
//! // Two triangles forming the unit square.
//! let soup = PolygonSoup::from_triangles(
//!     vec![
//!         Point3::new(0.0, 0.0, 0.0),
//!         Point3::new(1.0, 0.0, 0.0),
//!         Point3::new(1.0, 1.0, 0.0),
//!         Point3::new(0.0, 1.0, 0.0),
//!     ],
//!     &[[0, 1, 2], [0, 2, 3]],
//! );
//! let mesh = Mesh::from_soup(&soup).unwrap();
//! assert_eq!(mesh.edge_count(), 5);
//! assert!(mesh.is_disk());
//! assert!((mesh.total_area() - 1.0).abs() < 1e-15);
//! ```
//!
//! Conventions (orientation, boundary halfedges, circulation order, face frames) are
//! stated in the docs of [`mesh`](crate::Mesh), [`circulators`], [`frame`] and
//! [`surface_point`].

mod build;
pub mod circulators;
pub mod closed_curve;
pub mod cut;
mod error;
pub mod frame;
mod geometry;
mod ids;
pub mod io;
mod mesh;
pub mod parallel;
mod point_insertion;
pub mod primitives;
mod puncture;
pub mod renumber;
mod soup;
pub mod subdivision;
pub mod surface_point;
mod topology;
mod vertex_map;

pub use build::{BuildOptions, BuildReport, MAX_COORDINATE, MIN_EXTENT, PRECISION_BITS, Repair};
pub use cut::{
    CutError, CutGraph, CutMesh, Generator, GeneratorKind, TorusSides, cut_along, cut_graph,
    cut_to_disk, shortest_path_tree, split_corners,
};
pub use error::MeshError;
pub use frame::FaceFrame;
pub use geometry::BoundingBox;
pub use ids::{BoundaryLoopId, ComponentId, EdgeId, FaceId, HalfedgeId, VertexId};
pub use mesh::Mesh;
pub use point_insertion::PointsInserted;
pub use renumber::{Renumbering, index_spread, renumber_breadth_first};
pub use soup::PolygonSoup;
pub use surface_point::{SurfacePoint, SurfacePointError};
pub use topology::{BoundaryLoop, Component};
pub use vertex_map::VertexMap;

pub use nalgebra::{Point3, Vector2, Vector3};
