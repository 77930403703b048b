#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Cross-process object-cloud round trip over LCM's UDP multicast, confined
# to a private network namespace (only a loopback inside): the subscriber
# must report the point count and checksum the publisher sent.
# usage: udpm_cloud_roundtrip.sh <cloud_subscriber> <cloud_publisher> [<interpreter>]
#   <interpreter>: runs the subscriber, a script then (the Python module's
#   tests/rt/python/print_cloud_summary.py with python3)
# Exit: 0 pass, 1 fail, 77 skipped (no network namespaces here).
set -u
SUB=$1
PUB=$2
RUNNER=${3:-}
SKIP=77

if ! command -v unshare >/dev/null 2>&1 || ! command -v ip >/dev/null 2>&1; then
  echo "SKIP: needs unshare (util-linux) and ip (iproute2)"
  exit $SKIP
fi
# Probe first: unshare -n needs root or CAP_SYS_ADMIN (and a kernel and
# container runtime that allow it).
if ! unshare -n true 2>/dev/null; then
  echo "SKIP: cannot create a network namespace (unshare -n: not permitted here);"
  echo "      multicast is never tried on the host network"
  exit $SKIP
fi

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
export SUB PUB TMP RUNNER
export LCM_READY="$(cd "$(dirname "$0")" && pwd)/lcm_ready.sh"
export URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'
export CHANNEL=GRASPFILL_TEST_UDPM_CLOUD

# 20000 points with normals: ~500 KB, so LCM fragments the message.
unshare -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  $RUNNER "$SUB" "$URL" "$CHANNEL" 10000 >"$TMP/sub.out" 2>"$TMP/sub.err" &
  sub=$!
  wait_lcm_subscribed $sub || exit 95
  "$PUB" "$URL" "$CHANNEL" 20000 7 >"$TMP/pub.out" 2>"$TMP/pub.err" || exit 92
  wait $sub || exit 93
'
rc=$?
if [ $rc -ne 0 ]; then
  echo "FAIL: namespace script exited $rc"
  for f in sub.out sub.err pub.out pub.err; do
    [ -s "$TMP/$f" ] && { echo "--- $f"; cat "$TMP/$f"; }
  done
  exit 1
fi
sent=$(cat "$TMP/pub.out")
received=$(cat "$TMP/sub.out")
echo "sent:     $sent"
echo "received: $received"
if [ -z "$sent" ] || [ "$sent" != "$received" ]; then
  echo "FAIL: subscriber output does not match what was sent"
  exit 1
fi
echo "PASS"
