# Entry points of the README. Everything below builds with CMake into build/.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release
ifeq ($(CI),true)
CMAKE_FLAGS += -DCADMORPH_WERROR=ON
endif

.PHONY: all setup build demo test bench clean

all: build

setup:
	bash scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(BUILD)/cli/cadmorph demo -o $(BUILD)/demo

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -LE slow

bench: build
	sh benchmarks/run_all.sh $(BUILD)

clean:
	rm -rf $(BUILD)
