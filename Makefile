# wedge: the two quick-start commands are `make demo` and `make test`.
# Both install missing Debian packages first (scripts/install-deps.sh), then build in Release.

BUILD ?= build
JOBS  ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build demo test test-sanitize fuzz fuzz-smoke bench clean

all: build

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	@mkdir -p out
	$(BUILD)/wedge render cornell --method maaf -o out/demo.exr -o out/demo.png --stats out/demo-stats.json

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The whole suite under ASan + UBSan (clang; the first finding aborts its test, leaks included).
SANITIZE_BUILD ?= build-sanitize
export ASAN_OPTIONS ?= detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS ?= print_stacktrace=1
test-sanitize: deps
	@cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
	  -DWEDGE_SANITIZE=ON $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	@cd $(SANITIZE_BUILD) && ctest --output-on-failure -j $(JOBS) -E '$(SANITIZE_SKIP)'

# Statistical quality tests of whole renders that take 20-110 s each under the sanitizers (9 min
# of the suite's CPU time on 2 cores): the code they run is run, sanitized, by smaller tests
# (docs/reliability.md, "Timings"). `make test-sanitize SANITIZE_SKIP=NONE` runs them too.
SANITIZE_SKIP ?= ^(AafQuality\.(GridsBeatsMonteCarloAtItsAverageSpp|SphereLightPenumbraIsNotOverBlurred|LightsOfTwoSizesStayFiltered|TessellatedLampIsFilteredAsOneLight|PenumbraIsNotOverBlurred|TriangleLightPenumbraIsNotOverBlurred)|MaafQuality\.(TakesAafsSamplesNotOnlyThePapersFocalPlaneOnes|AllEffectsBeatsMonteCarloAtItsAverageSpp|NotWorseThanAafFilterAtEqualSamples|NarrowPenumbraBeatsAafAtItsOwnRates|NarrowPenumbraBeatsAafAtEqualSamples))$$

# libFuzzer targets (fuzz/targets.h, docs/reliability.md): build-fuzz/fuzz/fuzz_<target>.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 20
fuzz: deps
	@cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
	  -DWEDGE_FUZZ=ON $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_targets

# CI's short pass: each target for FUZZ_SECONDS.
fuzz-smoke: fuzz
	@bench/fuzz.sh $(FUZZ_SECONDS)

bench: build
	$(BUILD)/bench/wedge_bench --benchmark_counters_tabular=true
	WEDGE_EXTRAS=1 scripts/install-deps.sh && bench/pathtracer_peer.sh $(BUILD)

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD) $(FUZZ_BUILD) out
