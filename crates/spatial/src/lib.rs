//! # beltrami-spatial
//!
//! stub
pub mod closest_point;
pub mod error;
pub mod frame;
pub mod index;
pub mod morton;
pub mod motion;

pub use error::SpatialError;
pub use frame::TangentFrame;
pub use index::{Located, SurfaceIndex};
pub use motion::{BoundaryMode, MoveMethod, MoveOptions, MoveOutcome, MoveSummary, Moved};
