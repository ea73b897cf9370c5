"""lineao.load, info and save against independent readers: nibabel for .trk and .tck,
trx-python for .trx, and the counts of ../shared/data/FACTS.txt for the rest."""

import gzip
import io
from pathlib import Path

import nibabel as nib
import numpy as np
import pytest

import lineao
from conftest import DATA, data_files


def nibabel_streamlines(path: Path):
    if path.name.endswith(".gz"):
        opened = gzip.open(path)
        fileobj = io.BytesIO(opened.read())
        return nib.streamlines.TrkFile.load(fileobj).streamlines
    return nib.streamlines.load(str(path)).streamlines


def same_streamlines(t: lineao.Tractogram, reference) -> None:
    assert len(t) == len(reference)
    assert len(t.points) == sum(len(s) for s in reference)
    for i, expected in enumerate(reference):
        np.testing.assert_allclose(t[i], expected, rtol=0, atol=1e-4, err_msg=f"streamline {i}")


@pytest.mark.parametrize("path", data_files(".trk", ".tck", ".trk.gz"), ids=lambda p: p.name)
def test_trk_and_tck_load_to_nibabels_points(path):
    try:
        reference = nibabel_streamlines(path)
    except Exception as refusal:  # nibabel refuses it: so must we, with the file named
        with pytest.raises(lineao.LoadError) as error:
            lineao.load(path)
        assert error.value.file == str(path), refusal
        return
    same_streamlines(lineao.load(path), reference)


def trx_facts(path: Path) -> dict:
    """FACTS.txt's reading of a .trx's arrays by an independent raw reader."""
    for line in (DATA / "FACTS.txt").read_text().splitlines():
        if line.startswith("== ") and line.split()[1].endswith(path.name) and "arrays:" in line:
            words = line.split("arrays:")[1].replace("[", " [ ").replace("]", " ] ").split()
            value = lambda key: words[words.index(key) + 1]  # noqa: E731
            point = lambda key: [float(w.strip(",")) for w in words[words.index(key) + 2 : words.index(key) + 5]]  # noqa: E731
            return {
                "streamlines": int(value("streamlines")),
                "vertices": int(value("vertices")),
                "lengths": (int(value("len0")), int(value("min")), int(value("max"))),
                "first": point("first"),
                "last": point("last"),
            }
    raise AssertionError(f"{path.name}: not in FACTS.txt")


@pytest.mark.parametrize("path", data_files(".trx"), ids=lambda p: p.name)
def test_trx_loads_to_trx_pythons_points(path):
    """trx-python where it reads the file; where it refuses (two of niivue's demos have
    offsets or dps that disagree with their header), the raw arrays FACTS.txt read."""
    from trx.trx_file_memmap import load

    t = lineao.load(path)
    try:
        reference = load(str(path))
    except ValueError:
        facts = trx_facts(path)
        assert (len(t), len(t.points)) == (facts["streamlines"], facts["vertices"])
        assert (t.lengths[0], t.lengths.min(), t.lengths.max()) == facts["lengths"]
        np.testing.assert_allclose(t.points[0], facts["first"], atol=1e-4)
        np.testing.assert_allclose(t.points[-1], facts["last"], atol=1e-4)
        return
    try:
        same_streamlines(t, reference.streamlines)
    finally:
        reference.close()


@pytest.mark.parametrize(
    "name, streamlines, vertices",
    [
        ("atlas1.vtp", 500, 177405),
        ("TR_S_R.tt.gz", None, None),
        ("tinytrack_small.tt.gz", None, None),
    ],
)
def test_other_formats_load_to_the_independent_counts(name, streamlines, vertices):
    (path,) = [p for p in DATA.rglob(name)]
    t = lineao.load(path)
    facts = lineao.info(path)
    assert (len(t), len(t.points)) == (facts["streamlines"], facts["vertices"])
    if streamlines is not None:
        assert (len(t), len(t.points)) == (streamlines, vertices)
    assert len(t) > 0 and np.isfinite(t.points).all()


