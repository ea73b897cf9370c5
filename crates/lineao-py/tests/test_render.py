"""lineao.render and Renderer: the command line's picture pixel for pixel (its PNG read back
by Pillow), from every container a script has, without copies of nibabel's memory."""

import os
import subprocess
import sys
import tracemalloc
from pathlib import Path

import nibabel as nib
import numpy as np
import pytest
from PIL import Image as PilImage

import lineao
from conftest import DATA

TRK = DATA / "dipy+dipy/dipy/data/files/tracks300.trk"
SMALL = dict(width=320, height=256)


def cli_render(lineao_bin, tmp_path, *args):
    out = tmp_path / "cli.png"
    subprocess.run([str(lineao_bin), "render", *map(str, args), "-o", str(out)], check=True, capture_output=True)
    return np.asarray(PilImage.open(out).convert("RGBA"))


def test_render_equals_the_command_line_pixel_for_pixel(lineao_bin, tmp_path):
    expected = cli_render(lineao_bin, tmp_path, TRK, "--width", 320, "--height", 256, "--line-width", 3)
    for streamlines in (TRK, lineao.load(TRK), nib.streamlines.load(str(TRK)), nib.streamlines.load(str(TRK)).streamlines):
        image = lineao.render(streamlines, line_width=3, **SMALL)
        assert isinstance(image, lineao.Image) and image.shape == (256, 320, 4) and image.dtype == np.uint8
        assert (image != expected).sum() == 0, type(streamlines).__name__
    # The picture is not blank: lines over the white background, shaded by AO.
    assert (expected[..., :3] < 200).any(axis=2).mean() > 0.02


def test_cull_and_level_of_detail_are_the_command_lines(lineao_bin, tmp_path):
    t = lineao.load(TRK)
    for lod in (True, False):
        image = lineao.render(t, cull=True, lod=lod, **SMALL)
        expected = cli_render(
            lineao_bin, tmp_path, TRK, "--cull", "on", "--lod", "on" if lod else "off", "--width", 320, "--height", 256
        )
        assert (image != expected).sum() == 0, lod
    # Levels of detail move lines by under half a pixel: line edges change, and the occlusion
    # near them a little (measured: mean 0.42 / 255, 0.37 % of the pixels by more than 32).
    on, off = (lineao.render(t, cull=True, lod=lod, **SMALL).astype(int) for lod in (True, False))
    difference = np.abs(on - off)[..., :3]
    assert difference.mean() < 1.0 and (difference.max(axis=2) > 32).mean() < 0.01


def test_settings_compare_and_grid_are_the_command_lines(lineao_bin, tmp_path):
    t = lineao.load(TRK)
    compare = lineao.render(t, compare=("lineao", "ssao"), preset="paper", s_h=4, **SMALL)
    expected = cli_render(
        lineao_bin, tmp_path, TRK, "--compare", "lineao,ssao", "--preset", "paper", "--s-h", 4, "--width", 320, "--height", 256
    )
    assert (compare != expected).sum() == 0
    grid = lineao.render(t, grid=True, width=96, height=80)
    expected = cli_render(lineao_bin, tmp_path, TRK, "--grid", "--width", 96, "--height", 80)
    assert grid.shape == expected.shape and (grid != expected).sum() == 0
    coloured = lineao.render(t, color=(0.8, 0.2, 0.1), background=(0, 0, 0), method="vo-line", **SMALL)
    expected = cli_render(
        lineao_bin, tmp_path, TRK, "--color", "0.8,0.2,0.1", "--background", "0,0,0", "--method", "vo-line", "--width", 320, "--height", 256
    )
    assert (coloured != expected).sum() == 0
    # Typed settings as a dict are the command line's --settings JSON.
    typed = lineao.render(t, method="ssao", settings={"ssao": {"samples": 12}, "strength": 0.5}, **SMALL)
    expected = cli_render(
        lineao_bin, tmp_path, TRK, "--method", "ssao", "--ssao-samples", 12, "--strength", 0.5, "--width", 320, "--height", 256
    )
    assert (typed != expected).sum() == 0


def test_names_and_defaults_come_from_the_library():
    settings = lineao.settings()
    assert settings["width"][1] == "1280" and settings["line_width"][1] == "2"
    assert settings["method"][1] == "lineao" and "s_h" in settings and "output" not in settings
    assert {"lineao", "ssao", "vo-line", "raytraced", "sweep", "lineao+sweep"} <= set(lineao.methods())


