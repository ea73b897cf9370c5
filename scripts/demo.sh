#!/usr/bin/env bash
# The main job on the built-in data: the `bundles` scene split between no AO (left) and LineAO
# (right), written to lineao.png, so that what LineAO adds shows at a glance.
# Extra arguments go to `lineao render` (e.g. --scene spiral -o spiral.png).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-vulkan.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
cargo run --release --quiet -- render --scene bundles --compare none,lineao -o lineao.png "$@"
echo "lineao.png: the built-in bundles scene, no AO on the left, LineAO (the default) on the right"
