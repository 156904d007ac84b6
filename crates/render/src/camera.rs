//! The orbit camera of the 3D view: azimuth and elevation in degrees around the +y axis
//! (up, as in glTF and most OBJ files), orthographic projection.

use std::fmt;
use std::str::FromStr;

use beltrami_mesh::{Point3, Vector3};

use crate::RenderError;

/// Where the 3D view looks from, in degrees.
///
/// The camera sits on a sphere around the surface's bounding-box center and looks at it.
/// `azimuth` turns it about the +y axis, from +z towards +x; `elevation` lifts it above
/// the x-z plane (towards +y). `(0, 0)` looks along -z with +x to the right and +y up,
/// so a mesh in the plane z = 0 appears as in its own coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Camera {
    /// Turn about +y in degrees, from +z towards +x.
    pub azimuth: f64,
    /// Height above the x-z plane in degrees, in [-90, 90].
    pub elevation: f64,
}

impl Camera {
    /// A camera, checked: finite angles, elevation in [-90, 90].
    pub fn new(azimuth: f64, elevation: f64) -> Result<Self, RenderError> {
        if !(azimuth.is_finite() && elevation.is_finite() && elevation.abs() <= 90.0) {
            return Err(RenderError::Camera {
                text: format!("{azimuth},{elevation}"),
                reason: "expected finite degrees with the elevation in [-90, 90]".into(),
            });
        }
        Ok(Self { azimuth, elevation })
    }

    /// The view basis: `right` and `up` span the image plane (image x to the right,
    /// image y up), `back` points from the surface towards the camera.
    pub fn basis(&self) -> ViewBasis {
        let (sa, ca) = self.azimuth.to_radians().sin_cos();
        let (se, ce) = self.elevation.to_radians().sin_cos();
        let back = Vector3::new(sa * ce, se, ca * ce);
        let right = Vector3::new(ca, 0.0, -sa);
        let up = back.cross(&right);
        ViewBasis { right, up, back }
    }
}

/// An orthonormal, right-handed view basis (`right x up = back`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewBasis {
    /// Image x direction.
    pub right: Vector3<f64>,
    /// Image y direction (up on the picture).
    pub up: Vector3<f64>,
    /// Towards the camera.
    pub back: Vector3<f64>,
}

impl ViewBasis {
    /// `(x, y, depth)` of `p`: image-plane coordinates (y up) and the distance along
    /// the view direction (larger is farther from the camera).
    pub fn project(&self, p: &Point3<f64>) -> [f64; 3] {
        let v = p.coords;
        [v.dot(&self.right), v.dot(&self.up), -v.dot(&self.back)]
    }
}

impl FromStr for Camera {
    type Err = RenderError;

    /// Parses `AZIMUTH,ELEVATION` in degrees, e.g. `30,20`.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let error = |reason: &str| RenderError::Camera {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let (a, e) = text
            .split_once(',')
            .ok_or_else(|| error("expected AZIMUTH,ELEVATION in degrees, e.g. 30,20"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| error(&format!("`{s}` is not a number of degrees")))
        };
        let (a, e) = (parse(a)?, parse(e)?);
        Camera::new(a, e)
            .map_err(|_| error("expected finite degrees with the elevation in [-90, 90]"))
    }
}

impl fmt::Display for Camera {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{}", self.azimuth, self.elevation)
    }
}
