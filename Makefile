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

# The main job on the built-in default. Until the simulator and `run` land, this is the most
# complete thing there is: the stage-thread framework under a synthetic sensor stream, both
# back-pressure policies, with its stats written as summary.json and an LCM log.
demo: build
	$(BUILD)/bin/dynavins info
	$(BUILD)/bin/dynavins pipeline-check --frames 400 --out $(BUILD)/demo/lossless
	$(BUILD)/bin/dynavins pipeline-check --frames 200 --rate 1 --work-ms 80 --out $(BUILD)/demo/realtime
	$(BUILD)/bin/dynavins log-info $(BUILD)/demo/realtime/pipeline_stats.lcmlog

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
