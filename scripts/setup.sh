#!/usr/bin/env bash
# Installs every Debian package romo needs. Idempotent: packages already present are skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git clang libclang-rt-14-dev
  libopencv-dev libpcl-dev liblcm-dev liblcm-bin liblcm-java
  libaravis-dev aravis-tools
  libgeographiclib-dev libeigen3-dev libfreenect-dev libfreenect-bin
  libgtest-dev libgmock-dev libbenchmark-dev libyaml-cpp-dev libcli11-dev libspdlog-dev
  liboctomap-dev iproute2 default-jdk-headless
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${#missing[@]} package(s): ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
"${sudo_cmd[@]}" apt-get update -qq || echo "setup: apt-get update failed; trying with the cached package lists" >&2
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
