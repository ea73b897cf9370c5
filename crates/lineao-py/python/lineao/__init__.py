"""lineao: ambient occlusion for dense 3D lines (LineAO), and fast tractography loaders.

>>> import lineao
>>> t = lineao.load("bundle.trk")                  # .tck .trk .trx .vtk .vtp .tt.gz .fib …
>>> t.points.shape, t.offsets.shape                # (N, 3) float32 RAS+ mm, (streamlines,)
>>> image = lineao.render(t, method="lineao")      # (1024, 1280, 4) uint8, sRGB
>>> lineao.save_png(image, "bundle.png")

``render`` takes a lineao ``Tractogram``, nibabel's ``Tractogram``, ``ArraySequence``,
``TrkFile`` or ``TckFile``, DIPY's ``StatefulTractogram``, a list of (n, 3) arrays, or a
file's path. Its keyword arguments are ``lineao render``'s options with ``_`` for ``-``
(``lineao.settings()`` lists them with their defaults; ``lineao.methods()`` the methods): the
command line and Python share one definition, and the same settings give the same pixels.

Arrays are handed over without copies where the memory allows: ``load`` gives numpy the
loader's own buffers, and ``render`` reads float32 C-contiguous points (nibabel's
``ArraySequence._data``) in place. Anything else (float64, a strided view, a list of arrays)
is converted once to float32 C order — a copy, as ``np.ascontiguousarray(x, np.float32)``.
"""

from __future__ import annotations

import os
from typing import Any, Iterable, Optional, Union

import numpy as np

# The Vulkan loader warns on every device made without it (headless, in containers); the
# command line sets it the same way.
if "XDG_RUNTIME_DIR" not in os.environ:
    import tempfile

    os.environ["XDG_RUNTIME_DIR"] = tempfile.gettempdir()

from . import _lineao  # noqa: E402 (after the environment it reads)
from ._lineao import LoadError  # noqa: E402

__all__ = [
    "LoadError",
    "Image",
    "Renderer",
    "Tractogram",
    "info",
    "load",
    "methods",
    "render",
    "select",
    "save",
    "save_png",
    "score",
    "settings",
]


class Image(np.ndarray):
    """An (H, W, 4) uint8 sRGB picture: a numpy array that Jupyter shows as a PNG."""

    def _repr_png_(self) -> bytes:
        return _lineao.png(np.ascontiguousarray(self, dtype=np.uint8))


