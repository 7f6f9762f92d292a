#!/usr/bin/env bash
# wedge against Embree's own path tracer (Debian embree-tools), run back to back, `repeats` rounds:
# 1. Throughput: wedge's MC sampling stage on Sponza at 512x512, 16 spp (as rendered by default,
#    and with --layers off: no light field recorded), against the path tracer's on the same camera
#    (path length 2), in rays per second and in time per path sample.
# 2. A filtered frame against a noisy one (issue 29): wedge's whole AAF and MAAF render of the
#    conference room at 720x720 (the MAAF paper's setting) against the path tracer's 16-spp,
#    path-length-2 frame of the same view.
# The path tracer has no area light. It runs twice per view:
# - "ambient": a point light (at the centre of wedge's lamp) and an ambient light, as this script
#   always measured. The ambient light adds a second shadow ray at each of the two hits: about 5.8
#   rays per path sample, a third of them short occlusion rays, cheap for their count.
# - "point": the point light alone, the same path sample as wedge's (primary ray, shadow ray,
#   diffuse bounce, the bounce's shadow ray): at most 4 rays per path sample, as wedge's.
# Rays per second depend on which rays are counted; time per path sample (ns, the stage or frame
# over width x height x samples per pixel) compares the same work.
# Usage: bench/pathtracer_peer.sh [build-dir] [repeats] [threads]  (one thread each is steadier on
# a shared machine: docs/sampling-speed.md)
set -euo pipefail
build=${1:-build}
repeats=${2:-3}
threads=${3:-$(nproc)}
root=$(cd "$(dirname "$0")/.." && pwd)
command -v pathtracer >/dev/null || { echo "pathtracer not found: apt-get install embree-tools (WEDGE_EXTRAS=1 scripts/install-deps.sh)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The path tracer's average frames per second and Mrays/s, as "fps mrays".
peer() {
  pathtracer "$@" --max-path-length 2 --threads "$threads" 2>&1 |
    awk '/BENCHMARK_RENDER_AVG /{f=$2} /BENCHMARK_RENDER_MRAYPS_AVG /{m=$2} END{print f, m}'
}
sponza=(-i "$root/scenes/sponza/sponza.obj" --vp -120 20 0 --vi 100 40 0 --vu 0 1 0 --fov 60
  --pointlight 0 100 0 20000 20000 20000 --size 512 512 --spp 16 --benchmark 1 3)
conference=(-i "$root/scenes/conference/conference.obj" --vp 1550 330 -500 --vi 500 110 -140 --vu 0 1 0 --fov 50
  --pointlight 500 640 -140 4000000 4000000 4000000 --size 720 720 --spp 16 --benchmark 1 1)
for i in $(seq "$repeats"); do
  "$root/$build/wedge" render sponza --resolution 512x512 --spp 16 --threads "$threads" --quiet --stats "$tmp/w$i.json"
  "$root/$build/wedge" render sponza --resolution 512x512 --spp 16 --layers off --threads "$threads" --quiet --stats "$tmp/o$i.json"
  peer "${sponza[@]}" --ambientlight 0.3 0.3 0.3 > "$tmp/pa$i.txt"
  peer "${sponza[@]}" > "$tmp/pp$i.txt"
  for m in aaf maaf; do
    "$root/$build/wedge" render conference --method "$m" --resolution 720x720 --threads "$threads" --quiet \
      --stats "$tmp/$m$i.json" -o "$tmp/$m.exr"
  done
  peer "${conference[@]}" --ambientlight 0.3 0.3 0.3 > "$tmp/fa$i.txt"
  peer "${conference[@]}" > "$tmp/fp$i.txt"
done
python3 - "$tmp" "$repeats" <<'PY'
import json, sys, statistics
tmp, n = sys.argv[1], int(sys.argv[2])
med = statistics.median
runs = range(1, n + 1)
def seq(v, f="{:.2f}"): return " ".join(f.format(x) for x in v) + ", median " + f.format(med(v))
def peer(name): return [tuple(map(float, open(f"{tmp}/{name}{i}.txt").read().split())) for i in runs]
samples = 512 * 512 * 16
print("Sponza 512x512, 16 spp, MC sampling stage")
rows = {}
for key, label in (("w", "wedge"), ("o", "wedge --layers off")):
    st = [json.load(open(f"{tmp}/{key}{i}.json")) for i in runs]
    rows[label] = ([s["rays_per_second"] / 1e6 for s in st], [s["seconds"]["sampling"] / samples * 1e9 for s in st],
                   st[0]["rays"] / samples)
for key, label in (("pa", "pathtracer, ambient"), ("pp", "pathtracer, point")):
    p = peer(key)
    rows[label] = ([m for _, m in p], [1e9 / f / samples for f, _ in p], med(m / f for f, m in p) * 1e6 / samples)
for label, (mr, ns, rps) in rows.items():
    print(f"  {label:20s} Mrays/s {seq(mr)}; ns per path sample {seq(ns, '{:.0f}')}; rays per path sample {rps:.2f}")
for peer_label in ("pathtracer, ambient", "pathtracer, point"):
    pm, pn = med(rows[peer_label][0]), med(rows[peer_label][1])
    for label in ("wedge", "wedge --layers off"):
        print(f"  {label} / {peer_label}: {med(rows[label][0]) / pm:.2f}x the rays per second, "
              f"{pn / med(rows[label][1]):.2f}x the path samples per second")
print("conference 720x720")
frames = {key: [1 / f for f, _ in peer(key)] for key in ("fa", "fp")}
for key, label in (("fa", "ambient"), ("fp", "point")):
    print(f"  embree pathtracer ({label}), a noisy 16-spp frame, s:", seq(frames[key]))
fa, fp = med(frames["fa"]), med(frames["fp"])
for m in ("aaf", "maaf"):
    st = [json.load(open(f"{tmp}/{m}{i}.json")) for i in runs]
    total = med(r["seconds"]["total"] for r in st)
    first = med(r["seconds"]["sampling_initial"] for r in st)
    print(f"  wedge {m}: total {total:.2f} s (sampling {med(r['seconds']['sampling'] for r in st):.2f} s, "
          f"{st[0]['spp_average']:.1f} spp); total / pathtracer frame {total / fa:.2f} (ambient), {total / fp:.2f} (point)")
    print(f"    its first 16 spp (with the slopes' occluder queries): {first:.2f} s, {first / fa:.2f} / {first / fp:.2f} of the frames")
PY
