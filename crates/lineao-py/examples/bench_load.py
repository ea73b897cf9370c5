"""How fast `lineao.load` reads, against the CLI's loader in the same process kind and
nibabel, and what handing a nibabel ArraySequence to `render` costs in memory.

    lineao bench-load --vertices 10000000 --formats tck,trk --dir /tmp/bench --json > cli.json
    python bench_load.py /tmp/bench cli.json

Reads the files `lineao bench-load --dir` wrote and its JSON (the CLI's in-process medians),
loads each file with `lineao.load` and nibabel (medians of 5 and 3 runs), then renders a
10 M-vertex ArraySequence with `render` and reports numpy's traced peak (tracemalloc) and the
process's peak resident memory around it.
"""

import json
import resource
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

import nibabel as nib
import numpy as np

import lineao


def median_ms(f, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


def main(folder: Path, cli_json: Path) -> None:
    cli = {row["format"]: row for row in json.loads(cli_json.read_text())["files"]}
    for path in sorted(folder.iterdir()):
        fmt = path.suffix.lstrip(".")
        if fmt not in cli or path.stem == "empty":
            continue
        vertices = len(lineao.load(path).points)
        ours = median_ms(lambda: lineao.load(path), 5)
        theirs = median_ms(lambda: nib.streamlines.load(str(path)).streamlines._data, 3)
        cli_ms = cli[fmt]["load_ms"]
        print(
            f"{path.name}: {vertices / 1e6:.1f} M vertices, lineao.load {ours:.0f} ms, CLI {cli_ms:.0f} ms "
            f"({cli_ms / ours:.2f} x the CLI's speed), nibabel {theirs:.0f} ms ({theirs / ours:.1f} x faster)"
        )
    seq = nib.streamlines.load(str(next(folder.glob("*.tck")))).streamlines
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tracemalloc.start()
    lineao.render(seq, width=640, height=512)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    rss_after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(
        f"render(ArraySequence of {len(seq._data) / 1e6:.1f} M vertices, {seq._data.nbytes / 2**20:.0f} MiB of points): "
        f"numpy's traced peak {peak / 2**20:.1f} MiB; process peak RSS +{(rss_after - rss_before) / 2**10:.0f} MiB"
    )


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
