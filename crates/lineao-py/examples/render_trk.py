"""Render a tractogram with LineAO next to plain lines, and a turntable, from Python.

    python render_trk.py bundle.trk            # bundle.png (split screen) and bundle-orbit-*.png

Any file `lineao info` reads works (.trk .tck .trx .vtk .vtp .tt.gz …); so do nibabel's and
DIPY's objects (`lineao.render(nib.streamlines.load(path))`).
"""

import sys
from pathlib import Path

import lineao

path = Path(sys.argv[1])
tractogram = lineao.load(path, progress=True)
print(tractogram)

split = lineao.render(tractogram, compare=("none", "lineao"), width=1280, height=1024)
lineao.save_png(split, path.with_suffix(".png").name)

renderer = lineao.Renderer(tractogram, width=640, height=512)
print(renderer)
for i, frame in enumerate(renderer.orbit(8)):
    lineao.save_png(frame, f"{path.stem}-orbit-{i}.png")
