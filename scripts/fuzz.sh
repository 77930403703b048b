#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds graspfill's libFuzzer targets (clang, ASan + UBSan, tests/fuzz) and
# runs each for SECONDS (default 60) on its seed corpus
# (tests/fuzz/corpus/<target>/ and the crashes found so far,
# tests/fuzz/regressions/<target>/, read only; new inputs go to a scratch
# corpus in the build folder). Exits non-zero on any finding (crash, leak,
# sanitizer report, timeout, out of memory); the input is left in
# BUILD/fuzz/findings/<target>/ and its name is printed.
#
#   scripts/fuzz.sh [SECONDS]
# Environment: GRASPFILL_FUZZ_BUILD (build folder, default build/fuzz),
# GRASPFILL_FUZZ_JOBS (targets run at once, default 2),
# GRASPFILL_FUZZ_TARGETS (space-separated subset; default all).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -lt 1 ]; then
  echo "usage: scripts/fuzz.sh [SECONDS]   (SECONDS a whole number >= 1, default 60)" >&2
  exit 2
fi
build="${GRASPFILL_FUZZ_BUILD:-build/fuzz}"
jobs="${GRASPFILL_FUZZ_JOBS:-2}"
all_targets="fuzz_lcm_log_reader fuzz_depth_image fuzz_gripper_state fuzz_object_cloud
  fuzz_session_description fuzz_module_status fuzz_collision_mesh fuzz_ply_reader fuzz_cloud_chunks
  fuzz_claw fuzz_repair fuzz_live_bus"
targets="${GRASPFILL_FUZZ_TARGETS:-$all_targets}"

command -v clang++ > /dev/null || { echo "scripts/fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 1; }
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DGRASPFILL_FUZZ=ON -DBUILD_TESTING=OFF -DGRASPFILL_BUILD_CLI=OFF \
  -DGRASPFILL_INSTALL=OFF -DGRASPFILL_WITH_OPENNI2=OFF "${launcher[@]}" > "$build.configure.log" 2>&1 ||
  { cat "$build.configure.log" >&2; exit 1; }
# shellcheck disable=SC2086
cmake --build "$build" -j"${GRASPFILL_BUILD_JOBS:-$(nproc)}" --target $targets

# Open3D's OpenMP and LCM are not what is fuzzed: one thread, and leaks in
# libraries' one-time initialisation are not findings of ours.
export OMP_THREAD_LIMIT=1
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
run_one() {
  local target="$1" seconds="$2" build="$3"
  local corpus="tests/fuzz/corpus/${target#fuzz_}" scratch="$build/fuzz/corpus/$target"
  local regressions="tests/fuzz/regressions/${target#fuzz_}"
  [ -d "$regressions" ] || regressions=""
  local findings="$build/fuzz/findings/$target" log="$build/fuzz/$target.log"
  mkdir -p "$scratch" "$findings"
  rm -f "$findings"/*
  # -rss_limit_mb: an input may not make a target use more than 2 GB;
  # -timeout: nor take more than 10 s.
  if "$build/fuzz/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
       -max_len=65536 -print_final_stats=1 -artifact_prefix="$findings/" \
       "$scratch" "$corpus" $regressions > "$log" 2>&1; then
    local execs
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "$target: ok, $execs executions in ${seconds} s"
  else
    echo "$target: FINDING, see $log and $(ls "$findings" | head -1)"
    tail -30 "$log"
    return 1
  fi
}
export -f run_one
# shellcheck disable=SC2086
printf '%s\n' $targets | xargs -P "$jobs" -I{} bash -c 'run_one "$@"' _ {} "$seconds" "$build"
