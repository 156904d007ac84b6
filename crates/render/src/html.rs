//! A self-contained HTML page of a scene, to open in any browser or send to a colleague:
//! the surface and the map's image drawn with WebGL, turned by dragging and zoomed by the
//! wheel, faces colored by `|mu|` (viridis over a [`MuRange`], flipped faces red) or
//! plain without a map, and the distortion's figures in a header line.
//!
//! The page holds everything it needs (no network): the geometry as base64 of
//! little-endian `f32` triangle corners (quads split along their first diagonal, nine
//! numbers per triangle: the source surface, and the image of the map as `(u, v, 0)` or
//! its points in R^3), the face colors as base64 bytes (three per triangle), and a small
//! script that expands them, computes flat normals and draws with an orthographic camera
//! (the same azimuth/elevation convention as [`crate::Camera`]).

use base64::Engine as _;
use beltrami_mesh::{FaceId, Mesh, Point3};

use crate::{Layout, MuRange, Scene};

/// The color of a flipped face.
const FLIPPED: [u8; 3] = [228, 26, 28];
/// The color of every face when there is no map.
const PLAIN: [u8; 3] = [200, 200, 200];

/// The page of `scene` titled `title` (escaped here), `|mu|` colored over `range`.
pub fn html_page(scene: &Scene<'_>, title: &str, range: MuRange) -> String {
    let mesh = scene.mesh();
    let triangles = triangles(mesh);
    let source: Vec<[f32; 3]> = triangles
        .iter()
        .flat_map(|(_, corners)| corners.map(|(v, _)| to_f32(&mesh.position(v))))
        .collect();
    let image: Option<Vec<[f32; 3]>> = scene.image().map(|layout| {
        triangles
            .iter()
            .flat_map(|(_, corners)| {
                corners.map(|(v, h)| match layout {
                    Layout::Plane(uv) => [uv[h].x as f32, uv[h].y as f32, 0.0],
                    Layout::Space(points) => to_f32(&points[v.idx()]),
                })
            })
            .collect()
    });
    let colors: Vec<u8> = triangles
        .iter()
        .flat_map(|&(f, _)| match scene.distortion() {
            Some(d) if d.flipped[f.idx()] => FLIPPED,
            Some(d) => range.color(d.modulus[f.idx()]),
            None => PLAIN,
        })
        .collect();
    let figures = match scene.distortion() {
        Some(d) => format!(
            "{} faces, {} flipped, |mu| mean {:.4} max {:.4}",
            mesh.face_count(),
            d.stats.flipped,
            d.stats.mu_mean,
            d.stats.mu_max
        ),
        None => format!("{} faces, no map", mesh.face_count()),
    };
    let image_data = image
        .as_deref()
        .map_or(String::from("null"), |p| format!("\"{}\"", floats(p)));
    PAGE.replace("{{TITLE}}", &escape(title))
        .replace("{{FIGURES}}", &escape(&figures))
        .replace("{{RANGE}}", &format!("{} to {}", range.lo, range.hi))
        .replace("{{SOURCE}}", &floats(&source))
        .replace("{{IMAGE}}", &image_data)
        .replace(
            "{{COLORS}}",
            &base64::engine::general_purpose::STANDARD.encode(&colors),
        )
}

/// Every triangle of the mesh (quads split along their first diagonal) with its face
/// and its corners as `(vertex, corner index)`, the corner index being the face
/// halfedge's id as in [`Layout::Plane`].
fn triangles(mesh: &Mesh) -> Vec<(FaceId, [(beltrami_mesh::VertexId, usize); 3])> {
    let mut out = Vec::with_capacity(mesh.triangle_count() + 2 * mesh.quad_count());
    for f in mesh.faces() {
        let corners: Vec<_> = mesh
            .face_halfedges(f)
            .map(|h| (mesh.origin(h), h.idx()))
            .collect();
        for [a, b, c] in [[0, 1, 2], [0, 2, 3]].into_iter().take(corners.len() - 2) {
            out.push((f, [corners[a], corners[b], corners[c]]));
        }
    }
    out
}

