//! Helpers shared by the end-to-end tests: running the binary and small conversions.
// Each test binary compiles this module and uses only part of it.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `beltrami` binary with `args` from the repository root.
pub fn beltrami(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_beltrami"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the beltrami binary runs")
}

/// Process output as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A path as a command-line argument (test paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().expect("test paths are UTF-8")
}

/// `../shared/meshes` beside the repository, or `None` after printing `SKIPPED` with the
/// test's name (a user's fresh clone has no `../shared`; CI has it).
pub fn shared_meshes(test: &str) -> Option<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
    if dir.is_dir() {
        Some(dir)
    } else {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED {test}: {} not found; the shared-mesh tests need ../shared beside the repo",
            dir.display()
        );
        None
    }
}
