#!/usr/bin/env bash
# Throughput peer (issue: foundation benchmark): rays per second of wedge's sampling stage on
# Sponza at 512x512, 16 spp, against Embree's own path tracer (Debian embree-tools, path length
# 2, the same camera), run back to back. Usage: bench/pathtracer_peer.sh [build-dir] [repeats] [threads]
# (one thread each is steadier on a shared machine: docs/sampling-speed.md).
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
  pathtracer -i "$root/scenes/sponza/sponza.obj" --vp -120 20 0 --vi 100 40 0 --vu 0 1 0 --fov 60 \
    --pointlight 0 100 0 20000 20000 20000 --ambientlight 0.3 0.3 0.3 --size 512 512 --spp 16 \
    --max-path-length 2 --threads "$threads" --benchmark 1 3 2>&1 | awk '/BENCHMARK_RENDER_MRAYPS_AVG /{print $2}' > "$tmp/p$i.txt"
done
python3 - "$tmp" "$repeats" <<'PY'
import json, sys, statistics
tmp, n = sys.argv[1], int(sys.argv[2])
w = [json.load(open(f"{tmp}/w{i}.json"))["rays_per_second"] / 1e6 for i in range(1, n + 1)]
p = [float(open(f"{tmp}/p{i}.txt").read()) for i in range(1, n + 1)]
print("wedge sampling   Mrays/s:", " ".join(f"{v:.2f}" for v in w), f"median {statistics.median(w):.2f}")
print("embree pathtracer Mrays/s:", " ".join(f"{v:.2f}" for v in p), f"median {statistics.median(p):.2f}")
print(f"ratio wedge / pathtracer: {statistics.median(w) / statistics.median(p):.2f}")
PY
