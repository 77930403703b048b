#!/bin/sh
# graspfill.Subscriber on LCM's UDP multicast, fed by another process
# (tests/rt/cloud_publisher), confined to a private network namespace (only
# a loopback inside): the Python side must print the line the publisher
# printed for what it sent (count, checksum over every byte, holes).
# usage: udpm_subscriber.sh <python3> <print_cloud_summary.py> <cloud_publisher>
# Exit: 0 pass, 1 fail, 77 skipped (no network namespaces here).
set -u
PYTHON=$1
SUMMARY=$2
PUB=$3
LCM_READY="$(cd "$(dirname "$0")/.." && pwd)/lcm_ready.sh"
. "$LCM_READY"
require_private_network || exit 77

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
export PYTHON SUMMARY PUB TMP LCM_READY
# The receive buffer a ~500 KB burst of fragments needs (docs/planner-bindings.md).
export URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'
export CHANNEL=GRASPFILL_TEST_PYTHON_UDPM

unshare -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  "$PYTHON" "$SUMMARY" "$URL" "$CHANNEL" 20 >"$TMP/sub.out" 2>"$TMP/sub.err" &
  sub=$!
  wait_lcm_subscribed $sub || exit 95
  "$PUB" "$URL" "$CHANNEL" 20000 11 >"$TMP/pub.out" 2>"$TMP/pub.err" || exit 92
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
  echo "FAIL: the Python subscriber's line does not match what was sent"
  exit 1
fi
echo "PASS"