def test_the_arrays_own_the_loaders_memory():
    t = lineao.load(DATA / "dipy+dipy/dipy/data/files/tracks300.trk")
    for array in (t.points, t.offsets):
        assert not array.flags["OWNDATA"], "a view of the Rust allocation, not a numpy copy"
        assert type(array.base).__name__ == "PySliceContainer"
        assert array.flags["C_CONTIGUOUS"]
    assert t.points.dtype == np.float32 and t.points.shape == (14576, 3)
    assert t.offsets.dtype == np.int64 and t.lengths.dtype == np.int64
    assert t.affine.shape == (4, 4) and t.dimensions == (50, 50, 50) and t.voxel_sizes == (1.0, 1.0, 1.0)
    assert t.format == "trk"


def test_fields_and_info_keys():
    path = DATA / "nipy+nibabel/nibabel/tests/data/complex.trk"
    t = lineao.load(path)
    reference = nib.streamlines.load(str(path)).tractogram
    np.testing.assert_allclose(t.vertex_fields["fa"], reference.data_per_point["fa"].get_data()[:, 0])
    np.testing.assert_allclose(t.vertex_fields["colors"], reference.data_per_point["colors"].get_data())
    np.testing.assert_allclose(t.streamline_fields["mean_colors"], reference.data_per_streamline["mean_colors"])
    info = lineao.info(path)
    for key in ("format", "streamlines", "vertices", "vertex_fields", "streamline_fields", "bounds", "affine"):
        assert key in info
    assert info["streamlines"] == 3 and info["vertices"] == 8 and info["vertex_fields"] == {"colors": 3, "fa": 1}


def test_bad_files_raise_load_error_with_file_offset_and_expectation(tmp_path):
    bad = tmp_path / "bad.tck"
    bad.write_bytes(b"mrtrix tracks\ncount: 1\ndatatype: Float32LE\nfile: . 400\nEND\n")
    with pytest.raises(lineao.LoadError) as error:
        lineao.load(bad)
    assert isinstance(error.value, ValueError)
    assert error.value.file == str(bad)
    assert error.value.offset is not None and error.value.expected
    assert str(bad) in str(error.value)
    with pytest.raises(lineao.LoadError) as missing:
        lineao.load(tmp_path / "missing.trk")
    assert missing.value.offset is None
    with pytest.raises(lineao.LoadError):
        lineao.load(DATA / "tee-ar-ex+trx-rs/tests/fixtures/tinytrack_malformed.tt.gz")


def test_legacy_vtk_without_a_title_and_with_zero_lines_is_empty(tmp_path):
    # As MRtrix's tckconvert writes an empty tractogram: the version line, then ASCII directly.
    path = tmp_path / "empty.vtk"
    path.write_bytes(b"# vtk DataFile Version 1.0\nASCII\nDATASET POLYDATA\nPOINTS 0 float\nLINES 0 0\n")
    t = lineao.load(path)
    assert len(t) == 0 and t.points.shape == (0, 3)


def test_empty_files_load_empty():
    for name in ("empty.trk", "empty.tck"):
        t = lineao.load(DATA / "nipy+nibabel/nibabel/tests/data" / name)
        assert len(t) == 0 and t.points.shape == (0, 3) and t.offsets.shape == (0,)


def test_save_round_trips_and_keeps_fields(tmp_path):
    t = lineao.load(DATA / "nipy+nibabel/nibabel/tests/data/complex.trk")
    for ext in ("trk", "tck", "trx"):
        out = tmp_path / f"out.{ext}"
        if ext == "tck":
            with pytest.warns(UserWarning, match="cannot hold the fields colors, fa"):
                lineao.save(t, out)
        else:
            lineao.save(t, out)
        back = lineao.load(out)
        same_streamlines(back, list(t))
        if ext != "tck":
            np.testing.assert_allclose(back.vertex_fields["fa"], t.vertex_fields["fa"])
    # A list of arrays, saved and read by nibabel.
    lines = [np.array([[0, 0, 0], [1, 2, 3]], np.float64), np.arange(12, dtype=np.float32).reshape(4, 3)]
    lineao.save(lines, tmp_path / "list.tck")
    same_streamlines(lineao.load(tmp_path / "list.tck"), nib.streamlines.load(str(tmp_path / "list.tck")).streamlines)
    with pytest.raises(lineao.LoadError, match="we write"):
        lineao.save(lines, tmp_path / "out.vtk")
    # A path is loaded first: a conversion.
    lineao.save(DATA / "nipy+nibabel/nibabel/tests/data/complex.trk", tmp_path / "converted.trx")
    same_streamlines(lineao.load(tmp_path / "converted.trx"), list(t))


