"""An independent computation of lineao's legibility (docs/reference.md "Legibility"), exact form.

Every pair (p, p + o) with p a geometry pixel and o a non-zero integer offset with |o| <= r is
enumerated by shifting whole arrays; pairs whose partner is off the image or background, or whose
depths are within 0.005, are dropped; L = (concordant - discordant) / pairs. It shares no code
with `lineao::truth::legibility`, whose test `exact_equals_an_independent_implementation`
checks the numbers this prints, for the same two images.

    python3 crates/lineao/tests/legibility_numpy.py
"""
import numpy as np

W, H = 48, 40
y, x = np.mgrid[0:H, 0:W]
depth = (((x * 7 + y * 13) % 31) / 30.0).astype(np.float32)
dark = ((((x * 5 + y * 3) % 17) / 16.0).astype(np.float32) * np.float32(0.5)
        + np.float32(0.01) * y.astype(np.float32)).astype(np.float32)
mask = ((x + y * W) % W + 2 * y) % 5 != 0


def legibility(scale):
    r = max(scale * W, 1.0)
    n = int(np.floor(r))
    concordant = discordant = pairs = 0
    for dy in range(-n, n + 1):
        for dx in range(-n, n + 1):
            if dx == 0 and dy == 0 or dx * dx + dy * dy > r * r:
                continue
            # p at (y, x), q at (y + dy, x + dx): the overlapping windows.
            py0, py1 = max(0, -dy), min(H, H - dy)
            px0, px1 = max(0, -dx), min(W, W - dx)
            sp = (slice(py0, py1), slice(px0, px1))
            sq = (slice(py0 + dy, py1 + dy), slice(px0 + dx, px1 + dx))
            valid = mask[sp] & mask[sq]
            dz = depth[sp] - depth[sq]
            valid &= np.abs(dz) > np.float32(0.005)
            dd = dark[sp] - dark[sq]
            sign = np.sign(dz)
            along = dd * sign  # positive: the deeper one darker
            concordant += np.count_nonzero(valid & (along > np.float32(0.03)))
            discordant += np.count_nonzero(valid & (along < np.float32(-0.03)))
            pairs += np.count_nonzero(valid)
    return (concordant - discordant) / pairs


print(repr([legibility(s) for s in (0.01, 0.04, 0.15)]))
