#!/usr/bin/env python3
"""Before / after crops of the layered reconstruction (issue 27): a defocused silhouette, edges
near the focal plane and two motion-blurred objects, each rendered by MC and AAF with `--layers off`
and `--layers on` at the same samples, beside a high-sample MC reference, enlarged, with each
crop's relMSE against the reference's crop.

    export PYTHONPATH=$PWD/build/python
    python3 examples/layers_crops.py --out docs/layers-crops.png     # 2 minutes on 2 cores
    python3 examples/layers_crops.py --set camera --out docs/layers-camera-and-turns.png   # 8 minutes
    python3 examples/layers_crops.py --set order --out docs/layers-order.png   # 1 minute
    python3 examples/layers_crops.py --set sliver --out docs/layers-sliver.png   # 2 minutes

The crops are the rows of CROPS (scene, resolution, crop x, y, width, height); the
reference is plain MC without layers with its own seed, so that its noise is independent of
the renders'.
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")  # files only: runs without a display
import matplotlib.pyplot as plt
import numpy as np

import wedge

HERE = os.path.dirname(os.path.abspath(__file__))
# (label, scene, resolution, crop x, y, width, height)
CROPS = [
    ("defocused silhouette: a chair's back over its seat and the floor", "conference", (512, 512), 226, 276, 120, 80),
    ("near the focal plane: chair backs behind the table, the wall", "conference", (512, 512), 96, 180, 120, 80),
    ("motion: the trailing end of a moving sphere", os.path.join(HERE, "..", "docs", "motion.json"), (256, 256),
     40, 84, 90, 60),
    ("motion and a lens: a bunny moving past defocused slats, over a checkered floor",
     os.path.join(HERE, "..", "docs", "bunny-slats.json"), (256, 256), 100, 126, 90, 60),
]
# --set camera: a moving camera, a turning camera and a turning object (the held-out scenes of
# docs/layers.md, "A moving camera" and "Turning objects").
CAMERA_CROPS = [
    ("camera moving: Sponza's hangings and columns", os.path.join(HERE, "..", "docs", "sponza-campan.json"), (512, 512),
     20, 230, 160, 120),
    ("camera turning: the arches at the far end", os.path.join(HERE, "..", "docs", "sponza-turn.json"), (512, 512),
     190, 160, 160, 120),
    ("bunny turning: its head and ears", os.path.join(HERE, "..", "docs", "bunny-turn.json"), (384, 384),
     100, 100, 160, 120),
]
# --set order: a slat moving in front of the bunny's head while the bunny comes forward through the
# slats' depth (docs/layers.md, "Two moving layers ordered where they meet").
ORDER_CROPS = [
    ("two moving layers: slats crossing the bunny's head", os.path.join(HERE, "..", "docs", "bunny-slats.json"), (256, 256),
     95, 80, 90, 60),
]
# --set sliver: the floor beside the bottom of a box coming towards the camera (docs/layers.md, "A
# sliver of a moving box in front of the floor beside it").
SLIVER_CROPS = [
    ("a box coming closer: the floor at its bottom-left edge", os.path.join(HERE, "..", "docs", "moving-boxes.json"),
     (384, 384), 205, 250, 60, 50),
]
CROP_SETS = {"default": CROPS, "camera": CAMERA_CROPS, "order": ORDER_CROPS, "sliver": SLIVER_CROPS}
COLUMNS = [("mc", "off"), ("mc", "on"), ("aaf", "off"), ("aaf", "on")]


def display(linear):
    """Linear radiance -> what a PNG shows: clamped, then the sRGB curve (as `wedge render -o x.png`)."""
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--spp", type=int, default=16,
                   help="samples per pixel of every render (initial for aaf; default 16)")
    p.add_argument("--reference-spp", type=int, default=1024, help="MC reference samples per pixel (default 1024)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--zoom", type=int, default=2, help="enlargement of the crops (default 2)")
    p.add_argument("--scale", type=float, default=1.0,
                   help="scale of every resolution and crop (default 1; the tests run 0.125)")
    p.add_argument("--out", default="layers-crops.png", help="output PNG (default layers-crops.png)")
    p.add_argument("--set", choices=sorted(CROP_SETS), default="default",
                   help="the crops: a defocused silhouette, the focal plane and moving objects (default), a "
                        "moving camera, a turning camera and a turning object (camera), two moving layers "
                        "crossing (order), or the floor beside a box coming closer (sliver)")
    a = p.parse_args()
    if not 0 < a.scale <= 4:
        p.error("--scale: expected a number in (0, 4]")
    crops = [(label, name, tuple(max(8, round(v * a.scale)) for v in res), *(max(1, round(v * a.scale)) for v in box))
             for label, name, res, *box in CROP_SETS[a.set]]

    images = {}  # (scene, resolution) -> {column or "reference": colour}
    for _, name, res, *_ in crops:
        key = (name, res)
        if key in images:
            continue
        scene = wedge.load_scene(name)
        common = dict(quiet=True, resolution=res)
        row = {"reference": wedge.render(scene, method="mc", spp=a.reference_spp, layers="off",
                                         seed=a.seed + 1000, **common).color}
        for method, layers in COLUMNS:
            row[(method, layers)] = wedge.render(scene, method=method, spp=a.spp, layers=layers, seed=a.seed,
                                                 **common).color
        images[key] = row
        print("rendered", scene.name)

    titles = [f"{m.upper()}, --layers {l}" for m, l in COLUMNS] + [f"reference (MC {a.reference_spp} spp)"]
    keys = COLUMNS + ["reference"]
    heights = [c[6] for c in crops]
    width = crops[0][5]
    fig, axes = plt.subplots(len(crops), len(keys), squeeze=False, layout="constrained",
                             figsize=(len(keys) * width * a.zoom / 100,
                                      sum(heights) * a.zoom / 100 + 0.35 * len(crops) + 0.3),
                             gridspec_kw={"height_ratios": heights})
    for r, (label, name, res, x, y, w, h) in enumerate(crops):
        row = images[(name, res)]
        ref = row["reference"][y:y + h, x:x + w]
        for c, key in enumerate(keys):
            crop = row[key][y:y + h, x:x + w]
            ax = axes[r, c]
            ax.imshow(display(crop), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            text = titles[c] if key == "reference" else f"{titles[c]}\nrelMSE {wedge.compare(crop, ref)['relmse']:.2g}"
            ax.set_title(text, fontsize=7)
        axes[r, 0].set_ylabel(label.split(":")[0], fontsize=7)
    fig.suptitle(f"{a.spp} spp (AAF: initial), the same seed; rows as labelled (docs/layers.md describes them)",
                 fontsize=7)
    fig.savefig(a.out, dpi=100)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