def test_a_method_of_the_registry_alone_is_listed_and_renders():
    # run-tests.sh builds the package with the registry's test method `toy` (a folder and one
    # registry line in lineao, feature `toy-method`): Python lists it and renders it by name.
    assert "toy" in lineao.methods()
    line = np.array([[-4, 0, 0], [4, 0, 0]], dtype=np.float32)
    image = lineao.render([line], method="toy", width=32, height=16)
    assert image.shape == (16, 32, 4)


def test_a_methods_settings_are_keywords_from_their_description():
    # The toy's two settings, described in its folder alone: keywords with their defaults, the
    # values reaching its pass, a value out of range refused with the keyword named.
    settings = lineao.settings()
    assert settings["toy_radius"][1] == "1" and "zoom units" in settings["toy_radius"][0]
    assert "toy_invert" in settings
    line = np.array([[-4, 0, 0], [4, 0, 0]], dtype=np.float32)
    small = dict(method="toy", width=32, height=16, strength=1.0)
    plain = lineao.render([line], **small).astype(int)
    darker = lineao.render([line], toy_radius=3.0, **small).astype(int)
    inverted = lineao.render([line], toy_radius=3.0, toy_invert=True, **small).astype(int)
    lit = plain[..., :3].sum(axis=-1) < 3 * 250
    assert lit.any()
    brightness = lambda image: image[lit][:, :3].sum(axis=-1).mean()
    # Occlusion 0.25 (the default), 0.75, and 1 − 0.75: the default's picture again.
    assert brightness(darker) < brightness(plain) - 1
    assert (inverted == plain).all()

    with pytest.raises(ValueError, match=r"toy_radius.*\[0.25, 4\] zoom units"):
        lineao.render([line], toy_radius=9, **small)
    with pytest.raises(ValueError, match="--toy-radius must be in"):
        lineao.render([line], settings={"toy": {"radius_zoom": 9}}, **small)


def test_a_renderer_keeps_its_session_for_many_frames():
    t = lineao.load(TRK)
    r = lineao.Renderer(t, **SMALL)
    first, again = r.render(), r.render()
    assert (first != again).sum() == 0
    camera = r.camera
    assert set(camera) == {"eye", "target", "up", "fov"}
    closer = {**camera, "eye": tuple(np.add(camera["target"], np.subtract(camera["eye"], camera["target"]) * 0.5))}
    near = r.render(camera=closer)
    assert (near != first).any(axis=2).mean() > 0.05
    assert r.camera["eye"] == pytest.approx(closer["eye"])
    frames = r.orbit(4)
    assert len(frames) == 4 and (frames[0] != near).sum() == 0
    assert all((a != b).any(axis=2).mean() > 0.05 for a, b in zip(frames, frames[1:]))
    # A frame may change the method; not what the session was opened with.
    assert r.render(method="ssao").shape == first.shape
    with pytest.raises(ValueError, match="set when the Renderer is made"):
        r.render(color="field:fa")


def test_an_out_of_order_selection_renders_as_its_streamlines():
    seq = nib.streamlines.load(str(TRK)).streamlines
    selection = seq[[200, 3, 100, 7]]
    assert selection._data is seq._data and selection._offsets[0] > selection._offsets[1]
    a = lineao.render(selection, **SMALL)
    b = lineao.render([np.asarray(s, np.float64) for s in selection], **SMALL)
    assert (a != b).sum() == 0


def test_a_nibabel_array_sequence_is_read_in_place():
    """No copy on the Python side: numpy's allocations during render (traced by tracemalloc)
    stay far below the 12 MB of points."""
    rng = np.random.default_rng(3)
    n, length = 10_000, 100
    steps = rng.normal(scale=0.5, size=(n, length, 3)).astype(np.float32)
    points = (np.cumsum(steps, axis=1) + rng.uniform(-50, 50, size=(n, 1, 3)).astype(np.float32)).reshape(-1, 3)
    seq = nib.streamlines.ArraySequence()
    seq._data, seq._offsets, seq._lengths = points, np.arange(n) * length, np.full(n, length)
    tracemalloc.start()
    image = lineao.render(seq, width=64, height=48)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert image.shape == (48, 64, 4)
    assert peak < 0.05 * points.nbytes, f"{peak} bytes traced for {points.nbytes} bytes of points"


