#!/usr/bin/env bash
# Runs the shell blocks of README.md and docs/ marked runnable (a fence opened with
# "```sh runnable"), so the commands the docs show keep working. Each block runs in a fresh
# folder holding the test data's files by the names the docs use (stroke.trk.gz and its z-map
# and template from ../shared/data), with `cargo run --release --` replaced by the lineao
# binary of $LINEAO (default: target/debug/lineao, which `cargo test --workspace` builds).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
lineao="${LINEAO:-$root/target/debug/lineao}"
[ -x "$lineao" ] || cargo build --quiet --bin lineao
images="$root/../shared/data/niivue+niivue/packages/niivue/demos/images"
blocks=0
for page in README.md docs/*.md; do
  # Each runnable block of the page, NUL-separated.
  while IFS= read -r -d '' block; do
    blocks=$((blocks + 1))
    work=$(mktemp -d)
    for f in stroke.trk.gz strokez.nii.gz MNI152_2009_template.nii.gz; do ln -s "$images/$f" "$work/$f"; done
    script=${block//cargo run --release --/\"$lineao\"}
    echo "docs-commands: $page, block $blocks" >&2
    if ! (cd "$work" && export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}" && bash -euo pipefail -c "$script") >"$work/log" 2>&1; then
      echo "docs-commands: a command of $page failed:" >&2
      echo "$script" >&2
      tail -20 "$work/log" >&2
      exit 1
    fi
    rm -rf "$work"
  done < <(python3 - "$page" <<'PY'
import sys
lines, block, inside = open(sys.argv[1], encoding="utf-8").read().splitlines(), [], False
for line in lines:
    if not inside and line.strip() == "```sh runnable":
        inside, block = True, []
    elif inside and line.strip() == "```":
        sys.stdout.write("\n".join(block) + "\n\0")
        inside = False
    elif inside:
        block.append(line)
PY
)
done
echo "docs-commands: $blocks runnable blocks ran" >&2
