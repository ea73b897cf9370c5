"""Colour by data: lineao.sample_volume and render(color="volume:FILE") — a NIfTI volume
sampled at every vertex against an independent trilinear interpolation (nibabel's array and
affine, scipy's map_coordinates), and the picture the command line draws with it — and a
per-streamline field (TRX dps) spread over its streamlines' vertices. NIfTI-2 files, which
nibabel writes here, are read as their NIfTI-1 originals."""

import nibabel as nib
import numpy as np
import pytest
from scipy.ndimage import map_coordinates

import lineao
from conftest import DATA
from test_render import SMALL, cli_render

IMAGES = DATA / "niivue+niivue/packages/niivue/demos/images"
STROKE = IMAGES / "stroke.trk.gz"


def independent_samples(points, path):
    """Trilinear between voxel centres through nibabel's affine; NaN outside the centres' box."""
    img = nib.load(str(path))
    data = np.asarray(img.dataobj, dtype=np.float64)
    ijk = nib.affines.apply_affine(np.linalg.inv(img.affine), points.astype(np.float64)).T
    values = map_coordinates(data, ijk, order=1, mode="nearest", prefilter=False)
    inside = np.all((ijk >= 0) & (ijk <= (np.array(data.shape) - 1)[:, None]), axis=0)
    return np.where(inside, values, np.nan)


@pytest.mark.parametrize("volume", ["strokez.nii.gz", "MNI152_2009_template.nii.gz"])
def test_samples_along_the_streamlines_are_scipys(volume):
    t = lineao.load(STROKE)
    got = lineao.sample_volume(t, IMAGES / volume)
    assert got.dtype == np.float32 and got.shape == (len(t.points),)
    expected = independent_samples(t.points, IMAGES / volume)
    assert np.array_equal(np.isnan(got), np.isnan(expected))
    finite = ~np.isnan(expected)
    assert finite.mean() > 0.9, "stroke.trk.gz lies in the volume's space"
    scale = np.nanmax(np.abs(expected))
    assert np.abs(got[finite] - expected[finite]).max() <= 1e-5 * scale
    # The same from nibabel's streamlines (any container render takes).
    nib_streamlines = nib.streamlines.load(str(STROKE)).streamlines
    assert np.array_equal(lineao.sample_volume(nib_streamlines, IMAGES / volume), got, equal_nan=True)


@pytest.mark.parametrize("endianness", ["<", ">"])
def test_a_nifti2_volume_is_its_nifti1_original(tmp_path, endianness):
    """nibabel writes each shared volume as NIfTI-2 (its header widened to 64 bits, in either
    byte order, the voxels as stored: int16 with a slope for the z-map): the samples along the
    streamlines are the NIfTI-1 file's bit for bit, and the slices' picture is the same."""
    t = lineao.load(STROKE)
    for volume in ("strokez.nii.gz", "MNI152_2009_template.nii.gz"):
        img = nib.load(str(IMAGES / volume))
        header = nib.Nifti2Header.from_header(img.header).as_byteswapped(endianness)
        path = tmp_path / f"{endianness == '>'}-{volume}"
        # The stored integers and their scaling, not the scaled floats (which nibabel would
        # quantize anew).
        nifti2 = nib.Nifti2Image(img.dataobj.get_unscaled(), img.affine, header)
        nifti2.header.set_slope_inter(img.dataobj.slope, img.dataobj.inter)
        nib.save(nifti2, str(path))
        again = nib.load(str(path))
        assert isinstance(again, nib.Nifti2Image) and again.header.endianness == endianness
        assert np.array_equal(np.asanyarray(again.dataobj), np.asanyarray(img.dataobj))
        expected = lineao.sample_volume(t, IMAGES / volume)
        assert np.array_equal(lineao.sample_volume(t, path), expected, equal_nan=True), volume
        assert np.array_equal(np.isnan(expected), np.isnan(independent_samples(t.points, path)))
    rules = {**SMALL, "slices": "0,-18,10"}
    assert np.array_equal(lineao.render(t, volume=str(path), **rules), lineao.render(t, volume=str(IMAGES / volume), **rules))


