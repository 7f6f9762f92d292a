#!/usr/bin/env bash
# A filtered frame against a noisy one (issue 29): wedge's whole AAF and MAAF render of the
# conference room at 720x720 (the MAAF paper's setting), against Embree's own path tracer
# (Debian embree-tools) rendering a 16-spp, path-length-2 frame of the same view, run back to
# back, `repeats` rounds. The path tracer has no area light: it lights the room with a point light
# at the centre of wedge's ceiling lamp and an ambient light, so the rays are not the same rays.
# Usage: bench/frame_peer.sh [build-dir] [repeats] [threads]
set -euo pipefail
build=${1:-build}
repeats=${2:-3}
threads=${3:-$(nproc)}
root=$(cd "$(dirname "$0")/.." && pwd)
command -v pathtracer >/dev/null || { echo "pathtracer not found: apt-get install embree-tools (WEDGE_EXTRAS=1 scripts/install-deps.sh)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq "$repeats"); do
  for m in aaf maaf; do
    /usr/bin/time -f %e -o "$tmp/$m$i.wall" "$root/$build/wedge" render conference --method "$m" --resolution 720x720 \
      --threads "$threads" --quiet --stats "$tmp/$m$i.json" -o "$tmp/$m.exr"
  done
  pathtracer -i "$root/scenes/conference/conference.obj" --vp 1550 330 -500 --vi 500 110 -140 --vu 0 1 0 --fov 50 \
    --pointlight 500 640 -140 4000000 4000000 4000000 --ambientlight 0.3 0.3 0.3 --size 720 720 --spp 16 \
    --max-path-length 2 --threads "$threads" --benchmark 1 3 2>&1 | awk '/BENCHMARK_RENDER_AVG /{print 1 / $2}' > "$tmp/p$i.txt"
done
python3 - "$tmp" "$repeats" <<'PY'
import json, sys, statistics
tmp, n = sys.argv[1], int(sys.argv[2])
peer = [float(open(f"{tmp}/p{i}.txt").read()) for i in range(1, n + 1)]
print(f"embree pathtracer, 16 spp frame: {' '.join(f'{v:.2f}' for v in peer)} s, median {statistics.median(peer):.2f}")
for m in ("aaf", "maaf"):
    runs = [json.load(open(f"{tmp}/{m}{i}.json")) for i in range(1, n + 1)]
    wall = [float(open(f"{tmp}/{m}{i}.wall").read()) for i in range(1, n + 1)]
    total = statistics.median(r["seconds"]["total"] for r in runs)
    sampling = statistics.median(r["seconds"]["sampling"] for r in runs)
    print(f"wedge {m}: total {total:.2f} s (sampling {sampling:.2f}), whole process {statistics.median(wall):.2f} s, "
          f"spp {runs[0]['spp_average']:.1f}; total / pathtracer {total / statistics.median(peer):.2f}")
PY
