//! Mesh IO.
