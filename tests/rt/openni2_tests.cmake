# SPDX-License-Identifier: BSD-3-Clause
# OpenNI2 for real without a camera: libGraspfillReplay through Debian's
# libOpenNI2 (included from tests/rt/CMakeLists.txt when OpenNI2 is found).
graspfill_test(rt_openni2_replay_driver_test openni2_replay_driver_test.cc
  DEPS graspfill_rt_sources PkgConfig::OPENNI2)
graspfill_use_openni2_runtime(rt_openni2_replay_driver_test)
target_include_directories(rt_openni2_replay_driver_test PRIVATE ${PROJECT_SOURCE_DIR}/rt)

# graspfill live through OpenNI2 end to end (openni2_replay_session.sh):
# the replay device gives replay's cloud, an .oni recorded from it too,
# video modes and intrinsics overrides do what they say.
add_test(NAME rt_openni2_replay_session
  COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/openni2_replay_session.sh
    $<TARGET_FILE:graspfill> $<TARGET_FILE:cloud_compare>)
set_tests_properties(rt_openni2_replay_session PROPERTIES TIMEOUT 120
  ENVIRONMENT "OMP_THREAD_LIMIT=1")

graspfill_test(rt_openni2_camera_source_test openni2_camera_source_test.cc
  DEPS graspfill_rt_sources)
graspfill_use_openni2_runtime(rt_openni2_camera_source_test)
