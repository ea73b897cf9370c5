#!/usr/bin/env bash
# Lines rasterized in compute against the hardware rasterizer, on a GPU: one run of
# `lineao bench` with `lines-compute` beside `lines-culled` (and the cull alone) on the 1 M
# `bundles`, the 50 M and the 1 G whole brain at 1280 x 1024, each report as JSON under
# OUT (default: target/gpu-raster), and the adapter's name in each.
#
#   cargo build --release && scripts/gpu-raster.sh            # or, with a built binary:
#   LINEAO=path/to/lineao OUT=/tmp/out scripts/gpu-raster.sh
set -euo pipefail
cd "$(dirname "$0")/.."
lineao=${LINEAO:-target/release/lineao}
out=${OUT:-target/gpu-raster}
mkdir -p "$out"
passes=lines-culled,lines-compute,cull
"$lineao" bench --json --passes "$passes" --frames 10 --warmup 3 >"$out/bundles-1m.json"
for vertices in 50000000 1000000000; do
    "$lineao" bench --json --scene wholebrain --vertices "$vertices" --passes "$passes" --frames 5 --warmup 2 \
        >"$out/wholebrain-$vertices.json"
done
for report in "$out"/*.json; do
    python3 - "$report" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
ms = {p["name"]: p["ms_median"] for p in r["passes"]}
print(f'{r["adapter"]}: {r["scene"]} {r["vertices"]} vertices: ' +
      ", ".join(f"{k} {v:.2f} ms" for k, v in ms.items()) +
      f'; lines-compute / lines-culled {ms["lines-compute"] / ms["lines-culled"]:.2f}x')
PY
done