class Tractogram:
    """Streamlines as one array of points: streamline ``i`` is
    ``points[offsets[i] : offsets[i] + lengths[i]]``.

    ``points`` is (N, 3) float32 in RAS+ millimetres; ``offsets`` and ``lengths`` are int64
    (nibabel's ``ArraySequence`` layout). ``vertex_fields`` and ``streamline_fields`` map names
    to float32 arrays of N or ``len(self)`` rows (one column: 1-D); ``groups`` maps names to
    uint32 streamline indices; ``affine`` (4 × 4), ``dimensions`` and ``voxel_sizes`` describe the
    reference image where the file records one; ``format`` is the format read (``"trk"``…).
    A ``.tsf`` holds values without points: ``points`` is empty, and ``offsets`` and
    ``lengths`` index its ``vertex_fields``.
    """

    def __init__(
        self,
        points: Any,
        offsets: Any = None,
        lengths: Any = None,
        *,
        vertex_fields: Optional[dict] = None,
        streamline_fields: Optional[dict] = None,
        groups: Optional[dict] = None,
        affine: Any = None,
        dimensions: Optional[Iterable[int]] = None,
        voxel_sizes: Optional[Iterable[float]] = None,
        format: Optional[str] = None,
    ):
        self.points = _points(points, "points")
        if offsets is None and lengths is None:
            offsets, lengths = np.zeros(1, np.int64), np.array([len(self.points)], np.int64)
            if len(self.points) == 0:
                offsets, lengths = offsets[:0], lengths[:0]
        elif lengths is None:
            raise ValueError("lengths: required with offsets")
        elif offsets is None:
            lengths = _int64(lengths, "lengths")
            offsets = np.cumsum(lengths) - lengths
        self.offsets = _int64(offsets, "offsets")
        self.lengths = _int64(lengths, "lengths")
        if self.offsets.shape != self.lengths.shape:
            raise ValueError(f"offsets {self.offsets.shape} and lengths {self.lengths.shape} differ in shape")
        self.vertex_fields = dict(vertex_fields or {})
        self.streamline_fields = dict(streamline_fields or {})
        self.groups = dict(groups or {})
        self.affine = None if affine is None else np.asarray(affine, dtype=np.float64)
        self.dimensions = None if dimensions is None else tuple(int(d) for d in dimensions)
        self.voxel_sizes = None if voxel_sizes is None else tuple(float(v) for v in voxel_sizes)
        self.format = format

    @classmethod
    def from_streamlines(cls, streamlines: Iterable[Any]) -> "Tractogram":
        """A tractogram of (n, 3) arrays (copied once into one float32 array)."""
        arrays = [_points(s, f"streamlines[{i}]") for i, s in enumerate(streamlines)]
        lengths = np.array([len(a) for a in arrays], dtype=np.int64)
        points = np.concatenate(arrays) if arrays else np.zeros((0, 3), np.float32)
        return cls(points, None, lengths)

    def __len__(self) -> int:
        return len(self.offsets)

    def __getitem__(self, i: int) -> np.ndarray:
        start = int(self.offsets[i])
        return self.points[start : start + int(self.lengths[i])]

    def __iter__(self):
        for i in range(len(self)):
            yield self[i]

    def __repr__(self) -> str:
        kind = f" from .{self.format}" if self.format else ""
        return f"<lineao.Tractogram{kind}: {len(self)} streamlines, {len(self.points)} points>"


def _points(x: Any, name: str) -> np.ndarray:
    """(N, 3) float32 C-contiguous: the array itself when it is one, else one copy."""
    try:
        a = np.asarray(x)
    except Exception as e:  # noqa: BLE001 (numpy raises many kinds)
        raise TypeError(f"{name}: expected an (N, 3) array of numbers, got {type(x).__name__}") from e
    if a.dtype.kind not in "fiu":
        raise TypeError(f"{name}: expected an (N, 3) array of numbers, got dtype {a.dtype}")
    if a.size == 0 and a.ndim <= 2:
        a = a.reshape(0, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (N, 3), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float32)


def _int64(x: Any, name: str) -> np.ndarray:
    a = np.asarray(x)
    if a.dtype.kind not in "iu":
        raise TypeError(f"{name}: expected integers, got dtype {a.dtype}")
    if a.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.int64)


def load(path: "os.PathLike[str] | str", *, progress: Any = False) -> Tractogram:
    """Loads a tractography file (any format ``lineao info`` reads) into a ``Tractogram``.

    The arrays own the loader's memory (no copy). The GIL is released while the file is read;
    Ctrl-C interrupts a long load (``KeyboardInterrupt``). ``progress=True`` draws a bar on a
    terminal for files over 32 MiB; a callable is called as ``progress(bytes_read, total)``.
    A file that cannot be read raises ``LoadError`` (a ``ValueError``) with ``file``,
    ``offset`` and ``expected``.
    """
    parts = _lineao.load(os.fspath(path), progress)
    return Tractogram(**parts)


def sample_volume(streamlines: Any, path: "os.PathLike[str] | str") -> np.ndarray:
    """A NIfTI volume (``.nii``, ``.nii.gz``) sampled at every vertex of ``streamlines`` (any
    container ``render`` takes): float32, one value per row of its ``points``, trilinear between
    voxel centres through the volume's affine (sform, else qform, as nibabel places it), NaN
    outside the volume — the numbers ``render(..., color="volume:FILE")`` colours by.
    """
    return _lineao.sample_volume(_tractogram(streamlines).points, os.fspath(path))


