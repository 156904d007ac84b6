//! `beltrami view`: the HTML page of a map, opened in headless Chromium, shows the mesh.
//!
//! `.ci/run` installs Debian's Chromium; elsewhere, without `chromium` on the PATH, the
//! browser check is skipped with a message (the page's content is still checked).

use std::path::Path;
use std::process::Command;

mod common;
use common::{beltrami, s, text};

/// A screenshot of `page` by headless Chromium (SwiftShader's WebGL), or `None` when
/// there is no `chromium`.
fn screenshot(page: &Path, png: &Path) -> Option<()> {
    let user = tempfile::tempdir().unwrap();
    let status = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
            "--window-size=800,600",
        ])
        .arg(format!("--user-data-dir={}", user.path().display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("file://{}", page.canonicalize().unwrap().display()))
        .output();
    match status {
        Err(_) => {
            eprintln!("note: no `chromium` on the PATH: the page was not opened in a browser");
            None
        }
        Ok(out) => {
            assert!(
                png.exists(),
                "chromium wrote no screenshot: {}",
                text(&out.stderr)
            );
            Some(())
        }
    }
}

/// The RGB pixels of a PNG and its width.
fn pixels(png: &Path) -> (Vec<[u8; 3]>, usize) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buffer).unwrap();
    let channels = info.color_type.samples();
    let pixels = buffer[..info.buffer_size()]
        .chunks(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    (pixels, info.width as usize)
}

#[test]
fn the_page_of_a_map_shows_the_surface_colored_by_mu() {
    let dir = tempfile::tempdir().unwrap();
    let uv = dir.path().join("uv.obj");
    let out = beltrami(&[
        "param",
        "meshes/disk_hemisphere.obj",
        "--solver",
        "tutte",
        "-o",
        s(&uv),
        "-q",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let page = dir.path().join("page.html");
    let out = beltrami(&[
        "view",
        "meshes/disk_hemisphere.obj",
        "--map",
        s(&uv),
        "-o",
        s(&page),
        "--title",
        "tutte <map>",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("<title>tutte &lt;map&gt;</title>"));
    assert!(html.contains("3600 faces, 0 flipped"), "{}", &html[..2000]);
    assert!(!html.contains("http"), "the page needs no network");

    let png = dir.path().join("shot.png");
    if screenshot(&page, &png).is_none() {
        return;
    }
    let (pixels, width) = pixels(&png);
    let height = pixels.len() / width;
    // The hemisphere seen from +z fills the middle of the page; its faces are viridis
    // colors (blue-green-yellow, never grey or white), shaded.
    let middle = &pixels[(height / 2) * width + width / 2];
    assert!(
        middle != &[255, 255, 255],
        "the middle of the page is blank"
    );
    let colored = pixels
        .iter()
        .filter(|p| {
            let (lo, hi) = (
                *p.iter().min().unwrap() as i32,
                *p.iter().max().unwrap() as i32,
            );
            hi - lo > 40
        })
        .count();
    assert!(
        colored > pixels.len() / 10,
        "{colored} colored pixels of {}",
        pixels.len()
    );
}

#[test]
fn view_refuses_an_output_that_is_not_html() {
    let out = beltrami(&["view", "meshes/disk_hemisphere.obj", "-o", "page.png"]);
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("give an output name ending in .html"));
}
