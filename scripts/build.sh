#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Configures and builds graspfill (Release) into build/; the CLI lands in build/bin/graspfill.
#   scripts/build.sh            everything (the libraries, the CLI, the tests)
#   scripts/build.sh TARGET...  only those targets and what they need (the demo: graspfill)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build -j"$(nproc)" "${targets[@]}"