def test_a_progress_callback_sees_the_bytes_and_can_interrupt(tmp_path):
    big = tmp_path / "big.tck"
    rng = np.random.default_rng(1)
    lineao.save([rng.normal(size=(100, 3)).astype(np.float32) for _ in range(5000)], big)
    seen = []
    lineao.load(big, progress=lambda done, total: seen.append((done, total)))
    assert len(seen) >= 2 and seen[-1][0] == seen[-1][1] == big.stat().st_size

    def interrupt(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        lineao.load(big, progress=interrupt)


def test_ctrl_c_interrupts_a_long_load(tmp_path):
    """SIGINT during a load (the GIL released, the main thread in Rust) → KeyboardInterrupt."""
    import os
    import signal
    import threading

    big = tmp_path / "big.tck"
    rng = np.random.default_rng(2)
    lineao.save([rng.normal(size=(1000, 3)).astype(np.float32) for _ in range(3000)], big)
    calls = []

    def slow(done, total):  # keeps the load going until the signal has arrived
        calls.append(done)
        if len(calls) == 1:
            threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT)).start()
            import time

            # Short sleeps in a loop: its jumps let Python run the handler wherever the kernel
            # delivered the signal (the sending thread too), within up to 5 s.
            for _ in range(200):
                time.sleep(0.025)

    # Python raises KeyboardInterrupt only where SIGINT was not ignored when it started, and a
    # shell ignores it for what it starts in the background (`bash .ci/run &`): install the
    # handler a terminal's Python has.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            lineao.load(big, progress=slow)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(calls) < 8, f"the load stopped at the next report, not after {len(calls)}"


@pytest.mark.parametrize("path", data_files(""), ids=lambda p: str(p.relative_to(DATA)))
def test_every_shared_file_loads_or_is_a_load_error(path):
    """Every file of ../shared/data, tractogram or not: a Tractogram whose counts are what
    `info` says, or a LoadError naming the file — never another exception or a crash."""
    try:
        t = lineao.load(path)
    except lineao.LoadError as error:
        assert error.file == str(path)
        return
    facts = lineao.info(path)
    assert int(t.lengths.sum()) == facts["vertices"] and len(t) == facts["streamlines"]
    if path.suffix == ".tsf":  # values without points: the offsets index the values
        assert len(t.points) == 0 and all(len(v) == facts["vertices"] for v in t.vertex_fields.values())
    else:
        assert t.points.shape == (facts["vertices"], 3)


def test_save_gathers_out_of_order_streamlines_with_their_vertex_fields(tmp_path):
    points = np.arange(15, dtype=np.float32).reshape(5, 3)
    fa = np.arange(5, dtype=np.float32)
    t = lineao.Tractogram(points, offsets=[3, 0], lengths=[2, 3], vertex_fields={"fa": fa})
    lineao.save(t, tmp_path / "out.trk")
    back = lineao.load(tmp_path / "out.trk")
    np.testing.assert_array_equal(back.points, points[[3, 4, 0, 1, 2]])
    np.testing.assert_array_equal(back.vertex_fields["fa"], fa[[3, 4, 0, 1, 2]])
    with pytest.raises(ValueError, match="vertex field 'fa': expected 5 rows"):
        lineao.save(lineao.Tractogram(points, [0], [5], vertex_fields={"fa": fa[:4]}), tmp_path / "x.trk")
