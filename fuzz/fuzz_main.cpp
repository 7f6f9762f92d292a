// A libFuzzer binary for the target WEDGE_FUZZ_TARGET names (fuzz/targets.h): `make fuzz`
// builds one per target as build-fuzz/fuzz/fuzz_<target>.
#include <cstdio>
#include <cstdlib>

#include "fuzz/targets.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    wedge::fuzz::initialize();
    // `wedge compare --json` prints its metrics; libFuzzer's own report goes to stderr.
    if (!std::freopen("/dev/null", "w", stdout)) std::abort();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const wedge::fuzz::Target* target = wedge::fuzz::target(WEDGE_FUZZ_TARGET);
    target->run(data, size);
    return 0;
}
