//! `beltrami distortion`: the Beltrami coefficients of a map given as a mesh, their
//! statistics, flipped faces and (optionally) the per-face field.
//!
//! The map is MAPPED: a mesh with SOURCE's connectivity whose texture coordinates (a map
//! into the plane) or, without them, whose positions (a map into R^3) are the images of
//! SOURCE's vertices. Vertices correspond by their input index (the files' own order).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow, bail};
use beltrami_fem::distortion::{self, Distortion, Histogram};
use beltrami_fem::{Frame, element};
use beltrami_mesh::io::{self, LoadedMesh};
use beltrami_mesh::{BuildOptions, FaceId, Mesh, Point3, Repair, Vector3, VertexId};
use clap::Args;
use num_complex::Complex64;
use serde_json::json;

use super::load::load_mesh;

#[derive(Debug, Args)]
pub struct DistortionArgs {
    /// Source mesh (.obj, .gltf, .glb).
    pub source: PathBuf,
    /// The map: a mesh with SOURCE's faces (same vertex indices) whose texture
    /// coordinates (`vt`, a map into the plane) or, without them, whose positions (a map
    /// into R^3) are the images of SOURCE's vertices.
    pub mapped: PathBuf,
    /// For a map into R^3: judge flips against the normals of this surface at the images
    /// (the nearest face to each image face's centroid) instead of SOURCE's normals.
    #[arg(long, value_name = "TARGET")]
    pub target: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write the Beltrami coefficient of every face to FILE (`# mu frame=... faces=N`,
    /// then `re im` per face; frame global when SOURCE lies in the plane z = 0, face
    /// otherwise).
    #[arg(long, value_name = "FILE")]
    pub per_face: Option<PathBuf>,
    /// Repair what can be repaired safely in the meshes read (drop degenerate and
    /// duplicate faces, merge exactly coincident vertices) instead of failing.
    #[arg(long)]
    pub repair: bool,
}

pub fn run(args: &DistortionArgs, quiet: bool) -> anyhow::Result<()> {
    let quiet = quiet || args.json;
    let source = load_mesh(&args.source, args.repair, quiet)?.mesh;
    let mapped = load_mapped(&args.mapped, args.repair)?;
    let mesh = &source.mesh;
    let to_mapped = correspondence(mesh, &mapped.mesh, &args.source, &args.mapped)?;
    let planar_source = element::is_planar(mesh);
    // The frame mu is reported and written in: the plane's own when there is one.
    let frame = if planar_source {
        Frame::Global
    } else {
        Frame::Face
    };
    let measuring = || format!("measuring the map of {}", args.source.display());

    let (kind, measured) = if mapped.corner_uvs.is_some() {
        if args.target.is_some() {
            bail!(
                "{} has texture coordinates, a map into the plane: --target applies only to \
                 maps into R^3 (positions without vt)",
                args.mapped.display()
            );
        }
        let uv = mapped
            .vertex_uvs()
            .ok_or_else(|| seam_error(&mapped, &args.mapped))?;
        let map: Vec<Complex64> = to_mapped
            .iter()
            .map(|v| Complex64::new(uv[v.idx()].x, uv[v.idx()].y))
            .collect();
        let measured = distortion::measure_planar(mesh, &map, frame).with_context(measuring)?;
        (MapKind::Planar, measured)
    } else {
        let image: Vec<Point3<f64>> = to_mapped.iter().map(|&v| mapped.mesh.position(v)).collect();
        let normals = match &args.target {
            Some(path) => {
                let target = load_mesh(path, args.repair, quiet)?.mesh;
                let found = target_normals(&target.mesh, mesh, &image);
                if found.far_faces > 0 && !quiet {
                    eprintln!(
                        "note: the images of {} faces lie farther than {:.3e} from every face \
                         centroid of {}: is it the surface the map lands on?",
                        found.far_faces,
                        found.far,
                        path.display()
                    );
                }
                Some(found.normals)
            }
            None => Some(distortion::image_normals(mesh, &image)),
        };
        let measured = distortion::measure_surface(mesh, &image, normals.as_deref())
            .with_context(measuring)?;
        (MapKind::Spatial, measured)
    };

    if let Some(path) = &args.per_face {
        measured
            .field
            .to_frame(mesh, frame)
            .and_then(|field| field.write(path))
            .with_context(|| format!("writing the per-face field {}", path.display()))?;
    }
    print_report(args, kind, frame, &measured);
    Ok(())
}

/// What MAPPED holds.
#[derive(Debug, Clone, Copy)]
enum MapKind {
    /// Texture coordinates: a map into the plane.
    Planar,
    /// Positions: a map into R^3.
    Spatial,
}

impl MapKind {
    /// The name in JSON reports.
    fn name(self) -> &'static str {
        match self {
            MapKind::Planar => "vt",
            MapKind::Spatial => "positions",
        }
    }

