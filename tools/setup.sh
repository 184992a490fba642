#!/usr/bin/env bash
# Installs every build, test and run-time dependency of fahr from Debian
# packages. Idempotent: packages already present are skipped and the script
# says what it installs. Runs as root, or through sudo when not root.
set -euo pipefail

# One line per role, so it is clear why each package is here.
packages=(
  # toolchain
  g++ cmake ninja-build ccache pkg-config git
  # DDS: both vendors, their IDL compilers and tools
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  cyclonedds-dev cyclonedds-tools libcycloneddsidl0
  # numerics and geometry
  libeigen3-dev libsuitesparse-dev libblas-dev liblapack-dev libopenblas0-pthread libbullet-dev libassimp-dev
  # configuration, command lines, tests and benchmarks
  libyaml-cpp-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  # fuzzing (libFuzzer ships with clang's runtime) and sanitizers
  clang libclang-rt-14-dev
  # style checks (tools/lint.sh): Debian's clang-format and clang-tidy 14
  clang-format clang-tidy
  # network namespaces for multi-process tests; the lab test drops multicast
  # with nftables and checks the systemd units (systemd-analyze); the .deb
  # is listed with dpkg-deb (dpkg)
  iproute2 nftables systemd dpkg
  # MCAP recordings: chunk compression (zstd, lz4) and CRC-32 (zlib)
  libzstd-dev liblz4-dev zlib1g-dev
  # the recorder's HTML report is checked by rendering it headless; the
  # visualizer's page is tested in it (playwright-core drives Debian's build)
  chromium
  # the visualizer's HTTP + WebSocket server (Boost.Beast) and its JSON
  libboost-dev nlohmann-json3-dev
)
# The recorder tests read recordings back with Foxglove's npm packages:
# Debian's node and npm, unless a node is already installed (another
# distribution of node ships its own npm, which Debian's npm conflicts with).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "setup: not root and no sudo; install as root: apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi

echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq || echo "setup: apt-get update failed; trying the cached package lists" >&2
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"
