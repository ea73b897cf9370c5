#!/usr/bin/env bash
# Builds and tests lineao-bevy, a workspace of its own (its own Cargo.lock and target/): the
# headless tests on whatever adapter wgpu finds (lavapipe on CI), both examples (`cargo test`
# builds them) and the examples' windowless screenshots. Bevy 0.20 declares rustc 1.97.1 but
# builds on older toolchains with the features this crate uses; with such a rustc (1.95 on
# these machines) the script passes --ignore-rust-version, which a current toolchain never needs.
set -euo pipefail
cd "$(dirname "$0")/../crates/lineao-bevy"
flags=(--features window)
have=$(rustc --version | awk '{print $2}')
if [ "$(printf '%s\n' 1.97.1 "$have" | sort -V | head -n1)" != 1.97.1 ]; then
  echo "test-bevy: rustc $have is older than Bevy's 1.97.1: --ignore-rust-version"
  flags+=(--ignore-rust-version)
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
cargo test "${flags[@]}"
mkdir -p target/screenshots
cargo run -q "${flags[@]}" --example meshes -- --screenshot target/screenshots/meshes.png
cargo run -q "${flags[@]}" --example tractogram -- --scene bundles --screenshot target/screenshots/tractogram.png
echo "test-bevy: tests and examples passed in ${SECONDS} s; screenshots in crates/lineao-bevy/target/screenshots"
