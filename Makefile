# Cradle: the two commands are `make run` and `make test`; both install, configure and build first.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
CONFIG ?= configs/config_selftouch.yml
STEPS ?= 500000
ENVS ?= 2
EPISODES ?= 2
INTRINSIC ?= body_part_novelty
RESULTS ?= results/make_run
# `make test SANITIZE=1`: AddressSanitizer + UndefinedBehaviorSanitizer build of the C++ suite in
# build-asan (-O1 -g1, no Python module: the interpreter is not instrumented), built and run at
# nice 15; leaks are reported except the third-party ones in scripts/lsan.supp (docs/reliability.md).
SANITIZE ?= 0
NICE :=
ifeq ($(SANITIZE),1)
BUILD_DIR := build-asan
BUILD_TYPE := RelWithDebInfo
NICE := nice -n 15
# GCC 12 reports -Wmaybe-uninitialized false positives in libstdc++'s <regex> and LibTorch's
# optionals under -fsanitize at -O1; the release build keeps the warning (an error there).
SAN := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
SAN_WARN := -Wno-maybe-uninitialized
CMAKE_EXTRA := -DCMAKE_CXX_FLAGS="$(SAN) $(SAN_WARN)" -DCMAKE_C_FLAGS="$(SAN)" \
  -DCMAKE_EXE_LINKER_FLAGS="$(SAN)" -DCMAKE_SHARED_LINKER_FLAGS="$(SAN)" -DCRADLE_PYTHON=OFF \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
export ASAN_OPTIONS ?= detect_leaks=1:abort_on_error=1
export LSAN_OPTIONS ?= suppressions=$(CURDIR)/scripts/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS ?= print_stacktrace=1:halt_on_error=1
endif

.PHONY: all deps configure build run test bench install install-python format clean

all: build

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_EXTRA) >/dev/null

build: configure
	@$(NICE) cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job: installation test, then PPO with intrinsic motivation on CONFIG for STEPS env
# steps, its evaluation (scores, videos, plots) next to the random policy's on the same seeds.
run: build
	@$(BUILD_DIR)/cradle test-installation --save-dir $(RESULTS)/test_installation
	@$(BUILD_DIR)/cradle train --config $(CONFIG) --save-dir $(RESULTS)/trained --algo ppo \
	  --intrinsic $(INTRINSIC) --steps $(STEPS) --envs $(ENVS) --eval-episodes $(EPISODES) \
	  --compare-random

# The tests are built here, and the benchmarks (each binary runs once as a test, so they cannot
# rot unseen): `make build` and `make run` compile neither. In stages, each stage's tests running
# as soon as its binaries are built (scripts/test-in-stages.sh): the first results come in seconds.
test: build
	@scripts/test-in-stages.sh $(BUILD_DIR) $(JOBS) $(NICE)

# Google Benchmark targets (build/cradle_bench, build/teach_bench); `cradle bench` is the CLI's.
bench: build
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target cradle_benches

# `make install CMAKE_INSTALL_PREFIX=DIR`: the CLI into DIR/bin and its data files into
# DIR/share/cradle (default: the prefix the build was configured with, /usr/local).
install: build
	@cmake --install $(BUILD_DIR) $(if $(CMAKE_INSTALL_PREFIX),--prefix $(CMAKE_INSTALL_PREFIX))

# The Python package `cradle` (with its data files and the CLI in cradle/bin) into Debian python3's
# user site-packages (override PYTHON_PREFIX to install elsewhere, then put that folder on
# PYTHONPATH). Into a venv with the `cradle` command: pip install --no-build-isolation .
PYTHON ?= /usr/bin/python3
PYTHON_PREFIX ?= $(shell $(PYTHON) -c 'import site; print(site.getusersitepackages())')
install-python: build
	@cmake --install $(BUILD_DIR) --component python --prefix $(PYTHON_PREFIX)
	@echo "installed: $(PYTHON_PREFIX)/cradle (try: $(PYTHON) -c 'import cradle')"

format:
	@find src tests bench -name '*.cc' -o -name '*.h' | xargs clang-format -i

clean:
	@rm -rf $(BUILD_DIR)
