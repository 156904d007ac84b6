#![warn(missing_docs)]
//! # beltrami-spatial
//!
//! Point location and motion on a target surface, for maps onto a mesh (beltrami-core's
//! `Map::OnMesh` stores one [`SurfacePoint`] per source vertex) and for the Beltrami flow
//! on target meshes, which moves every mapped vertex in its tangent plane and lands it
//! back on the target at each step.
//!
//! - [`SurfaceIndex`] ([`index`]): a kiddo kd-tree over samples of the faces, answering
//!   [`SurfaceIndex::locate`] with the **exact** closest point of the mesh (face and
//!   coordinates), proved by a search radius bound; batch versions process points in
//!   Morton order and take per-point face hints for warm starts.
//! - [`closest_point`]: exact closest points on segments, triangles (all Voronoi regions,
//!   robust for slivers and degenerate triangles) and bilinear quads.
//! - [`PolylineIndex`] ([`polyline`]): exact closest points on a polyline (a boundary
//!   loop or a feature curve the flow slides vertices along), by a kd-tree of pieces of
//!   its segments.
//! - [`frame`]: the tangent frame at a surface point from interpolated vertex normals.
//! - [`motion`]: moving a surface point by a tangent displacement, by walking along the
//!   surface (unfolding across edges, straightest continuation through vertices,
//!   stopping at or sliding along the boundary) or by projection.
//! - [`SpatialError`] ([`error`]): typed errors naming the bad point, face or item.
//!
//! Coordinates follow [`beltrami_mesh::surface_point`]: barycentric in face vertex order
//! for triangles, bilinear weights `((1-u)(1-v), u(1-v), u v, (1-u) v)` for quads.
//!
//! ```
//! use beltrami_mesh::primitives::{Cells, grid};
//! use beltrami_mesh::{Mesh, Point3, Vector3};
//! use beltrami_spatial::{MoveOptions, MoveOutcome, SurfaceIndex};
//!
//! let mesh = Mesh::from_soup(&grid(10, 10, Cells::Triangles)).unwrap();
//! let index = SurfaceIndex::new(&mesh).unwrap();
//!
//! // The closest point of the unit square to a point above it.
//! let located = index.locate(&Point3::new(0.25, 0.5, 2.0)).unwrap();
//! assert!((located.distance - 2.0).abs() < 1e-15);
//! assert_eq!(located.point.position(&mesh), located.position);
//!
//! // Walk 0.5 to the right: on a flat mesh, plain addition.
//! let moved = index
//!     .move_point(&located.point, &Vector3::new(0.5, 0.0, 0.0), &MoveOptions::default())
//!     .unwrap();
//! assert_eq!(moved.outcome, MoveOutcome::Arrived);
//! assert!((moved.position - Point3::new(0.75, 0.5, 0.0)).norm() < 1e-15);
//!
//! // The tangent frame there: (e1, e2, normal) orthonormal, normal = +z.
//! let frame = index.frame(&moved.point).unwrap();
//! assert!((frame.normal - Vector3::z()).norm() < 1e-15);
//! ```
//!
//! A flow step over all mapped vertices, with their previous faces as hints:
//!
//! ```
//! # use beltrami_mesh::primitives::icosphere;
//! # use beltrami_mesh::{Mesh, SurfacePoint, Vector2};
//! # use beltrami_spatial::{MoveOptions, SurfaceIndex};
//! let target = Mesh::from_soup(&icosphere(3)).unwrap();
//! let index = SurfaceIndex::new(&target).unwrap();
//! let mut images: Vec<SurfacePoint> = target
//!     .vertices()
//!     .map(|v| SurfacePoint::at_vertex(&target, v))
//!     .collect();
//! // Displacements (u_i, v_i) in each point's tangent frame (the flow's unknowns).
//! let steps: Vec<_> = images
//!     .iter()
//!     .map(|p| index.frame(p).unwrap().to_world(&Vector2::new(0.01, -0.02)))
//!     .collect();
//! let summary = index
//!     .move_all(&mut images, &steps, &MoveOptions::default())
//!     .unwrap();
//! assert_eq!(summary.arrived, images.len());
//! ```

pub mod boundary;
pub mod closest_point;
pub mod error;
pub mod frame;
pub mod index;
pub mod morton;
pub mod motion;
pub mod polyline;

pub use beltrami_mesh::SurfacePoint;
pub use error::SpatialError;
pub use frame::TangentFrame;
pub use index::{Located, SurfaceIndex};
pub use motion::{BoundaryMode, MoveMethod, MoveOptions, MoveOutcome, MoveSummary, Moved};
pub use polyline::{CORNER_TOLERANCE, Corner, OnPolyline, PolylineIndex};
