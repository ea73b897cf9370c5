#!/usr/bin/env bash
# The legibility table of docs/ground-truth.md: `lineao score --json` on every real tractogram
# of ../shared/data with at least 10 streamlines, at 640 × 512 from each file's home camera,
# 64 rays for both truths (local: binary AO to 2 mm; bundle-scale: obscurance, linear falloff
# to 20 % of the longest side), with the default preset (legible) and with --preset paper.
# Writes the JSON into target/legibility/ and prints two Markdown tables (python3 formats them).
set -euo pipefail
cd "$(dirname "$0")/.."
data=../shared/data/
out=target/legibility
mkdir -p "$out"
files=(
  "SlicerDMRI+whitematteranalysis/tests/test_atlas_results/atlas1.vtp"
  "dipy+dipy/dipy/data/files/EuDX_small_25.trk"
  "dipy+dipy/dipy/data/files/tracks300.trk"
  "niivue+niivue/packages/niivue/demos/images/TR_S_R.tt.gz"
  "niivue+niivue/packages/niivue/demos/images/dpsv.trx"
  "niivue+niivue/packages/niivue/demos/images/stroke.trk.gz"
  "niivue+niivue/packages/niivue/demos/images/sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx"
  "niivue+niivue/packages/niivue/demos/images/tract.IFOF_R.trk"
  "niivue+niivue/packages/niivue/demos/images/tract.SLF1_R.tck"
  "nipy+nibabel/nibabel/tests/data/standard.LPS.trk"
  "nipy+nibabel/nibabel/tests/data/standard.tck"
  "nipy+nibabel/nibabel/tests/data/standard.trk"
)
cargo build --quiet --bin lineao
for file in "${files[@]}"; do
  name=$(basename "$file")
  for preset in legible paper; do
    ./target/debug/lineao score "$data$file" --width 640 --height 512 --rays 64 --preset "$preset" \
      --methods lineao,lineao-reference,vo-line,vo-area,ssao --json 2>/dev/null >"$out/$name.$preset.json"
  done
done
python3 - "$out" "${files[@]}" <<'PY'
import json, os, sys
out, files = sys.argv[1], [os.path.basename(f) for f in sys.argv[2:]]
def l(x):
    if "absent" in x:
        return "absent", "", ""
    return ("%+.2f / %+.2f / %+.2f" % (x["l_local"], x["l_bundle"], x["l_global"]),
            "%.2f" % x["mean_darkening"], "%.1f %%" % (100 * x["near_black"]))
print("| data | picture | L 1 / 4 / 15 % | mean darkening | near-black | corr. with bundle truth |")
print("|---|---|---|---:|---:|---:|")
for name in files:
    r = {p: json.load(open(os.path.join(out, f"{name}.{p}.json"))) for p in ("legible", "paper")}
    pictures = {p["picture"]: p["legibility"] for p in r["legible"]["pictures"]}
    rows = [("no AO", pictures["none"], ""), ("truth, binary 2 mm", pictures["truth"], ""),
            ("truth, linear %s" % r["legible"]["bundle_truth"]["ao_distance"], pictures["bundle-truth"], "")]
    for preset in ("legible", "paper"):
        for m in r[preset]["methods"]:
            rows.append(("%s (%s)" % (m["method"], preset), m["legibility"], "%.3f" % m["bundle"]["correlation"]))
    for i, (what, x, corr) in enumerate(rows):
        print("| %s | %s | %s | %s | %s | %s |" % ((name if i == 0 else ""), what, *l(x), corr))
print()
print("| data | LineAO default L 1 / 4 / 15 % | paper | default − paper (≥ −0.02?) | default darkening, near-black | buried (truth) |")
print("|---|---|---|---|---|---:|")
for name in files:
    report = json.load(open(os.path.join(out, f"{name}.legible.json")))
    d = report["methods"][0]["legibility"]
    p = json.load(open(os.path.join(out, f"{name}.paper.json")))["methods"][0]["legibility"]
    if "absent" in d or "absent" in p:
        print("| %s | absent | | | | |" % name)
        continue
    keys = ("l_local", "l_bundle", "l_global")
    diff = [d[k] - p[k] for k in keys]
    ok = "yes" if min(diff) >= -0.02 else "no"
    print("| %s | %s | %s | %s (%s) | %.2f, %.1f %% | %.1f %% |" % (name, l(d)[0], l(p)[0],
          " / ".join("%+.2f" % x for x in diff), ok, d["mean_darkening"], 100 * d["near_black"],
          100 * report["buried_share"]))
PY
