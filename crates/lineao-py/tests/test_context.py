"""Tractograms in context: each selection rule of `lineao info --json` and `render` against a
count made apart from lineao (nibabel's streamlines and numpy), a selected-out streamline that
leaves no pixel, and the anatomy slices and slab as Python keywords."""

import json
import subprocess

import nibabel as nib
import numpy as np
import pytest

import lineao
from conftest import DATA

IMAGES = DATA / "niivue+niivue/packages/niivue/demos/images"
STROKE = IMAGES / "stroke.trk.gz"
MNI = IMAGES / "MNI152_2009_template.nii.gz"


def selected(lineao_bin, path, *rules):
    out = subprocess.run(
        [str(lineao_bin), "info", "--json", str(path), *rules], check=True, capture_output=True, text=True
    )
    return json.loads(out.stdout)["selected"]


def stroke_streamlines():
    return list(nib.streamlines.load(str(STROKE)).streamlines)


def segments_meet_sphere(points, center, radius):
    """Whether a segment of `points` comes within `radius` of `center` (closest point on each)."""
    a, b = points[:-1].astype(np.float64), points[1:].astype(np.float64)
    ab = b - a
    length2 = np.maximum((ab * ab).sum(1), 1e-300)
    t = np.clip(((center - a) * ab).sum(1) / length2, 0.0, 1.0)
    closest = a + t[:, None] * ab
    return bool((((closest - center) ** 2).sum(1) <= radius * radius).any())


def segments_meet_box(points, lo, hi):
    """The slab test per segment."""
    a, b = points[:-1].astype(np.float64), points[1:].astype(np.float64)
    d = b - a
    with np.errstate(divide="ignore", invalid="ignore"):
        u, v = (lo - a) / d, (hi - a) / d
    t0 = np.where(d == 0, np.where((a >= lo) & (a <= hi), -np.inf, np.inf), np.minimum(u, v)).max(1)
    t1 = np.where(d == 0, np.where((a >= lo) & (a <= hi), np.inf, -np.inf), np.maximum(u, v)).min(1)
    return bool((np.maximum(t0, 0.0) <= np.minimum(t1, 1.0)).any())


def test_length_and_regions_select_what_numpy_counts(lineao_bin):
    lines = stroke_streamlines()
    lengths = np.array([np.linalg.norm(np.diff(s, axis=0), axis=1).sum() for s in lines])
    assert selected(lineao_bin, STROKE, "--length", "40,120") == int(((lengths >= 40) & (lengths <= 120)).sum())

    center, radius = np.array([0.0, -18.0, 10.0]), 15.0
    in_sphere = np.array([segments_meet_sphere(s, center, radius) for s in lines])
    assert selected(lineao_bin, STROKE, "--include", "sphere:0,-18,10,15") == int(in_sphere.sum())
    lo, hi = np.array([-40.0, -30.0, 0.0]), np.array([-10.0, 10.0, 30.0])
    in_box = np.array([segments_meet_box(s, lo, hi) for s in lines])
    box = "box:-40,-30,0,-10,10,30"
    assert selected(lineao_bin, STROKE, "--include", box) == int(in_box.sum())
    # Through both, and through the sphere but not the box (mrview's rule).
    both = selected(lineao_bin, STROKE, "--include", "sphere:0,-18,10,15", "--include", box)
    assert both == int((in_sphere & in_box).sum())
    assert selected(lineao_bin, STROKE, "--include", "sphere:0,-18,10,15", "--exclude", box) == int(
        (in_sphere & ~in_box).sum()
    )


def test_select_gives_the_mask_render_draws():
    t = lineao.load(STROKE)
    lengths = np.array([np.linalg.norm(np.diff(s, axis=0), axis=1).sum() for s in stroke_streamlines()])
    keep = lineao.select(t, length=(40, 120))
    assert keep.dtype == bool and np.array_equal(keep, (lengths >= 40) & (lengths <= 120))
    both = lineao.select(t, length=(40, 120), include=["sphere:0,-18,10,15"])
    assert np.array_equal(both, keep & lineao.select(t, include="sphere:0,-18,10,15"))
    assert lineao.select(t).all()
    with pytest.raises(TypeError, match="the rules are: subset"):
        lineao.select(t, includ="sphere:0,0,0,1")
    with pytest.raises(ValueError, match="no per-streamline field 'fa'"):
        lineao.select(t, field=("fa", 0, 1))


def test_a_field_range_and_a_subset_select_what_numpy_counts(lineao_bin):
    trx = IMAGES / "dpsv.trx"
    # The per-streamline DataSetID (TRX dps), read with numpy from the zip apart from lineao.
    import zipfile

    with zipfile.ZipFile(trx) as z:
        name = next(n for n in z.namelist() if n.startswith("dps/DataSetID."))
        values = np.frombuffer(z.read(name), dtype=np.dtype(name.rsplit(".", 1)[1])).astype(np.float64)
    assert selected(lineao_bin, trx, "--field", "DataSetID,0,0.5") == int(((values >= 0) & (values <= 0.5)).sum())
    # A tenth of the streamlines: near a tenth, the same for the same seed, nested in a half.
    n = len(stroke_streamlines())
    tenth = selected(lineao_bin, STROKE, "--subset", "10%", "--subset-seed", "3")
    assert abs(tenth - n / 10) < 4 * np.sqrt(n * 0.1 * 0.9), (tenth, n)
    assert tenth == selected(lineao_bin, STROKE, "--subset", "0.1", "--subset-seed", "3")


