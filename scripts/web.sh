#!/usr/bin/env bash
# The viewer as a web page (WebGPU): builds the static bundle into target/web/ — index.html,
# lineao_web.js and lineao_web_bg.wasm, from crates/lineao-web — and serves it on 127.0.0.1.
#
#   bash scripts/web.sh                 build, then serve on http://127.0.0.1:8080/
#   bash scripts/web.sh --port 9000     another port
#   bash scripts/web.sh --build-only    build only (what scripts/test-web.sh runs first)
#
# The bundle is plain static files: any static host serves it. For `?url=`, files must come
# from the same origin; the served folder links ../shared/data as data/ when it is there, so
# http://127.0.0.1:8080/?url=data/niivue%2Bniivue/packages/niivue/demos/images/stroke.trk.gz works.
#
# The wasm32 build uses rustup's wasm32-unknown-unknown target where installed; otherwise
# Debian's rustc-web (rustc 1.96 with its standard library's source, rust-web-src, and lld-22)
# builds the standard library itself (-Zbuild-std), as these machines do. wasm-bindgen-cli is
# installed from crates.io at the version Cargo.lock pins for the wasm-bindgen crate.
set -euo pipefail
cd "$(dirname "$0")/.."
port=8080
serve=1
while [ $# -gt 0 ]; do
  case "$1" in
    --port) port="$2"; shift 2 ;;
    --build-only) serve=0; shift ;;
    *) echo "usage: scripts/web.sh [--build-only] [--port N]" >&2; exit 2 ;;
  esac
done
target=wasm32-unknown-unknown
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}/wasm32"
# WebAssembly's 128-bit SIMD, which every browser with WebGPU runs. Measured: a .wasm 0.2 MB
# smaller, stroke.trk.gz's parse no faster.
export CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="${CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS:--C target-feature=+simd128}"
start=$(date +%s)
if rustup target list --installed 2>/dev/null | grep -qx "$target"; then
  echo "web: rustup's $target target"
  cargo build -p lineao-web --lib --target "$target" --profile web
elif [ -x /usr/bin/rustc ] && [ -d /usr/lib/rustlib/src/rust/library ] && command -v lld-22 >/dev/null; then
  echo "web: Debian's rustc-web ($(/usr/bin/rustc --version)) with -Zbuild-std"
  # RUSTC_BOOTSTRAP lets this stable rustc take -Zbuild-std, the one unstable flag used.
  RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 /usr/bin/cargo build -p lineao-web --lib --target "$target" --profile web \
    -Zbuild-std=std,panic_abort
else
  echo "web: no wasm32 toolchain: run 'rustup target add $target', or install Debian's" \
    "rustc-web cargo-web rust-web-src lld-22 (as .ci/run does)" >&2
  exit 1
fi
built=$(date +%s)
version=$(awk '$0 == "name = \"wasm-bindgen\"" { getline; gsub(/version = |"/, ""); print }' Cargo.lock)
if ! wasm-bindgen --version 2>/dev/null | grep -qx "wasm-bindgen $version"; then
  echo "web: installing wasm-bindgen-cli $version (Cargo.lock's wasm-bindgen)"
  cargo install wasm-bindgen-cli --version "$version"
fi
out=target/web
rm -rf "$out"
mkdir -p "$out"
wasm-bindgen --target web --no-typescript --remove-name-section --remove-producers-section --out-dir "$out" "$CARGO_TARGET_DIR/$target/web/lineao_web.wasm"
cp crates/lineao-web/web/index.html "$out/"
if [ -d ../shared/data ]; then
  ln -s "$(cd ../shared/data && pwd)" "$out/data"
fi
wasm="$out/lineao_web_bg.wasm"
echo "web: built in $((built - start)) s (wasm-bindgen $(( $(date +%s) - built )) s): $wasm" \
  "$(stat -c %s "$wasm") bytes, $(gzip -9 -c "$wasm" | wc -c) gzipped"
if [ "$serve" = 1 ]; then
  echo "web: serving $out on http://127.0.0.1:$port/ (Ctrl-C stops)"
  exec python3 -m http.server --bind 127.0.0.1 --directory "$out" "$port"
fi