    /// The description in text reports.
    fn describe(self) -> &'static str {
        match self {
            MapKind::Planar => "texture coordinates (a map into the plane)",
            MapKind::Spatial => "positions (a map into R^3)",
        }
    }
}

/// Reads MAPPED. Its positions are the map's image (or do not matter, for a map given by
/// texture coordinates), so they must not change its connectivity: a face collapsed by
/// the map is a measurement (`|mu| = 1`, flipped), not a defect. So no face counts as
/// degenerate by its area and no vertices are merged; with `--repair`, faces with a
/// repeated vertex and duplicate faces are dropped, as in SOURCE.
pub(super) fn load_mapped(path: &Path, repair: bool) -> anyhow::Result<LoadedMesh> {
    let options = BuildOptions {
        // The threshold `tolerance * diagonal^2` is then -inf (or NaN): no area is below.
        degenerate_area_tolerance: f64::NEG_INFINITY,
        repair: Repair {
            drop_degenerate_faces: repair,
            drop_duplicate_faces: repair,
            merge_coincident_vertices: false,
        },
    };
    Ok(io::read(path, &options)?)
}

/// For every SOURCE vertex, the MAPPED vertex with the same input index, after checking
/// that both meshes have the same faces with the same input vertex indices (in order).
pub(super) fn correspondence(
    source: &Mesh,
    mapped: &Mesh,
    source_path: &Path,
    mapped_path: &Path,
) -> anyhow::Result<Vec<VertexId>> {
    let names = || {
        format!(
            "{} does not have the connectivity of {}",
            mapped_path.display(),
            source_path.display()
        )
    };
    if source.face_count() != mapped.face_count() {
        bail!(
            "{}: it has {} faces, the source has {}",
            names(),
            mapped.face_count(),
            source.face_count()
        );
    }
    let (source_map, mapped_map) = (source.vertex_map(), mapped.vertex_map());
    let mut to_mapped = vec![None; source.vertex_count()];
    for f in source.faces() {
        // Input indices of MAPPED's corners, read as SOURCE vertices (this also accepts
        // vertices that a repair merged in SOURCE).
        let same = source.face_to_input(f) == mapped.face_to_input(f)
            && source.face_degree(f) == mapped.face_degree(f)
            && source
                .face_vertices(f)
                .zip(mapped.face_vertices(f))
                .all(|(v, w)| source_map.from_input(mapped_map.to_input(w)) == Some(v));
        if !same {
            let a: Vec<usize> = source
                .face_vertices(f)
                .map(|v| source_map.to_input(v))
                .collect();
            let b: Vec<usize> = mapped
                .face_vertices(f)
                .map(|v| mapped_map.to_input(v))
                .collect();
            bail!(
                "{}: face {} has vertices {a:?} in the source but face {} of the map has \
                 {b:?} (0-based input indices)",
                names(),
                source.face_to_input(f),
                mapped.face_to_input(f)
            );
        }
        for (v, w) in source.face_vertices(f).zip(mapped.face_vertices(f)) {
            to_mapped[v.idx()] = Some(w);
        }
    }
    // Every mesh vertex lies on a face (the builder leaves out unreferenced ones).
    to_mapped
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| anyhow!("{}: a source vertex lies on no face", names()))
}

/// The error for a map whose texture coordinates have seams, naming the first vertex
/// (input index) with two different `vt`.
fn seam_error(mapped: &LoadedMesh, path: &Path) -> anyhow::Error {
    let mesh = &mapped.mesh;
    let mut first = vec![None; mesh.vertex_count()];
    let seam = mapped.corner_uvs.as_ref().and_then(|corner| {
        mesh.faces()
            .flat_map(|f| mesh.face_halfedges(f))
            .find_map(|h| {
                let v = mesh.origin(h);
                match first[v.idx()] {
                    None => {
                        first[v.idx()] = Some(corner[h.idx()]);
                        None
                    }
                    Some(uv) if uv != corner[h.idx()] => Some(v),
                    Some(_) => None,
                }
            })
    });
    let at = seam.map_or_else(String::new, |v| {
        format!(
            " (vertex {} has two different vt)",
            mesh.vertex_map().to_input(v)
        )
    });
    anyhow!(
        "{} has texture seams{at}: a map into the plane needs one vt per vertex",
        path.display()
    )
}

