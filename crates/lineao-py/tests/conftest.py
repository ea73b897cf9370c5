"""Where the tests find the shared data (../shared/data next to the repository) and the
`lineao` binary they compare with (target/debug/lineao, built by `cargo test --workspace`)."""

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
DATA = Path(os.environ.get("LINEAO_DATA", ROOT.parent / "shared" / "data"))
sys.path.insert(0, str(Path(__file__).parent))


def data_files(*suffixes):
    """The shared data's files ending in one of `suffixes`, sorted."""
    assert DATA.is_dir(), f"{DATA}: the shared data is missing (set LINEAO_DATA)"
    return sorted(p for p in DATA.rglob("*") if p.is_file() and p.name.endswith(suffixes))


@pytest.fixture(scope="session")
def lineao_bin():
    path = Path(os.environ.get("LINEAO_BIN", ROOT / "target" / "debug" / "lineao"))
    assert path.is_file(), f"{path}: build the command line first (cargo build) or set LINEAO_BIN"
    return path
