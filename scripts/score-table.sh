#!/usr/bin/env bash
# Reproduces the README's table "How far each method is from the truth": `lineao score --json`
# on the built-in scenes and the real tractograms of ../shared/data, at R = 2 mm (the default)
# and R = 5 mm, 640 × 512, 256 rays, each method at the preset's values (`physical`, the
# calibration against the local truth these tables were made with, by default; PRESET=legible
# for the default preset, PRESET=paper for the papers'). Prints a Markdown table (python3 formats the JSON).
set -euo pipefail
cd "$(dirname "$0")/.."
data=../shared/data
preset=${PRESET:-physical}
sources=(--scene=bundles --scene=spiral --scene=vortex
  "$data/niivue+niivue/packages/niivue/demos/images/stroke.trk.gz"
  "$data/niivue+niivue/packages/niivue/demos/images/sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx"
  "$data/SlicerDMRI+whitematteranalysis/tests/test_atlas_results/atlas1.vtp"
  "$data/dipy+dipy/dipy/data/files/tracks300.trk")
cargo build --release --quiet
format='
import json, os, sys
r = json.load(sys.stdin)
name = os.path.basename(r["scene"])
for m in r["methods"]:
    print("| %s | %g | %s | %s | %.3f | %.3f | %+.3f | %.3f | %.3f | %.3f | %.2f | %.3f |" % (
        name, r["ao_distance_world"], m["method"], m["truth"], m["mean"], m["truth_mean"], m["bias"],
        m["rmse"], m["correlation"], m["ssim"], m["scale"], m["image_ssim"]))
'
echo "| data | R | method | truth | mean | truth mean | bias | RMSE | corr. | SSIM | scale | image SSIM |"
echo "|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"
for source in "${sources[@]}"; do
  for distance in 2 5; do
    ./target/release/lineao score "$source" --width 640 --height 512 --rays 256 --ao-distance "$distance" \
      --preset "$preset" --json 2>/dev/null | python3 -c "$format"
  done
done
