#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# A grasp-and-model session across real processes on LCM's UDP multicast,
# confined to a private network namespace (loopback only): lcm-logplayer
# plays the bundled recording (depth + gripper states), `graspfill live`
# fuses and repairs it and publishes the object cloud, a separate subscriber
# receives it (with the repair's added points and holes).
# With <bad_bus_log>, the recording is first damaged by it (bit flips,
# truncations, bad intrinsics, bad poses): live must still model the object
# and its status must count every damaged message by its reason.
# usage: live_udpm_session.sh <graspfill> <cloud_subscriber> <recording.lcmlog> [<bad_bus_log>]
# Exit: 0 pass, 1 fail, 77 skipped (no network namespaces here).
set -u
GRASPFILL=$1
SUB=$2
LOG=$3
DAMAGE=${4:-}
SKIP=77

. "$(dirname "$0")/lcm_ready.sh"
require_private_network || exit $SKIP

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
if [ -n "$DAMAGE" ]; then
  damaged=$("$DAMAGE" "$LOG" "$TMP/damaged.lcmlog") || { echo "FAIL: $DAMAGE failed"; exit 1; }
  LOG="$TMP/damaged.lcmlog"
fi
export GRASPFILL SUB LOG TMP
export LCM_READY="$(cd "$(dirname "$0")" && pwd)/lcm_ready.sh"
export URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'

unshare -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  "$SUB" "$URL" GRASPFILL_OBJECT_CLOUD 30000 >"$TMP/sub.out" 2>"$TMP/sub.err" &
  sub=$!
  "$GRASPFILL" live --depth-from-lcm --lcm-url "$URL" --publish-every 0 \
      --idle-exit-s 1.5 --duration-s 25 >"$TMP/live.out" 2>"$TMP/live.err" &
  live=$!
  wait_lcm_subscribed $sub || exit 95
  wait_lcm_subscribed $live || exit 95
  lcm-logplayer --lcm-url="$URL" "$LOG" >"$TMP/player.out" 2>&1 || exit 92
  wait $live || exit 93
  wait $sub || exit 94
'
rc=$?
for f in live.out live.err sub.out sub.err; do
  [ -s "$TMP/$f" ] && { echo "--- $f"; cat "$TMP/$f"; }
done
if [ $rc -ne 0 ]; then
  echo "FAIL: namespace script exited $rc"
  exit 1
fi
points=$(sed -n 's/.*points=\([0-9]*\).*/\1/p' "$TMP/sub.out")
if [ -z "$points" ] || [ "$points" -lt 5000 ]; then
  echo "FAIL: expected an object cloud of >= 5000 points, got '${points}'"
  exit 1
fi
if ! grep -q "fused" "$TMP/live.out"; then
  echo "FAIL: live printed no summary"
  exit 1
fi
# The planner gets the repaired cloud: added points (provenance) and holes.
added=$(sed -n 's/.*added=\([0-9]*\).*/\1/p' "$TMP/sub.out")
holes=$(sed -n 's/.*holes=\([0-9]*\).*/\1/p' "$TMP/sub.out")
if [ -z "$added" ] || [ "$added" -lt 1 ] || [ -z "$holes" ] || [ "$holes" -lt 1 ]; then
  echo "FAIL: expected a repaired cloud (added points and holes), got added='${added}' holes='${holes}'"
  exit 1
fi
# The status counts what was damaged, by reason (live prints the last
# status's counts, those with a count).
if [ -n "$DAMAGE" ]; then
  set -- $damaged  # malformed N bad_intrinsics N bad_pose N
  want="live: decode errors by reason: malformed $2, bad_intrinsics $4, bad_pose $6"
  if ! grep -qx "$want" "$TMP/live.out"; then
    echo "FAIL: expected the line '$want'"
    exit 1
  fi
fi
echo "PASS: the subscriber received a cloud of $points points, $added added by the repair, $holes holes"
