#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# graspfill used as its users use it (tests/install/CMakeLists.txt registers
# one CTest test per step):
#   install        a fresh `cmake --install` into PREFIX; the package files,
#                  headers, libraries, CLI, data and planner bindings (Python, Java) are there and name no
#                  path of this source or build tree; nothing of the tools synth and eval is
#                  (headers, libraries, targets, graspfill.pc)
#   find_package   tests/install/downstream configured against PREFIX
#                  (find_package(graspfill)), built, and its grasp_loop run
#                  on the installed bundled recording
#   pkg_config     grasp_loop.cpp compiled with `pkg-config --cflags --libs
#                  graspfill` alone, and run
#   subdirectory   tests/install/downstream with add_subdirectory(graspfill),
#                  OpenNI2 off: targets, no tests, pose_check built and run
#   subdirectory_full  the same with grasp_loop (opt-in: minutes)
#   cli            the installed CLI copied elsewhere, its demo run from
#                  another directory (data found relative to the executable)
# usage: package_test.sh STEP SOURCE_DIR BUILD_DIR WORK_DIR CMAKE CXX CONFIG [PYTHON]
# (PYTHON: the interpreter the Python module was built for; default python3)
# WORK_DIR/prefix is the install prefix (made by `install`, used by the others).
set -u
STEP=$1
SRC=$2
BUILD=$3
WORK=$4
CMAKE=$5
CXX=$6
CONFIG=$7
PYTHON=${8:-python3}
PREFIX=$WORK/prefix
DOWNSTREAM=$SRC/tests/install/downstream
RECORDING=$PREFIX/share/graspfill/replay/default/recording.lcmlog
JOBS=${GRASPFILL_PACKAGE_TEST_JOBS:-2}

fail() {
  echo "FAIL: $*"
  exit 1
}
run() {
  echo "+ $*"
  "$@" || fail "$1 exited with $?"
}

