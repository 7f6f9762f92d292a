#!/usr/bin/env bash
# The layered reconstruction on and off (issue 27; docs/layers.md, "Measured"): every method at
# 16 spp with --layers off and on, on the five lens scenes at 512x512 and docs/motion.json at its
# own size, `rounds` rounds with off and on alternating, the faster `total` of each; relMSE
# overall and in `wedge compare --regions`' mixed class against 1024-spp MC references (rendered
# into refs-dir with --layers off --seed 77 where missing), and efficiency, 1 / (relMSE x
# seconds), on against off and against MC's default (on). With `net` as the fourth argument, a
# second reference per scene (--seed 78, refs-dir/NAME-2.exr) measures the first one's own noise
# (`wedge compare --reference-noise-from`), and the table gives relMSE net of it as well.
# Usage: bench/layers_onoff.sh [build-dir] [refs-dir] [rounds] [net]
set -euo pipefail
build=${1:-build}
refs=${2:-out/layers-refs}
rounds=${3:-2}
net=${4:-}
wedge="$build/wedge"
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$refs"

scenes=(cornell conference sponza bunny cornell-sphere "$here/docs/motion.json")
results="$work/results.txt"
for sc in "${scenes[@]}"; do
    name=$(basename "$sc" .json)
    res=(--resolution 512x512)
    [[ $sc == *.json ]] && res=()
    ref="$refs/$name.exr"
    if [[ ! -f $ref ]]; then
        echo "reference $ref (1024 spp)..." >&2
        "$wedge" render "$sc" --method mc --spp 1024 --layers off --seed 77 "${res[@]}" --quiet -o "$ref"
    fi
    noise=()
    if [[ $net == net ]]; then
        ref2="$refs/$name-2.exr"
        if [[ ! -f $ref2 ]]; then
            echo "second reference $ref2 (1024 spp)..." >&2
            "$wedge" render "$sc" --method mc --spp 1024 --layers off --seed 78 "${res[@]}" --quiet -o "$ref2"
        fi
        noise=(--reference-noise-from "$ref2")
    fi
    for m in mc aaf maaf atrous; do
        rm -f "$work"/t_*
        for ((r = 0; r < rounds; ++r)); do
            for L in off on; do
                "$wedge" render "$sc" --method $m --spp 16 --layers $L "${res[@]}" --quiet \
                    --stats "$work/s_$L.json" -o "$work/x_$L.exr"
                python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['seconds']['total'], d['seconds'].get('layers', 0))" \
                    "$work/s_$L.json" >>"$work/t_$L"
            done
        done
        for L in off on; do
            read -r total layers < <(sort -g "$work/t_$L" | head -1)
            out=$("$wedge" compare "$work/x_$L.exr" "$ref" --regions "${noise[@]}")
            rel=$(awk '/^relMSE/ {print $2}' <<<"$out")
            mixed=$(awk '/^mixed/ {print $2, $4}' <<<"$out")
            # Net of the reference's noise (the same as measured without `net`).
            relnet=$(awk '/^net relMSE/ {print $3}' <<<"$out")
            mixednet=$(awk '/^mixed/ {print ($6 == "" ? $4 : $6)}' <<<"$out")
            echo "$name $m $L $rel $mixed $total $layers ${relnet:-$rel} $mixednet" >>"$results"
        done
    done
done

python3 - "$results" "$net" <<'PY'
import sys
net = sys.argv[2] == "net"
rows = {}
for line in open(sys.argv[1]):
    name, m, L, rel, share, mixed, total, layers, relnet, mixednet = line.split()
    rows[(name, m, L)] = (float(rel), share, float(mixed), float(total), float(layers), float(relnet), float(mixednet))
extra = " net relMSE off → on | net mixed relMSE off → on | net efficiency on / off |" if net else ""
print("| scene | method | relMSE off → on | mixed pixels: share, relMSE off → on | seconds off → on (layers stage) "
      "| efficiency on / off | efficiency vs MC's default (on): off, on |" + extra)
print("|---|---|---|---|---|---|---|" + ("---|---|---|" if net else ""))
names = list(dict.fromkeys(k[0] for k in rows))
for name in names:
    mc = rows[(name, "mc", "on")]
    emc = 1 / (mc[0] * mc[3])
    for m in ("mc", "aaf", "maaf", "atrous"):
        a, b = rows[(name, m, "off")], rows[(name, m, "on")]
        ea, eb = 1 / (a[0] * a[3]), 1 / (b[0] * b[3])
        line = (f"| {name} | {m} | {a[0]:.3g} → {b[0]:.3g} ({a[0] / b[0]:.2f}x) | {b[1]}, {a[2]:.3g} → {b[2]:.3g} "
                f"({a[2] / b[2]:.2f}x) | {a[3]:.2f} → {b[3]:.2f} ({b[4]:.2f}) | {eb / ea:.2f}x | {ea / emc:.1f}x, {eb / emc:.1f}x |")
        if net:
            line += (f" {a[5]:.3g} → {b[5]:.3g} ({a[5] / b[5]:.2f}x) | {a[6]:.3g} → {b[6]:.3g} ({a[6] / b[6]:.2f}x) "
                     f"| {(a[5] * a[3]) / (b[5] * b[3]):.2f}x |")
        print(line)
PY
