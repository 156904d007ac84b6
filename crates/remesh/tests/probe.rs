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
    }
}