case $STEP in
install)
  rm -rf "$PREFIX"
  run "$CMAKE" --install "$BUILD" --prefix "$PREFIX" --config "$CONFIG" >"$WORK/install.log" 2>&1 \
    || { cat "$WORK/install.log"; exit 1; }
  libdir=$(sed -n 's/^libdir=${prefix}\///p' "$BUILD/graspfill.pc")
  for f in \
      "$libdir/cmake/graspfill/graspfillConfig.cmake" \
      "$libdir/cmake/graspfill/graspfillConfigVersion.cmake" \
      "$libdir/cmake/graspfill/graspfillTargets.cmake" \
      "$libdir/pkgconfig/graspfill.pc" \
      "$libdir/libgraspfill_core.a" "$libdir/libgraspfill_pipeline.a" "$libdir/libgraspfill_repair.a" \
      "$libdir/libgraspfill_rt_sources.a" "$libdir/libgraspfill_rt_sinks.a" "$libdir/libgraspfill_rt_module.a" \
      include/graspfill/types.hpp include/graspfill/pipeline/pipeline.hpp \
      include/graspfill/repair/repairer.hpp \
      include/graspfill/object_cloud_t.hpp include/graspfill/depth_image_t.hpp \
      include/graspfill/rt/sources/lcm_log_source.hpp include/graspfill/rt/module/grasp_module.hpp \
      include/graspfill/rt/sinks/lcm_publisher.hpp \
      bin/graspfill \
      share/graspfill/replay/default/recording.lcmlog share/graspfill/replay/default/gt_cloud.ply \
      share/graspfill/claws/robotiq_3f.json; do
    [ -f "$PREFIX/$f" ] || fail "not installed: $f"
  done
  [ -L "$PREFIX/share/graspfill/replay" ] && fail "share/graspfill/replay is a link, not the data"
  # synth and eval are the CLI's and the tests' tools, not the package's: no
  # headers, libraries, exported targets or pkg-config entries of theirs, and
  # no installed header includes one of their headers.
  for tool in synth eval; do
    [ -e "$PREFIX/include/graspfill/$tool" ] && fail "installed: include/graspfill/$tool/ (a tool's headers)"
    [ -e "$PREFIX/$libdir/libgraspfill_$tool.a" ] && fail "installed: $libdir/libgraspfill_$tool.a (a tool)"
    grep -lE "graspfill::$tool([^_a-z]|\$)" "$PREFIX/$libdir/cmake/graspfill/"*.cmake \
      && fail "the package's CMake files (above) name graspfill::$tool"
    grep -qE -- "-lgraspfill_$tool( |\$)" "$PREFIX/$libdir/pkgconfig/graspfill.pc" \
      && fail "graspfill.pc links graspfill_$tool"
  done
  if grep -rlE '#include [<"]((graspfill/)?(synth|eval)/)' "$PREFIX/include"; then
    fail "installed headers (above) include a header of synth or eval"
  fi
  # The planner bindings: the Python package imports from the prefix alone;
  # the jar is installed where the build made one (a JDK and lcm.jar found).
  PYDIR=$PREFIX/lib/python3/dist-packages
  [ -f "$PYDIR/graspfill/object_cloud_t.py" ] || fail "not installed: the Python package graspfill"
  if command -v python3 >/dev/null; then
    (cd / && PYTHONPATH=$PYDIR python3 -c 'from graspfill import object_cloud_t, hole_t') \
      || fail "the installed Python package graspfill does not import"
  fi
  # The Python module (rt/python), where the build made one: imported from
  # the prefix alone by the interpreter it was built for, and a repair of a
  # cloud the installed CLI makes.
  if ls "$BUILD"/lcmtypes/lcmgen/python/graspfill/_native*.so >/dev/null 2>&1; then
    ls "$PYDIR"/graspfill/_native*.so >/dev/null 2>&1 || fail "not installed: the Python module graspfill/_native"
    rm -rf "$WORK/python-synth"
    run "$PREFIX/bin/graspfill" synth --protocol paper --shape cylinder --points 20000 -o "$WORK/python-synth"
    (cd / && PYTHONPATH=$PYDIR "$PYTHON" -c '
import sys
import graspfill
assert graspfill.__file__.startswith(sys.argv[1]), graspfill.__file__
cloud = graspfill.read_ply(sys.argv[2])
points, provenance, confidence, report = graspfill.repair(cloud["points"])
assert report["status"] == "repaired", report["status"]
assert len(points) > len(cloud["points"]) and provenance.max() > 0
print("installed module:", len(cloud["points"]), "->", len(points), "points,", len(report["holes"]), "holes")
' "$PYDIR" "$WORK/python-synth/holey.ply") || fail "the installed Python module does not import or repair"
  fi
  if [ -f "$BUILD/lcmtypes/graspfill_lcmtypes.jar" ]; then
    [ -f "$PREFIX/share/java/graspfill_lcmtypes.jar" ] || fail "not installed: share/java/graspfill_lcmtypes.jar"
  fi
  # Relocatable: the package files name no folder of this checkout.
  if grep -rlF -e "$SRC/" -e "$BUILD/" "$PREFIX/$libdir/cmake" "$PREFIX/$libdir/pkgconfig"; then
    fail "package files name the source or build tree (above)"
  fi
  echo "installed to $PREFIX"
  ;;

find_package)
  B=$WORK/find-package
  rm -rf "$B"
  run "$CMAKE" -S "$DOWNSTREAM" -B "$B" -DCMAKE_BUILD_TYPE="$CONFIG" -DCMAKE_CXX_COMPILER="$CXX" \
    -DCMAKE_PREFIX_PATH="$PREFIX"
  grep -q "graspfill_DIR:PATH=$PREFIX/" "$B/CMakeCache.txt" || fail "graspfill not found in $PREFIX"
  run "$CMAKE" --build "$B" --config "$CONFIG" -j "$JOBS"
  run "$B/grasp_loop" "$RECORDING"
  ;;

