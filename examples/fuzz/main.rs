//! A mutation fuzzer on stable Rust for beltrami's input parsers and mesh algorithms.
//!
//! ```text
//! cargo run --release --example fuzz -- TARGET SECONDS [SEED]
//! cargo run --release --example fuzz -- all SECONDS [SEED]   # SECONDS per target
//! ```
//!
//! Targets are listed in `targets.rs` (`TARGETS`: the mesh readers, the builder, the
//! expression and field parsers, landmarks, correspondences, cuts, circle domains,
//! remeshing and the batch jobs file). Seeds are built in and read from
//! `tests/corpus/TARGET/`; each run takes a seed, applies a few random byte-level and
//! token-level mutations (bit flips, inserted/deleted/duplicated ranges, numbers at the
//! edges of f64, indices `0` and `-9`, deep nesting, splices of another seed) and runs
//! the target under `catch_unwind`. A panic is saved to `target/fuzz-crashes/` and makes
//! the driver exit with status 1 after printing it; a stack overflow ends the process
//! (non-zero status), which is a failure too. Prints executions, executions per second,
//! accepted and refused inputs per target. Deterministic for a given SEED apart from
//! the time budget.

mod targets;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Deterministic xorshift64* generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Tokens a hostile user would type: numbers at the edges of f64, OBJ indices that name
/// no vertex, separators and operators that nest.
const TOKENS: [&str; 28] = [
    "nan",
    "inf",
    "-inf",
    "1e308",
    "1e200",
    "-1e300",
    "1e-308",
    "1e-320",
    "1e75",
    "1e76",
    "0",
    "-9",
    "-1",
    "4294967295",
    "18446744073709551616",
    "\n",
    " ",
    "/",
    "//",
    "(",
    ")",
    "^",
    "-",
    "*",
    "z",
    "\nf 1 2 3\n",
    "\nv 1e300 1 0\n",
    "\u{0}",
];

/// Applies one to four random mutations to `data`; `other` is another seed to splice.
fn mutate(rng: &mut Rng, data: &mut Vec<u8>, other: &[u8]) {
    for _ in 0..1 + rng.below(4) {
        let len = data.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                data[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                data[i] = rng.next() as u8;
            }
            2 if len > 0 => {
                let i = rng.below(len);
                let n = 1 + rng.below(len - i).min(16);
                data.drain(i..i + n);
            }
            3 if len > 0 => {
                let i = rng.below(len);
                let n = 1 + rng.below(len - i).min(64);
                let copy: Vec<u8> = data[i..i + n].to_vec();
                let at = rng.below(len + 1);
                data.splice(at..at, copy);
            }
            4 | 5 => {
                let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                let at = rng.below(len + 1);
                data.splice(at..at, token.iter().copied());
            }
            6 if !other.is_empty() => {
                let i = rng.below(other.len());
                let n = 1 + rng.below(other.len() - i).min(128);
                let at = rng.below(len + 1);
                data.splice(at..at, other[i..i + n].iter().copied());
            }
            _ => {
                // A deep nest of one character: parentheses, signs, powers.
                let (open, close) = [("(", ")"), ("-", ""), ("z^", "")][rng.below(3)];
                let depth = 1 + rng.below(20_000);
                let at = rng.below(len + 1);
                let mut nest = open.repeat(depth).into_bytes();
                nest.extend_from_slice(b"z");
                nest.extend(close.repeat(depth).into_bytes());
                data.splice(at..at, nest);
            }
        }
        // Keep inputs small enough for many executions per second.
        data.truncate(1 << 16);
    }
}

