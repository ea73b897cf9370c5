#!/usr/bin/env bash
# Checks that the core (`lineao`) and the loaders (`lineao-tracts`) build for the web
# (wasm32-unknown-unknown, wgpu's WebGPU backend): `cargo build --target wasm32-unknown-unknown`.
# With a rustup toolchain that has the wasm32 target (`rustup target add wasm32-unknown-unknown`)
# it uses that; otherwise Debian's rustc-web (rustc 1.96 with its standard library's source,
# rust-web-src, and lld-22) builds the standard library for wasm32 itself (-Zbuild-std), which
# is how these machines, which have no rustup wasm32 target, do it. .ci/run installs those
# packages. The build goes to target/wasm32 so it never disturbs the host build.
set -euo pipefail
cd "$(dirname "$0")/.."
target=wasm32-unknown-unknown
crates=(-p lineao -p lineao-tracts)
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}/wasm32"
if rustup target list --installed 2>/dev/null | grep -qx "$target"; then
  echo "check-wasm: rustup's $target target"
  cargo build "${crates[@]}" --target "$target"
elif [ -x /usr/bin/rustc ] && [ -d /usr/lib/rustlib/src/rust/library ] && command -v lld-22 >/dev/null; then
  echo "check-wasm: Debian's rustc-web ($(/usr/bin/rustc --version)) with -Zbuild-std"
  # RUSTC_BOOTSTRAP lets this stable rustc take -Zbuild-std, the one unstable flag used.
  RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 /usr/bin/cargo build "${crates[@]}" --target "$target" \
    -Zbuild-std=std,panic_abort
else
  echo "check-wasm: no wasm32 toolchain: run 'rustup target add $target', or install Debian's" \
    "rustc-web cargo-web rust-web-src lld-22 (as .ci/run does)" >&2
  exit 1
fi
echo "check-wasm: lineao and lineao-tracts build for $target"
