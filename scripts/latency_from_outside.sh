#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Latency measured from outside the module, with LCM's own tools (issue 39):
# in a private network namespace (never the host's network), lcm-logplayer
# plays LOG at SPEED into `graspfill live --depth-from-lcm` (its defaults),
# and lcm-logger records every message with its receive time. Each cloud's
# latency is its receipt (the first moment all its slices were in) minus
# the receipt of its newest frame (the cloud's utime). The last cloud is the
# grasp's final model: a recording ends without a grasp-end signal, so live
# publishes it when no frame came for IDLE_S seconds (--idle-exit-s), and its
# latency is that wait; it is printed apart. Needs root (unshare -n),
# lcm-logplayer/lcm-logger (liblcm-bin) and python3.
# usage: scripts/latency_from_outside.sh GRASPFILL SPEED LOG [IDLE_S]
set -eu
[ $# -ge 3 ] || { echo "usage: $0 GRASPFILL SPEED LOG [IDLE_S]" >&2; exit 2; }
GRASPFILL=$1 SPEED=$2 REC=$3 IDLE_S=${4:-1.5}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
export GRASPFILL SPEED REC IDLE_S TMP
export LCM_READY="$(cd "$(dirname "$0")/../tests/rt" && pwd)/lcm_ready.sh"
. "$LCM_READY"
require_private_network || exit 77
unset LCM_DEFAULT_URL
unshare -n sh -c '
  . "$LCM_READY"
  loopback_multicast_up || exit 90
  lcm-logger --lcm-url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216" "$TMP/bus.lcmlog" \
      >/dev/null 2>&1 &
  logger=$!
  "$GRASPFILL" live --depth-from-lcm --idle-exit-s "$IDLE_S" --duration-s 600 >"$TMP/live.out" 2>&1 &
  live=$!
  for pid in $logger $live; do wait_lcm_subscribed $pid || exit 95; done
  lcm-logplayer -s "$SPEED" "$REC" >/dev/null 2>&1 || exit 92
  wait $live || exit 93
  sleep 0.5
  kill $logger
  wait $logger 2>/dev/null || true
' || { echo "FAIL: the session in the namespace (exit $?)"; cat "$TMP/live.out" 2>/dev/null; exit 1; }
grep -E "^live: [0-9]+ frames in" "$TMP/live.out" || true
python3 - "$TMP/bus.lcmlog" "$SPEED" <<'PY'
import struct, sys
def events(path):
    data = open(path, "rb").read()
    i = 0
    while i + 28 <= len(data):
        _, _, stamp, channel_len, data_len = struct.unpack(">IqqII", data[i:i + 28])
        i += 28
        channel = data[i:i + channel_len].decode()
        i += channel_len
        yield stamp, channel, data[i:i + data_len]
        i += data_len
frames, clouds = {}, {}
for stamp, channel, msg in events(sys.argv[1]):
    # Both messages open with their 8-byte fingerprint, then int64 utime;
    # a cloud's slice (object_cloud_chunk_t) goes on with seq, cloud bytes,
    # crc, num_chunks and chunk_index.
    if channel == "GRASPFILL_DEPTH":
        frames.setdefault(struct.unpack(">q", msg[8:16])[0], stamp)
    elif channel == "GRASPFILL_OBJECT_CLOUD" and len(msg) >= 40:
        utime, seq, _, _, count, index = struct.unpack(">qqiiii", msg[8:40])
        c = clouds.setdefault(seq, {"utime": utime, "have": set(), "done": None})
        c["have"].add(index)
        if c["done"] is None and len(c["have"]) == count:
            c["done"] = stamp
ms = [(c["done"] - frames[c["utime"]]) / 1000.0 for _, c in sorted(clouds.items())
      if c["done"] is not None and c["utime"] in frames]
if not ms:
    print("no cloud whose newest frame was recorded")
    sys.exit(1)
final, periodic = ms[-1], sorted(ms[:-1])
def q(p):
    return periodic[min(len(periodic) - 1, int(p / 100.0 * len(periodic)))] if periodic else float("nan")
print("speed %sx: %d depth frames recorded, %d clouds; frame -> cloud [ms] p50 %.1f, p99 %.1f, max %.1f "
      "over the %d clouds before the final model; the final model %.1f (its grasp's end: the idle wait)"
      % (sys.argv[2], len(frames), len(ms), q(50), q(99), periodic[-1] if periodic else float("nan"),
         len(periodic), final))
PY