def test_dipy_stateful_tractograms_are_rendered_in_ras_mm():
    from dipy.io.stateful_tractogram import Space, StatefulTractogram

    seq = nib.streamlines.load(str(TRK))
    reference = str(TRK)
    in_mm = StatefulTractogram(seq.streamlines, reference, Space.RASMM)
    expected = lineao.render(seq.streamlines, **SMALL)
    assert (lineao.render(in_mm, **SMALL) != expected).sum() == 0
    in_voxels = StatefulTractogram(seq.streamlines, reference, Space.RASMM)
    in_voxels.to_vox()
    got = lineao.render(in_voxels, **SMALL)
    assert in_voxels.space == Space.VOX, "the caller's object is left as it was"
    # Voxel → mm and back in float32: a few pixels may round differently.
    assert (got != expected).any(axis=2).mean() < 0.002


def test_bad_input_names_the_argument(tmp_path):
    with pytest.raises(ValueError, match=r"points: expected shape \(N, 3\)"):
        lineao.render(np.zeros((10, 2), np.float32))
    with pytest.raises(TypeError, match="points"):
        lineao.render(np.array([["a", "b", "c"]]))
    with pytest.raises(TypeError, match="unexpected keyword argument 'linewidth'"):
        lineao.render(lineao.load(TRK), linewidth=3)
    with pytest.raises(ValueError, match="invalid value '0' for 'width'"):
        lineao.render(lineao.load(TRK), width=0)
    with pytest.raises(ValueError, match="unknown method 'bogus'"):
        lineao.render(lineao.load(TRK), method="bogus")
    with pytest.raises(ValueError, match="ssao.sample: unknown field `sample`"):
        lineao.render(lineao.load(TRK), settings={"ssao": {"sample": 12}})
    # Typed values, each checked by its option's own parser, the keyword named.
    with pytest.raises(ValueError, match="background: expected three numbers"):
        lineao.render(lineao.load(TRK), background=(0, 0))
    with pytest.raises(ValueError, match="line_width: invalid type: string"):
        lineao.render(lineao.load(TRK), line_width="thick")
    with pytest.raises(ValueError, match="'compare' cannot be used with 'grid'"):
        lineao.render(lineao.load(TRK), compare=("lineao", "ssao"), grid=True)
    image = lineao.render(lineao.load(TRK), width=np.int64(32), height=16, line_width=np.float32(2))
    assert image.shape == (16, 32, 4)
    with pytest.raises(ValueError, match="no finite points"):
        lineao.render([])
    with pytest.raises(ValueError, match="outside the"):
        lineao.render(lineao.Tractogram(np.zeros((4, 3), np.float32), [2], [5]))
    with pytest.raises(lineao.LoadError):
        lineao.render(tmp_path / "missing.trk")
    with pytest.raises(ValueError, match="image"):
        lineao.save_png(np.zeros((4, 4, 3), np.uint8), tmp_path / "x.png")


def test_strided_and_float64_points_are_copied_by_the_rule():
    t = lineao.load(TRK)
    wide = np.zeros((len(t.points), 6), np.float64)
    wide[:, ::2] = t.points
    strided = wide[:, ::2]
    assert not strided.flags["C_CONTIGUOUS"]
    converted = lineao.Tractogram(strided, t.offsets, t.lengths)
    assert converted.points.flags["C_CONTIGUOUS"] and converted.points.dtype == np.float32
    assert (lineao.render(converted, **SMALL) != lineao.render(t, **SMALL)).sum() == 0


def test_images_save_and_show_as_png(tmp_path):
    image = lineao.render(lineao.load(TRK), width=64, height=48)
    lineao.save_png(image, tmp_path / "x.png")
    assert (np.asarray(PilImage.open(tmp_path / "x.png").convert("RGBA")) == image).all()
    png = image._repr_png_()
    assert png.startswith(b"\x89PNG") and len(png) > 100


def test_without_a_vulkan_driver_render_says_what_to_install():
    env = {**os.environ, "WGPU_BACKEND": "vulkan", "VK_ICD_FILENAMES": "/nonexistent.json", "VK_DRIVER_FILES": "/nonexistent.json"}
    code = "import lineao, numpy as np; lineao.render([np.eye(3)])"
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.returncode == 1, result.stderr
    assert "RuntimeError" in result.stderr and "mesa-vulkan-drivers" in result.stderr, result.stderr


