# ghostfx: the two commands of the README.
#   make demo   install missing Debian packages, configure, build, run the default example
#   make test   install missing Debian packages, configure, build, run the test suite (ctest),
#               then the MPI tests in a GHOSTFX_MPI build (test-mpi; MPI_TESTS=0 skips them)
# Other targets: build, bench, test-double, test-sanitize, test-checked, test-mpi, format, clean.
#
# Variables: BUILD_DIR (default build), JOBS (default: number of cores), CMAKE_ARGS (extra -D...).

BUILD_DIR  ?= build
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=
GENERATOR  := $(shell command -v ninja >/dev/null 2>&1 && echo Ninja || echo "Unix Makefiles")
CTEST_ARGS ?=
MPI_TESTS  ?= 1

.PHONY: all deps configure build demo test bench test-double test-sanitize test-checked test-mpi format clean

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
ifneq ($(MPI_TESTS),0)
	@$(MAKE) --no-print-directory test-mpi
endif

bench: build
	@./scripts/run-bench.sh $(BUILD_DIR)

# The double-precision build must pass the same tests (DESIGN.md, "Math").
test-double:
	@$(MAKE) --no-print-directory test BUILD_DIR=build-double MPI_TESTS=0 \
	    CMAKE_ARGS="-DGHOSTFX_DOUBLE=ON -DGHOSTFX_BUILD_BENCH=OFF $(CMAKE_ARGS)"

# AddressSanitizer + UndefinedBehaviorSanitizer. -O1 -g1 (line tables, no variables) compiles a
# quarter faster than RelWithDebInfo's -O2 -g and keeps file:line in every report.
SANITIZE_ARGS := -DGHOSTFX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO='-O1 -g1 -DNDEBUG' -DGHOSTFX_BUILD_BENCH=OFF
test-sanitize:
	@$(MAKE) --no-print-directory test BUILD_DIR=build-asan MPI_TESTS=0 \
	    CMAKE_ARGS="$(SANITIZE_ARGS) $(CMAKE_ARGS)"

# CI's second pass: the suite with Real = double under the sanitizers, one build for both checks
# (test-double and test-sanitize each cost a full build; bench/RESULTS.md, "CI time").
test-checked:
	@$(MAKE) --no-print-directory test BUILD_DIR=build-checked MPI_TESTS=0 \
	    CMAKE_ARGS="-DGHOSTFX_DOUBLE=ON $(SANITIZE_ARGS) $(CMAKE_ARGS)"

# One simulation over MPI processes (docs/distributed.md): Open MPI, a build with GHOSTFX_MPI
# (the program and the MPI tests only), and the MPI tests under mpirun.
test-mpi:
	@./scripts/install-deps.sh --mpi
	@cmake -S . -B build-mpi -G "$(GENERATOR)" -DGHOSTFX_MPI=ON -DGHOSTFX_PYTHON=OFF \
	    -DGHOSTFX_BUILD_BENCH=OFF -DGHOSTFX_BUILD_EXAMPLES=OFF $(CMAKE_ARGS) \
	    > build-mpi.configure.log 2>&1 || (cat build-mpi.configure.log; exit 1)
	@cmake --build build-mpi --parallel $(JOBS) \
	    --target ghostfx ghostfx_mpi_tests ghostfx_compare_points ghostfx_sph_tests
	@cd build-mpi && ctest --output-on-failure -R "^mpi\\.|DomainDecomposition|ParticleSet" $(CTEST_ARGS)

# The house style (.clang-format, from STYLE.md) over every tracked C++ file.
format:
	@git ls-files '*.h' '*.cc' | xargs clang-format -i

clean:
	rm -rf build build-double build-asan build-mpi build*.configure.log
