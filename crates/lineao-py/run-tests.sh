#!/usr/bin/env bash
# The Python package's tests, from a fresh clone: a virtual environment in target/python-venv
# (made once), the package built by pip from this checkout into it — in the workspace's target
# directory and dev profile, so after `cargo test --workspace` only the bindings compile — and
# pytest, which compares with the `lineao` binary of the same build.
set -euo pipefail
cd "$(dirname "$0")"
root="$(cd ../.. && pwd)"
venv="$root/target/python-venv"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
export PATH="$venv/bin:$PATH"   # as `activate` does: the build backend runs `maturin`
pip=("$venv/bin/pip" install -q --disable-pip-version-check)
"${pip[@]}" -r tests/requirements.txt
# With the registry's test method `toy`, as the workspace's test build has it (and so that
# build's lineao is reused): the tests find it in `methods()`.
MATURIN_PEP517_ARGS="--features toy-method" "${pip[@]}" --no-build-isolation --force-reinstall --no-deps .
# The binary the tests compare with, from the same build as `cargo test --workspace` (a no-op
# right after it; a build of the binary alone would resolve features differently and rebuild).
cargo test -q --workspace --no-run
LINEAO_BIN="$root/target/debug/lineao" "$venv/bin/python" -m pytest -q tests
