//! `beltrami info`: size, topology and geometry of a mesh.

use std::path::PathBuf;

use clap::Args;
use serde_json::json;

use super::load::load_mesh;

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb).
    pub mesh: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Repair what can be repaired safely (drop degenerate and duplicate faces, merge
    /// exactly coincident vertices) instead of failing; every repair is reported.
    #[arg(long)]
    pub repair: bool,
}

pub fn run(args: &InfoArgs, quiet: bool) -> anyhow::Result<()> {
    let loaded = load_mesh(&args.mesh, args.repair, quiet || args.json)?;
    let m = &loaded.mesh.mesh;
    let report = &loaded.mesh.report;
    let components = m.components();
    let loops = m.boundary_loop_sizes();
    let genus: Vec<i64> = components.iter().map(|c| c.genus).collect();
    let bbox = m.bounding_box();
    let area = m.total_area();
    let parse_ms = loaded.parse.as_secs_f64() * 1e3;
    let build_ms = loaded.build.as_secs_f64() * 1e3;

    if args.json {
        let genus_value = if genus.len() == 1 {
            json!(genus[0])
        } else {
            json!(genus)
        };
        let value = json!({
            "file": args.mesh.display().to_string(),
            "vertices": m.vertex_count(),
            "edges": m.edge_count(),
            "faces": m.face_count(),
            "triangles": m.triangle_count(),
            "quads": m.quad_count(),
            "components": components.len(),
            "boundary_loops": loops,
            "euler_characteristic": m.euler_characteristic(),
            "genus": genus_value,
            "manifold": true,
            "orientable": true,
            "faces_reoriented": report.faces_reoriented,
            "unreferenced_vertices": report.unreferenced_vertices.len(),
            "coincident_vertices": coincident_vertices(m),
            "stl_weld": loaded.mesh.weld.map(|w| json!({"corners": w.corners, "vertices": w.vertices})),
            "repaired": {
                "dropped_degenerate_faces": report.dropped_degenerate_faces,
                "dropped_duplicate_faces": report.dropped_duplicate_faces,
                "merged_vertices": report.merged_vertices.len(),
            },
            "area": area,
            "bounding_box": {
                "min": [bbox.min.x, bbox.min.y, bbox.min.z],
                "max": [bbox.max.x, bbox.max.y, bbox.max.z],
            },
            "parse_ms": parse_ms,
            "build_ms": build_ms,
        });
        println!("{value}");
        return Ok(());
    }

    let loops_text = if loops.is_empty() {
        "none (closed)".to_string()
    } else {
        format!(
            "{} loop{} with {} vertices",
            loops.len(),
            if loops.len() == 1 { "" } else { "s" },
            join(&loops)
        )
    };
    println!("{}", args.mesh.display());
    println!("  vertices        {}", m.vertex_count());
    println!("  edges           {}", m.edge_count());
    println!(
        "  faces           {} ({} triangles, {} quads)",
        m.face_count(),
        m.triangle_count(),
        m.quad_count()
    );
    println!("  components      {}", components.len());
    println!("  boundary        {loops_text}");
    println!("  euler char.     {}", m.euler_characteristic());
    println!("  genus           {}", join(&genus));
    println!("  manifold        yes");
    println!(
        "  orientable      yes ({} faces re-oriented)",
        report.faces_reoriented
    );
    if !report.unreferenced_vertices.is_empty() {
        println!(
            "  unreferenced    {} vertices (left out; indices follow the file)",
            report.unreferenced_vertices.len()
        );
    }
    if let Some(weld) = loaded.mesh.weld {
        println!(
            "  STL weld        {} corners into {} vertices (exact positions)",
            weld.corners, weld.vertices
        );
    }
    println!("  area            {area:.6e}");
    println!(
        "  bounding box    [{:.6}, {:.6}, {:.6}] .. [{:.6}, {:.6}, {:.6}]",
        bbox.min.x, bbox.min.y, bbox.min.z, bbox.max.x, bbox.max.y, bbox.max.z
    );
    println!("  load            {parse_ms:.1} ms parse + {build_ms:.1} ms build");
    let coincident = coincident_vertices(m);
    if coincident > 0 {
        println!(
            "hint: {coincident} vertices lie exactly on another vertex (a triangle soup, or seams cut for texturing), so the surface falls into {} components with {} boundary loops; `--repair` merges them",
            components.len(),
            loops.len()
        );
    }
    Ok(())
}

/// The items joined by commas, the first [`LISTED`] of them and a count of the rest (the
/// JSON output has every item).
fn join<T: ToString>(items: &[T]) -> String {
    let mut text = items
        .iter()
        .take(LISTED)
        .map(T::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > LISTED {
        text.push_str(&format!(
            ", ... ({} more; --json lists all)",
            items.len() - LISTED
        ));
    }
    text
}

/// How many items of a list the text output shows.
const LISTED: usize = 12;

/// The number of mesh vertices that share their exact position with an earlier one.
fn coincident_vertices(mesh: &beltrami_mesh::Mesh) -> usize {
    let mut seen = std::collections::HashSet::with_capacity(mesh.vertex_count());
    mesh.positions()
        .iter()
        .filter(|p| !seen.insert([p.x, p.y, p.z].map(|c| (c + 0.0).to_bits())))
        .count()
}
