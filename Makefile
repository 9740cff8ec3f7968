# Cradle: the two commands are `make run` and `make test`; both install, configure and build first.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
CONFIG ?= configs/config_selftouch.yml
STEPS ?= 20000
EPISODES ?= 2

.PHONY: all deps configure build run test install format clean

all: build

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job: installation test, a random-policy baseline on CONFIG, then its evaluation.
run: build
	@$(BUILD_DIR)/cradle test-installation
	@$(BUILD_DIR)/cradle random --config $(CONFIG) --train_for $(STEPS)
	@$(BUILD_DIR)/cradle evaluate --config $(CONFIG) --episodes $(EPISODES)

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

install: build
	@cmake --install $(BUILD_DIR)

format:
	@find src tests bench -name '*.cc' -o -name '*.h' | xargs clang-format -i

clean:
	@rm -rf $(BUILD_DIR)
