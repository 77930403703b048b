#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# The planner gets every model with LCM's defaults (issue 38): no
# recv_buf_size, LCM's default URL, the kernel's default receive buffer.
# Inside a private network namespace (loopback only; multicast never
# touches the host's network):
#  1. `graspfill live --depth-from-lcm` models a 300-frame recording that
#     lcm-logplayer plays at 1x; the C++, Java and Python example
#     subscribers (and a reference lcm-logger with a large buffer) must
#     each receive every cloud live says it published, and replay's final
#     model after them: each model goes out as paced one-datagram slices
#     (object_cloud_chunk_t), sent twice, which the subscribers join
#     (docs/measurements/2026-12-06-cloud-delivery.md);
#  2. `graspfill replay` publishes its final model: the reference capture's
#     joined and decoded points equal replay's PLY within half the 50 um
#     step on each axis (0.0434 mm as a distance), and each subscriber's
#     last cloud has the PLY's point count;
#  3. the Python log reader joins every model from the reference capture.
# The namespace's UDP receive-buffer drops (/proc/net/snmp, RcvbufErrors:
# datagrams of any channel, mostly depth frames, that found a socket full)
# are printed.
# usage: default_url_delivery.sh <graspfill> <cpp_subscriber> <cloud_compare>
#            <python> <pythonpath> <python_subscriber.py> [<java> <classpath>]
#   (python '-': no Python module built; java absent: no Java example built)
# Exit: 0 pass, 1 fail, 77 skipped (no network namespaces here).
set -u
GRASPFILL=$1
CPP_SUB=$2
COMPARE=$3
PYTHON=$4
PYTHON_PATH=$5
PY_SUB=$6
JAVA=${7:-}
JAVA_CP=${8:-}
[ "$PYTHON" = "-" ] && PYTHON=
SKIP=77

. "$(dirname "$0")/../rt/lcm_ready.sh"
require_private_network || exit $SKIP

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$GRASPFILL" synth --shape cylinder --frames 300 --seed 5 --quiet -o "$TMP/rec" >/dev/null ||
  { echo "FAIL: synth"; exit 1; }
"$GRASPFILL" replay "$TMP/rec/recording.lcmlog" -o "$TMP/replay.ply" --no-publish --quiet >/dev/null ||
  { echo "FAIL: replay"; exit 1; }
export GRASPFILL CPP_SUB JAVA JAVA_CP PYTHON PYTHON_PATH PY_SUB TMP
export LCM_READY="$(cd "$(dirname "$0")/../rt" && pwd)/lcm_ready.sh"
unset LCM_DEFAULT_URL

unshare -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  echo "rmem_default $(cat /proc/sys/net/core/rmem_default)" >"$TMP/kernel.out"
  udp_drops() { awk '"'"'/^Udp:/ { if (n++) print $6 }'"'"' /proc/net/snmp; }
  # The reference: every message on the bus, with a buffer of its own.
  lcm-logger --lcm-url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304" \
      -c GRASPFILL_OBJECT_CLOUD "$TMP/bus.lcmlog" >/dev/null 2>&1 &
  logger=$!
  "$CPP_SUB" --count 100000 --timeout-s 200 >"$TMP/cpp.out" 2>"$TMP/cpp.err" &
  cpp=$!
  java=
  if [ -n "$JAVA" ]; then
    "$JAVA" -cp "$JAVA_CP" ObjectCloudSubscriber --count 100000 --timeout-s 200 \
        >"$TMP/java.out" 2>"$TMP/java.err" &
    java=$!
  fi
  python=
  if [ -n "$PYTHON" ]; then
    PYTHONPATH="$PYTHON_PATH" "$PYTHON" "$PY_SUB" --timeout-s 200 >"$TMP/python.out" 2>"$TMP/python.err" &
    python=$!
  fi
  "$GRASPFILL" live --depth-from-lcm --publish-every 10 --idle-exit-s 1.5 --duration-s 60 \
      >"$TMP/live.out" 2>"$TMP/live.err" &
  live=$!
  for pid in $logger $cpp $live; do wait_lcm_subscribed $pid || exit 95; done
  if [ -n "$java" ]; then wait_lcm_subscribed $java || exit 95; fi
  if [ -n "$python" ]; then wait_lcm_subscribed $python || exit 95; fi
  lcm-logplayer "$TMP/rec/recording.lcmlog" >"$TMP/player.out" 2>&1 || exit 92
  wait $live || exit 93
  # Then replay publishes its final model once.
  "$GRASPFILL" replay "$TMP/rec/recording.lcmlog" -o "$TMP/replay_again.ply" --quiet \
      >"$TMP/replay.out" 2>&1 || exit 96
  # Every subscriber prints each cloud as it comes: wait (up to 20 s,
  # however loaded the machine) until each has printed as many as were
  # published, then stop them.
  published=$(sed -n "s/^latency: \([0-9]*\) clouds published.*/\1/p" "$TMP/live.out")
  want=$((${published:-0} + 1))
  i=0
  while [ $i -lt 200 ]; do
    all=1
    for f in cpp.out ${java:+java.out} ${python:+python.out}; do
      [ "$(grep -c "^seq=" "$TMP/$f")" -ge $want ] || all=0
    done
    [ $all -eq 1 ] && break
    sleep 0.1
    i=$((i + 1))
  done
  ss -uamnp >"$TMP/sockets.out" 2>&1  # drops per socket (d...), while the subscribers run
  for pid in $cpp $java $python; do kill $pid 2>/dev/null; wait $pid; done
  sleep 0.5
  kill $logger
  wait $logger
  echo "udp receive-buffer drops $(udp_drops)" >>"$TMP/kernel.out"
  exit 0