def select(streamlines: Any, **rules: Any) -> np.ndarray:
    """Which streamlines ``rules`` keep, one bool each — the selection ``render`` draws with the
    same keywords: ``subset`` (a share, or ``"10%"``) with ``subset_seed``, ``length=(min,
    max)`` (arc length, mm), ``field=("name", min, max)`` (a per-streamline field),
    ``groups=[...]`` (any of them), ``include=[...]`` and ``exclude=[...]`` regions
    (``"sphere:x,y,z,r"``, ``"box:x0,y0,z0,x1,y1,z1"``; kept when some segment passes through
    every include region and none through an exclude one: mrview's rule). An unknown keyword is
    a ``TypeError``, a bad value or a field the streamlines lack a ``ValueError``.

    >>> keep = lineao.select(t, length=(40, 200), include="sphere:0,-18,10,15")
    """
    t = _tractogram(streamlines)
    return _lineao.select(
        t.points,
        t.offsets,
        t.lengths,
        {k: np.ascontiguousarray(v, np.float32) for k, v in t.streamline_fields.items()},
        {k: np.asarray(v, np.uint32) for k, v in t.groups.items()},
        rules,
    )


def info(path: "os.PathLike[str] | str") -> dict:
    """``lineao info --json`` of a file: format, counts, fields, groups, bounds, voxel space."""
    import json

    return json.loads(_lineao.info(os.fspath(path)))


def save(tractogram: Any, path: "os.PathLike[str] | str") -> None:
    """Writes streamlines as .tck, .trk or .trx (by the extension), with their fields, groups
    and voxel space where the format holds them (a field it cannot hold is warned about)."""
    t = _tractogram(tractogram)
    dropped = _lineao.save(
        os.fspath(path),
        t.points,
        t.offsets,
        t.lengths,
        {k: np.ascontiguousarray(v, np.float32) for k, v in t.vertex_fields.items()},
        {k: np.ascontiguousarray(v, np.float32) for k, v in t.streamline_fields.items()},
        {k: np.asarray(v, np.uint32) for k, v in t.groups.items()},
        None if t.affine is None else np.ascontiguousarray(t.affine, np.float64),
        t.dimensions,
        t.voxel_sizes,
    )
    if dropped:
        import warnings

        warnings.warn(f"{os.fspath(path)}: the format cannot hold the fields {', '.join(dropped)}", stacklevel=2)


def _tractogram(x: Any) -> Tractogram:
    """Any streamline container as a lineao ``Tractogram`` over the same memory where it can."""
    if isinstance(x, Tractogram):
        return x
    if isinstance(x, (str, os.PathLike)):
        return load(x)
    # DIPY's StatefulTractogram: to RAS+ mm with the NIfTI (voxel-centre) origin, on a copy
    # when it is in another space (to_rasmm and to_center change the object in place).
    if hasattr(x, "to_rasmm") and hasattr(x, "space") and hasattr(x, "streamlines"):
        from dipy.io.stateful_tractogram import Origin, Space

        if x.space != Space.RASMM or x.origin != Origin.NIFTI:
            import copy

            x = copy.deepcopy(x)
            x.to_rasmm()
            x.to_center()
        return _tractogram(x.streamlines)
    # nibabel's TrkFile/TckFile (tractogram in RAS+ mm) and Tractogram.
    if hasattr(x, "tractogram") and hasattr(x, "header"):
        x = x.tractogram
    if hasattr(x, "streamlines") and hasattr(x, "affine_to_rasmm"):
        to_rasmm = np.asarray(x.affine_to_rasmm)
        if not np.allclose(to_rasmm, np.eye(4)):
            x = x.copy().to_world()
        x = x.streamlines
    # nibabel's ArraySequence: its buffer, offsets and lengths, without a copy.
    if hasattr(x, "_data") and hasattr(x, "_offsets") and hasattr(x, "_lengths"):
        data = x._data
        if data.size == 0:
            data = np.zeros((0, 3), np.float32)
        return Tractogram(data, x._offsets, x._lengths)
    if isinstance(x, np.ndarray):
        return Tractogram(x)
    if isinstance(x, (list, tuple)) or hasattr(x, "__iter__"):
        return Tractogram.from_streamlines(x)
    raise TypeError(
        "streamlines: expected a lineao or nibabel Tractogram, an ArraySequence, a TrkFile or TckFile, "
        f"a DIPY StatefulTractogram, a list of (n, 3) arrays or a path, got {type(x).__name__}"
    )


