#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# CI's sanitizer step (issue 12), after scripts/test.sh. Two builds of their
# own, -O1 -g1 (RelWithDebInfo's flags overridden: line numbers in reports,
# less compile time than -O2), each building only the tests it runs:
#
#   build-asan (-DGRASPFILL_SANITIZE=address,undefined, leaks checked too):
#     the fast, meaningful part of the suite: io (messages, PLY, LCM log
#     reader, fuzz regressions, files), claw, core, fusion, evidence,
#     pipeline, repair (all but evidence_repair, the suite's slowest test at
#     70 s in Release, and incremental_repair, which fuses a grasp and
#     repairs it 10 times; the repairer and bounded-repair tests run the whole
#     repair), rt (log, publisher, prefetching source, CLI options, rig
#     config, module: grasp module, cloud repair, repair stage, sequencer,
#     live session with the recorder).
#     Not run: e2e (the CLI end to end: slow, and the same code as above),
#     synth, eval, refine, the install/package tests, the OpenNI2 driver
#     and the udpm scripts (other processes inside `unshare -n`).
#   build-tsan (-DGRASPFILL_SANITIZE=thread): the rt/ tests, the code with
#     threads of its own (repair stage, grasp module, prefetching source,
#     LCM bus subscriber, session recorder, live session, session loop), all
#     but rt_cli_options_test (option parsing, no threads).
#
# Tests run as in the suite (OMP_THREAD_LIMIT=1, memq://). Third-party
# findings are suppressed narrowly, each with its reason, in
# tests/sanitizers/tsan.supp (ASan, LSan and UBSan need none). TSAN_OPTIONS
# is set before the build too: gtest's test discovery runs each program.
# Prints ctest's counts and the wall time of each part; exits non-zero if
# a build or any test fails.
#
#   scripts/test_sanitizers.sh [asan|tsan|all]     (default all)
# Environment: GRASPFILL_BUILD_JOBS (default nproc).
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
case "$what" in asan|tsan|all) ;; *) echo "usage: scripts/test_sanitizers.sh [asan|tsan|all]" >&2; exit 2 ;; esac
jobs="${GRASPFILL_BUILD_JOBS:-$(nproc)}"
supp="$PWD/tests/sanitizers"

asan_tests="
  io_messages_test io_ply_test io_pcd_test io_atomic_file_test io_output_path_test io_lcm_log_reader_test
  io_fuzz_regressions_test io_cloud_chunks_test io_collision_mesh_codec_test mesh_outward_decimation_test
  claw_model_test claw_mask_test claw_loader_test claw_validation_test urdf_claw_test mesh_file_test
  pose_interpolation_test raycaster_test bit_grid_test tsdf_fusion_test unit_integrator_test workspace_crop_test
  depth_edges_test
  closest_point_grid_test claw_registration_test pose_refiner_test synth_renderer_test
  visibility_record_test safe_bound_test seen_free_carve_test point_list_queries_test pipeline_test
  pipeline_allocations_test
  repair_neighbor_index_test repair_analysis_cloud_test repair_outlier_removal_test
  repair_boundary_detection_test repair_boundary_linking_test repair_virtual_frame_test
  repair_axis_refinement_test repair_boundary_classification_test repair_boundary_completion_test
  repair_claw_hole_repair_test repair_symmetry_repair_test repair_repairer_test
  repair_bounded_repair_test repair_geometry_plane_fit_test repair_geometry_gap_grid_test
  repair_geometry_polygon_2d_test repair_geometry_ransac_planes_test
  repair_revolution_fill_test repair_top_search_test repair_local_surfaces_test
  rt_lcm_log_test rt_lcm_publisher_test rt_prefetching_source_test rt_cli_options_test
  rt_config_test rt_grasp_module_test rt_cloud_repair_test rt_repair_stage_test
  rt_grasp_sequencer_test rt_live_session_test rt_sample_window_test rt_receive_buffer_test
  rt_cloud_pacer_test"
tsan_tests="
  rt_lcm_log_test rt_lcm_publisher_test rt_prefetching_source_test rt_cloud_pacer_test
  rt_config_test rt_grasp_module_test rt_cloud_repair_test rt_repair_stage_test
  rt_grasp_sequencer_test rt_live_session_test"

# run_sanitized NAME SANITIZERS TESTS: configure, build TESTS, run them.
run_sanitized() {
  local name="$1" sanitizers="$2" tests="$3" build="build-$1" start log regex
  start=$(date +%s)
  log="$build/ctest.log"
  mkdir -p "$build"
  echo "== $name ($sanitizers): $(echo $tests | wc -w) test programs"
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DGRASPFILL_SANITIZE="$sanitizers" > "$build/configure.log" 2>&1 ||
    { cat "$build/configure.log" >&2; return 1; }
  # shellcheck disable=SC2086
  cmake --build "$build" -j"$jobs" --target $tests > "$build/build.log" 2>&1 ||
    { tail -50 "$build/build.log" >&2; echo "$name: build FAILED (see $build/build.log)" >&2; return 1; }
  echo "$name: built in $(( $(date +%s) - start )) s"
  regex="^($(echo $tests | tr ' ' '|'))\\."
  local rc=0
  ctest --test-dir "$build" -R "$regex" --output-on-failure -j"$jobs" > "$log" 2>&1 || rc=$?
  # The failures with their output, then ctest's counts.
  if [ "$rc" -ne 0 ]; then
    sed -n '/The following tests FAILED/,$p' "$log"
    grep -B2 -A60 -E "ERROR: (Address|Leak|Thread)Sanitizer|WARNING: ThreadSanitizer|runtime error:" "$log" | head -200 || true
  fi
  grep -E "tests passed|Total Test time" "$log" || true
  echo "$name: $([ "$rc" -eq 0 ] && echo clean || echo FAILED) in $(( $(date +%s) - start )) s (log: $log)"
  return "$rc"
}

export OMP_THREAD_LIMIT=1
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$supp/tsan.supp"

status=0
total_start=$(date +%s)
if [ "$what" != tsan ]; then run_sanitized asan address,undefined "$asan_tests" || status=1; fi
if [ "$what" != asan ]; then run_sanitized tsan thread "$tsan_tests" || status=1; fi
echo "sanitizers: $([ "$status" -eq 0 ] && echo clean || echo FAILED) in $(( $(date +%s) - total_start )) s"
exit "$status"
