#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs what is missing, builds, and replays the bundled default recording:
# writes the object cloud (PLY), publishes it over LCM (LCM's default URL, or
# LCM_DEFAULT_URL), and prints a summary with timings and accuracy.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh graspfill   # the CLI alone: the tests are built by scripts/test.sh
build/bin/graspfill demo "$@"
