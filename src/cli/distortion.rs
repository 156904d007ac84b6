//! `beltrami distortion`: the Beltrami coefficients of a map given as a mesh, their
//! statistics, flipped faces and (optionally) the per-face field.
//!
//! The map is MAPPED: a mesh with SOURCE's connectivity whose texture coordinates (a map
//! into the plane) or, without them, whose positions (a map into R^3) are the images of
//! SOURCE's vertices. Vertices correspond by their input index (the files' own order).

use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow, bail};
use beltrami_fem::distortion::{self, Distortion, Histogram};
use beltrami_fem::{Frame, ReferenceNormal, element};
use beltrami_mesh::io::{self, LoadedMesh};
use beltrami_mesh::{BuildOptions, Mesh, Point3, Repair, SurfacePoint, Vector3, VertexId};
use beltrami_spatial::SurfaceIndex;
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
    /// For a map into R^3: the surface the map lands on. Flips are judged against its
    /// normals at the images (each image vertex located on TARGET by its exact closest
    /// point; per face the sum of TARGET's interpolated normals at its corners' images),
    /// as `register` judges them. Without it the image's shape decides: +z for an image
    /// in the plane z = 0, the radial direction for one on a sphere about the origin,
    /// else SOURCE's normals.
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
    // Notes on the reference normal: printed, or in the JSON report.
    let mut notes = Vec::new();

    let (kind, reference, measured) = if mapped.corner_uvs.is_some() {
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
        (
            MapKind::Planar,
            Reference::Chosen(ReferenceNormal::Plane),
            measured,
        )
    } else {
        let image: Vec<Point3<f64>> = to_mapped.iter().map(|&v| mapped.mesh.position(v)).collect();
        let (reference, measured) = match &args.target {
            Some(path) => {
                let target = load_mesh(path, args.repair, quiet)?.mesh;
                let (normals, note) = target_normals(&target.mesh, mesh, &image, path)?;
                notes.extend(note);
                let measured =
                    distortion::measure_surface(mesh, &image, ReferenceNormal::PerFace(&normals))
                        .with_context(measuring)?;
                (Reference::Target, measured)
            }
            None => {
                let reference = ReferenceNormal::for_image(&image);
                notes.extend(source_reference_note(reference, &args.source));
                let measured =
                    distortion::measure_surface(mesh, &image, reference).with_context(measuring)?;
                (Reference::Chosen(reference), measured)
            }
        };
        (MapKind::Spatial, reference, measured)
    };
    if !quiet {
        for note in &notes {
            eprintln!("note: {note}");
        }
    }

    if let Some(path) = &args.per_face {
        measured
            .field
            .to_frame(mesh, frame)
            .and_then(|field| field.write(path))
            .with_context(|| format!("writing the per-face field {}", path.display()))?;
    }
    print_report(args, kind, frame, reference, &notes, &measured);
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

/// The reference normal flips were judged against, for the reports.
#[derive(Debug, Clone, Copy)]
enum Reference {
    /// Chosen from the map's image ([`ReferenceNormal::for_image`]), or `Plane` for a
    /// map given by texture coordinates.
    Chosen(ReferenceNormal<'static>),
    /// TARGET's normals at the images.
    Target,
}

impl Reference {
    /// The name in JSON reports: `plane`, `radial`, `source` or `target`.
    fn name(self) -> &'static str {
        match self {
            Reference::Chosen(reference) => reference.name(),
            Reference::Target => "target",
        }
    }

    /// The description in text reports.
    fn describe(self) -> &'static str {
        match self {
            Reference::Chosen(ReferenceNormal::Plane) => "+z (the image lies in the plane z = 0)",
            Reference::Chosen(ReferenceNormal::Radial) => {
                "the radial direction (the image lies on a sphere about the origin)"
            }
            Reference::Chosen(_) => "SOURCE's normals",
            Reference::Target => "TARGET's normals at the images",
        }
    }
}

/// The note for flips of a map into R^3 judged against SOURCE's normals (`reference`
/// is [`ReferenceNormal::Source`]), else `None`.
pub(super) fn source_reference_note(
    reference: ReferenceNormal<'_>,
    source: &Path,
) -> Option<String> {
    matches!(reference, ReferenceNormal::Source).then(|| {
        format!(
            "the image is neither in the plane z = 0 nor on a sphere about the origin: flips \
             are judged against the normals of {} (right for an image close to it); \
             --target gives the surface the map lands on",
            source.display()
        )
    })
}

/// Per face of `source`, the normal of `target` at its image (the reference of
/// [`ReferenceNormal::PerFace`]): every image point located on `target` by its exact
/// closest point ([`SurfaceIndex::locate_all`]), then
/// [`SurfaceIndex::face_reference_normals`], the rule `register` judges its maps by.
/// Also a note when images lie farther from `target` than its mean face size.
pub(super) fn target_normals(
    target: &Mesh,
    source: &Mesh,
    image: &[Point3<f64>],
    target_path: &Path,
) -> anyhow::Result<(Vec<Vector3<f64>>, Option<String>)> {
    let context = || format!("locating the map's image on {}", target_path.display());
    let index = SurfaceIndex::new(target).with_context(context)?;
    let located = index.locate_all(image).with_context(context)?;
    let face_size = (target.total_area() / target.face_count() as f64).sqrt();
    let (far, farthest) = located
        .iter()
        .filter(|l| l.distance > face_size)
        .fold((0, 0.0), |(n, d), l| (n + 1, l.distance.max(d)));
    let note = (far > 0).then(|| {
        format!(
            "{far} image vertices lie farther than a mean face size ({face_size:.3e}) from \
             {}, up to {farthest:.3e}: is it the surface the map lands on?",
            target_path.display()
        )
    });
    let points: Vec<SurfacePoint> = located.into_iter().map(|l| l.point).collect();
    let normals = index
        .face_reference_normals(source, &points)
        .with_context(context)?;
    Ok((normals, note))
}

fn print_report(
    args: &DistortionArgs,
    kind: MapKind,
    frame: Frame,
    reference: Reference,
    notes: &[String],
    d: &Distortion,
) {
    let s = &d.stats;
    let h = &s.histogram;
    if args.json {
        let value = json!({
            "source": args.source.display().to_string(),
            "mapped": args.mapped.display().to_string(),
            "map": kind.name(),
            "frame": frame.name(),
            "reference": reference.name(),
            "notes": notes,
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
    println!("  flips judged against {}", reference.describe());
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
