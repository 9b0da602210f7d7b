# Thin wrapper: each target installs missing Debian packages, configures, builds, then runs.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: deps configure build demo test bench gap-selftest clean

deps:
	@scripts/install-deps

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	@scripts/run-demo $(BUILD)

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	@bench/run-all $(BUILD)

# The full blind self-test of the sim-to-real diagnosis (docs/gap.md, "The self-test"): hours on
# two cores; prints the score line and the confusion matrix.
gap-selftest: build
	OMP_WAIT_POLICY=PASSIVE $(BUILD)/apps/grainlink gap selftest --scale full --jobs 2

clean:
	rm -rf $(BUILD)
