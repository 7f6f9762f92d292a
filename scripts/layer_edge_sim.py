#!/usr/bin/env python3
"""The bias of a blurred layer's grid at a defocused edge, by edge position (numpy only).

Simulates, in one dimension, what src/filter/layers.cpp does to the edge of a lit half-plane
(pinhole image x < E) of defocus slope c over a background: samples uniform over the pixels and
the lens disc, each splatted at its sharp position x + c u into 1-pixel cells (N: the samples on
the half-plane; D: all of them), both smoothed by the coverage's Gaussian (sigma = clamp(0.15 c,
floor, 2), the same unnormalised taps as smooth(); the floor 0.5 px before 2026-11-27, the
radiance's, and 0.25 px since: LayerOptions::sigmaCoverageMin), alpha = N / D per cell, then read by rays
jittered over the pixel, sheared by the shaped disc (kDiscShape at rho = sqrt(grid blur) / c,
the same table and lerp as layers.cpp) and looked up bilinearly between cell centres. Against it
the thin lens's truth: the share of a pixel's (position, lens point) pairs that see the plane.
A layer below the grid's own blur (|c| < 2 sqrt(kCellBlur + 0.25), 1.41 px) is sharp: each pixel
its own samples, which is exact (no sharing) at any slope. Below it, the second table runs the
near-focus slopes that Monte Carlo's samples share at 16 spp (LayerOptions::sharpShare 0.5: a
layer is sharp only below |c| = 1.0 px).

It prints, per floor and slope, the mean over 8 edge positions (E = 48 + k / 8) of the squared coverage
error summed over the pixels of the edge, and the worst pixel at an edge on a cell boundary
(E = 48) and at a cell centre (E = 48.5). docs/layers.md, "What the mixed pixels' error is made
of", has the numbers and what they mean.

    python3 scripts/layer_edge_sim.py
"""
import numpy as np

RNG = np.random.default_rng(1)
CELL_BLUR = 1.0 / 12.0 + 1.0 / 6.0  # kCellBlur: the cell (box) and the bilinear lookup
DISC_SHAPE = [  # kDiscShape of layers.cpp: (a, b) at rho = 0, 0.025, ..., 0.475; none from 0.5
    (1.00000, -0.00000), (1.00153, -0.00417), (1.00677, -0.01492), (1.01555, -0.03761),
    (1.02771, -0.06661), (1.04971, -0.11469), (1.07619, -0.17139), (1.12727, -0.27347),
    (1.17004, -0.36329), (1.17198, -0.39066), (1.15090, -0.38363), (1.12572, -0.37524),
    (1.09538, -0.36513), (1.06032, -0.35344), (1.02180, -0.34060), (0.97460, -0.32487),
    (0.91818, -0.30606), (0.85231, -0.28410), (0.76514, -0.25505), (0.54811, -0.18270),
    (0.0, 0.0)]
LO, HI = 30, 67  # the cells simulated: [LO, HI)
PIXELS = range(43, 53)


def shaped(rho):
    if not rho < 0.5:
        return 0.0, 0.0
    at = min(rho / 0.025, len(DISC_SHAPE) - 1 - 1e-3)
    i = int(at)
    f = at - i
    (a0, b0), (a1, b1) = DISC_SHAPE[i], DISC_SHAPE[i + 1]
    return a0 + f * (a1 - a0), b0 + f * (b1 - b0)


def disc(n):
    r = np.sqrt(RNG.random(n))
    t = 2 * np.pi * RNG.random(n)
    return r * np.cos(t), r * np.sin(t)


def smooth(a, sigma):
    r = int(np.ceil(3 * sigma))
    k = np.exp(-0.5 * np.arange(-r, r + 1) ** 2 / sigma ** 2)
    return np.convolve(a, k, "same")


def profiles(c, edge, floor, samples=1_000_000, rays=60_000, share=1.0):
    """The layer's and the truth's coverage of PIXELS, and whether the layer is sharp (below
    `share` times the grid's own blur: LayerOptions::sharpShare)."""
    sigma = min(max(floor, 0.15 * c), 2.0)
    grid_blur = CELL_BLUR + sigma ** 2
    ray_a, ray_b = shaped(np.sqrt(grid_blur) / c) if 0.25 * c * c >= grid_blur else (0.0, 0.0)
    sharp = 0.25 * c * c < share * (CELL_BLUR + 0.25)
    x = 40 + 16 * RNG.random(samples)
    ux, _ = disc(samples)
    pos = x + c * ux
    front = pos < edge
    layer, truth = [], []
    if not sharp:
        bins = np.arange(LO, HI + 1)
        n = np.histogram(pos[front], bins=bins)[0].astype(float)
        d = np.histogram(pos, bins=bins)[0].astype(float)
        alpha = smooth(n, sigma) / np.maximum(smooth(d, sigma), 1e-9)
    for p in PIXELS:
        q = RNG.random(rays)
        vx, vy = disc(rays)
        truth.append(((p + q + c * vx) < edge).mean())
        if sharp:
            inside = (x >= p) & (x < p + 1)
            layer.append(front[inside].mean())
            continue
        y = p + q + c * (ray_a + ray_b * (vx * vx + vy * vy)) * vx
        f = y - LO - 0.5
        i = np.floor(f).astype(int)
        w = f - i
        layer.append(((1 - w) * alpha[i] + w * alpha[i + 1]).mean())
    return np.array(layer), np.array(truth), sharp


def row(floor, c, share=1.0):
    """One line of the table: the edge's squared error over 8 positions, the worst pixels."""
    total, worst = 0.0, []
    for k in range(8):
        layer, truth, sharp = profiles(c, 48 + k / 8, floor, share=share)
        err = layer - truth
        total += (err ** 2).sum() / 8
        if k in (0, 4):
            worst.append(np.abs(err).max())
    print(f"{floor:5.2f}  {c:7.2f}  {int(sharp):5d}  {total:32.5f}  {worst[0]:.3f}, {worst[1]:.3f}")


def main():
    print("floor  slope c  sharp  mean squared error (8 positions)  worst |error| at E = 48, 48.5")
    for floor, c in [(f, c) for f in (0.5, 0.25) for c in (1.2, 1.45, 1.49, 1.6, 1.7, 2.0, 2.5, 3.5, 5.0)]:
        row(floor, c)
    print("sharpShare 0.5 (Monte Carlo at 16 spp), floor 0.25:")
    for c in (1.0, 1.1, 1.2, 1.3):
        row(0.25, c, share=0.5)


if __name__ == "__main__":
    main()
