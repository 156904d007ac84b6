//! `beltrami distortion`: the Beltrami coefficients of a map given as a mesh, their
//! statistics, flipped faces and (optionally) the per-face field.
//!
//! The map is MAPPED: a mesh with SOURCE's connectivity whose texture coordinates (a map
//! into the plane) or, without them, whose positions (a map into R^3) are the images of
//! SOURCE's vertices. Vertices correspond by their input index (the files' own order).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use beltrami::mapped;
use beltrami_atlas::Stretch;
use beltrami_fem::distortion::{self, Distortion, Histogram};
use beltrami_fem::{Frame, ReferenceNormal, element};
use beltrami_mesh::io::LoadedMesh;
use beltrami_mesh::{Mesh, Point3, Vector3, VertexId};
use clap::Args;
use serde_json::json;

use super::load::load_mesh;

#[derive(Debug, Args)]
pub struct DistortionArgs {
    /// Source mesh (.obj, .ply, .stl, .off, .gltf, .glb).
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
    super::outputs::check(&[("--per-face", args.per_face.as_deref())])?;
    let quiet = quiet || args.json;
    let source = load_mesh(&args.source, args.repair, quiet)?.mesh;
    let mapped = read_mapped(&args.mapped, args.repair)?;
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
    // Sander's texture stretch, for maps into the plane.
    let mut stretch = None;

    let (kind, reference, measured) = if mapped.corner_uvs.is_some() {
        if args.target.is_some() {
            bail!(
                "{} has texture coordinates, a map into the plane: --target applies only to \
                 maps into R^3 (positions without vt)",
                args.mapped.display()
            );
        }
        let seamed = mapped::corner_images(mesh, &mapped);
        let measured = match (mapped::planar_images(&mapped, &to_mapped), &seamed) {
            (Ok(map), _) => distortion::measure_planar(mesh, &map.unwrap_or_default(), frame)
                .with_context(measuring)?,
            // Seams: each face measured with its own corners' coordinates, on the source
            // split where the coordinates differ (same faces, in the same order).
            (Err(mapped::MappedError::Seam { .. }), Some(uv)) => {
                mapped::measure_seamed(mesh, uv, frame).with_context(measuring)?
            }
            (Err(error), _) => {
                return Err(
                    anyhow::Error::new(error).context(format!("{} has", args.mapped.display()))
                );
            }
        };
        stretch = seamed.map(|uv| beltrami_atlas::stretch(mesh, &uv));
        (
            MapKind::Planar,
            Reference::Chosen(ReferenceNormal::Plane),
            measured,
        )
    } else {
        let image = mapped::spatial_images(&mapped.mesh, &to_mapped);
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
    print_report(args, kind, frame, reference, &notes, &measured, stretch);
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

/// Reads MAPPED ([`mapped::read_mapped`]: no area threshold, no merged vertices).
pub(super) fn read_mapped(path: &Path, repair: bool) -> anyhow::Result<LoadedMesh> {
    Ok(mapped::read_mapped(path, repair)?)
}

/// [`mapped::correspondence`], with both file names in the error.
pub(super) fn correspondence(
    source: &Mesh,
    mapped: &Mesh,
    source_path: &Path,
    mapped_path: &Path,
) -> anyhow::Result<Vec<VertexId>> {
    mapped::correspondence(source, mapped).with_context(|| {
        format!(
            "{} does not have the connectivity of {}",
            mapped_path.display(),
            source_path.display()
        )
    })
}

/// TARGET's normals at the image ([`mapped::target_normals`]) and a note when image
/// vertices lie farther from TARGET than its mean face size.
pub(super) fn target_normals(
    target: &Mesh,
    source: &Mesh,
    image: &[Point3<f64>],
    target_path: &Path,
) -> anyhow::Result<(Vec<Vector3<f64>>, Option<String>)> {
    let found = mapped::target_normals(target, source, image)
        .with_context(|| format!("locating the map's image on {}", target_path.display()))?;
    let note = (found.far > 0).then(|| {
        format!(
            "{} image vertices lie farther than a mean face size ({:.3e}) from {}, up to \
             {:.3e}: is it the surface the map lands on?",
            found.far,
            found.face_size,
            target_path.display(),
            found.farthest
        )
    });
    Ok((found.normals, note))
}

fn print_report(
    args: &DistortionArgs,
    kind: MapKind,
    frame: Frame,
    reference: Reference,
    notes: &[String],
    d: &Distortion,
    stretch: Option<Stretch>,
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
            "stretch": stretch.map(|t| json!({
                "l2": t.l2,
                "linf": t.linf,
                "area_distortion": t.area_distortion,
            })),
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
    if let Some(t) = stretch {
        println!(
            "  stretch         L2 {:.4}  Linf {:.3}  area distortion {:.4} (Sander et al. 2001)",
            t.l2, t.linf, t.area_distortion
        );
    }
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