'
rc=$?
show() { for f in "$@"; do [ -s "$TMP/$f" ] && { echo "--- $f"; cat "$TMP/$f"; }; done; }
if [ $rc -ne 0 ]; then
  echo "FAIL: namespace script exited $rc"
  show kernel.out live.out live.err cpp.err java.err player.out replay.out
  exit 1
fi
cat "$TMP/kernel.out"
# Per process, its sockets' drops (sending sockets drop nothing).
grep -o 'users:(("[^"]*",pid=[0-9]*\|skmem:([^)]*)' "$TMP/sockets.out" | paste - - |
  sed -n 's/users:(("\([^"]*\)",pid=\([0-9]*\).*,d\([0-9]*\))$/socket drops: \1 (pid \2) \3/p' |
  sort -u
published=$(sed -n 's/^latency: \([0-9]*\) clouds published.*/\1/p' "$TMP/live.out")
if [ -z "$published" ] || [ "$published" -lt 3 ]; then
  echo "FAIL: live published '${published}' clouds (at least 3 expected)"
  show live.out live.err
  exit 1
fi
expected=$((published + 1))  # and replay's final model
echo "live published $published clouds, replay 1: $expected"
fail=0
# ... each subscriber: every one, once. Its last line is replay's model.
check() {  # check NAME FILE
  got=$(grep -c '^seq=' "$TMP/$2")
  echo "$1 received $got of $expected"
  [ "$got" -eq "$expected" ] || { echo "FAIL: $1 received $got of $expected"; show "${2%.out}.err"; fail=1; }
  last_points=$(grep '^seq=' "$TMP/$2" | tail -n 1 | sed -n 's/.* points=\([0-9]*\) .*/\1/p')
  [ "$last_points" = "$ply_points" ] ||
    { echo "FAIL: $1's last cloud has '$last_points' points, replay's PLY $ply_points"; fail=1; }
}
ply_points=$(sed -n 's/^element vertex \([0-9]*\).*/\1/p' "$TMP/replay.ply" | head -n 1)
check "the C++ example" cpp.out
[ -n "$JAVA" ] && check "the Java example" java.out
[ -n "$PYTHON" ] && check "the Python module's subscriber" python.out
# The reference capture holds the slices as lcm-logger saw them: the Python
# log reader joins every model from it.
if [ -n "$PYTHON" ]; then
  logged=$(PYTHONPATH="$PYTHON_PATH" "$PYTHON" "$(dirname "$PY_SUB")/read_object_clouds.py" "$TMP/bus.lcmlog" |
           grep -c '^seq=')
  echo "the Python log reader joined $logged from lcm-logger's capture"
  [ "$logged" -eq "$expected" ] || { echo "FAIL: the Python log reader joined $logged of $expected"; fail=1; }
fi
# What the decoded final model is worth.
"$COMPARE" "$TMP/bus.lcmlog" "$TMP/replay.ply" GRASPFILL_OBJECT_CLOUD 0.0434 within ||
  { echo "FAIL: replay's published model is not its PLY within half a step"; fail=1; }
[ $fail -eq 0 ] && echo "PASS"
exit $fail
