#!/usr/bin/env bash
# The docs' checks, the last part of the test command:
# - the core crates' rustdoc with every warning an error (`missing_docs` is denied in the crates
#   themselves), all features on, as docs.rs builds them;
# - their crates.io metadata, by `cargo package` (without building the package again);
# - every relative link and anchor of README.md and docs/ (scripts/check-links.py);
# - the shell blocks the docs mark runnable (scripts/docs-commands.sh).
# docs/options.md is checked by `cargo test` (crates/lineao-web/tests/options_doc.rs).
set -euo pipefail
cd "$(dirname "$0")/.."
RUSTDOCFLAGS="-D warnings" cargo doc --quiet --no-deps -p lineao -p lineao-tracts \
  --features lineao/reference,lineao/truth,lineao/volume,lineao/serde
cargo package --quiet --no-verify --allow-dirty -p lineao-tracts -p lineao
python3 scripts/check-links.py
bash scripts/docs-commands.sh
echo "check-docs: rustdoc, package metadata, links and runnable commands all pass" >&2
