"""The legibility numbers the Rust test `exact_equals_an_independent_implementation` holds are
what the independent numpy computation prints today (so the constant cannot go stale)."""
import pathlib
import re
import runpy
import contextlib
import io

ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_numpy_legibility_equals_the_rust_tests_constant():
    script = ROOT / "crates/lineao/tests/legibility_numpy.py"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        runpy.run_path(str(script), run_name="__main__")
    printed = [float(x) for x in re.findall(r"[-+]?\d+\.\d+(?:e[-+]?\d+)?", out.getvalue())]
    source = (ROOT / "crates/lineao/src/truth/legibility.rs").read_text()
    constant = re.search(r"const NUMPY_EXACT: \[f64; 3\] = \[([^\]]*)\]", source).group(1)
    rust = [float(x.replace("_", "")) for x in constant.split(",")]
    assert len(printed) == 3 and len(rust) == 3
    for p, r in zip(printed, rust):
        assert abs(p - r) < 1e-15, (printed, rust)