/// The normals of a target surface at the images of the source faces.
struct TargetNormals {
    /// Per source face: the normal of the target face whose centroid is nearest to the
    /// centroid of the face's image.
    normals: Vec<Vector3<f64>>,
    /// Source faces whose image centroid is farther than [`TargetNormals::far`] from
    /// every target centroid.
    far_faces: usize,
    /// The distance beyond which an image is far from the target: about 8 mean target
    /// face sizes (the grid's cell size).
    far: f64,
}

/// The normals of `target` at the images of the faces of `source` (see
/// [`TargetNormals`]).
fn target_normals(target: &Mesh, source: &Mesh, image: &[Point3<f64>]) -> TargetNormals {
    let centroids: Vec<Point3<f64>> = target.faces().map(|g| target.face_centroid(g)).collect();
    // Cells 8 mean face sizes wide: about 64 centroids per cell on a surface, few cells
    // to visit per query even for images a few cells off the target.
    let face_size = (target.total_area() / target.face_count() as f64).sqrt();
    let cell = 8.0 * face_size.max(1e-9 * target.bounding_box().diagonal());
    let grid = CentroidGrid::new(&centroids, if cell > 0.0 { cell } else { 1.0 });
    let mut far_faces = 0;
    let normals = source
        .faces()
        .map(|f| {
            let (v, n) = source.face_vertex_array(f);
            let sum: Vector3<f64> = v[..n].iter().map(|v| image[v.idx()].coords).sum();
            let (g, distance) = grid.nearest(&Point3::from(sum / n as f64));
            if distance > grid.cell {
                far_faces += 1;
            }
            target.face_normal(FaceId(g))
        })
        .collect();
    TargetNormals {
        normals,
        far_faces,
        far: grid.cell,
    }
}

/// Nearest-point search over the target's face centroids with a uniform grid of
/// buckets (a hash map of occupied cells). A stand-in until the `beltrami-spatial` crate
/// brings its kd-tree (kiddo): fine for ~100K faces whose images lie on or near the
/// target (0.4 s for 100K faces on the target, 0.7 s at 15 face sizes off it), but a
/// query visits about `(distance / cell)^3` cells, so images far off the target are slow.
struct CentroidGrid<'a> {
    points: &'a [Point3<f64>],
    origin: Point3<f64>,
    cell: f64,
    /// Cell index range occupied by the points, per axis.
    lo: [i64; 3],
    hi: [i64; 3],
    buckets: HashMap<[i64; 3], Vec<u32>>,
}

impl<'a> CentroidGrid<'a> {
    /// Buckets `points` (at least one, finite) into cubes of side `cell > 0`.
    fn new(points: &'a [Point3<f64>], cell: f64) -> Self {
        let origin = points.iter().fold(points[0], |m, p| m.inf(p));
        let mut grid = Self {
            points,
            origin,
            cell,
            lo: [i64::MAX; 3],
            hi: [i64::MIN; 3],
            buckets: HashMap::new(),
        };
        for (i, p) in points.iter().enumerate() {
            let key = grid.cell_of(p);
            for ((lo, hi), &x) in grid.lo.iter_mut().zip(&mut grid.hi).zip(&key) {
                *lo = (*lo).min(x);
                *hi = (*hi).max(x);
            }
            grid.buckets.entry(key).or_default().push(i as u32);
        }
        grid
    }

    fn cell_of(&self, p: &Point3<f64>) -> [i64; 3] {
        std::array::from_fn(|k| ((p[k] - self.origin[k]) / self.cell).floor() as i64)
    }

    /// Index of the point nearest to `q`, and its distance.
    ///
    /// Visits shells of cells at Chebyshev index distance `r = 0, 1, ..` around `q`'s
    /// cell (clamped into the occupied range) and stops once the best point found is no
    /// farther than [`CentroidGrid::unvisited_bound`], so queries far from the points
    /// stay cheap too.
    fn nearest(&self, q: &Point3<f64>) -> (u32, f64) {
        let c: [i64; 3] = {
            let u = self.cell_of(q);
            std::array::from_fn(|k| u[k].clamp(self.lo[k], self.hi[k]))
        };
        let mut best = (f64::INFINITY, 0u32);
        let visit = |cell: [i64; 3], best: &mut (f64, u32)| {
            for &i in self.buckets.get(&cell).into_iter().flatten() {
                let d = (self.points[i as usize] - q).norm_squared();
                if d < best.0 {
                    *best = (d, i);
                }
            }
        };
        for r in 0.. {
            let span = |k: usize| (-r).max(self.lo[k] - c[k])..=r.min(self.hi[k] - c[k]);
            for dx in span(0) {
                for dy in span(1) {
                    if dx.abs() == r || dy.abs() == r {
                        for dz in span(2) {
                            visit([c[0] + dx, c[1] + dy, c[2] + dz], &mut best);
                        }
                    } else {
                        // Inside the shell's x-y square only its top and bottom cells.
                        for dz in [-r, r] {
                            if span(2).contains(&dz) {
                                visit([c[0] + dx, c[1] + dy, c[2] + dz], &mut best);
                            }
                        }
                    }
                }
            }
            let bound = self.unvisited_bound(q, c, r);
            if best.0 <= bound * bound {
                break;
            }
        }
        (best.1, best.0.sqrt())
    }

