#!/usr/bin/env bash
# bench/fuzz.sh SECONDS [TARGET...]: runs each libFuzzer target of `make fuzz` for SECONDS
# (all of fuzz/targets.cpp's by default) and prints the executions per target. Each starts from
# its seeds (fuzz/corpus/<target>/) and the findings kept so far (fuzz/regressions/<target>/) in a
# working corpus under build-fuzz/corpus/, never in the repository. A crash, a sanitizer report,
# a leak, a hang of 10 s or more than 2.5 GB of memory is a finding: the input lands in
# build-fuzz/findings/<target>/ (add it to fuzz/regressions/<target>/, then fix it), and the
# script exits 1 after the last target.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:?usage: bench/fuzz.sh SECONDS [TARGET...]}
shift
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] && targets=(scene obj png jpeg exr pfm compare)
build=${FUZZ_BUILD:-build-fuzz}
# The targets write each input's files to a scratch folder (fuzz/targets.h): memory, not disk.
[[ -d /dev/shm && -w /dev/shm ]] && export TMPDIR=${TMPDIR:-/dev/shm}

found=0
# Findings of this run only: those of earlier runs stay in build-fuzz/findings/ until they are
# moved to fuzz/regressions/, and counting them made every later run fail.
stamp=$(mktemp)
trap 'rm -f "$stamp"' EXIT
printf '%-8s %8s %12s %10s %9s\n' target seconds executions 'exec/s' findings
for t in "${targets[@]}"; do
  bin=$build/fuzz/fuzz_$t
  [[ -x $bin ]] || { echo "fuzz.sh: $bin is missing; run 'make fuzz'" >&2; exit 2; }
  corpus=$build/corpus/$t findings=$build/findings/$t log=$build/fuzz-$t.log
  mkdir -p "$corpus" "$findings"
  cp -n fuzz/corpus/"$t"/* "$corpus"/ 2>/dev/null || true
  [[ -d fuzz/regressions/$t ]] && cp -n fuzz/regressions/"$t"/* "$corpus"/ 2>/dev/null || true
  dict=()
  [[ -f fuzz/$t.dict ]] && dict=(-dict=fuzz/"$t".dict)
  rc=0
  "$bin" "$corpus" "${dict[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2560 \
    -artifact_prefix="$findings"/ -print_final_stats=1 >"$log" 2>&1 || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  n=$(find "$findings" -type f -newer "$stamp" | wc -l)
  [[ $rc -ne 0 || $n -gt 0 ]] && found=1
  printf '%-8s %8s %12s %10s %9s\n' "$t" "$seconds" "${execs:-0}" "$(( ${execs:-0} / seconds ))" "$n"
done
if [[ $found -ne 0 ]]; then
  echo "fuzz.sh: findings in $build/findings/ (logs: $build/fuzz-<target>.log)" >&2
  exit 1
fi
