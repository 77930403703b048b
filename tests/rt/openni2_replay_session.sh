#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# OpenNI2 end to end without a camera: `graspfill live --device
# graspfill-replay:LOG` reads a synthetic recording's depth through
# Debian's libOpenNI2 and graspfill's replay driver (gripper states read
# alongside from LOG) and must publish replay's cloud; an .oni recorded from
# that device plays back (`--device FILE.oni --gripper-log LOG`) to the same
# cloud; a mode the device lacks is an error listing its modes; --width/
# --height pick the half-size mode; --fx.. override the .oni's intrinsics.
# Clouds are captured with LCM's file:// provider (no network).
# usage: openni2_replay_session.sh <graspfill> <cloud_compare>
set -u
G=$1
CMP=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
CH=GRASPFILL_OBJECT_CLOUD
fail() { echo "FAIL: $*"; for f in "$TMP"/*.out "$TMP"/*.err; do [ -s "$f" ] && { echo "--- $f"; cat "$f"; }; done; exit 1; }
bus() { echo "file://$TMP/$1.lcmlog?mode=w"; }

"$G" synth --shape cylinder --frames 8 -o "$TMP/s" >"$TMP/synth.out" 2>&1 || fail "synth"
LOG=$TMP/s/recording.lcmlog
"$G" replay "$LOG" -o "$TMP/replay.ply" --lcm-url "$(bus replay)" >"$TMP/replay.out" 2>&1 ||
  fail "replay"

# 1. The replay device through libOpenNI2 gives replay's cloud, bit for bit.
"$G" live --device "graspfill-replay:$LOG" --replay-speed 0 --publish-every 0 \
    --lcm-url "$(bus live)" >"$TMP/live.out" 2>"$TMP/live.err" || fail "live --device graspfill-replay:"
grep -q "8 frames in, [0-9]* fused, 0 dropped" "$TMP/live.out" || fail "live did not take all 8 frames"
"$CMP" "$TMP/replay.lcmlog" "$TMP/live.lcmlog" $CH 0.1 identical >"$TMP/cmp1.out" ||
  fail "live's cloud is not replay's: $(cat "$TMP/cmp1.out")"
echo "replay device: $(cat "$TMP/cmp1.out")"

# 2. An .oni recorded from the device (OpenNI2's recorder) plays back through
#    OpenNI2's file driver to the same cloud (its intrinsics come from the
#    recorded field of view, float: within 0.1 mm).
"$G" oni-record --device "graspfill-replay:$LOG" -o "$TMP/r.oni" >"$TMP/rec.out" 2>&1 ||
  fail "oni-record"
grep -q "8 frames (640x480@30/1mm) into .*, 8 read back" "$TMP/rec.out" || fail "oni-record: $(cat "$TMP/rec.out")"
"$G" live --device "$TMP/r.oni" --gripper-log "$LOG" --publish-every 0 \
    --lcm-url "$(bus oni)" >"$TMP/oni.out" 2>"$TMP/oni.err" || fail "live --device FILE.oni"
grep -q "8 frames in, [0-9]* fused, 0 dropped" "$TMP/oni.out" || fail ".oni playback lost frames"
"$CMP" "$TMP/replay.lcmlog" "$TMP/oni.lcmlog" $CH 0.1 within >"$TMP/cmp2.out" ||
  fail ".oni cloud differs: $(cat "$TMP/cmp2.out")"
echo ".oni: $(cat "$TMP/cmp2.out")"

# 3. Intrinsics override: the recording's own pinhole makes the .oni's cloud
#    replay's exactly; a 5% longer focal length moves it by millimetres.
K=$(sed -n '/"intrinsics"/,/}/p' "$TMP/s/scene.json")
num() { echo "$K" | sed -n "s/.*\"$1\": *\([-0-9.e]*\).*/\1/p" | head -1; }
FX=$(num fx); FY=$(num fy); CX=$(num cx); CY=$(num cy)
[ -n "$FX" ] && [ -n "$CY" ] || fail "no intrinsics in scene.json"
"$G" live --device "$TMP/r.oni" --gripper-log "$LOG" --publish-every 0 \
    --fx "$FX" --fy "$FY" --cx "$CX" --cy "$CY" \
    --lcm-url "$(bus onik)" >"$TMP/onik.out" 2>"$TMP/onik.err" || fail "live --fx.."
"$CMP" "$TMP/replay.lcmlog" "$TMP/onik.lcmlog" $CH 0.1 identical >"$TMP/cmp3.out" ||
  fail "with the recorded intrinsics the .oni's cloud is not replay's: $(cat "$TMP/cmp3.out")"
FX5=$(awk "BEGIN { printf \"%.6f\", $FX * 1.05 }")
"$G" live --device "graspfill-replay:$LOG" --replay-speed 0 --publish-every 0 --fx "$FX5" \
    --lcm-url "$(bus fx5)" >"$TMP/fx5.out" 2>"$TMP/fx5.err" || fail "live --fx $FX5"
"$CMP" "$TMP/replay.lcmlog" "$TMP/fx5.lcmlog" $CH 1.0 differ >"$TMP/cmp4.out" ||
  fail "--fx $FX5 did not change the cloud: $(cat "$TMP/cmp4.out")"
echo "intrinsics override: exact K $(cat "$TMP/cmp3.out"); fx x1.05 $(cat "$TMP/cmp4.out")"

# 4. Modes: one the device lacks is an error listing those it has; the half
#    size is one of them and replays every frame.
"$G" live --device "graspfill-replay:$LOG" --width 800 --height 600 \
    --lcm-url "$(bus bad)" >"$TMP/bad.out" 2>"$TMP/bad.err" && fail "--width 800 was accepted"
grep -q "has no depth mode 800x600@\*/1mm; available: 640x480@30/1mm 640x480@30/100um 320x240@30/1mm 320x240@30/100um" \
  "$TMP/bad.err" || fail "no list of modes: $(cat "$TMP/bad.err")"
"$G" live --device "graspfill-replay:$LOG" --replay-speed 0 --width 320 --height 240 \
    --publish-every 0 --no-repair --lcm-url "$(bus half)" >"$TMP/half.out" 2>"$TMP/half.err" ||
  fail "live --width 320 --height 240"
grep -q "8 frames in, [1-9][0-9]* fused, 0 dropped" "$TMP/half.out" || fail "half size: $(cat "$TMP/half.out")"
echo "modes: 800x600 refused with the list; 320x240: $(grep -o '8 frames in[^;]*' "$TMP/half.out")"

# 5. A depth 1% long: live says what the claw's size shows, and that it
#    divided it out (docs/imperfect-robots.md, the depth scale).
"$G" synth --shape cylinder --claw parallel --frames 60 --depth-scale 1.01 -o "$TMP/long" \
    >"$TMP/long_synth.out" 2>&1 || fail "synth --depth-scale 1.01"
"$G" live --device "graspfill-replay:$TMP/long/recording.lcmlog" --replay-speed 0 --publish-every 0 \
    --no-repair --lcm-url "$(bus long)" >"$TMP/long.out" 2>"$TMP/long.err" || fail "live on the 1% long depth"
grep -Eq "refine: the depth reads \+(0\.9[0-9]|1\.0[0-9]) \+- 0\.[0-9]+% against the claw's size, over [0-9]+ frames; divided out" \
  "$TMP/long.out" || fail "no depth scale of about +1% divided out: $(cat "$TMP/long.out")"
echo "depth 1% long: $(grep -o 'the depth reads.*' "$TMP/long.out")"
echo "PASS"
