#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs graspfill's build and test dependencies from Debian 12 packages.
# Skips apt entirely when everything is already there.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libopen3d-dev libembree-dev
  liblcm-dev liblcm-bin libglib2.0-dev
  libopenni2-dev nlohmann-json3-dev zlib1g-dev
  libgtest-dev
  liburdfdom-dev libassimp-dev libyaml-cpp-dev  # URDF claws, DAE meshes, the rig config
  iproute2 util-linux  # ip and unshare: the cross-process udpm test
  liblcm-java default-jdk-headless  # the Java bindings and example (skipped without them)
  pybind11-dev python3-dev python3-numpy  # the Python module (skipped without pybind11)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "installing: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
