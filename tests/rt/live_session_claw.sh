#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# `graspfill live --depth-from-lcm` takes its claw from the session
# description on the bus: a parallel-claw recording made by `graspfill
# synth` is played by lcm-logplayer on LCM's UDP multicast, confined to a
# private network namespace (loopback only). Without --claw live must say
# it uses the recording's parallel claw; with --claw three-finger it must
# warn that this is not the session's claw.
# usage: live_session_claw.sh <graspfill>
# Exit: 0 pass, 1 fail, 77 skipped (no network namespaces here).
set -u
GRASPFILL=$1
SKIP=77

. "$(dirname "$0")/lcm_ready.sh"
require_private_network || exit $SKIP

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$GRASPFILL" synth --shape cuboid --size 0.05x0.05x0.08 --claw parallel --frames 30 \
    --wall-m 0 --seed 3 -o "$TMP/rec" >"$TMP/synth.out" 2>&1 || {
  cat "$TMP/synth.out"; echo "FAIL: synth"; exit 1; }
export GRASPFILL TMP
export LCM_READY="$(cd "$(dirname "$0")" && pwd)/lcm_ready.sh"
export URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'

# $1: name of the run, then live's extra flags.
run() {
  name=$1
  shift
  NAME=$name FLAGS="$*" unshare -n sh -c '
    . "$LCM_READY"
    loopback_multicast_up || exit 90
    "$GRASPFILL" live --depth-from-lcm --lcm-url "$URL" --no-repair --publish-every 0 \
        --idle-exit-s 1.5 --duration-s 25 $FLAGS >"$TMP/$NAME.out" 2>"$TMP/$NAME.err" &
    live=$!
    wait_lcm_subscribed $live || exit 95
    lcm-logplayer --lcm-url="$URL" "$TMP/rec/recording.lcmlog" >"$TMP/$NAME.player" 2>&1 || exit 92
    wait $live || exit 93
  '
  rc=$?
  for f in "$name.out" "$name.err"; do
    [ -s "$TMP/$f" ] && { echo "--- $f"; cat "$TMP/$f"; }
  done
  if [ $rc -ne 0 ]; then
    echo "FAIL: $name: namespace script exited $rc"
    exit 1
  fi
  if ! grep -q "fused" "$TMP/$name.out" || grep -q " 0 fused" "$TMP/$name.out"; then
    echo "FAIL: $name: live fused nothing"
    exit 1
  fi
}

run own
if ! grep -qF "live: claw parallel (from the session description on GRASPFILL_SESSION)" "$TMP/own.out"; then
  echo "FAIL: without --claw live did not take the session description's claw"
  exit 1
fi
if grep -q "warning" "$TMP/own.err"; then
  echo "FAIL: a warning without --claw"
  exit 1
fi
# The cloud is replay's (which takes the same claw from the log), within 1%
# when no frame was dropped on the way.
LCM_DEFAULT_URL=memq:// "$GRASPFILL" replay "$TMP/rec/recording.lcmlog" -o "$TMP/replay.ply" \
    --no-repair --no-publish >"$TMP/replay.out" 2>&1 || { cat "$TMP/replay.out"; echo "FAIL: replay"; exit 1; }
replay_points=$(sed -n 's/^object cloud: \([0-9]*\) points.*/\1/p' "$TMP/replay.out")
live_points=$(sed -n 's/.*cloud of \([0-9]*\) points.*/\1/p' "$TMP/own.out")
if grep -q " 0 dropped" "$TMP/own.out"; then
  if [ -z "$replay_points" ] || [ -z "$live_points" ] ||
     [ $((100 * (live_points - replay_points))) -gt "$replay_points" ] ||
     [ $((100 * (replay_points - live_points))) -gt "$replay_points" ]; then
    echo "FAIL: live's cloud has ${live_points} points, replay's ${replay_points}"
    exit 1
  fi
fi

run wrong --claw three-finger
if ! grep -qF "graspfill live: warning: --claw three-finger differs from the claw of the session description on GRASPFILL_SESSION (parallel); using three-finger" "$TMP/wrong.err"; then
  echo "FAIL: --claw three-finger on a parallel-claw session was not warned about"
  exit 1
fi
echo "PASS: live took the session's parallel claw ($live_points points, replay $replay_points), and warned about --claw three-finger"
