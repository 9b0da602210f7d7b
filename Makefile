# Thin wrapper: each target installs missing Debian packages, configures, builds, then runs.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
# UNITY=ON compiles each library as one unit: faster for a build made once from a clean checkout
# (.ci/run sets it; test programs too: 518 s against 625 s per file on two cores), slower to
# rebuild after an edit.
UNITY ?= OFF

.PHONY: deps configure build demo test install bench gap-selftest asan-build asan asan-ci fuzz tsan \
        soak clean

deps:
	@scripts/install-deps

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=$(UNITY) $(CMAKE_FLAGS) \
	       >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	@scripts/run-demo $(BUILD)

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The program and the files it ships under PREFIX (bin/grainlink, share/grainlink/...).
PREFIX ?= /usr/local
install: build
	@cmake --install $(BUILD) --prefix $(PREFIX)

bench: build
	@bench/run-all $(BUILD)

# The full blind self-test of the sim-to-real diagnosis (docs/gap.md, "The self-test"): about
# 17-27 min on two cores from an empty cache; prints the score line and the confusion matrix.
gap-selftest: build
	OMP_WAIT_POLICY=PASSIVE $(BUILD)/apps/grainlink gap selftest --scale full --jobs 2

# Hardening (docs/hardening.md). One clang build with AddressSanitizer + UndefinedBehaviorSanitizer,
# for the portable instruction set (x86-64), holds the fuzz targets too: `make asan` runs the test
# suite in it (all but the tests that only repeat simulations: ASAN_SKIP), `make fuzz` a fuzzing
# campaign of FUZZ_SECONDS per target. `make tsan` runs the coupling's tests (the coordinator's
# threads) under ThreadSanitizer. The clang builds compile each library as one unit (CMake's unity
# build: the coupling's in half the time). `make asan-ci` is CI's cut of `make asan` (.ci/run;
# docs/hardening.md, "What CI runs"): without the test programs of lab, gap and study, whose
# physics runs take hours under AddressSanitizer, and without the implicit coupling's DEM run.
ASAN_BUILD ?= build-asan
TSAN_BUILD ?= build-tsan
FUZZ_SECONDS ?= 300
ASAN_SKIP ?= selftest|slurm|cli:mirror-half-model|cli:coupled-wheel-rests|cli:rover-on|cli:coupled-wheel-resumes
ASAN_TEST_PARTS ?=
# Left out of CI's cut too (docs/hardening.md, "What CI runs"): coupled runs of 40-60 s under
# AddressSanitizer whose code the shorter coupled runs also take (the rig, the soil node, the
# coordinator), and whose models' own code the mbs unit tests run under it; only their error
# paths and the whole-stack wiring are their own.
ASAN_CI_SKIP ?= cli:wheel-test-verdict|cli:mirror-wheel-off-the-plane|cli:coupling-fault-wall-clearance|cli:progress-reaches-every-node|cli:rig-starts-at-its-clearance|cli:mole-hammers-on-a-rigid-floor|cli:coupled-wheel-on-a-rigid-floor|cli:urdf-user-model-rolls-on-a-rigid-floor
CLANG_FLAGS = -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
              "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
              -DGRAINLINK_BUILD_BENCH=OFF -DCMAKE_UNITY_BUILD=ON

asan-build:
	@scripts/install-deps hardening
	@cmake -S . -B $(ASAN_BUILD) $(CLANG_FLAGS) -DGRAINLINK_SANITIZE=address -DGRAINLINK_FUZZ=ON \
	       -DGRAINLINK_ARCH=x86-64 \
	       $(if $(ASAN_TEST_PARTS),"-DGRAINLINK_TEST_PARTS=$(ASAN_TEST_PARTS)") >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS)

asan: asan-build
	@cd $(ASAN_BUILD) && ctest --output-on-failure -j $(JOBS) -E '$(ASAN_SKIP)'

asan-ci:
	@$(MAKE) --no-print-directory asan ASAN_BUILD=build-asan-ci \
	    "ASAN_TEST_PARTS=config;dem;coupling;mbs;apps;integration" \
	    "ASAN_SKIP=$(ASAN_SKIP)|cli:implicit-coupling-on-dem-soil|$(ASAN_CI_SKIP)"

fuzz: asan-build
	@fuzz/run-campaign $(ASAN_BUILD) $(FUZZ_SECONDS)

tsan:
	@scripts/install-deps hardening
	@cmake -S . -B $(TSAN_BUILD) $(CLANG_FLAGS) -DGRAINLINK_SANITIZE=thread >/dev/null
	@cmake --build $(TSAN_BUILD) -j $(JOBS) --target test_coupling
	@cd $(TSAN_BUILD) && TSAN_OPTIONS=suppressions=$(CURDIR)/cmake/tsan.supp \
	    ctest --output-on-failure -j $(JOBS) -R '^coupling:'

# The fault soak (docs/hardening.md): coupled runs with faults injected at random windows,
# each resumed and compared with an uninterrupted run; SOAK_MINUTES bounds it.
SOAK_MINUTES ?= 5
soak: build
	@OMP_WAIT_POLICY=PASSIVE /usr/bin/python3 tests/soak/soak.py $(BUILD)/apps/grainlink \
	    --minutes $(SOAK_MINUTES) --work $(BUILD)/soak

clean:
	rm -rf $(BUILD)
