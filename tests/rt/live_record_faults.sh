#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# `graspfill live --record` when the session ends badly (issue 36), through
# real processes: lcm-logplayer plays a synth recording on LCM's UDP
# multicast inside a private network and mount namespace (loopback only, a
# tmpfs of its own), and live records it.
#  - SIGKILL mid-session: the log is at its name (no hidden temporary file)
#    and every event written is read by graspfill replay and lcm-logplayer.
#  - SIGHUP (a closed terminal or ssh session): live ends cleanly, exit 0,
#    the log complete.
#  - a full disk (a tmpfs of half the recording's size): the recording
#    stops with one message on stderr (strerror), the log keeps what was
#    written (replayable, playable), the summary's status says so, live
#    fuses on to the end and exits 1 (the recording is incomplete).
#  - a rig config's camera.max_depth_pixels under the frames' size: every
#    frame is refused as bad_size.
# usage: live_record_faults.sh <graspfill>
# Exit: 0 pass, 1 fail, 77 skipped (no network or mount namespaces here).
set -u
GRASPFILL=$1
SKIP=77
for tool in unshare ip lcm-logplayer mount stat; do
  command -v $tool >/dev/null 2>&1 || {
    echo "SKIP: needs unshare, mount (util-linux), ip (iproute2), stat and lcm-logplayer (liblcm-bin)"
    exit $SKIP
  }
done
if ! unshare -m -n true 2>/dev/null; then
  echo "SKIP: cannot create network and mount namespaces; multicast is never tried on the host network"
  exit $SKIP
fi
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
FAILED=0
fail() { echo "FAIL: $*"; FAILED=1; }

"$GRASPFILL" synth --shape cylinder --frames 40 --wall-m 0 --seed 4 -o "$TMP/rec" \
    >"$TMP/synth.out" 2>&1 || { cat "$TMP/synth.out"; fail "synth"; exit 1; }
REC="$TMP/rec/recording.lcmlog"
REC_BYTES=$(stat -c %s "$REC")
printf 'camera:\n  max_depth_pixels: 1000\n' >"$TMP/small.yaml"
export GRASPFILL TMP REC REC_BYTES
export LCM_READY="$(cd "$(dirname "$0")" && pwd)/lcm_ready.sh"
export URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'

unshare -m -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  live() {  # name, options: live in the background, its pid in $live
    name=$1
    shift
    "$GRASPFILL" live --depth-from-lcm --lcm-url "$URL" --publish-every 0 --duration-s 60 \
        "$@" >"$TMP/$name.out" 2>"$TMP/$name.err" &
    live=$!
    wait_lcm_subscribed $live || echo "live $name did not subscribe" >>"$TMP/ns.err"
  }
  play() {  # speed: the recording on the bus, in the background
    lcm-logplayer --speed=$1 --lcm-url="$URL" "$REC" >/dev/null 2>&1 &
    player=$!
  }
  # Until $1 holds a third of the recording (mid-session), at most 15 s.
  wait_third() {
    i=0
    while [ $i -lt 300 ]; do
      size=$(stat -c %s "$1" 2>/dev/null || echo 0)
      [ "$size" -ge $((REC_BYTES / 3)) ] && return 0
      sleep 0.05
      i=$((i + 1))
    done
  }

  mkdir "$TMP/kill" "$TMP/hup" "$TMP/full"
  live kill --record "$TMP/kill/session.lcmlog"
  play 0.5
  wait_third "$TMP/kill/session.lcmlog"
  kill -KILL $live
  wait $live
  echo $? >"$TMP/kill.rc"
  wait $player

  live hup --record "$TMP/hup/session.lcmlog"
  play 0.5
  wait_third "$TMP/hup/session.lcmlog"
  kill -HUP $live
  wait $live
  echo $? >"$TMP/hup.rc"
  wait $player

  mount -t tmpfs -o size=$((REC_BYTES / 2048))k tmpfs "$TMP/full" || exit 96
  live full --record "$TMP/full/session.lcmlog" --idle-exit-s 1.5
  play 0.5
  wait $player
  wait $live
  echo $? >"$TMP/full.rc"
  cp "$TMP/full/session.lcmlog" "$TMP/full_kept.lcmlog"
  umount "$TMP/full"

  live small --config "$TMP/small.yaml"
  play 2
  wait $player
  sleep 0.5
  kill -TERM $live
  wait $live
  echo $? >"$TMP/small.rc"
'
rc=$?
for f in ns.err kill.err hup.out hup.err full.out full.err small.out small.err; do
  [ -s "$TMP/$f" ] && { echo "--- $f"; cat "$TMP/$f"; }
done
[ $rc -eq 0 ] || { fail "namespace script exited $rc"; exit 1; }

