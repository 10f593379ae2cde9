#!/usr/bin/env python3
"""lunar_tile_dem.py - the procedural DEM of configs/examples/lunar_tile.yaml.

A 256 x 256 tile of 0.5 m pixels (128 m square): heights in metres of
fractal relief (gradient-free value noise, octaves from 64 m to 1 m, RMS
falling as wavelength^0.8) and 60 craters of 2 to 30 m drawn from a
cumulative power law N(>D) ~ D^-2 (parabolic bowls of depth 0.2 D and a rim
of 0.04 D, as render/craters.c makes them), written as a float32 FITS image,
row 1 the northern edge (ROWORDER = 'TOP-DOWN'). Pure Python, deterministic:
    python3 scripts/lunar_tile_dem.py configs/examples/data/lunar_tile_dem.fits
"""
import math
import random
import struct
import sys

W = H = 256
PIXEL_M = 0.5


def value_noise(rng, n):
    """A periodic lattice of n x n random values, sampled bilinearly with a smooth fade."""
    lat = [[rng.gauss(0, 1) for _ in range(n)] for _ in range(n)]

    def f(x, y):
        x0, y0 = math.floor(x), math.floor(y)
        tx, ty = x - x0, y - y0
        tx, ty = tx * tx * (3 - 2 * tx), ty * ty * (3 - 2 * ty)
        a = lat[y0 % n][x0 % n] + tx * (lat[y0 % n][(x0 + 1) % n] - lat[y0 % n][x0 % n])
        b = lat[(y0 + 1) % n][x0 % n] + tx * (lat[(y0 + 1) % n][(x0 + 1) % n] - lat[(y0 + 1) % n][x0 % n])
        return a + ty * (b - a)
    return f


def main(out):
    rng = random.Random(2024)
    h = [[0.0] * W for _ in range(H)]
    wl = 64.0
    while wl >= 1.0:
        f = value_noise(rng, 64)
        amp = 0.05 * wl ** 0.8
        for r in range(H):
            for c in range(W):
                h[r][c] += amp * f(c * PIXEL_M / wl, r * PIXEL_M / wl)
        wl /= 2
    for _ in range(60):
        d = 2.0 * (1 - rng.random() * (1 - (2.0 / 30.0) ** 2)) ** -0.5  # N(>D) ~ D^-2 on [2, 30] m
        cx, cy = rng.uniform(0, W * PIXEL_M), rng.uniform(0, H * PIXEL_M)
        R = d / 2
        for r in range(max(0, int((cy - 3 * R) / PIXEL_M)), min(H, int((cy + 3 * R) / PIXEL_M) + 1)):
            for c in range(max(0, int((cx - 3 * R) / PIXEL_M)), min(W, int((cx + 3 * R) / PIXEL_M) + 1)):
                x = math.hypot(c * PIXEL_M - cx, r * PIXEL_M - cy) / R
                if x < 1:
                    h[r][c] += -0.2 * d + (0.2 + 0.04) * d * x * x
                elif x < 3:
                    h[r][c] += 0.04 * d * x ** -3 * (1 - ((x - 1) / 2) ** 2)
    cards = ["SIMPLE  =                    T", "BITPIX  =                  -32", "NAXIS   =                    2",
             f"NAXIS1  = {W:20d}", f"NAXIS2  = {H:20d}", "BUNIT   = 'm       '",
             "ROWORDER= 'TOP-DOWN'", "COMMENT lunar_tile_dem.py: heights in metres, 0.5 m pixels", "END"]
    head = "".join(c.ljust(80) for c in cards)
    head += " " * (-len(head) % 2880)
    data = b"".join(struct.pack(">%df" % W, *row) for row in h)
    data += b"\0" * (-len(data) % 2880)
    with open(out, "wb") as fh:
        fh.write(head.encode("ascii") + data)


if __name__ == "__main__":
    main(sys.argv[1])
