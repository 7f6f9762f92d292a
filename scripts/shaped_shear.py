#!/usr/bin/env python3
"""Prints the tables kDiscShape and kSegmentShape of src/filter/layers.cpp (numpy only).

A reconstruction ray through a layer's grid is sheared by (a + b r^2) times its lens point u
(r = |u|, u on the unit disc) or times its shutter offset s = t - 1/2 (r = 2 |s|). The grid blurs
what a ray reads by a near-Gaussian whose standard deviation, in units of the true blur (the
disc's radius, the segment's length), is rho. Per rho this finds the monotone map (a + 3 b >= 0)
whose blur, convolved with that Gaussian, has the edge profile (the CDF of its marginal along one
axis) nearest the true blur's, in the least-squares sense over the blur's reach. Beside each row
it prints the RMS profile error of the plain narrowed map (b = 0, a matching the second moment).

    python3 scripts/shaped_shear.py
"""
import math

import numpy as np

DX = 0.002
X = np.arange(-2.5, 2.5 + DX / 2, DX)


def histogram(points):  # on X
    h, _ = np.histogram(points, bins=len(X), range=(X[0] - DX / 2, X[-1] + DX / 2))
    return h / h.sum()


def blurred_cdf(points, sigma):
    g = np.exp(-0.5 * (X / max(sigma, 0.01)) ** 2)
    return np.cumsum(np.convolve(histogram(points), g / g.sum(), mode="same"))


def search(err):
    """(error, s, k) of least error over s in [0, 1] (the pull towards the rim) and k (a over the
    a that keeps the true second moment): a grid of 21 x 13, then three refinements of 7 x 7."""
    best = min((err(s, k), s, k) for s in np.linspace(0.0, 1.0, 21) for k in np.linspace(0.7, 1.3, 13))
    ds, dk = 0.05, 0.05
    for _ in range(3):
        ss = np.linspace(max(0.0, best[1] - ds), min(1.0, best[1] + ds), 7)
        ks = np.linspace(best[2] - dk, best[2] + dk, 7)
        best = min([best] + [(err(s, k), s, k) for s in ss for k in ks])
        ds, dk = ds / 3, dk / 3
    return best


def table(name, points, r, reach, step, count):
    """The rows at rho = 0, step, ...: points are the unit blur's along the profile's axis, r
    their map's argument (|u| or 2 |s|), reach the unit blur's half-width."""
    true = blurred_cdf(points, 0.0)
    variance = np.mean(points**2)
    rows = []
    for k in range(count):
        rho = k * step
        sel = np.abs(X) < reach + 3 * rho

        def scale(s):  # the a that keeps the true second moment with the grid's rho^2
            m = np.mean((points * (1.0 - s / 3.0 * r * r)) ** 2)
            return math.sqrt(max(0.0, variance - rho * rho) / m)

        def err(s, k):
            cdf = blurred_cdf(points * k * scale(s) * (1.0 - s / 3.0 * r * r), rho)
            return math.sqrt(np.mean((cdf - true)[sel] ** 2))

        e, s, k = search(err)
        a = k * scale(s)
        rows.append((a, -a * s / 3.0))
        print(f"// {name} rho {rho:.3f}: narrowed RMS {err(0.0, 1.0):.4f}; shaped a {a:.5f} b {-a * s / 3:+.5f}, RMS {e:.4f}")
    rows.append((0.0, 0.0))
    print(f"{name} = {{" + ", ".join(f"{{{a:.5f}f, {b:.5f}f}}" for a, b in rows) + "};")


def main():
    # The unit disc's points, area-uniform on a polar grid; the profile is along x.
    radius = np.sqrt((np.arange(400) + 0.5) / 400)[:, None]
    theta = (np.arange(256) + 0.5) / 256 * 2 * math.pi
    disc_x = (radius * np.cos(theta)[None, :]).ravel()
    disc_r = np.broadcast_to(radius, (400, 256)).ravel()
    table("kDiscShape", disc_x, disc_r, 1.0, 0.025, 20)
    s = (np.arange(20000) + 0.5) / 20000 - 0.5
    table("kSegmentShape", s, 2 * np.abs(s), 0.5, 0.02, 15)


if __name__ == "__main__":
    main()
