#!/usr/bin/env python3
"""Depth complexity of a tractogram in lineao's default view: line layers per covered pixel.

usage: depth-complexity.py FILE.tck [--width 1280 --height 1024] [--replicate N]

Reads a .tck (Float32LE, as `lineao convert` writes it) with numpy, frames it as `lineao render`
frames a file (ViewHint::for_tractogram: the sphere around the box's centre through the
farthest point, seen from (-1, 0.35, 0.3) with a 35° field of view, superior up), and rasterizes
every segment's centre line at half-pixel steps, counting each segment once per pixel. Prints
the covered share of the image and the mean and 90th percentile of the segments per covered
pixel. With --replicate N it first resamples the streamlines to 1 mm steps and copies them with
small smooth offsets (a random shift of up to 1.5 mm and a slow 1 mm wander per copy) until they
hold about N points: the replica of a real whole brain that the issue "whole-brain tractograms"
describes, to set beside `--scene wholebrain` of the same size.
"""
import argparse
import sys

import numpy as np


def read_tck(path):
    with open(path, "rb") as f:
        data = f.read()
    head = data[: data.index(b"\nEND\n") + 5].decode("latin-1")
    offset = next(int(line.split(".")[-1]) for line in head.splitlines() if line.startswith("file:"))
    values = np.frombuffer(data, dtype="<f4", offset=offset)
    values = values[: values.size // 3 * 3].reshape(-1, 3)
    ends = np.flatnonzero(np.isinf(values[:, 0]))
    if ends.size:
        values = values[: ends[0]]
    breaks = np.flatnonzero(np.isnan(values[:, 0]))
    lines, start = [], 0
    for b in breaks:
        if b > start:
            lines.append(values[start:b])
        start = b + 1
    if start < len(values):
        lines.append(values[start:])
    return lines


def resample(line, step=1.0):
    seg = np.linalg.norm(np.diff(line, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return line
    t = np.arange(0.0, s[-1] + 1e-6, step)
    return np.stack([np.interp(t, s, line[:, a]) for a in range(3)], axis=1).astype(np.float32)


def replicate(lines, target, rng):
    base = [resample(l) for l in lines if len(l) >= 2]
    out, total = [], 0
    while total < target:
        shift = rng.uniform(-1.5, 1.5, 3).astype(np.float32)
        phase = rng.uniform(0, 2 * np.pi, 3)
        for l in base:
            k = np.arange(len(l))[:, None]
            wander = np.sin(0.07 * k + phase) * 1.0
            out.append(l + shift + wander.astype(np.float32))
            total += len(l)
            if total >= target:
                break
    return out


def view(points, width, height):
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    radius = max(np.sqrt(((points - centre) ** 2).sum(axis=1)).max(), 1.0)
    fov = np.radians(35.0)
    distance = 0.9 * radius / np.tan(fov / 2)
    direction = np.array([-1.0, 0.35, 0.3])
    eye = centre + direction / np.linalg.norm(direction) * distance
    forward = (centre - eye) / np.linalg.norm(centre - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    f = (height / 2) / np.tan(fov / 2)
    return eye, forward, right, up, f


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("file")
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=1024)
    p.add_argument("--replicate", type=int, default=0)
    args = p.parse_args()
    lines = read_tck(args.file)
    if args.replicate:
        lines = replicate(lines, args.replicate, np.random.default_rng(1))
    points = np.concatenate(lines)
    eye, forward, right, up, f = view(points, args.width, args.height)
    w, h = args.width, args.height
    counts = np.zeros(w * h, dtype=np.int32)
    segments = 0
    for l in lines:
        rel = l - eye
        z = rel @ forward
        x = w / 2 + f * (rel @ right) / z
        y = h / 2 - f * (rel @ up) / z
        a = np.stack([x[:-1], y[:-1]], axis=1)
        b = np.stack([x[1:], y[1:]], axis=1)
        n = np.maximum(np.ceil(np.linalg.norm(b - a, axis=1) * 2).astype(int), 1)
        seg = np.repeat(np.arange(len(n)), n + 1)
        t = np.concatenate([np.linspace(0, 1, k + 1) for k in n])
        pts = a[seg] + (b[seg] - a[seg]) * t[:, None]
        px, py = np.floor(pts[:, 0]).astype(int), np.floor(pts[:, 1]).astype(int)
        ok = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        key = np.unique((seg[ok] + segments).astype(np.int64) * (w * h) + py[ok] * w + px[ok])
        np.add.at(counts, (key % (w * h)).astype(np.int64), 1)
        segments += len(n)
    covered = counts[counts > 0]
    print(
        f"{args.file}{' replicated' if args.replicate else ''}: {len(points)} points, {len(lines)} streamlines; "
        f"{w}x{h}: {covered.size / (w * h) * 100:.1f} % of the pixels covered, "
        f"{covered.mean():.1f} segments per covered pixel (90th percentile {np.percentile(covered, 90):.0f})"
    )


if __name__ == "__main__":
    sys.exit(main())
