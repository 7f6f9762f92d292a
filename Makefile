# wedge: the two quick-start commands are `make demo` and `make test`.
# Both install missing Debian packages first (scripts/install-deps.sh), then build in Release.

BUILD ?= build
JOBS  ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build demo test bench clean

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

bench: build
	$(BUILD)/bench/wedge_bench --benchmark_counters_tabular=true
	WEDGE_EXTRAS=1 scripts/install-deps.sh && bench/pathtracer_peer.sh $(BUILD)

clean:
	rm -rf $(BUILD) out
