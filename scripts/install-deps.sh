#!/usr/bin/env bash
# Installs every system package DynaVINS needs on Debian 12. The one place the dependency list lives.
# Idempotent: only asks apt for what is missing, so `make demo` / `make test` stay fast on a set-up machine.
set -euo pipefail

PACKAGES=(
  # build tools
  build-essential cmake ninja-build ccache pkg-config
  # maths, vision, optimisation
  libeigen3-dev libceres-dev libopencv-dev
  # lock-free bounded queues (moodycamel)
  libconcurrentqueue-dev libreaderwriterqueue-dev
  # logging, command line, tests
  libspdlog-dev libcli11-dev catch2
  # LCM: C/C++ library, lcm-gen/lcm-logger/lcm-spy, Java bindings for lcm-spy, a JDK for the types jar
  liblcm-dev liblcm-bin liblcm-java default-jdk-headless
  # lcm-spy's charts, and a headless X server (+ xwd) for the lcm-spy test and its screenshot
  libjchart2d-java xvfb x11-apps
  # gzip-compressed trajectory files
  zlib1g-dev
  # network namespace tools for udpm tests (unshare, ip)
  util-linux iproute2
  # ROS 1 bag import (rosbag_storage + message headers, no ROS master)
  librosbag-storage-dev libsensor-msgs-dev libnav-msgs-dev
  # naming and format checks (make lint, make format-check)
  clang-tidy clang-format
  # libFuzzer and the sanitizer runtimes for clang (make fuzz)
  clang libclang-rt-14-dev
  # benchmark report and figures (bench/report/make_report.py, run with /usr/bin/python3)
  python3 python3-matplotlib python3-numpy
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