def _camera_settings(camera: Optional[dict]) -> dict:
    """A camera dict (eye, target, up, fov or ortho) as render's settings."""
    if camera is None:
        return {}
    unknown = set(camera) - {"eye", "target", "up", "fov", "ortho"}
    if unknown:
        raise TypeError(f"camera: unexpected keys {sorted(unknown)}; a camera has eye, target, up, fov or ortho")
    return {k: v for k, v in camera.items() if v is not None}


class Renderer:
    """Keeps the device, the streamlines on the GPU and the pipelines for many frames.

    >>> r = lineao.Renderer(lineao.load("bundle.tck"), method="lineao", width=640, height=512)
    >>> first = r.render()
    >>> turntable = r.orbit(36)                     # 36 frames around the up axis
    """

    def __init__(self, streamlines: Any, **settings: Any):
        # The first camera is the session's; later frames keep the last one they were given.
        camera = _camera_settings(settings.pop("camera", None))
        opening = {**settings, **camera}
        self._settings = settings
        if isinstance(streamlines, (str, os.PathLike)):
            self._native = _lineao.Renderer(opening, path=os.fspath(streamlines))
        elif streamlines is None:
            self._native = _lineao.Renderer(opening)  # the built-in `scene`
        else:
            t = _tractogram(streamlines)
            name = getattr(streamlines, "name", None) or "streamlines"
            data = (
                {k: np.ascontiguousarray(v, np.float32) for k, v in t.vertex_fields.items()},
                {k: np.ascontiguousarray(v, np.float32) for k, v in t.streamline_fields.items()},
                {k: np.asarray(v, np.uint32) for k, v in t.groups.items()},
            )
            self._native = _lineao.Renderer(
                opening, points=t.points, offsets=t.offsets, lengths=t.lengths, name=str(name), data=data
            )

    def render(self, *, camera: Optional[dict] = None, **settings: Any) -> Image:
        """One frame with this renderer's settings, `settings` changed for this frame, seen by
        `camera` (a dict of eye, target, up, fov or ortho; by default the last frame's, at
        first the view that frames the streamlines)."""
        return self._native.render(self._frame_settings(camera, settings)).view(Image)

    def _frame_settings(self, camera: Optional[dict], settings: dict) -> dict:
        """The session's settings with this frame's, and a whole camera when one is given."""
        merged = {**self._settings, **settings}
        if camera is not None:
            whole = {**self.camera, **_camera_settings(camera)}
            if "ortho" in camera:
                whole.pop("fov", None)
            elif "fov" in camera:
                whole.pop("ortho", None)
            merged.update(whole)
        return merged

    def score(self, methods: Optional[Iterable[str]] = None, *, camera: Optional[dict] = None, **settings: Any) -> dict:
        """``lineao score --json`` on this renderer's view: each method's AO against the
        ray-traced truth (``methods``: ``lineao``, ``lineao-reference``, ``vo-line``,
        ``vo-area``, ``ssao``, ``raytraced``; None: all), with the truth's settings
        (``rays``, ``ao_distance``, ``ao_falloff``…) among ``settings``."""
        merged = self._frame_settings(camera, settings)
        import json

        return json.loads(self._native.score(merged, None if methods is None else list(methods)))

    def __repr__(self) -> str:
        streamlines, vertices = self._native.counts()
        return f"<lineao.Renderer: {streamlines} streamlines, {vertices} vertices on {self.device}>"

    @property
    def camera(self) -> dict:
        """The last frame's camera: eye, target, up, and fov (degrees) or ortho (height)."""
        return self._native.camera()

    @property
    def device(self) -> str:
        """The GPU adapter, e.g. ``llvmpipe (LLVM 19.1.7, 256 bits) (Vulkan, Cpu)``."""
        return self._native.device()

    def orbit(
        self,
        n_frames: int,
        *,
        degrees: float = 360.0,
        movie: Optional[Union[str, os.PathLike]] = None,
        fps: int = 30,
        **settings: Any,
    ) -> list:
        """A turntable: `n_frames` images with the eye turned about the target around the
        camera's up axis, `degrees` in all (the last frame one step short of a full turn), the
        cameras of ``lineao render --turntable``. With `movie` (a ``.apng``/``.png`` file, or
        ``.mp4``, ``.webm``… through the ffmpeg program) the frames are also written there at
        `fps`, as ``--movie`` writes them."""
        if n_frames < 1:
            raise ValueError(f"n_frames: expected at least 1, got {n_frames}")
        start = self.camera
        settings = dict(settings)
        camera = _camera_settings(settings.pop("camera", None))
        start.update(camera)
        eyes = _lineao.turntable(start["eye"], start["target"], start["up"], n_frames, float(degrees))
        frames = [self.render(camera={**start, "eye": tuple(eye)}, **settings) for eye in eyes]
        if movie is not None:
            _lineao.write_movie([np.asarray(f) for f in frames], os.fspath(movie), int(fps))
        return frames


