#!/usr/bin/env python3
"""Methods side by side: one scene rendered with MC, AAF, MAAF and à-trous at the same base sample
count, against a high-sample MC reference, in one figure: the full images with an inset box, the
insets enlarged, and each method's per-pixel error map (log10 relative squared error, as
`wedge compare --heatmap` draws it) with its relMSE, PSNR and SSIM from wedge.compare().

    export PYTHONPATH=$PWD/build/python
    python3 examples/methods_side_by_side.py                     # cornell, 256x256 -> methods.png
    python3 examples/methods_side_by_side.py --scene grids --resolution 200x150 --out grids.png

The inset sits where the three filters together err most (a window of a fifth of the image),
unless --inset gives it.
"""
import argparse
import time

import matplotlib

matplotlib.use("Agg")  # files only: runs without a display
import matplotlib.pyplot as plt
import numpy as np

import wedge

METHODS = ["mc", "aaf", "maaf", "atrous"]


def display(linear):
    """Linear radiance -> what a PNG shows: clamped, then the sRGB curve (as `wedge render -o x.png`)."""
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def relative_error(test, ref, eps=0.01):
    """Per-pixel (x - r)^2 / (r^2 + eps) averaged over the channels: the map whose mean is relMSE."""
    return np.mean((test - ref) ** 2 / (ref ** 2 + eps), axis=2)


def worst_window(error, size):
    """Top-left corner (x, y) of the size x size window with the largest summed error."""
    s = np.pad(np.cumsum(np.cumsum(error, 0), 1), ((1, 0), (1, 0)))
    sums = s[size:, size:] - s[:-size, size:] - s[size:, :-size] + s[:-size, :-size]
    y, x = np.unravel_index(np.argmax(sums), sums.shape)
    return int(x), int(y)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scene", default="cornell", help="built-in name or scene file (default cornell)")
    p.add_argument("--resolution", default="256x256", help="WxH (default 256x256)")
    p.add_argument("--spp", type=int, default=8, help="base samples per pixel of every method (default 8)")
    p.add_argument("--reference-spp", type=int, default=1024, help="MC reference samples per pixel (default 1024)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--layers", default="auto", choices=["auto", "on", "off"],
                   help="the methods' --layers (default auto: on for mc and atrous, and for aaf and maaf where the scene moves); the reference is always off")
    p.add_argument("--inset", help="x,y,size of the inset in pixels (default: where MC errs most)")
    p.add_argument("--out", default="methods.png", help="output PNG (default methods.png)")
    a = p.parse_args()
    w, h = (int(v) for v in a.resolution.lower().split("x"))

    scene = wedge.load_scene(a.scene)
    common = dict(seed=a.seed, resolution=(w, h), quiet=True)
    # The reference: plain Monte Carlo (the layered reconstruction's smoothing would be a bias at
    # any spp) with its own seed, so that its noise is independent of the methods'.
    ref = wedge.render(scene, method="mc", spp=a.reference_spp, layers="off",
                       **{**common, "seed": a.seed + 1000}).color
    results = {}
    for m in METHODS:
        t0 = time.perf_counter()
        results[m] = wedge.render(scene, method=m, spp=a.spp, layers=a.layers, **common)
        print(f"{m:7s} {time.perf_counter() - t0:6.2f} s  {wedge.compare(results[m], ref)}")

    if a.inset:
        ix, iy, size = (int(v) for v in a.inset.split(","))
    else:
        size = max(4, min(w, h) // 5)
        filtered = sum(relative_error(results[m].color, ref) for m in METHODS if m != "mc")
        ix, iy = worst_window(filtered, size)

    columns = ["reference"] + METHODS
    fig, axes = plt.subplots(3, len(columns), figsize=(2.1 * len(columns), 2.3 * 3 * max(h / w, 0.6)),
                             squeeze=False, layout="constrained")
    for col, name in enumerate(columns):
        img = ref if name == "reference" else results[name].color
        top, mid, bottom = axes[0, col], axes[1, col], axes[2, col]
        top.imshow(display(img), interpolation="nearest")
        top.add_patch(plt.Rectangle((ix - 0.5, iy - 0.5), size, size, fill=False, edgecolor="#ff3030", lw=1.2))
        mid.imshow(display(img[iy:iy + size, ix:ix + size]), interpolation="nearest")
        if name == "reference":
            top.set_title(f"reference\nMC {a.reference_spp} spp", fontsize=9)
            bottom.axis("off")
        else:
            r = results[name]
            m = wedge.compare(r, ref)
            top.set_title(f"{name}\n{r.stats['spp_average']:.1f} spp, {r.stats['seconds']['total']:.2f} s", fontsize=9)
            heat = bottom.imshow(np.log10(np.maximum(relative_error(img, ref), 1e-4)), vmin=-4, vmax=0,
                                 cmap="inferno", interpolation="nearest")
            bottom.set_title(f"relMSE {m['relmse']:.3g}\nPSNR {m['psnr']:.1f} dB, SSIM {m['ssim']:.3f}", fontsize=8)
        for ax in (top, mid, bottom):
            ax.set_xticks([])
            ax.set_yticks([])
    axes[1, 0].set_ylabel("inset", fontsize=9)
    axes[2, 1].set_ylabel("log10 rel. sq. error", fontsize=8)
    fig.colorbar(heat, ax=list(axes[2, 1:]), shrink=0.8, ticks=[-4, -3, -2, -1, 0])
    fig.suptitle(f"{scene.name}, {w}x{h}, {a.spp} spp per method (initial spp for aaf and maaf), seed {a.seed}, "
                 f"layers {a.layers}",
                 fontsize=10)
    fig.savefig(a.out, dpi=80)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
