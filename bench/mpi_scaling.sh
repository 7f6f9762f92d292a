#!/usr/bin/env bash
# Strong scaling of `wedge render` over MPI ranks against threads (docs/mpi.md): for each case,
# 1 rank x T threads against T ranks x 1 thread (and 1 x 1), alternating, REPEAT times each; the
# wall time of the whole command (scene loading, MPI start-up and the output included), each
# process's CPU seconds (user + system, /usr/bin/time: what a dedicated core would take), the
# render's own total, and the bytes rank 0 sent and received per frame. Not a test: timings on
# a shared machine move.
#   bench/mpi_scaling.sh [BUILD] [T] [REPEAT]
set -euo pipefail
build=${1:-build}
T=${2:-2}
repeat=${3:-2}
wedge="$build/wedge"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
mpirun_flags=(--oversubscribe --bind-to none --mca btl self,vader)
[[ $(id -u) -eq 0 ]] && mpirun_flags+=(--allow-run-as-root)

cases=(
  "cornell --method mc --spp 64 --layers off --resolution 512x512"
  "cornell --method mc --spp 16 --resolution 512x512"
  "cornell --method aaf --resolution 512x512"
  "cornell --method maaf --resolution 512x512"
  "cornell --method atrous --resolution 512x512"
  "sponza --method mc --spp 64 --layers off --resolution 360x360"
)

run() {  # label, ranks, then the command; prints wall and CPU seconds, the render's totals, bytes
  local label=$1 ranks=$2; shift 2
  local start end
  rm -f "$out"/cpu.*
  start=$(date +%s.%N)
  if [[ $ranks -eq 0 ]]; then
    /usr/bin/time -f "%U %S" -o "$out/cpu.0" "$@" --quiet --stats "$out/s.json" -o "$out/x.exr" >/dev/null
  else
    mpirun "${mpirun_flags[@]}" -n "$ranks" sh -c '/usr/bin/time -f "%U %S" -o "$0/cpu.$OMPI_COMM_WORLD_RANK" "$@"' \
      "$out" "$@" --quiet --stats "$out/s.json" -o "$out/x.exr" >/dev/null
  fi
  end=$(date +%s.%N)
  python3 - "$label" "$start" "$end" "$out" <<'PY'
import glob, json, sys
label, start, end, out = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
s = json.load(open(out + "/s.json"))
cpu = [sum(map(float, open(f).read().split()[-2:])) for f in sorted(glob.glob(out + "/cpu.*"))]
print(f"  {label:5s} wall {end - start:6.2f} s  cpu/process {' '.join(f'{c:6.2f}' for c in cpu)} s"
      f"  render total {s['seconds']['total']:6.2f} s  sampling {s['seconds'].get('sampling', 0):6.2f} s"
      f"  rays/rank {s['rays_per_rank']}  rank 0 sent+received {s.get('mpi_bytes_exchanged', 0) / 2**20:6.1f} MiB")
PY
}

for c in "${cases[@]}"; do
  read -r -a args <<<"$c"
  echo "$c"
  for ((i = 0; i < repeat; ++i)); do
    run "1x1" 0 "$wedge" render "${args[@]}" --threads 1
    run "1x$T" 0 "$wedge" render "${args[@]}" --threads "$T"
    run "${T}x1" "$T" "$wedge" render "${args[@]}" --threads 1
  done
done
