use beltrami_core::{Context, Solver};
use beltrami_init::{Lscm, Tutte};
use beltrami_mesh::{BuildOptions, io};
use beltrami_remesh::{RemeshOptions, quality, remesh};
use std::time::Instant;

#[test]
fn probe() {
    for name in [
        "disk_human_face",
        "g0_spot",
        "g1_bob",
        "mc4_face_a",
        "disk_hemisphere",
    ] {
        let path = format!("/work/shared/meshes/{name}.obj");
        let mesh = io::read(std::path::Path::new(&path), &BuildOptions::default())
            .unwrap()
            .mesh;
        let l = 0.01 * mesh.bounding_box().diagonal();
        let t = Instant::now();
        let solvers: [&dyn Solver; 2] = [&Lscm, &Tutte];
        let r = remesh(
            &mesh,
            &solvers,
            &RemeshOptions::with_edge_length(l),
            &mut Context::new(),
        );
        let secs = t.elapsed().as_secs_f64();
        match r {
            Ok(r) => {
                let q = quality::measure(&mesh, &r.remeshed.mesh).unwrap();
                eprintln!(
                    "{name}: {} {:?} {:.2}s passes {} timings {:?} notes {:?}\n  V {} F {} min {:.2} mean {:.2} <30 {:.4}% edge mean/L {:.3} spread {:.3} H {:.4}% mean {:.5}%",
                    r.parameterizer,
                    r.opening,
                    secs,
                    r.size_passes,
                    r.timings,
                    r.notes,
                    q.vertices,
                    q.faces,
                    q.min_angle,
                    q.mean_angle,
                    100.0 * q.share_below_30,
                    q.edge_mean / l,
                    q.edge_spread,
                    100.0 * q.hausdorff / q.diagonal,
                    100.0 * q.mean_distance / q.diagonal
                );
            }
            Err(e) => eprintln!("{name}: ERROR {e}"),
        }
        if let Ok(r) = remesh(
            &mesh,
            &solvers,
            &RemeshOptions::with_edge_length(l),
            &mut Context::new(),
        ) {
            let m = &r.remeshed.mesh;
            let (mut bd, mut inner) = (0, 0);
            let mut worst = vec![];
            for f in m.faces() {
                let a = m
                    .face_halfedges(f)
                    .map(|h| m.corner_angle(h).to_degrees())
                    .fold(180.0, f64::min);
                if a < 20.0 {
                    if m.face_vertices(f).any(|v| m.is_boundary_vertex(v)) {
                        bd += 1
                    } else {
                        inner += 1
                    }
                    worst.push((
                        a,
                        m.face_vertices(f)
                            .map(|v| r.remeshed.on_source[v.idx()].face.0)
                            .collect::<Vec<_>>(),
                    ));
                }
            }
            worst.sort_by(|a, b| a.0.total_cmp(&b.0));
            eprintln!(
                "  <20: boundary {bd} interior {inner} worst {:?}",
                &worst[..worst.len().min(4)]
            );
        }
    }
}