def test_score_is_the_command_lines_json(lineao_bin):
    import json

    args = ["--width", "160", "--height", "128", "--rays", "16"]
    cli = subprocess.run(
        [str(lineao_bin), "score", str(TRK), *args, "--methods", "lineao,vo-line", "--json"],
        check=True,
        capture_output=True,
        text=True,
    )
    expected = json.loads(cli.stdout)
    got = lineao.score(lineao.load(TRK), ["lineao", "vo-line"], width=160, height=128, rays=16)
    assert got["methods"] == expected["methods"] and got["geometry_pixels"] == expected["geometry_pixels"]
    with pytest.raises(ValueError, match="methods: unknown method 'bogus'"):
        lineao.score(TRK, ["bogus"])


def test_renders_and_loads_release_the_gil(tmp_path):
    """While another thread is inside render (or load), this thread keeps running Python: a
    call that held the GIL would stop it for the whole call (one or two ticks in all)."""
    import threading
    import time

    big = tmp_path / "big.tck"
    rng = np.random.default_rng(4)
    lineao.save([np.cumsum(rng.normal(size=(200, 3)), axis=0).astype(np.float32) for _ in range(20000)], big)
    for work in (lambda: lineao.render(big, width=320, height=256), lambda: lineao.load(big, progress=True)):
        ticks, done = 0, threading.Event()
        thread = threading.Thread(target=lambda: (work(), done.set()))
        start = time.perf_counter()
        thread.start()
        while not done.is_set():
            ticks += 1
            done.wait(0.001)
        thread.join()
        ms = (time.perf_counter() - start) * 1e3
        assert ticks > max(5, 0.2 * ms / 1.0) * 0.5, f"only {ticks} ticks in the other thread's {ms:.0f} ms"


def test_the_render_trk_example_runs(tmp_path):
    example = Path(__file__).parents[1] / "examples" / "render_trk.py"
    result = subprocess.run([sys.executable, str(example), str(TRK)], cwd=tmp_path, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    written = sorted(p.name for p in tmp_path.glob("*.png"))
    assert written == ["tracks300-orbit-%d.png" % i for i in range(8)] + ["tracks300.png"]
    split = np.asarray(PilImage.open(tmp_path / "tracks300.png"))
    assert split.shape == (1024, 1280, 4)


def test_orbit_writes_the_command_lines_turntable(lineao_bin, tmp_path):
    """Renderer.orbit's frames and movie are `lineao render --turntable`'s, byte for byte."""
    out = tmp_path / "spin.png"
    args = ["render", TRK, "--turntable", "3", "--fps", "10", "--width", "160", "--height", "128", "-o", out]
    subprocess.run([str(lineao_bin), *map(str, args)], check=True, capture_output=True)
    r = lineao.Renderer(TRK, width=160, height=128)
    frames = r.orbit(3, movie=tmp_path / "orbit.apng", fps=10)
    for k, frame in enumerate(frames):
        expected = np.asarray(PilImage.open(tmp_path / f"spin-00{k}.png").convert("RGBA"))
        assert (frame != expected).sum() == 0, k
    assert (tmp_path / "orbit.apng").read_bytes() == (tmp_path / "spin.apng").read_bytes()
    with pytest.raises(ValueError, match="fps"):
        r.orbit(2, movie=tmp_path / "bad.apng", fps=0)
    with pytest.raises(ValueError, match="Renderer.orbit"):
        r.render(turntable=3)


def test_views_are_a_keyword_as_on_the_command_line(lineao_bin, tmp_path):
    expected = cli_render(lineao_bin, tmp_path, TRK, "--views", "left,top", "--width", 160, "--height", 128)
    image = lineao.render(TRK, views=("left", "top"), width=160, height=128)
    assert image.shape == (128, 320, 4) and (image != expected).sum() == 0
    with pytest.raises(ValueError, match="not a view"):
        lineao.render(TRK, views="left,sideways", width=32, height=32)


def test_orbit_places_the_camera_as_on_the_command_line(lineao_bin, tmp_path):
    expected = cli_render(lineao_bin, tmp_path, TRK, "--orbit", "60,20,0.8", "--width", 160, "--height", 128)
    image = lineao.render(TRK, orbit=(60, 20, 0.8), width=160, height=128)
    assert (image != expected).sum() == 0
    with pytest.raises(ValueError, match="AZIMUTH,ELEVATION,ZOOM"):
        lineao.render(TRK, orbit="60,95,1", width=32, height=32)
