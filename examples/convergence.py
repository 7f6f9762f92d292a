#!/usr/bin/env python3
"""The convergence plot: relMSE against render time, log-log, for MC, AAF, MAAF and à-trous over a
range of sample counts, each point one render measured against a high-sample MC reference with
wedge.compare(); time is the render's own total (stats["seconds"]["total"]). A method whose
curve lies lower reaches a given error sooner; MC's slope is -1 (relMSE ~ 1/spp ~ 1/seconds).

    export PYTHONPATH=$PWD/build/python
    python3 examples/convergence.py                               # cornell, 256x256 -> convergence.png
    python3 examples/convergence.py --scene grids --spp 2,4,8,16,32 --out grids-convergence.png
"""
import argparse

import matplotlib

matplotlib.use("Agg")  # files only: runs without a display
import matplotlib.pyplot as plt

import wedge

STYLE = {"mc": ("#444444", "o"), "aaf": ("#1f77b4", "s"), "maaf": ("#d62728", "D"), "atrous": ("#2ca02c", "^")}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scene", default="cornell", help="built-in name or scene file (default cornell)")
    p.add_argument("--resolution", default="256x256", help="WxH (default 256x256)")
    p.add_argument("--spp", default="1,2,4,8,16,32,64",
                   help="comma-separated sample counts (default 1,2,4,8,16,32,64)")
    p.add_argument("--methods", default="mc,aaf,maaf,atrous")
    p.add_argument("--reference-spp", type=int, default=1024, help="MC reference samples per pixel (default 1024)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--layers", default="auto", choices=["auto", "on", "off"],
                   help="the methods' --layers (default auto: on for mc and atrous, and for aaf and maaf where the scene moves); the reference is always off")
    p.add_argument("--repeat", type=int, default=1,
                   help="renders per point, the fastest counts (as wedge experiment --repeat; timings are noisy)")
    p.add_argument("--out", default="convergence.png", help="output PNG (default convergence.png)")
    a = p.parse_args()
    w, h = (int(v) for v in a.resolution.lower().split("x"))
    counts = [int(s) for s in a.spp.split(",")]

    scene = wedge.load_scene(a.scene)
    common = dict(resolution=(w, h), quiet=True)
    # Plain Monte Carlo for the reference (layers off: their smoothing would be a bias at any spp).
    ref = wedge.render(scene, method="mc", spp=a.reference_spp, seed=a.seed + 1000, layers="off", **common)

    fig, ax = plt.subplots(figsize=(6, 4.2))
    for m in a.methods.split(","):
        seconds, errors = [], []
        for spp in counts:
            runs = [wedge.render(scene, method=m, spp=spp, seed=a.seed, layers=a.layers, **common)
                    for _ in range(a.repeat)]
            r = min(runs, key=lambda run: run.stats["seconds"]["total"])  # the same image each time
            seconds.append(r.stats["seconds"]["total"])
            errors.append(wedge.compare(r, ref)["relmse"])
            print(f"{m:7s} {spp:5d} spp  {seconds[-1]:7.3f} s  relMSE {errors[-1]:.5f}")
        color, marker = STYLE.get(m, ("black", "x"))
        ax.loglog(seconds, errors, marker=marker, color=color, label=m)
        ax.annotate(f"{counts[0]}", (seconds[0], errors[0]), textcoords="offset points", xytext=(4, 4),
                    fontsize=7, color=color)
        ax.annotate(f"{counts[-1]} spp", (seconds[-1], errors[-1]), textcoords="offset points", xytext=(4, 4),
                    fontsize=7, color=color)
    ax.set_xlabel("seconds (render total)")
    ax.set_ylabel("relMSE against MC %d spp" % a.reference_spp)
    ax.set_title(f"{scene.name}, {w}x{h}, layers {a.layers}: error against time", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