# Depth frames graspfill replay reads from $1 (its note, if any, on $2);
# 0 if it cannot replay it.
replay_frames() {
  [ -f "$1" ] || { echo 0; return; }
  LCM_DEFAULT_URL=memq:// "$GRASPFILL" replay "$1" -o "$TMP/replay.ply" --force --json \
      --no-publish >"$TMP/replay.json" 2>"$2" || { cat "$2" >&2; echo 0; return; }
  sed -n 's/^  "frames_read": \([0-9]*\),*$/\1/p' "$TMP/replay.json"
}
# Events lcm-logplayer plays from $1 (in-process memq: nothing leaves).
played_events() {
  [ -f "$1" ] || { echo 0; return; }
  lcm-logplayer --verbose --speed=1000 --lcm-url=memq:// "$1" 2>&1 | grep -c 'GRASPFILL_'
}

# SIGKILL: the log at its name, nothing beside it, its events readable.
[ "$(cat "$TMP/kill.rc")" = 137 ] || fail "live was not killed (exit $(cat "$TMP/kill.rc"))"
[ "$(ls -A "$TMP/kill")" = "session.lcmlog" ] ||
  fail "after SIGKILL the folder holds: $(ls -A "$TMP/kill" | tr '\n' ' ')"
kill_frames=$(replay_frames "$TMP/kill/session.lcmlog" "$TMP/kill_replay.err")
kill_played=$(played_events "$TMP/kill/session.lcmlog")
echo "SIGKILL: log of $(stat -c %s "$TMP/kill/session.lcmlog") bytes, $kill_frames depth frames replayed, $kill_played events played by lcm-logplayer"
[ "${kill_frames:-0}" -ge 5 ] || fail "the killed session's log replays $kill_frames frames"
[ "${kill_frames:-0}" -lt 40 ] || fail "the kill came after the session ($kill_frames frames)"
# lcm-logplayer plays every whole event: the session description, the
# frames and the gripper states (at least one per frame).
[ "$kill_played" -gt $((2 * kill_frames)) ] || fail "lcm-logplayer played $kill_played events"

# SIGHUP: a clean end, the log complete (no partial event).
[ "$(cat "$TMP/hup.rc")" = 0 ] || fail "live after SIGHUP exited $(cat "$TMP/hup.rc")"
hup_events=$(sed -n 's/^record: \([0-9]*\) events written to .*, 0 dropped$/\1/p' "$TMP/hup.out")
[ -n "$hup_events" ] || { fail "no clean record line after SIGHUP"; hup_events=-1; }
hup_frames=$(replay_frames "$TMP/hup/session.lcmlog" "$TMP/hup_replay.err")
grep -q "partial event" "$TMP/hup_replay.err" && fail "the SIGHUP log ends in a partial event"
[ "$(played_events "$TMP/hup/session.lcmlog")" = $((hup_events + 1)) ] ||
  fail "lcm-logplayer did not play the $hup_events events and the session description"
[ "$hup_frames" -ge 5 ] && [ "$hup_frames" -lt 40 ] || fail "SIGHUP log: $hup_frames frames"
echo "SIGHUP: exit $(cat "$TMP/hup.rc"), $hup_events events written, $hup_frames depth frames replayed"

# A full disk: said once, the log kept whole, live fused on and exits 1.
[ "$(cat "$TMP/full.rc")" = 1 ] || fail "live with a full disk exited $(cat "$TMP/full.rc")"
[ "$(grep -c "recording stopped after [0-9]* events: cannot write log '$TMP/full/session.lcmlog': No space left on device" "$TMP/full.err")" = 1 ] ||
  fail "stderr does not say once that the disk is full"
grep -q "^record: [0-9]* events written to .*; stopped early: cannot write log .*: No space left on device$" \
    "$TMP/full.out" || fail "the record line does not say the recording stopped"
grep -q "state [a-z]*: recording stopped: cannot write log" "$TMP/full.out" ||
  fail "the last status does not say the recording stopped"
full_frames=$(replay_frames "$TMP/full_kept.lcmlog" "$TMP/full_replay.err")
grep -q "partial event" "$TMP/full_replay.err" && fail "the full disk's log ends in a partial event"
full_played=$(played_events "$TMP/full_kept.lcmlog")
full_events=$(sed -n 's/^record: \([0-9]*\) events written.*/\1/p' "$TMP/full.out")
full_events=${full_events:--1}
[ "$full_played" = $((full_events + 1)) ] ||
  fail "lcm-logplayer played $full_played events of the $full_events kept and the description"
fused=$(sed -n 's/^live: [0-9]* frames in, \([0-9]*\) fused.*/\1/p' "$TMP/full.out")
fused=${fused:-0}
[ "$fused" -gt "$full_frames" ] ||
  fail "live fused $fused frames, no more than the $full_frames recorded before the disk was full"
echo "full disk: $full_events events kept ($full_frames frames, replayable, played), $fused frames fused"

# The rig config's pixel limit reaches the bus subscriber.
[ "$(cat "$TMP/small.rc")" = 0 ] || fail "live with the small limit exited $(cat "$TMP/small.rc")"
grep -q "^live: decode errors by reason: bad_size 40$" "$TMP/small.out" ||
  fail "the 40 frames over camera.max_depth_pixels were not counted as bad_size"
[ $FAILED -eq 0 ] && echo "PASS"
exit $FAILED
