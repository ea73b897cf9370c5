#!/usr/bin/env bash
# The main job on the built-in data: the `bundles` scene with LineAO, written to lineao.png.
# Extra arguments go to `lineao render` (e.g. --scene spiral -o spiral.png).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-vulkan.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
cargo run --release --quiet -- render --scene bundles --method lineao -o lineao.png "$@"
