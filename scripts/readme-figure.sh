#!/usr/bin/env bash
# The README's first figure, docs/stroke-legibility.png: a real whole brain (niivue's
# stroke.trk.gz, 36 763 streamlines) at 1280 × 1024 — no AO | LineAO at the default preset |
# Crytek SSAO | the bundle-scale truth (obscurance, linear falloff to 20 % of the longest side,
# 64 rays, CPU) — each over a crop at full resolution, labelled with its legibility L at 1, 4
# and 15 % of the width from `lineao score --json` on the same view. Needs ImageMagick
# (`convert`) with a font, and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
file=../shared/data/niivue+niivue/packages/niivue/demos/images/stroke.trk.gz
out=target/readme-figure
mkdir -p "$out"
size=(--width 1280 --height 1024)
cargo build --quiet --bin lineao
lineao=./target/debug/lineao
$lineao render "$file" "${size[@]}" --method none -o "$out/none.png"
$lineao render "$file" "${size[@]}" --method lineao -o "$out/lineao.png"
$lineao render "$file" "${size[@]}" --method ssao -o "$out/ssao.png"
$lineao render "$file" "${size[@]}" --method raytraced --cpu --rays 64 --ao-falloff linear --ao-distance 20% \
  -o "$out/truth.png"
$lineao score "$file" "${size[@]}" --rays 64 --methods lineao,ssao --json >"$out/score.json"
labels=$(python3 - "$out/score.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
pictures = {p["picture"]: p["legibility"] for p in r["pictures"]}
methods = {m["method"]: m["legibility"] for m in r["methods"]}
def l(x):
    return "L %+.2f / %+.2f / %+.2f, darkening %.2f" % (x["l_local"], x["l_bundle"], x["l_global"], x["mean_darkening"])
print(l(pictures["none"]))
print(l(methods["lineao"]))
print(l(methods["ssao"]))
print(l(pictures["bundle-truth"]))
PY
)
mapfile -t label <<<"$labels"
titles=("no ambient occlusion" "LineAO (default)" "Crytek SSAO" "truth: obscurance to 20 %")
columns=()
for i in 0 1 2 3; do
  name=(none lineao ssao truth)
  # The whole frame at 3/8, and a 480 × 384 crop of the brain at full resolution.
  convert "$out/${name[$i]}.png" -resize 480x384 "$out/full-$i.png"
  convert "$out/${name[$i]}.png" -crop 480x384+560+300 +repage "$out/crop-$i.png"
  convert -size 480x44 xc:white -font DejaVu-Sans -pointsize 17 -annotate +6+18 "${titles[$i]}" \
    -pointsize 13 -annotate +6+38 "${label[$i]}" "$out/label-$i.png"
  convert "$out/label-$i.png" "$out/full-$i.png" "$out/crop-$i.png" -append "$out/column-$i.png"
  columns+=("$out/column-$i.png")
done
convert "${columns[@]}" -bordercolor white -border 4 +append docs/stroke-legibility.png
echo "docs/stroke-legibility.png"
printf '%s\n' "${label[@]}"
