# NavCam convenience targets. The real build is CMake; this file only chains
# "install what is missing" -> configure -> build -> run.
BUILD   ?= build
TESTBUILD ?= build-test
JOBS    ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps build demo test bench docs clean

all: build

deps:
	@scripts/install-deps.sh

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j $(JOBS)

# The main job on the built-in default scene: no data, no hardware.
demo: build
	scripts/demo.sh $(BUILD)/navcam out

# From scratch: a fresh build tree, warnings as errors, every ctest test; then
# the same tests again under AddressSanitizer and UndefinedBehaviorSanitizer.
test:
	@scripts/install-deps.sh --test
	rm -rf $(TESTBUILD) $(TESTBUILD)-asan
	cmake -S . -B $(TESTBUILD) -DCMAKE_BUILD_TYPE=Release -DNAVCAM_WERROR=ON $(CMAKE_FLAGS)
	cmake --build $(TESTBUILD) -j $(JOBS)
	cmake -S . -B $(TESTBUILD)-asan -DCMAKE_BUILD_TYPE=Asan -DNAVCAM_WERROR=ON -DNAVCAM_BUILD_BENCH=OFF $(CMAKE_FLAGS)
	cmake --build $(TESTBUILD)-asan -j $(JOBS)
	cd $(TESTBUILD)-asan && UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ctest --output-on-failure -j $(JOBS) --timeout 900 -LE vm
	cd $(TESTBUILD) && ctest --output-on-failure -j $(JOBS) --timeout 600

bench: build
	@scripts/install-deps.sh --stars
	bench/startup.sh $(BUILD)
	$(BUILD)/bench_render
	$(BUILD)/bench_render --subdivisions 7 --spp 4
	$(BUILD)/bench_lod
	$(BUILD)/bench_stars
	$(BUILD)/bench_rubble
	$(BUILD)/bench_brdf
	$(BUILD)/bench_sensor
	$(BUILD)/bench_latency
	$(BUILD)/bench_gige
	bench/freerun.sh $(BUILD)
	@if command -v qemu-system-x86_64 >/dev/null && [ -x $(BUILD)/tests/v4l2_capture ]; then \
	  bench/bench_edge_to_frame.sh $(BUILD); \
	else echo "bench_edge_to_frame: needs the qemu guest of tests/vm (scripts/install-deps.sh --test)"; fi
	@if command -v slurmctld >/dev/null; then bench/batch_scaling.sh $(BUILD); \
	else echo "batch_scaling: needs Slurm and munge (scripts/install-deps.sh --test)"; fi

# Generated documentation: the drivers' option tables (tests/app/test_cli.sh
# checks that docs/drivers.md matches).
docs: build
	$(BUILD)/navcam serve --driver-docs > docs/drivers.md

clean:
	rm -rf $(BUILD) $(TESTBUILD) $(TESTBUILD)-asan out