fn to_f32(p: &Point3<f64>) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// Base64 of the little-endian bytes of the points' coordinates.
fn floats(points: &[[f32; 3]]) -> String {
    let bytes: Vec<u8> = points
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// `text` with the characters HTML gives a meaning escaped.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page; `{{...}}` are filled in by [`html_page`].
const PAGE: &str = r#"<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{{TITLE}}</title>
<style>
  html, body { margin: 0; height: 100%; background: #fff; font: 14px sans-serif; }
  #bar { position: absolute; top: 0; left: 0; right: 0; padding: 6px 10px; background: rgba(255,255,255,0.85); }
  #bar button { margin-left: 6px; }
  #bar button.on { font-weight: bold; }
  canvas { display: block; width: 100%; height: 100%; }
</style>
</head>
<body>
<div id="bar"><b>{{TITLE}}</b> &mdash; <span id="figures">{{FIGURES}}</span>
  (|mu| colors: viridis from {{RANGE}}, flipped faces red)
  <button id="show-source" class="on">surface</button><button id="show-image">map</button>
  &mdash; drag to turn, wheel to zoom</div>
<canvas id="view"></canvas>
<script>
"use strict";
const SOURCE = "{{SOURCE}}";
const IMAGE = {{IMAGE}};
const COLORS = "{{COLORS}}";

function bytes(text) {
  const raw = atob(text);
  const out = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; i++) out[i] = raw.charCodeAt(i);
  return out;
}

// One drawable per geometry: corners, flat normals, colors, and its bounding sphere.
function geometry(text) {
  const p = new Float32Array(bytes(text).buffer);
  const faceColors = bytes(COLORS);
  const n = new Float32Array(p.length), c = new Float32Array(p.length);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let t = 0; t < p.length / 9; t++) {
    const o = 9 * t;
    const u = [p[o + 3] - p[o], p[o + 4] - p[o + 1], p[o + 5] - p[o + 2]];
    const v = [p[o + 6] - p[o], p[o + 7] - p[o + 1], p[o + 8] - p[o + 2]];
    const m = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    const len = Math.hypot(m[0], m[1], m[2]) || 1;
    for (let k = 0; k < 3; k++) {
      for (let a = 0; a < 3; a++) {
        n[o + 3 * k + a] = m[a] / len;
        c[o + 3 * k + a] = faceColors[3 * t + a] / 255;
        lo[a] = Math.min(lo[a], p[o + 3 * k + a]);
        hi[a] = Math.max(hi[a], p[o + 3 * k + a]);
      }
    }
  }
  const center = [0, 1, 2].map(a => (lo[a] + hi[a]) / 2);
  const radius = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2 || 1;
  return { p, n, c, count: p.length / 3, center, radius };
}

const canvas = document.getElementById("view");
const gl = canvas.getContext("webgl", { antialias: true, preserveDrawingBuffer: true });
function shader(type, text) {
  const s = gl.createShader(type);
  gl.shaderSource(s, text);
  gl.compileShader(s);
  return s;
}
const program = gl.createProgram();
gl.attachShader(program, shader(gl.VERTEX_SHADER, `
  attribute vec3 position; attribute vec3 normal; attribute vec3 color;
  uniform mat4 view; varying vec3 shade;
  void main() {
    gl_Position = view * vec4(position, 1.0);
    vec3 m = normalize((view * vec4(normal, 0.0)).xyz);
    shade = color * (0.35 + 0.65 * abs(m.z));
  }`));
gl.attachShader(program, shader(gl.FRAGMENT_SHADER, `
  precision mediump float; varying vec3 shade;
  void main() { gl_FragColor = vec4(shade, 1.0); }`));
gl.linkProgram(program);
gl.useProgram(program);

function upload(g) {
  g.buffers = [["position", g.p], ["normal", g.n], ["color", g.c]].map(([name, data]) => {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    return [gl.getAttribLocation(program, name), b];
  });
  return g;
}
const shapes = { source: upload(geometry(SOURCE)), image: IMAGE ? upload(geometry(IMAGE)) : null };
// The surface starts turned a little, to show its relief; the map starts head-on (a map
// into the plane lies in z = 0).
const START = { source: [-30, 25], image: [0, 0] };
let shown = "source", [azimuth, elevation] = START.source, zoom = 1;
if (!shapes.image) document.getElementById("show-image").disabled = true;

