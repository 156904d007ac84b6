//! # beltrami-spatial
//!
//! stub
pub mod closest_point;
pub mod error;
pub mod frame;
pub mod index;

pub use error::SpatialError;
pub use index::{Located, SurfaceIndex};
