# The front door: `make demo` and `make test` (README.md). Everything else is CMake in build/.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
DEMO_OUT ?= demo-out

.PHONY: all deps configure build demo test bundle conformance clean

all: build

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	EGL_PLATFORM=surfaceless $(BUILD)/bin/splinewalk demo -o $(DEMO_OUT)

test: build
	cd $(BUILD) && EGL_PLATFORM=surfaceless ctest --output-on-failure -j $(JOBS) $(CTEST_FLAGS)

# One folder that runs on another x86-64 Linux with a GL/EGL driver (scripts/bundle, docs/bundle.md).
bundle: build
	scripts/bundle --full $(BUILD)

# The full conformance sweep (tests/conformance/run_conformance.sh; about two hours on 2 cores):
# every sample model, its IGES export and scaled copies, three views, against BRepMesh.
conformance: build
	EGL_PLATFORM=surfaceless LP_NUM_THREADS=2 tests/conformance/run_conformance.sh \
	  $(BUILD)/bin/test_images $(BUILD)/bin/scaled_iges /usr/share/opencascade/data \
	  $(BUILD)/conformance full

clean:
	rm -rf $(BUILD) $(DEMO_OUT) build-bundle