def test_selected_out_streamlines_leave_no_pixel_and_the_mask_is_dumped(lineao_bin, tmp_path):
    t = lineao.load(STROKE)
    everything = np.asarray(lineao.render(t, width=256, height=200, method="none"))
    # Every streamline away from a sphere, drawn alone: the background where the rest was.
    rules = {"exclude": "sphere:0,-18,10,2000", "width": 256, "height": 200, "method": "none"}
    nothing = np.asarray(lineao.render(t, **rules))
    assert (everything[..., :3] != 255).any(axis=-1).mean() > 0.05
    assert (nothing[..., :3] == 255).all(), "a selected-out streamline left pixels"
    dump = tmp_path / "dump"
    subprocess.run(
        [str(lineao_bin), "render", str(STROKE), "--length", "40,120", "--dump", str(dump),
         "--width", "64", "--height", "48", "-o", str(tmp_path / "x.png")],
        check=True, capture_output=True,
    )
    mask = np.load(dump / "selected.npy")
    lengths = np.array([np.linalg.norm(np.diff(s, axis=0), axis=1).sum() for s in stroke_streamlines()])
    assert mask.dtype == np.uint8 and np.array_equal(mask.astype(bool), (lengths >= 40) & (lengths <= 120))


def test_slices_and_a_slab_are_keywords():
    t = lineao.load(STROKE)
    rules = {"width": 200, "height": 160, "volume": str(MNI), "slices": "-,-,10"}
    with_slice = np.asarray(lineao.render(t, **rules))
    alone = np.asarray(lineao.render(t, width=200, height=160))
    # The slice's gray pixels (the lines are coloured by their direction).
    def gray(image):
        rgb = image[..., :3].astype(int)
        return ((rgb[..., 0] == rgb[..., 1]) & (rgb[..., 1] == rgb[..., 2]) & (rgb[..., 0] < 250)).mean()

    # Transparent where the template holds no data (0) the slice shows the brain's section; opaque,
    # the zeros around it too.
    opaque = np.asarray(lineao.render(t, **rules, opaque_slices=True))
    assert gray(alone) < 0.002 < 0.01 < gray(with_slice) < gray(opaque) - 0.05, (gray(alone), gray(with_slice), gray(opaque))
    background = lambda image: (image[..., :3] == 255).all(axis=-1).mean()
    slab = np.asarray(lineao.render(t, width=200, height=160, slab="z,10,6"))
    assert background(slab) > background(alone) + 0.1


def test_transparency_and_context_are_keywords():
    t = lineao.load(STROKE)
    frame = {"width": 200, "height": 160, "method": "none"}
    opaque = np.asarray(lineao.render(t, **frame)).astype(int)
    seen_through = np.asarray(lineao.render(t, **frame, alpha=0.3, layers=4)).astype(int)
    drawn = (opaque[..., :3] != 255).any(axis=-1)
    # Over a white background, lines at opacity 0.3 are lighter where they are drawn.
    assert seen_through[drawn][:, :3].mean() > opaque[drawn][:, :3].mean() + 5
    # The context: what a selection leaves out, faint, where it alone would leave background.
    sphere = "sphere:0,-20,10,25"
    focus = np.asarray(lineao.render(t, **frame, include=sphere)).astype(int)
    context = np.asarray(lineao.render(t, **frame, include=sphere, context_alpha=0.1)).astype(int)
    empty = (focus[..., :3] == 255).all(axis=-1)
    assert (context[empty][:, :3] != 255).any(axis=-1).mean() > 0.05
    with pytest.raises(ValueError, match="alpha"):
        lineao.render(t, **frame, alpha=1.5)


def test_streamlines_in_memory_keep_their_groups_and_fields():
    # pyAFQ's arcuate fasciculi, loaded into numpy and rendered from memory: coloured and
    # selected by their groups as the file itself is.
    afq = IMAGES / "sub-01_ses-01_dwi_space-RASMM_model-probCSD_algo-AFQ_tractography.trx"
    t = lineao.load(afq)
    assert sorted(t.groups) == ["ARC_L", "ARC_R"]
    frame = {"width": 160, "height": 128, "method": "none"}
    for rules in ({"color": "groups"}, {"color": "groups", "groups": ["ARC_R"]}):
        from_memory = np.asarray(lineao.render(t, **frame, **rules))
        from_file = np.asarray(lineao.render(str(afq), **frame, **rules))
        assert np.array_equal(from_memory, from_file), rules
    # A per-streamline field made here colours the lines: two values, two colours.
    t.streamline_fields["side"] = np.array([float(i in set(t.groups["ARC_R"])) for i in range(len(t))], np.float32)
    image = np.asarray(lineao.render(t, **frame, color="field:side", colormap="gray"))
    drawn = image[(image[..., :3] != 255).any(axis=-1)][:, :3].astype(int)
    assert (drawn.max(axis=1) - drawn.min(axis=1) <= 2).all(), "gray lines"
