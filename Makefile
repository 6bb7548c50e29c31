# Thin wrapper over CMake so that a fresh Debian 12 machine needs one command per job.
# Every target installs missing system packages first (scripts/install-deps.sh; sudo when not root).

BUILD      ?= build
TSAN_BUILD ?= build-tsan
CMAKE_GEN  := -G Ninja
CTEST_J    ?= 2

.PHONY: all deps build demo test test-unit test-tsan clean

all: build

deps:
	@./scripts/install-deps.sh

build: deps
	cmake -S . -B $(BUILD) $(CMAKE_GEN) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD)

# The main job on the built-in default. Until the estimator lands (`run`), this is the most complete
# thing there is: the `high` dynamic scene generated once (cached in bench/cache/high: stereo LCM
# log, ground truth, preview images), replayed through the pipeline's queues at full speed, and the
# stage-thread framework paced in real time with a tracker too slow to keep up (drops counted).
demo: build
	$(BUILD)/bin/dynavins info
	./scripts/cached-sim.sh high
	$(BUILD)/bin/dynavins log-info bench/cache/high/sensors.lcmlog
	$(BUILD)/bin/dynavins replay --log bench/cache/high/sensors.lcmlog --rate 0
	$(BUILD)/bin/dynavins pipeline-check --frames 200 --rate 1 --work-ms 80 --out $(BUILD)/demo/realtime
	@echo "demo: the high scene's busiest stereo frame is bench/cache/high/preview.png (moving pixels: preview_labels.png)"

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(CTEST_J)
	$(MAKE) --no-print-directory test-tsan

test-unit: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(CTEST_J)

# The whole suite under ThreadSanitizer (separate build tree; -O1 -g).
test-tsan: deps
	cmake -S . -B $(TSAN_BUILD) $(CMAKE_GEN) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNAVINS_TSAN=ON
	cmake --build $(TSAN_BUILD)
	TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$(CURDIR)/tests/tsan.supp" \
	  ctest --test-dir $(TSAN_BUILD) --output-on-failure -j $(CTEST_J) -LE heavy

clean:
	rm -rf $(BUILD) $(TSAN_BUILD)
