#!/usr/bin/env python3
"""Checks that the loops whose speed rests on the compiler vectorising them still are vectorised
in a Release binary: the layered reconstruction's rays (filter/layers.cpp, traceBlurredRays, and a
moving layer's window, traceWindowed) and
the sampler's camera rays, light samples and bounce directions (render/camera.cpp,
render/path_sampler.cpp). A change that turns one of them scalar keeps every image and test as
it was and only costs time, which no test asserts: this looks at the code instead.

Each function must hold packed single-precision arithmetic on the CPU's full vector registers
(ymm or zmm where the CPU has AVX2, as a -march=native build there uses them): a loop the
vectoriser gave up on holds scalar (ss) arithmetic, and at most a few 4-wide xmm operations of
the straight-line vectoriser. Usage: check_vectorised.py BINARY. Exit 0 when every function is
found and vectorised, 1 otherwise (naming each one), 2 when the tools are missing.
"""
import re
import shutil
import subprocess
import sys

# (what the function is, a pattern of its demangled name, how many instances, what must appear in it)
PACKED = r"\bv?(add|sub|mul|div|sqrt|min|max)ps\b|\bvfn?m(add|sub)\d+ps\b"
CHECKS = [
    # (Not the two instances along a large turn's arcs, kArc: GCC does not vectorise them, a
    # known lead in filter/layers.cpp; they run only where a layer turns that far.)
    ("the layered reconstruction's rays", r"traceBlurredRays<[^>]*, false>", 8, PACKED),
    # A moving layer's window: which rays can read a covered cell.
    ("a moving layer's window", r"traceWindowed<(true|false), (true|false)>\(", 4, PACKED),
    ("the camera rays of a batch", r"Camera::generate\(int,", 1, PACKED),
    ("the light samples of a batch", r"samplePlanarLights\(", 1, PACKED),
    # traceMany's own arithmetic is scalar but for the bounce directions' loop (bounceDirections,
    # inlined): its packed square root is that loop's.
    ("the bounce directions of a wave", r"PathSampler::traceMany\(.*\) const$", 1, r"\bv?sqrtps\b"),
]


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    binary = sys.argv[1]
    for tool in ("nm", "objdump"):
        if not shutil.which(tool):
            print(f"check_vectorised: {tool} not found (binutils)")
            return 2
    with open("/proc/cpuinfo") as f:
        wide = " avx2 " in f.read().replace("\n", " ")
    registers = r"%[yz]mm" if wide else r"%xmm"
    nm = subprocess.run(["nm", "-S", "-C", binary], capture_output=True, text=True, check=True).stdout
    symbols = []
    for line in nm.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2] in ("t", "T"):
            symbols.append((int(parts[0], 16), int(parts[1], 16), parts[3]))
    failed = 0
    for what, pattern, count, required in CHECKS:
        found = {name: (address, size) for address, size, name in symbols
                 if re.search(pattern, name) and not name.endswith("[clone .localalias]")}
        if len(found) != count:
            print(f"FAIL {what}: {len(found)} functions match {pattern!r}, expected {count} (renamed or inlined?)")
            failed += 1
        instruction = re.compile(f"({required}).*{registers}")
        for name, (address, size) in sorted(found.items()):
            code = subprocess.run(["objdump", "-d", "--no-show-raw-insn", f"--start-address={address}",
                                   f"--stop-address={address + size}", binary],
                                  capture_output=True, text=True, check=True).stdout
            n = sum(1 for line in code.splitlines() if instruction.search(line))
            status = "ok  " if n > 0 else "FAIL"
            failed += n == 0
            print(f"{status} {what}: {n} packed instructions on {registers[1:]} in {name[:110]}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