/// The built-in seeds of a target.
fn builtin_seeds(target: &str) -> Vec<Vec<u8>> {
    let square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    let seeds: Vec<String> = match target {
        "obj" => vec![square.into(), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nf 1 2 4 3\n".into()],
        "gltf" => vec![
            r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=","byteLength":44}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}"#.into(),
        ],
        "build" => vec![
            "\u{0}\u{3}\u{1}\u{0}\u{0}\u{0}\u{1}\u{0}\u{0}\u{0}\u{1}\u{0}\u{0}\u{1}\u{2}".into(),
            "\u{1f}\u{4}\u{81}\u{2}\u{0}\u{0}\u{0}\u{0}\u{8b}\u{1}\u{0}\u{1}\u{0}\u{1}\u{4}\u{0}\u{3}\u{1}\u{2}\u{0}\u{1}\u{2}".into(),
        ],
        "expr" => vec!["0.6*z".into(), "0.3+0.3i".into(), "-(z^2)/(1+abs(z))".into()],
        "field" => vec![format!(
            "# mu frame=global faces=16\n{}",
            "0.1 0.2\n".repeat(16)
        )],
        "landmarks" => vec!["v 0 1\nv 3 3\np 2 0.1 0.2 0\nc 1,2,3 1,2,3\n".into()],
        "correspondence" => vec![targets::correspondence_seed()],
        "cut" => vec![format!("\u{0}{}", targets::torus_obj()), format!("\u{1}{square}")],
        "ply" => vec![format!("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n3 0 1 2\n3 0 2 3\n")],
        "stl" => vec!["solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n".into()],
        "circle-domain" => vec!["\u{3}\u{28}\u{3c}\u{1e}\u{4d}\u{4b}\u{14}".into()],
        "remesh" => vec!["\u{0}\u{10}\u{1e}\u{40}\u{7}".into(), "\u{3}\u{40}\u{1e}\u{7f}\u{7}".into()],
        "jobs" => vec![
            "\u{feff}# jobs\n{\"command\": \"param\", \"input\": \"a.obj\", \"output\": \"b.obj\", \"options\": {\"solver\": \"lscm\", \"pin\": [\"v0\", \"v9\"], \"repair\": true, \"json\": false, \"tolerance\": 1e-6}}\n\n{\"command\": \"register\", \"input\": [\"s.obj\", \"t.obj\"], \"output\": \"o.obj\"}\n".into(),
            "{\"command\": \"qc\", \"input\": \"a\", \"output\": \"b\", \"options\": {\"mu\": \"-0.5\", \"max-iters\": 40}}\n".into(),
        ],
        "off" => vec!["OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n4 0 2 3 1\n".into(), "STCOFF 3 1 0\n0 0 0 1 0 0 1 0 0\n1 0 0 0 1 0 1 1 0\n0 1 0 0 0 1 1 0 1\n3 0 1 2\n".into()],
        _ => Vec::new(),
    };
    let mut seeds: Vec<Vec<u8>> = seeds.into_iter().map(String::into_bytes).collect();
    seeds.extend(binary_seeds(target));
    seeds
}

/// Built-in seeds that are not text: a binary PLY (big endian) and a binary STL square.
fn binary_seeds(target: &str) -> Vec<Vec<u8>> {
    let square = [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
    match target {
        "ply" => {
            let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
            for c in square.iter().flatten() {
                bytes.extend(f64::from(*c).to_be_bytes());
            }
            for face in [[0u32, 1, 2], [0, 2, 3]] {
                bytes.push(3);
                face.iter().for_each(|i| bytes.extend(i.to_be_bytes()));
            }
            vec![bytes]
        }
        "stl" => {
            let mut bytes = vec![0u8; 80];
            bytes.extend(2u32.to_le_bytes());
            for t in [[0, 1, 2], [0, 2, 3]] {
                bytes.extend([0u8; 12]);
                t.iter()
                    .flat_map(|&k| square[k])
                    .for_each(|c| bytes.extend(c.to_le_bytes()));
                bytes.extend([0u8; 2]);
            }
            vec![bytes]
        }
        _ => Vec::new(),
    }
}

/// The seeds of a target: built in, plus every file of `tests/corpus/TARGET/`.
fn seeds(target: &str) -> Vec<Vec<u8>> {
    let mut out = builtin_seeds(target);
    let folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(target);
    if let Ok(entries) = std::fs::read_dir(&folder) {
        let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        files.sort();
        out.extend(files.iter().filter_map(|f| std::fs::read(f).ok()));
    }
    out
}

/// What one target's run found.
struct Tally {
    execs: u64,
    accepted: u64,
    crashes: u64,
    seconds: f64,
}

/// Fuzzes `target` for `budget`, saving crashing inputs.
fn fuzz(target: &str, budget: Duration, seed: u64) -> Tally {
    let seeds = seeds(target);
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut tally = Tally {
        execs: 0,
        accepted: 0,
        crashes: 0,
        seconds: 0.0,
    };
    let start = Instant::now();
    // Every seed once unmutated, then mutants.
    let mut k = 0usize;
    while start.elapsed() < budget || k < seeds.len() {
        let mut data = seeds[k % seeds.len()].clone();
        if k >= seeds.len() {
            let other = &seeds[rng.below(seeds.len())];
            mutate(&mut rng, &mut data, other);
        }
        k += 1;
        tally.execs += 1;
        match catch_unwind(AssertUnwindSafe(|| targets::run(target, &data))) {
            Ok(Ok(())) => tally.accepted += 1,
            Ok(Err(_)) => {}
            Err(_) => {
                tally.crashes += 1;
                save_crash(target, &data);
            }
        }
    }
    tally.seconds = start.elapsed().as_secs_f64();
    tally
}

/// Writes a crashing input to `target/fuzz-crashes/TARGET-<hash>` and says where.
fn save_crash(target: &str, data: &[u8]) {
    let hash = data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/fuzz-crashes");
    let path = folder.join(format!("{target}-{hash:016x}"));
    match std::fs::create_dir_all(&folder).and_then(|()| std::fs::write(&path, data)) {
        Ok(()) => eprintln!("CRASH {target}: input saved to {}", path.display()),
        Err(e) => eprintln!("CRASH {target}: cannot save the input ({e}): {data:?}"),
    }
}

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: fuzz TARGET|all SECONDS [SEED]";
    let (Some(target), Some(seconds)) = (args.first(), args.get(1)) else {
        eprintln!("{usage}; targets: {}", targets::TARGETS.join(", "));
        return std::process::ExitCode::from(2);
    };
    let Ok(seconds) = seconds.parse::<f64>() else {
        eprintln!("{usage}: SECONDS must be a number, got `{seconds}`");
        return std::process::ExitCode::from(2);
    };
    if !(seconds.is_finite() && seconds >= 0.0) {
        eprintln!("{usage}: SECONDS must be finite and >= 0, got {seconds}");
        return std::process::ExitCode::from(2);
    }
    let seed = match args.get(2).map(|s| s.parse::<u64>()) {
        None => 1,
        Some(Ok(s)) => s,
        Some(Err(_)) => {
            eprintln!("{usage}: SEED must be a whole number");
            return std::process::ExitCode::from(2);
        }
    };
    let list: Vec<&str> = if target == "all" {
        targets::TARGETS.to_vec()
    } else if targets::TARGETS.contains(&target.as_str()) {
        vec![target.as_str()]
    } else {
        eprintln!(
            "unknown target `{target}`; targets: {}",
            targets::TARGETS.join(", ")
        );
        return std::process::ExitCode::from(2);
    };
    // Panics are counted and saved; their default message would flood the output.
    std::panic::set_hook(Box::new(|info| eprintln!("panic: {info}")));
    println!(
        "{:<15} {:>10} {:>10} {:>10} {:>8} {:>8}",
        "target", "execs", "execs/s", "accepted", "crashes", "seconds"
    );
    let mut crashes = 0;
    for name in list {
        let t = fuzz(name, Duration::from_secs_f64(seconds), seed);
        println!(
            "{name:<15} {:>10} {:>10.0} {:>10} {:>8} {:>8.1}",
            t.execs,
            t.execs as f64 / t.seconds.max(1e-9),
            t.accepted,
            t.crashes,
            t.seconds
        );
        crashes += t.crashes;
    }
    if crashes > 0 {
        eprintln!("{crashes} crashing inputs (saved under target/fuzz-crashes/)");
        return std::process::ExitCode::FAILURE;
    }
    std::process::ExitCode::SUCCESS
}
