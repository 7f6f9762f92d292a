#!/usr/bin/env bash
# wedge against Embree's own path tracer (Debian embree-tools), run back to back, `repeats` rounds:
# 1. Throughput: rays per second of wedge's MC sampling stage on Sponza at 512x512, 16 spp (as
#    rendered by default, and with --layers off: no light field recorded), against the path
#    tracer's on the same camera (path length 2).
# 2. A filtered frame against a noisy one (issue 29): wedge's whole AAF and MAAF render of the
#    conference room at 720x720 (the MAAF paper's setting) against the path tracer's 16-spp,
#    path-length-2 frame of the same view.
# The path tracer has no area light: it lights with a point light (at the centre of wedge's lamp
# in the conference room) and an ambient light, so the rays are not the same rays.
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
for i in $(seq "$repeats"); do
  "$root/$build/wedge" render sponza --resolution 512x512 --spp 16 --threads "$threads" --quiet --stats "$tmp/w$i.json"
  "$root/$build/wedge" render sponza --resolution 512x512 --spp 16 --layers off --threads "$threads" --quiet --stats "$tmp/o$i.json"
  pathtracer -i "$root/scenes/sponza/sponza.obj" --vp -120 20 0 --vi 100 40 0 --vu 0 1 0 --fov 60 \
    --pointlight 0 100 0 20000 20000 20000 --ambientlight 0.3 0.3 0.3 --size 512 512 --spp 16 \
    --max-path-length 2 --threads "$threads" --benchmark 1 3 2>&1 | awk '/BENCHMARK_RENDER_MRAYPS_AVG /{print $2}' > "$tmp/p$i.txt"
  for m in aaf maaf; do
    "$root/$build/wedge" render conference --method "$m" --resolution 720x720 --threads "$threads" --quiet \
      --stats "$tmp/$m$i.json" -o "$tmp/$m.exr"
  done
  pathtracer -i "$root/scenes/conference/conference.obj" --vp 1550 330 -500 --vi 500 110 -140 --vu 0 1 0 --fov 50 \
    --pointlight 500 640 -140 4000000 4000000 4000000 --ambientlight 0.3 0.3 0.3 --size 720 720 --spp 16 \
    --max-path-length 2 --threads "$threads" --benchmark 1 1 2>&1 | awk '/BENCHMARK_RENDER_AVG /{print 1 / $2}' > "$tmp/f$i.txt"
done
python3 - "$tmp" "$repeats" <<'PY'
import json, sys, statistics
tmp, n = sys.argv[1], int(sys.argv[2])
med = statistics.median
def seq(v): return " ".join(f"{x:.2f}" for x in v) + f", median {med(v):.2f}"
w = [json.load(open(f"{tmp}/w{i}.json"))["rays_per_second"] / 1e6 for i in range(1, n + 1)]
o = [json.load(open(f"{tmp}/o{i}.json"))["rays_per_second"] / 1e6 for i in range(1, n + 1)]
p = [float(open(f"{tmp}/p{i}.txt").read()) for i in range(1, n + 1)]
print("Sponza 512x512, 16 spp")
print("  wedge sampling    Mrays/s:", seq(w))
print("  --layers off      Mrays/s:", seq(o), "(no light field recorded for the layered reconstruction)")
print("  embree pathtracer Mrays/s:", seq(p))
print(f"  ratio wedge / pathtracer: {med(w) / med(p):.2f} ({med(o) / med(p):.2f} with --layers off)")
f = [float(open(f"{tmp}/f{i}.txt").read()) for i in range(1, n + 1)]
print("conference 720x720")
print("  embree pathtracer, a 16-spp frame, s:", seq(f))
for m in ("aaf", "maaf"):
    runs = [json.load(open(f"{tmp}/{m}{i}.json")) for i in range(1, n + 1)]
    total = med(r["seconds"]["total"] for r in runs)
    print(f"  wedge {m}: total {total:.2f} s (sampling {med(r['seconds']['sampling'] for r in runs):.2f} s, "
          f"{runs[0]['spp_average']:.1f} spp); total / pathtracer frame {total / med(f):.2f}")
PY
