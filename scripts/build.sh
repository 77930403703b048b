#!/usr/bin/env bash
# Configures and builds graspfill (Release) into build/; the CLI lands in build/bin/graspfill.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
