#!/usr/bin/env bash
# Opens a whole brain larger than 1 GiB in the web page, once (not part of the test command: on
# SwiftShader it takes many minutes): writes it with `lineao convert --scene wholebrain`
# (95 M points, 1.14 GB as .tck by default), serves it beside the page's bundle and opens it
# by ?url= in headless Chromium (crates/lineao-web/browser/large.mjs), which prints the status
# as it changes and checks the counts against `lineao info`. The page keeps none of its bytes
# (a file past hold=, 256 MiB by default, is drawn but not kept).
# usage: scripts/web-large.sh [VERTICES]   (after scripts/test-web.sh has built the bundle)
set -euo pipefail
cd "$(dirname "$0")/.."
vertices=${1:-95000000}
bash scripts/web.sh --build-only
cargo build --release --quiet --bin lineao
file=target/web/large.tck
trap 'kill ${server:-} 2>/dev/null || true; rm -f "$file"' EXIT
target/release/lineao convert --scene wholebrain --vertices "$vertices" "$file"
target/release/lineao info --json "$file" > target/web-large-info.json
ls -l "$file"
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -m http.server --bind 127.0.0.1 --directory target/web "$port" > /dev/null 2>&1 &
server=$!
for _ in $(seq 50); do python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/')" 2>/dev/null && break; sleep 0.2; done
(cd crates/lineao-web/browser && npm ci --no-audit --no-fund --silent)
node crates/lineao-web/browser/large.mjs "http://127.0.0.1:$port" large.tck target/web-large-info.json target/web-large.png
