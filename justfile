# Short recipes for development. The README's commands never need `just`
# (install it with `pip install rust-just` if you want it).

# Run the main job on the bundled mesh.
demo:
    cargo run --release -- register meshes/spot.obj meshes/blob.obj -o spot_on_blob.obj

# Build everything in release mode.
build:
    cargo build --workspace --release

# Run the whole test suite (release: numerics are ~30x slower in debug).
test:
    cargo test --workspace --release

# Install the Python package into the active environment and run its tests.
python:
    pip install "./python[test]"
    python -m pytest -q python/tests

# Build the distributable Python wheel into dist/: abi3 (CPython 3.9 and later),
# manylinux2014 (x86_64 Linux with glibc 2.17 or newer).
wheel:
    bash python/build_wheel.sh dist

# What CI runs: fmt, clippy, tests.
ci:
    bash .ci/run

# Loading benchmark: parse and build times of generated meshes.
bench:
    cargo run --release -- bench load

# Format the workspace.
fmt:
    cargo fmt --all
