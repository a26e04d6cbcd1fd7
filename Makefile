# ghostfx: the two commands of the README.
#   make demo   install missing Debian packages, configure, build, run the default example
#   make test   install missing Debian packages, configure, build, run the test suite (ctest)
# Other targets: build, bench, test-double, test-sanitize, format, clean.
#
# Variables: BUILD_DIR (default build), JOBS (default: number of cores), CMAKE_ARGS (extra -D...).

BUILD_DIR  ?= build
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=
GENERATOR  := $(shell command -v ninja >/dev/null 2>&1 && echo Ninja || echo "Unix Makefiles")
CTEST_ARGS ?=

.PHONY: all deps configure build demo test bench test-double test-sanitize format clean

all: build

deps:
	@./scripts/install-deps.sh

# Re-running cmake is cheap and keeps the cache in step with CMAKE_ARGS.
configure: deps
	@cmake -S . -B $(BUILD_DIR) -G "$(GENERATOR)" $(CMAKE_ARGS) > $(BUILD_DIR).configure.log 2>&1 \
	    || (cat $(BUILD_DIR).configure.log; exit 1)
	@grep -E "^-- ghostfx" $(BUILD_DIR).configure.log || true

build: configure
	@cmake --build $(BUILD_DIR) --parallel $(JOBS)

# The demo needs only the command-line program, not the tests and benchmarks.
demo: configure
	@cmake --build $(BUILD_DIR) --parallel $(JOBS) --target ghostfx
	@./scripts/demo.sh $(BUILD_DIR)

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure --parallel $(JOBS) $(CTEST_ARGS)

bench: build
	@./scripts/run-bench.sh $(BUILD_DIR)

# The double-precision build must pass the same tests (DESIGN.md, "Math").
test-double:
	@$(MAKE) --no-print-directory test BUILD_DIR=build-double \
	    CMAKE_ARGS="-DGHOSTFX_DOUBLE=ON -DGHOSTFX_BUILD_BENCH=OFF $(CMAKE_ARGS)"

# AddressSanitizer + UndefinedBehaviorSanitizer, debug-ish optimisation.
test-sanitize:
	@$(MAKE) --no-print-directory test BUILD_DIR=build-asan \
	    CMAKE_ARGS="-DGHOSTFX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGHOSTFX_BUILD_BENCH=OFF $(CMAKE_ARGS)"

# The house style (.clang-format, from STYLE.md) over every tracked C++ file.
format:
	@git ls-files '*.h' '*.cc' | xargs clang-format -i

clean:
	rm -rf build build-double build-asan build*.configure.log
