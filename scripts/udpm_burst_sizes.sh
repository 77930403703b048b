#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Which object_cloud_t sizes reach a subscriber that keeps LCM's defaults
# (docs/measurements/2026-12-06-cloud-delivery.md): in a private network
# namespace (never the host's network), a publisher sends 20 messages of
# each size 100 ms apart to a subscriber on LCM's default URL. Needs root
# (unshare -n), a C compiler and liblcm-dev.
set -eu
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cat >"$TMP/probe.c" <<'C'
#include <lcm/lcm.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
static int received = 0;
static void on_message(const lcm_recv_buf_t* rbuf, const char* channel, void* handler_us) {
  (void)rbuf, (void)channel;
  ++received;
  usleep((useconds_t)atoi((const char*)handler_us));
}
int main(int argc, char** argv) {
  if (argc != 4) return 2;
  lcm_t* lcm = lcm_create(NULL);
  if (!lcm) return 3;
  if (argv[1][0] == 's') {  /* s SECONDS HANDLER_US */
    lcm_subscribe(lcm, "PROBE", on_message, argv[3]);
    for (int i = 0; i < 10 * atoi(argv[2]); ++i) lcm_handle_timeout(lcm, 100);
    printf("%d\n", received);
  } else {  /* p BYTES COUNT */
    void* bytes = calloc((size_t)atoi(argv[2]), 1);
    for (int i = 0; i < atoi(argv[3]); ++i) {
      lcm_publish(lcm, "PROBE", bytes, (unsigned)atoi(argv[2]));
      usleep(100000);
    }
    free(bytes);
  }
  lcm_destroy(lcm);
  return 0;
}
C
cc "$TMP/probe.c" -o "$TMP/probe" -llcm
export TMP
unset LCM_DEFAULT_URL
unshare -n sh -c '
  ip link set lo up && ip route add 224.0.0.0/4 dev lo
  echo "net.core.rmem_default = $(cat /proc/sys/net/core/rmem_default)"
  echo "| message [bytes] | received, handled at once | received, 2 ms per message |"
  for size in 60000 100000 150000 200000 300000 500000 760000; do
    row="| $size |"
    for handler_us in 0 2000; do
      "$TMP/probe" s 3 $handler_us >"$TMP/count" 2>/dev/null &
      sub=$!
      sleep 0.5
      "$TMP/probe" p $size 20
      wait $sub
      row="$row $(cat "$TMP/count") / 20 |"
    done
    echo "$row"
  done
'