    /// A lower bound of the distance from `q` to every cell of the occupied range whose
    /// Chebyshev index distance from `c` exceeds `r` (infinite when there is none).
    ///
    /// Such a cell lies beyond `c +- r` along some axis `k`; its distance to `q` is at
    /// least the gap from `q` to the slab of the cells beyond, along `k`, combined with
    /// the gaps from `q` to the whole occupied range along the other two axes.
    fn unvisited_bound(&self, q: &Point3<f64>, c: [i64; 3], r: i64) -> f64 {
        // Distance along axis k from q to the slab of cells first..=last.
        let gap = |k: usize, first: i64, last: i64| {
            let a = self.origin[k] + first as f64 * self.cell;
            let b = self.origin[k] + (last + 1) as f64 * self.cell;
            (a - q[k]).max(q[k] - b).max(0.0)
        };
        let whole: [f64; 3] = std::array::from_fn(|k| gap(k, self.lo[k], self.hi[k]).powi(2));
        (0..3)
            .filter_map(|k| {
                let below = (c[k] - r > self.lo[k]).then(|| gap(k, self.lo[k], c[k] - r - 1));
                let above = (c[k] + r < self.hi[k]).then(|| gap(k, c[k] + r + 1, self.hi[k]));
                let g = below.into_iter().chain(above).reduce(f64::min)?;
                let others: f64 = (0..3).filter(|&m| m != k).map(|m| whole[m]).sum();
                Some((g * g + others).sqrt())
            })
            .fold(f64::INFINITY, f64::min)
    }
}

fn print_report(args: &DistortionArgs, kind: MapKind, frame: Frame, d: &Distortion) {
    let s = &d.stats;
    let h = &s.histogram;
    if args.json {
        let value = json!({
            "source": args.source.display().to_string(),
            "mapped": args.mapped.display().to_string(),
            "map": kind.name(),
            "frame": frame.name(),
            "faces": s.faces,
            "flipped": s.flipped,
            "mu_mean": s.mu_mean,
            "mu_max": s.mu_max,
            "mu_std": s.mu_std,
            "mu_l2": s.mu_l2,
            "histogram": {
                "bin_width": Histogram::WIDTH,
                "counts": h.bins,
                "at_least_one": h.at_least_one,
            },
        });
        println!("{value}");
        return;
    }
    println!(
        "{} -> {}: {}, mu in the {} frame",
        args.source.display(),
        args.mapped.display(),
        kind.describe(),
        frame.name()
    );
    println!("  faces           {}", s.faces);
    println!("  flipped         {}", s.flipped);
    println!("  |mu| mean       {:.6e}", s.mu_mean);
    println!("  |mu| max        {:.6e}", s.mu_max);
    println!("  |mu| std        {:.6e}", s.mu_std);
    println!("  |mu| L2 (area)  {:.6e}", s.mu_l2);
    println!("  |mu| histogram");
    for (k, count) in h.bins.iter().enumerate() {
        let (a, b) = (
            k as f64 * Histogram::WIDTH,
            (k + 1) as f64 * Histogram::WIDTH,
        );
        println!("    [{a:.1}, {b:.1})    {count}");
    }
    println!("    >= 1          {}", h.at_least_one);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bucket_grid_finds_the_nearest_point() {
        // A deterministic cloud on a wavy sheet, queried near it and far away.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let points: Vec<Point3<f64>> = (0..2000)
            .map(|_| {
                let (x, y) = (next(), next());
                Point3::new(x, y, 0.1 * (6.0 * x).sin() * y)
            })
            .collect();
        for cell in [0.01, 0.03, 0.4] {
            let grid = CentroidGrid::new(&points, cell);
            for k in 0..300 {
                let spread = [1.2, 10.0, 1000.0][k % 3];
                let q = Point3::new(
                    spread * (next() - 0.4),
                    spread * (next() - 0.4),
                    spread * (next() - 0.5),
                );
                let brute = points
                    .iter()
                    .map(|p| (p - q).norm_squared())
                    .fold(f64::INFINITY, f64::min);
                let (i, distance) = grid.nearest(&q);
                let found = (points[i as usize] - q).norm_squared();
                assert_eq!(found, brute, "cell {cell}, query {q}");
                assert_eq!(distance, brute.sqrt());
            }
        }
    }
}
