#![warn(missing_docs)]
//! # beltrami-render
//!
//! Pictures of maps, written as PNG with no viewer needed: the parameter domain (uv
//! view), the surface in 3D (a small z-buffered rasterizer with Lambert shading), or
//! both side by side, with faces colored by `|mu|` (viridis, color bar), by a
//! checkerboard of the map's image (squares where the map is conformal) or plainly;
//! boundary loops drawn thick, flipped faces outlined in red; a legend with faces,
//! flips and mean/max `|mu|`. And histograms of `|mu|` over faces or area.
//!
//! Conventions:
//! - Pictures have their y axis **down** (row 0 at the top); drawings keep their own
//!   axes: x to the right, y up (uv and planar meshes), so a map looks as plotted.
//! - The 3D camera orbits the +y axis: azimuth and elevation in degrees
//!   ([`Camera`]); projection is orthographic.
//! - `|mu|` colors span a [`MuRange`], `[0, 1]` by default; values outside take the
//!   end colors.
//!
//! Dependencies (all permissive): `tiny-skia` (BSD-3-Clause) for antialiased lines and
//! shapes, `png` (MIT OR Apache-2.0) to encode (the `image` crate would only wrap it),
//! `font8x8` (MIT, public-domain glyphs) for text. The fills of both views go through the
//! small rasterizer of this crate ([`Raster`]): exact integer edge functions with a tie
//! rule (no cracks between neighbouring triangles, which per-triangle antialiased fills
//! would show), a z-buffer, and 2x2 supersampling for antialiasing.
//!
//! ```
//! use beltrami_mesh::{Mesh, Vector2, primitives::{self, Cells}};
//! use beltrami_render::{ColorBy, Layout, Scene, Size, Style, View, render};
//!
//! // The identity map of a planar grid, as texture coordinates.
//! let mesh = Mesh::from_soup(&primitives::grid(8, 8, Cells::Triangles)).unwrap();
//! let uv: Vec<Vector2<f64>> = mesh.positions().iter().map(|p| Vector2::new(p.x, p.y)).collect();
//! let image = Layout::plane_from_vertices(&mesh, &uv).unwrap();
//! let scene = Scene::new(&mesh, Some(image)).unwrap();
//! let style = Style { size: Size::new(400, 300).unwrap(), view: View::Uv, color: ColorBy::Checker, ..Style::default() };
//! let picture = render(&scene, &style).unwrap();
//! assert_eq!((picture.width(), picture.height()), (400, 300));
//! ```

mod camera;
mod colorbar;
pub mod colormap;
mod error;
mod figure;
pub mod histogram;
mod html;
mod legend;
mod picture;
mod raster3d;
mod scene;
mod shading;
mod size;
mod surface_view;
mod text;
mod uv_view;
mod viewport;

pub use camera::{Camera, ViewBasis};
pub use colormap::{MuRange, viridis};
pub use error::RenderError;
pub use figure::{ColorBy, Style, View, render};
pub use html::html_page;
pub use picture::{Picture, check_png_path};
pub use raster3d::{Fragment, Raster};
pub use scene::{FaceDistortion, Layout, Scene, corner_count};
pub use size::Size;