pkg_config)
  B=$WORK/pkg-config
  rm -rf "$B"
  mkdir -p "$B"
  PKG_CONFIG_PATH=$(dirname "$(find "$PREFIX" -name graspfill.pc)")
  export PKG_CONFIG_PATH
  version=$(pkg-config --modversion graspfill) || fail "pkg-config finds no graspfill"
  echo "pkg-config graspfill $version"
  flags=$(pkg-config --cflags --libs graspfill) || fail "pkg-config --cflags --libs graspfill"
  echo "pkg-config --cflags --libs graspfill: $flags"
  # Word splitting of $flags is intended.
  # shellcheck disable=SC2086
  run "$CXX" -std=c++17 -O1 -o "$B/grasp_loop" "$DOWNSTREAM/grasp_loop.cpp" $flags
  run "$B/grasp_loop" "$RECORDING"
  ;;

subdirectory)
  B=$WORK/subdirectory
  rm -rf "$B"
  run "$CMAKE" -S "$DOWNSTREAM" -B "$B" -DCMAKE_BUILD_TYPE="$CONFIG" -DCMAKE_CXX_COMPILER="$CXX" \
    -DGRASPFILL_SOURCE_DIR="$SRC" -DGRASPFILL_WITH_OPENNI2=OFF
  run "$CMAKE" --build "$B" --config "$CONFIG" -j "$JOBS" --target pose_check
  run "$B/pose_check" "$SRC/replay/default/recording.lcmlog" --expect-no-openni2
  ;;

subdirectory_full)
  # As above, OpenNI2 as found, and grasp_loop built (all of graspfill from
  # source: ~5 min at -j1) and run.
  B=$WORK/subdirectory-full
  rm -rf "$B"
  run "$CMAKE" -S "$DOWNSTREAM" -B "$B" -DCMAKE_BUILD_TYPE="$CONFIG" -DCMAKE_CXX_COMPILER="$CXX" \
    -DGRASPFILL_SOURCE_DIR="$SRC" -DDOWNSTREAM_FULL_BUILD=ON
  run "$CMAKE" --build "$B" --config "$CONFIG" -j "$JOBS" --target grasp_loop
  run "$B/grasp_loop" "$SRC/replay/default/recording.lcmlog"
  ;;

cli)
  # A copy of the installed tree elsewhere, run from a third directory: no
  # path of this checkout or of PREFIX is used.
  MOVED=$WORK/cli/moved-prefix
  RUNDIR=$WORK/cli/elsewhere
  rm -rf "$WORK/cli"
  mkdir -p "$RUNDIR"
  cp -a "$PREFIX" "$MOVED" || fail "cannot copy $PREFIX"
  if strings "$MOVED/bin/graspfill" | grep -F -e "$SRC/replay" -e "$SRC/config" -e "$BUILD"; then
    fail "the CLI has this checkout's paths compiled in (above)"
  fi
  "$MOVED/bin/graspfill" bench --help >"$WORK/cli/bench-help.txt" || fail "bench --help"
  grep -qF "$MOVED/share/graspfill/replay/default/recording.lcmlog" "$WORK/cli/bench-help.txt" \
    || { cat "$WORK/cli/bench-help.txt"; fail "bench's default log is not the moved copy's"; }
  cd "$RUNDIR" || fail "cd $RUNDIR"
  env -u GRASPFILL_DATA_DIR "$MOVED/bin/graspfill" demo --no-publish >"$WORK/cli/demo.txt" 2>&1 \
    || { cat "$WORK/cli/demo.txt"; fail "graspfill demo exited with $?"; }
  cat "$WORK/cli/demo.txt"
  grep -qF "$MOVED/share/graspfill/replay/default" "$WORK/cli/demo.txt" \
    || fail "the demo did not replay the moved copy's recording"
  [ -s "$RUNDIR/graspfill-demo/cloud.ply" ] || fail "no graspfill-demo/cloud.ply in the current directory"
  ;;

*)
  echo "unknown step '$STEP'"
  exit 2
  ;;
esac
echo "PASSED: $STEP"
