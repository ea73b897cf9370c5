#!/usr/bin/env bash
# The web page's test: builds the bundle (scripts/web.sh --build-only), serves it on
# 127.0.0.1, drives it in Debian's headless Chromium (WebGPU on SwiftShader) with playwright-core
# (crates/lineao-web/browser/test.mjs: a scene, a real file by ?url=, drops, bad files and URLs,
# no WebGPU), then checks natively that each frame the page read back agrees with lineao's CPU
# reference on exactly its inputs (lineao-web-check), and times the page's LineAO pass against
# the native one on lavapipe. Prints what each part cost. Needs: chromium, node and npm
# (.ci/run installs chromium).
set -euo pipefail
cd "$(dirname "$0")/.."
t0=$(date +%s)
bash scripts/web.sh --build-only
t1=$(date +%s)
# `lineao` and `lineao-web-check` as the workspace's tests build them (the same features, so
# after `cargo test --workspace` nothing is compiled again; `cargo build -p …` would rebuild
# lineao without the tests' features: 3.5 min in CI).
cargo test --workspace --no-run --quiet 2> /dev/null || cargo test --workspace --no-run
(cd crates/lineao-web/browser && npm ci --no-audit --no-fund --silent)
out=target/web-test
rm -rf "$out"
# Files the page reads whole over its limit (a tractogram, a colour file), sparse (no disk):
# the server states their size, the page refuses them. And a whole brain of 2 M points, which
# the page decodes as it arrives.
truncate -s 1100M target/web/too-large.trx
truncate -s 1100M target/web/too-large.tsf
target/debug/lineao convert --scene wholebrain --vertices 2000000 target/web/wholebrain.tck
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -m http.server --bind 127.0.0.1 --directory target/web "$port" > /dev/null 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true; rm -f target/web/too-large.trx target/web/too-large.tsf target/web/wholebrain.tck' EXIT
for _ in $(seq 50); do python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/')" 2>/dev/null && break; sleep 0.2; done
t2=$(date +%s)
node crates/lineao-web/browser/test.mjs "http://127.0.0.1:$port" "$out" target/debug/lineao ../shared/data \
  target/web/wholebrain.tck
t3=$(date +%s)
# LINEAO_WEB_ONLY=text ran only the browser's checks named by it: nothing to compare.
[ -z "${LINEAO_WEB_ONLY:-}" ] || exit 0
target/debug/lineao-web-check "$out"/scene/0 "$out"/scene/1 "$out"/stroke/0 "$out"/stroke/1
# The same passes natively on lavapipe: the same scene at the page's frame size, `lineao bench`
# (median of 5 frames after 2 of warm-up).
size=$(python3 -c "import json; print('%d %d' % tuple(json.load(open('$out/results.json'))['timings']['size']))")
read -r width height <<< "$size"
target/debug/lineao bench --scene bundles --vertices 200000 --width "$width" --height "$height" --frames 5 --warmup 2 \
  --passes lines,lineao --json > "$out/native-bench.json"
python3 - "$out/results.json" "$out/native-bench.json" <<'PY'
import json, sys
page = json.load(open(sys.argv[1]))
bench = json.load(open(sys.argv[2]))
native = {p["name"]: p["ms_median"] for p in bench["passes"]}
ours = dict(page["timings"]["passes"])
print("web: bundles, 200 000 vertices, %s px; GPU ms per pass, page on %s vs native on %s:"
      % ("x".join(map(str, page["timings"]["size"])), page["timings"]["adapter"], bench["adapter"]))
for name in ("lines", "lineao"):
    print("  %-8s page %9.2f   native %9.2f   ratio %.2f" % (name, ours[name], native[name], ours[name] / native[name]))
stroke = page["stroke"]["status"]
print("web: stroke.trk.gz: page parse and upload %.0f ms; opened by ?url= in %.1f s (fetch, parse, upload, first frames)"
      % (stroke["loadMs"], page["stroke"]["ms"] / 1000))
whole = page["streamed"]["status"]
print("web: wholebrain.tck (%d points, decoded as it arrived): first part on the GPU %.0f ms, first picture %.0f ms, all %.0f ms; ready in %.1f s"
      % (whole["vertices"], whole["firstMs"], whole["firstPictureMs"] or -1, whole["loadMs"], page["streamed"]["ms"] / 1000))
PY
# The same parse natively (the bytes in memory, lineao-tracts at opt-level 3 as in release).
target/debug/lineao-web-check --load ../shared/data/niivue+niivue/packages/niivue/demos/images/stroke.trk.gz
t4=$(date +%s)
echo "test-web: build $((t1 - t0)) s, browser $((t3 - t2)) s, checks and native timing $((t4 - t3)) s, total $((t4 - t0)) s"