// Orthographic camera orbiting +y: azimuth from +z towards +x, elevation above x-z.
function viewMatrix(g) {
  const a = azimuth * Math.PI / 180, e = elevation * Math.PI / 180;
  const right = [Math.cos(a), 0, -Math.sin(a)];
  const toward = [Math.sin(a) * Math.cos(e), Math.sin(e), Math.cos(a) * Math.cos(e)];
  const up = [toward[1] * right[2] - toward[2] * right[1], toward[2] * right[0] - toward[0] * right[2], toward[0] * right[1] - toward[1] * right[0]];
  const aspect = canvas.width / canvas.height;
  const s = zoom / (1.1 * g.radius);
  const sx = aspect > 1 ? s / aspect : s, sy = aspect > 1 ? s : s * aspect, sz = -s / 2;
  const rows = [right.map(x => x * sx), up.map(x => x * sy), toward.map(x => x * sz)];
  const m = new Float32Array(16);
  for (let r = 0; r < 3; r++) {
    for (let k = 0; k < 3; k++) m[4 * k + r] = rows[r][k];
    m[12 + r] = -(rows[r][0] * g.center[0] + rows[r][1] * g.center[1] + rows[r][2] * g.center[2]);
  }
  m[15] = 1;
  return m;
}

function draw() {
  const w = canvas.clientWidth * devicePixelRatio, h = canvas.clientHeight * devicePixelRatio;
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(1, 1, 1, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  const g = shapes[shown];
  for (const [location, buffer] of g.buffers) {
    gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
    gl.enableVertexAttribArray(location);
    gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
  }
  gl.uniformMatrix4fv(gl.getUniformLocation(program, "view"), false, viewMatrix(g));
  gl.drawArrays(gl.TRIANGLES, 0, g.count);
}

function show(which) {
  shown = which;
  [azimuth, elevation] = START[which];
  zoom = 1;
  document.getElementById("show-source").className = which === "source" ? "on" : "";
  document.getElementById("show-image").className = which === "image" ? "on" : "";
  draw();
}
document.getElementById("show-source").onclick = () => show("source");
document.getElementById("show-image").onclick = () => show("image");
let drag = null;
canvas.onpointerdown = e => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); };
canvas.onpointerup = () => { drag = null; };
canvas.onpointermove = e => {
  if (!drag) return;
  azimuth -= (e.clientX - drag[0]) * 0.5;
  elevation = Math.max(-89, Math.min(89, elevation + (e.clientY - drag[1]) * 0.5));
  drag = [e.clientX, e.clientY];
  draw();
};
canvas.onwheel = e => { e.preventDefault(); zoom *= Math.exp(-e.deltaY * 0.001); draw(); };
window.onresize = draw;
draw();
</script>
</body>
</html>
"#;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colormap::viridis_rgb;
    use beltrami_mesh::Vector2;
    use beltrami_mesh::primitives::{Cells, grid};

    #[test]
    fn the_page_holds_every_triangle_and_a_color_per_triangle() {
        let mesh = Mesh::from_soup(&grid(3, 2, Cells::Quads)).unwrap();
        let uv: Vec<Vector2<f64>> = mesh
            .positions()
            .iter()
            .map(|p| Vector2::new(2.0 * p.x, p.y))
            .collect();
        let scene = Scene::new(
            &mesh,
            Some(Layout::plane_from_vertices(&mesh, &uv).unwrap()),
        )
        .unwrap();
        let page = html_page(&scene, "a <b> & c", MuRange::default());
        assert!(page.contains("<title>a &lt;b&gt; &amp; c</title>"));
        let field = |name: &str| {
            let start = page.find(&format!("const {name} = \"")).unwrap() + name.len() + 10;
            let end = start + page[start..].find('"').unwrap();
            base64::engine::general_purpose::STANDARD
                .decode(&page[start..end])
                .unwrap()
        };
        // 6 quads, 12 triangles: 9 floats each, 3 color bytes each.
        assert_eq!(field("SOURCE").len(), 12 * 9 * 4);
        assert_eq!(field("IMAGE").len(), 12 * 9 * 4);
        let colors = field("COLORS");
        assert_eq!(colors.len(), 12 * 3);
        // A stretch by 2 has |mu| = 1/3 everywhere: one viridis color.
        let third = viridis_rgb(1.0 / 3.0);
        assert!(colors.chunks(3).all(|c| c == third), "{colors:?}");
        assert!(page.contains("6 faces, 0 flipped, |mu| mean 0.3333 max 0.3333"));
    }

    #[test]
    fn without_a_map_the_image_is_null_and_faces_plain() {
        let mesh = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        let page = html_page(&Scene::new(&mesh, None).unwrap(), "t", MuRange::default());
        assert!(page.contains("const IMAGE = null;"));
        assert!(page.contains("8 faces, no map"));
    }
}