def test_points_outside_are_nan_and_bad_files_raise(tmp_path):
    far = lineao.Tractogram(np.array([[500.0, 0, 0], [0, -18, 18]], np.float32))
    values = lineao.sample_volume(far, IMAGES / "MNI152_2009_template.nii.gz")
    assert np.isnan(values[0]) and values[1] == 58.0
    four_d = tmp_path / "4d.nii.gz"
    nib.save(nib.Nifti1Image(np.zeros((4, 4, 4, 2), np.float32), np.eye(4)), str(four_d))
    with pytest.raises(lineao.LoadError, match="3-D") as e:
        lineao.sample_volume(far, four_d)
    assert e.value.file == str(four_d)


def test_render_colored_by_a_volume_is_the_command_lines(lineao_bin, tmp_path):
    volume = IMAGES / "strokez.nii.gz"
    image = lineao.render(STROKE, color=f"volume:{volume}", **SMALL)
    expected = cli_render(lineao_bin, tmp_path, STROKE, "--color", f"volume:{volume}", "--width", 320, "--height", 256)
    assert (image != expected).sum() == 0
    # Not the tangent colours: the z-map through viridis (and gray outside).
    plain = lineao.render(STROKE, **SMALL)
    assert (image != plain).any(axis=2).mean() > 0.05


def read_tsf(path):
    """An MRtrix track scalar file by its specification: a text header up to `END`, whose
    `file: . OFFSET` says where the float32 values start (`datatype`), a NaN after each
    streamline, an Inf at the end (when written whole)."""
    data = path.read_bytes()
    header = data[: data.index(b"\nEND\n")].decode().splitlines()
    fields = dict(line.split(": ", 1) for line in header[1:])
    assert fields["datatype"] == "Float32LE"
    values = np.frombuffer(data[int(fields["file"].split()[1]) :], "<f4")
    values = values[: np.argmax(np.isinf(values))] if np.isinf(values).any() else values
    ends = np.flatnonzero(np.isnan(values))
    runs = np.split(values, ends + 1)[: len(ends)]
    return [run[:-1] for run in runs]


def test_a_tsf_colours_the_tck_it_belongs_to(lineao_bin, tmp_path):
    """`--color tsf:FILE` (mrview's scalar file) is the same picture as the .tsf's values,
    read here by its specification, given as a per-vertex field; a .tsf of another
    tractogram is an error naming both."""
    tck, tsf = IMAGES / "tract.SLF1_R.tck", IMAGES / "mni152.SLF1_R.tsf"
    t = lineao.load(tck)
    runs = read_tsf(tsf)
    assert [len(r) for r in runs] == list(t.lengths)
    values = np.concatenate(runs).astype(np.float32)
    assert np.ptp(values) > 0
    given = lineao.Tractogram(t.points, t.offsets, t.lengths, vertex_fields={"v": values})
    image = lineao.render(tck, color=f"tsf:{tsf}", **SMALL)
    assert (image != lineao.render(given, color="field:v", **SMALL)).sum() == 0
    assert (image != lineao.render(tck, **SMALL)).any(axis=2).mean() > 0.005
    expected = cli_render(lineao_bin, tmp_path, tck, "--color", f"tsf:{tsf}", "--width", 320, "--height", 256)
    assert (image != expected).sum() == 0
    with pytest.raises(Exception, match=r"SLF1_R\.tsf does not belong to .*stroke\.trk\.gz: it holds values for 13"):
        lineao.render(STROKE, color=f"tsf:{tsf}", **SMALL)
    # Streamlines whose lengths differ from the .tsf's: the first one that differs is named.
    first_short = lineao.Tractogram(t.points[1:], np.r_[0, t.offsets[1:] - 1], np.r_[11, t.lengths[1:]])
    with pytest.raises(Exception, match="streamline 0 holds 12 values and 11 points"):
        lineao.render(first_short, color=f"tsf:{tsf}", **SMALL)


def test_a_per_streamline_field_colours_whole_streamlines(lineao_bin, tmp_path):
    trx = IMAGES / "dpsv.trx"
    image = lineao.render(trx, color="field:DataSetID", **SMALL)
    expected = cli_render(lineao_bin, tmp_path, trx, "--color", "field:DataSetID", "--width", 320, "--height", 256)
    assert (image != expected).sum() == 0
    assert (image != lineao.render(trx, **SMALL)).any(axis=2).mean() > 0.01
    with pytest.raises(Exception, match="DataSetID"):
        # The error lists the fields a file has, per-streamline ones included.
        lineao.render(trx, color="field:nothing", **SMALL)
