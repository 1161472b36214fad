# Entry points of the README. Everything below builds with CMake into build/.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release
ifeq ($(CI),true)
CMAKE_FLAGS += -DCADMORPH_WERROR=ON
endif

.PHONY: all setup build demo test test-all bench clean check-asan fuzz fuzz-run

all: build

setup:
	bash scripts/setup.sh

# benchmarks off here even where `make bench` turned them on in the same build directory
build: setup
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS) -DCADMORPH_BUILD_BENCHMARKS=OFF
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(BUILD)/cli/cadmorph demo -o $(BUILD)/demo

# every label but slow (tests over ~20 s); test-all runs them too
test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -LE slow

test-all: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

# the benchmarks are built on request only: the same build directory, configured with them
# (benchmarks/README.md)
bench: setup
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS) -DCADMORPH_BUILD_BENCHMARKS=ON
	cmake --build $(BUILD) -j $(JOBS)
	sh benchmarks/run_all.sh $(BUILD)

# Unit and CLI tests with AddressSanitizer and UBSan in $(BUILD)-asan. LSan skips
# OpenCASCADE's one-time statics (tests/lsan.supp); OpenCASCADE is built without frame
# pointers, so only the slow unwinder sees far enough up the stack to match them.
check-asan: setup
	cmake -S . -B $(BUILD)-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCADMORPH_SANITIZE=ON
	cmake --build $(BUILD)-asan -j $(JOBS)
	ASAN_OPTIONS=detect_leaks=1:fast_unwind_on_malloc=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	ctest --test-dir $(BUILD)-asan -L 'unit|cli' -LE slow --output-on-failure -j $(JOBS)

# libFuzzer drivers (clang) in $(BUILD)-fuzz, seed corpora in $(BUILD)-fuzz/corpus; run one with
# e.g. $(BUILD)-fuzz/tests/fuzz/fuzz_vtu $(BUILD)-fuzz/corpus/vtu -max_total_time=300
# (tests/fuzz/README.md). `make fuzz-run` runs every driver in turn for FUZZ_SECONDS each, one
# process at a time, and stops at the first finding (the reproducer is left in the current
# directory as crash-*, leak-*, timeout-* or oom-*).
FUZZ_SECONDS ?= 60
FUZZ_DRIVERS = msh vtu vtk medit fluent su2 nastran cgns inp exodus obj off stl foam foam_gz \
  dcsv prm ctrl nodes sens design list step_scan
fuzz: setup
	cmake -S . -B $(BUILD)-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCADMORPH_FUZZ=ON \
	  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++
	cmake --build $(BUILD)-fuzz -j $(JOBS) --target fuzz_drivers
	sh tests/fuzz/seeds.sh $(CURDIR) $(BUILD)-fuzz/corpus

fuzz-run: fuzz
	for d in $(FUZZ_DRIVERS); do \
	  $(BUILD)-fuzz/tests/fuzz/fuzz_$$d $(BUILD)-fuzz/corpus/$$d -max_total_time=$(FUZZ_SECONDS) \
	    -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 || exit 1; \
	done

clean:
	rm -rf $(BUILD) $(BUILD)-asan $(BUILD)-fuzz