def render(
    streamlines: Any,
    *,
    method: Optional[str] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    camera: Optional[dict] = None,
    line_width: Optional[float] = None,
    geometry: Optional[str] = None,
    color: Any = None,
    background: Optional[Iterable[float]] = None,
    **settings: Any,
) -> Image:
    """Renders streamlines with ambient occlusion: an (height, width, 4) uint8 sRGB image.

    ``streamlines`` is any container ``Tractogram`` names, a file's path, or None for the
    built-in ``scene=``. The keyword arguments are ``lineao render``'s options
    (``lineao.settings()``): None leaves the library's default (method ``"lineao"``, 1280 ×
    1024, lines 2 px wide, tangent colours on white). ``compare=("lineao", "ssao")`` gives a
    split screen, ``grid=True`` every method, ``preset="paper"``, ``s_h=…`` a setting; the same
    settings give the same pixels as the command line. ``color`` is ``"tangent"``,
    ``(r, g, b)`` in [0, 1], ``"field:NAME"``, ``"volume:FILE.nii.gz"`` (a NIfTI-1 or NIfTI-2
    volume sampled at every vertex), ``"tsf:FILE.tsf"`` (an MRtrix track scalar file's values,
    a vertex each) or ``"groups"``. Bad settings raise ``ValueError`` with the
    library's message; with no Vulkan driver, ``RuntimeError`` says what to install.
    """
    if color is not None and not isinstance(color, str):
        color = ",".join(str(c) for c in color)
    given = dict(
        method=method,
        width=width,
        height=height,
        line_width=line_width,
        geometry=geometry,
        color=color,
        background=None if background is None else tuple(background),
    )
    settings.update({k: v for k, v in given.items() if v is not None})
    return Renderer(streamlines, camera=camera, **settings).render()


def score(streamlines: Any, methods: Optional[Iterable[str]] = None, **settings: Any) -> dict:
    """``lineao score --json`` of streamlines (any container ``render`` takes): each method's
    AO against the ray-traced truth on one view, as a dict (docs/reference.md's keys)."""
    camera = settings.pop("camera", None)
    return Renderer(streamlines, camera=camera, **settings).score(methods)


def save_png(image: np.ndarray, path: "os.PathLike[str] | str") -> None:
    """Writes an (H, W, 4) uint8 image as an sRGB PNG."""
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 4:
        raise ValueError(f"image: expected an (H, W, 4) uint8 array, got {image.dtype} {image.shape}")
    _lineao.png(np.ascontiguousarray(image), os.fspath(path))


def settings() -> dict:
    """``render``'s keyword arguments: name → (help, default), from the command line's
    definition (the one source of names and defaults)."""
    return {name: (help, default) for name, help, default in _lineao.settings()}


def methods() -> list:
    """The method names ``render`` accepts, in the grid's order."""
    return list(_lineao.methods())
