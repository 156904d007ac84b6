//! Typed indices of mesh elements.
//!
//! Every index is a `u32` newtype so that a vertex index can never be passed where a face
//! index is expected. Indices are dense: a mesh with `n` vertices has `VertexId(0)` to
//! `VertexId(n - 1)`. They index the halfedge mesh, which may differ from the input file's
//! order when unreferenced vertices were left out; [`crate::VertexMap`] converts.

use std::fmt;

macro_rules! typed_index {
    ($(#[$doc:meta])* $name:ident, $prefix:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
        pub struct $name(pub u32);

        impl $name {
            /// The index as a `usize`, for indexing slices.
            #[inline]
            pub const fn idx(self) -> usize {
                self.0 as usize
            }

            /// Builds the index from a `usize`.
            ///
            /// # Panics
            /// If `i` does not fit in a `u32`; meshes are limited to `u32::MAX` elements
            /// and the builder checks that before any index is made.
            #[inline]
            pub fn from_usize(i: usize) -> Self {
                Self(u32::try_from(i).expect("mesh element index exceeds u32::MAX"))
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }

        impl From<$name> for usize {
            #[inline]
            fn from(i: $name) -> usize {
                i.idx()
            }
        }
    };
}

typed_index!(
    /// A vertex of the halfedge mesh.
    VertexId,
    "v"
);
typed_index!(
    /// A directed halfedge. Interior halfedges belong to a face; boundary halfedges belong
    /// to a [`BoundaryLoopId`] and have the surface on their right.
    HalfedgeId,
    "h"
);
typed_index!(
    /// An undirected edge: a pair of twin halfedges.
    EdgeId,
    "e"
);
typed_index!(
    /// A triangle or quad face.
    FaceId,
    "f"
);
typed_index!(
    /// A boundary loop: a cycle of boundary halfedges, walked like a face.
    BoundaryLoopId,
    "b"
);
typed_index!(
    /// A connected component (faces connected through shared edges).
    ComponentId,
    "c"
);
