#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Bus input is data, never control (issue 36): `graspfill live
# --depth-from-lcm` gets the bundled recording from lcm-logplayer on LCM's
# UDP multicast, confined to a private network namespace (loopback only),
# with a crafted session description in it (tests/rt/session_fault_log.cpp).
# Whatever the description says, live must go on fusing, write no file it
# names, count the description in its status by reason, and keep its status
# coming at its period. One case per run:
#   traversal     claw name ../../victim: no victim.json written above live's
#                 temporary folder; counted bad_claw_name
#   absolute      claw name TMP/abs_victim: likewise
#   voxel         voxel 1 m: counted out_of_limits, live fuses at its own
#   workspace     box +-1e300 m: counted out_of_limits
#   missing_mesh  a URDF claw whose mesh is not under --claw-mesh-root:
#                 counted claw_unloadable
#   other_claw    a later description with another claw, three times:
#                 warned about once
#   urdf_stall    a late URDF claw of 10,000 links: the status keeps coming
#                 (no gap over 2.5 periods, from the first depth frame on)
#   replay_traversal  `graspfill replay` of a log with claw name
#                 ../../victim: a clear error naming the name, nothing written
# usage: live_bus_faults.sh <graspfill> <session_fault_log> <status_subscriber> <recording.lcmlog> <case>
# Exit: 0 pass, 1 fail, 77 skipped (no network namespaces here).
set -u
GRASPFILL=$1
FAULT=$2
STATUS=$3
LOG=$4
CASE=$5
SKIP=77

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
# live's temporary folder is $TMP/a/b: a name "../../victim" joined under a
# folder there would land on $TMP/a/victim.json.
mkdir -p "$TMP/a/b" "$TMP/meshes"
echo original >"$TMP/a/victim.json"
echo original >"$TMP/abs_victim.json"
name=""
case "$CASE" in
  traversal|replay_traversal) name="../../victim" ;;
  absolute) name="$TMP/abs_victim" ;;
esac
kind=$CASE
[ "$CASE" = replay_traversal ] && kind=traversal
# shellcheck disable=SC2086
"$FAULT" "$LOG" "$TMP/faulty.lcmlog" "$kind" $name >"$TMP/fault.out" 2>&1 || {
  cat "$TMP/fault.out"; echo "FAIL: session_fault_log"; exit 1; }

fail() {
  for f in live.out live.err status.out replay.out; do
    [ -s "$TMP/$f" ] && { echo "--- $f"; cat "$TMP/$f"; }
  done
  echo "FAIL: $CASE: $*"
  exit 1
}

# No file a description named: the victims as they were, no other .json.
check_nothing_written() {
  [ "$(cat "$TMP/a/victim.json")" = original ] || fail "$TMP/a/victim.json was overwritten"
  [ "$(cat "$TMP/abs_victim.json")" = original ] || fail "$TMP/abs_victim.json was overwritten"
  others=$(find "$TMP" -name '*.json' ! -path "$TMP/a/victim.json" ! -path "$TMP/abs_victim.json")
  [ -z "$others" ] || fail "files written: $others"
}

if [ "$CASE" = replay_traversal ]; then
  TMPDIR="$TMP/a/b" LCM_DEFAULT_URL=memq:// "$GRASPFILL" replay "$TMP/faulty.lcmlog" \
      -o "$TMP/out.ply" --no-repair --no-publish >"$TMP/replay.out" 2>&1
  rc=$?
  [ $rc -eq 1 ] || fail "replay exited $rc, expected 1"
  grep -q "claw_name '../../victim'" "$TMP/replay.out" || fail "the error does not name the claw name"
  [ ! -e "$TMP/out.ply" ] || fail "a cloud was written"
  check_nothing_written
  echo "PASS: replay refused the log: $(grep -m1 "claw_name" "$TMP/replay.out")"
  exit 0
fi

. "$(dirname "$0")/lcm_ready.sh"
require_private_network || exit $SKIP

FLAGS="--idle-exit-s 1.5"
case "$CASE" in
  missing_mesh) FLAGS="$FLAGS --claw-mesh-root $TMP/meshes" ;;
  urdf_stall) FLAGS="--idle-exit-s 6" ;;  # long enough to see the status during the build
esac
export GRASPFILL STATUS TMP FLAGS
export LCM_READY="$(cd "$(dirname "$0")" && pwd)/lcm_ready.sh"
export URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'
unshare -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  "$STATUS" "$URL" GRASPFILL_STATUS 60000 90000 GRASPFILL_DEPTH >"$TMP/status.out" 2>&1 &
  status=$!
  TMPDIR="$TMP/a/b" "$GRASPFILL" live --depth-from-lcm --lcm-url "$URL" --no-repair \
      --publish-every 0 --duration-s 60 $FLAGS >"$TMP/live.out" 2>"$TMP/live.err" &
  live=$!
  wait_lcm_subscribed $status || exit 95
  wait_lcm_subscribed $live || exit 95
  lcm-logplayer --lcm-url="$URL" "$TMP/faulty.lcmlog" >"$TMP/player.out" 2>&1 || exit 92
  wait $live || exit 93
  sleep 0.5  # the last status on its way
  kill -TERM $status
  wait $status || exit 94
'
rc=$?
check_nothing_written
[ $rc -eq 0 ] || fail "namespace script exited $rc (93: live failed)"
grep -q " fused" "$TMP/live.out" && ! grep -q " 0 fused" "$TMP/live.out" || fail "live fused nothing"

# $1: reason, $2: count; in live's summary and in the last status received.
expect_reason() {
  grep -q "decode errors by reason: .*$1 $2" "$TMP/live.out" || fail "live's summary does not count $1 $2"
  grep -qx "reason $1 $2" "$TMP/status.out" || fail "the status does not count $1 $2"
  rejected=$(grep -c "rejected" "$TMP/live.err")
  [ "$rejected" -eq 1 ] || fail "$rejected lines about rejected descriptions, expected 1"
  grep -q "claw three-finger (default" "$TMP/live.out" || fail "live did not go on with the default claw"
}

case "$CASE" in
  traversal|absolute) expect_reason bad_claw_name 1 ;;
  voxel|workspace) expect_reason out_of_limits 1 ;;
  missing_mesh)
    expect_reason claw_unloadable 1
    grep -q "missing.stl" "$TMP/live.err" || fail "the message does not name the missing mesh"
    ;;
  other_claw)
    grep -q "claw three-finger (from the session description" "$TMP/live.out" ||
      fail "live did not take the head description's claw"
    warnings=$(grep -c "warning" "$TMP/live.err")
    [ "$warnings" -eq 1 ] || fail "$warnings warnings, expected 1 for the three descriptions"
    grep "warning" "$TMP/live.err" | grep -q "parallel" || fail "the warning does not name the other claw"
    ;;
  urdf_stall)
    gap=$(sed -n 's/.*max_gap_ms=\([0-9]*\).*/\1/p' "$TMP/status.out")
    [ -n "$gap" ] && [ "$gap" -lt 2500 ] || fail "the status paused for ${gap} ms (period 1000 ms)"
    ;;
  *) fail "unknown case" ;;
esac
echo "PASS: $CASE: $(head -1 "$TMP/status.out")"
