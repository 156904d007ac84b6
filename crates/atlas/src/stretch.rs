//! Texture stretch of a seamed UV map (Sander, Snyder, Gortler and Hoppe 2001, "Texture
//! mapping progressive meshes", section 3).
//!
//! On a face, let `S` be the affine map from the UV triangle to the surface triangle and
//! `Gamma >= gamma` the singular values of its Jacobian (how far a unit step in the
//! texture goes on the surface). The face's stretch is `L2 = sqrt((Gamma^2 + gamma^2)/2)`
//! and `Linf = Gamma`; over the mesh
//!
//! `L2 = sqrt(sum_f L2_f^2 A_f / sum_f A_f)`, `Linf = max_f Gamma_f`
//!
//! with `A_f` the surface area, both multiplied by `sqrt(sum_f a_f / sum_f A_f)` (`a_f` the
//! UV area) so that a uniform scaling of the UVs does not change them. Both are 1 for an
//! isometry up to scale and grow with area distortion and anisotropy; a conformal map
//! with log scale factor `u` has `L2^2 = mean_A(e^{-2u}) mean_A(e^{2u})`.
//!
//! The area distortion is the area-weighted mean of `|ln(a_f / (s A_f))|` with `s` the
//! ratio of total areas. Faces with a non-positive UV area count as flipped and are
//! left out of the sums (their stretch is infinite).

use beltrami_mesh::Mesh;

use crate::SeamedUv;

/// The stretch of a UV map over a set of faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stretch {
    /// Sander's L2 stretch, normalized by the total areas (1 for an isometry).
    pub l2: f64,
    /// Sander's Linf stretch, normalized the same way.
    pub linf: f64,
    /// Area-weighted mean of `|ln(a_f / (s A_f))|`.
    pub area_distortion: f64,
    /// Faces whose UV triangle has a non-positive signed area.
    pub flipped_faces: usize,
}

/// The stretch of `uv` on the faces of `mesh` (triangles).
pub fn stretch(mesh: &Mesh, uv: &SeamedUv) -> Stretch {
    let mut surface_area = 0.0;
    let mut uv_area = 0.0;
    let mut l2_sum = 0.0;
    let mut linf: f64 = 0.0;
    let mut flipped_faces = 0;
    let mut kept = Vec::with_capacity(mesh.face_count());
    for f in mesh.faces() {
        let area2 = uv.signed_double_area(f);
        if area2 <= 0.0 || !area2.is_finite() {
            flipped_faces += 1;
            continue;
        }
        let (v, _) = mesh.face_vertex_array(f);
        let [q0, q1, q2] = uv.face_uvs(f);
        let (p0, p1, p2) = (
            mesh.position(v[0]),
            mesh.position(v[1]),
            mesh.position(v[2]),
        );
        // S_s and S_t: partial derivatives of the affine map from (s, t) to the surface.
        let ss = (p0.coords * (q1[1] - q2[1])
            + p1.coords * (q2[1] - q0[1])
            + p2.coords * (q0[1] - q1[1]))
            / area2;
        let st = (p0.coords * (q2[0] - q1[0])
            + p1.coords * (q0[0] - q2[0])
            + p2.coords * (q1[0] - q0[0]))
            / area2;
        let (a, b, c) = (ss.dot(&ss), ss.dot(&st), st.dot(&st));
        let big = (0.5 * ((a + c) + ((a - c).powi(2) + 4.0 * b * b).sqrt())).sqrt();
        let area = mesh.face_area(f);
        surface_area += area;
        uv_area += 0.5 * area2;
        l2_sum += 0.5 * (a + c) * area;
        linf = linf.max(big);
        kept.push((area, 0.5 * area2));
    }
    if surface_area <= 0.0 {
        return Stretch {
            l2: f64::INFINITY,
            linf: f64::INFINITY,
            area_distortion: f64::INFINITY,
            flipped_faces,
        };
    }
    let norm = (uv_area / surface_area).sqrt();
    let s = uv_area / surface_area;
    let area_distortion = kept
        .iter()
        .map(|&(area, a)| area * (a / (s * area)).ln().abs())
        .sum::<f64>()
        / surface_area;
    Stretch {
        l2: (l2_sum / surface_area).sqrt() * norm,
        linf: linf * norm,
        area_distortion,
        flipped_faces,
    }
}
