#!/bin/sh
# SPDX-License-Identifier: BSD-3-Clause
# Why a model of two or three datagrams is lost now and then at a
# subscriber that keeps LCM's defaults (docs/measurements/
# 2026-12-06-cloud-delivery.md): in a private network namespace (never the
# host's network), three subscribers on LCM's default URL count 30 clouds
# of 145 kB sent 333 ms apart, whole or cut into 60 kB messages (sent back
# to back or PACE ms apart, COPIES rounds), with or without depth-like
# traffic on the same multicast group (137 kB at 30 Hz on another channel,
# as lcm-logplayer plays a recording) and with or without busy loops
# loading the CPUs (three). Each cell: clouds complete / messages received /
# datagrams the socket dropped (/proc/net/udp), per subscriber.
# Needs root (unshare -n), a C compiler and liblcm-dev. About 15 s a row.
set -eu
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cat >"$TMP/probe.c" <<'C'
/* SPDX-License-Identifier: BSD-3-Clause */
#include <lcm/lcm.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
static int received = 0;
static long bytes_got = 0;
static unsigned char got[1000][16];
static int complete = 0;
static void on_message(const lcm_recv_buf_t* rbuf, const char* channel, void* u) {
  (void)channel, (void)u;
  ++received;
  bytes_got += rbuf->data_size;
  int h[3];
  memcpy(h, rbuf->data, sizeof h);
  if (h[0] < 0 || h[0] >= 1000 || h[1] < 0 || h[1] >= 16 || h[2] < 1 || h[2] > 16) return;
  if (got[h[0]][h[1]]) return;
  got[h[0]][h[1]] = 1;
  int all = 1;
  for (int c = 0; c < h[2]; ++c) all &= got[h[0]][c];
  complete += all;
}
static void sleep_ms(double ms) {
  struct timespec ts = {(time_t)(ms / 1000), (long)((ms - 1000 * (long)(ms / 1000)) * 1e6)};
  nanosleep(&ts, NULL);
}
/* this process's UDP sockets' drop counters, from /proc/net/udp */
static long own_drops(void) {
  long drops = 0;
  DIR* d = opendir("/proc/self/fd");
  struct dirent* e;
  char path[300], link[64];
  unsigned long inodes[64];
  int n = 0;
  while (d && (e = readdir(d)) && n < 64) {
    snprintf(path, sizeof path, "/proc/self/fd/%s", e->d_name);
    ssize_t len = readlink(path, link, sizeof link - 1);
    if (len <= 0) continue;
    link[len] = 0;
    if (sscanf(link, "socket:[%lu]", &inodes[n]) == 1) ++n;
  }
  if (d) closedir(d);
  FILE* f = fopen("/proc/net/udp", "r");
  char line[512];
  if (!f) return -1;
  fgets(line, sizeof line, f);
  while (fgets(line, sizeof line, f)) {
    unsigned long inode; long drop;
    /* sl local rem st tx:rx tr:when retr uid timeout inode ref pointer drops */
    if (sscanf(line, "%*s %*s %*s %*s %*s %*s %*s %*s %*s %lu %*s %*s %ld", &inode, &drop) != 2) continue;
    for (int i = 0; i < n; ++i) if (inodes[i] == inode) drops += drop;
  }
  fclose(f);
  return drops;
}
int main(int argc, char** argv) {
  lcm_t* lcm = lcm_create(NULL);
  if (!lcm || argc < 2) return 3;
  if (argv[1][0] == 's') { /* s SECONDS CHANNEL: count messages */
    lcm_subscribe(lcm, argv[3], on_message, NULL);
    time_t end = time(NULL) + atoi(argv[2]);
    while (time(NULL) < end) lcm_handle_timeout(lcm, 100);
    printf("%d %d %ld\n", complete, received, own_drops());
  } else if (argv[1][0] == 'd') { /* d BYTES HZ SECONDS: depth-like traffic */
    size_t size = (size_t)atoi(argv[2]);
    double period = 1000.0 / atof(argv[3]);
    void* bytes = calloc(size, 1);
    for (int i = 0; i < atof(argv[4]) * atof(argv[3]); ++i) {
      lcm_publish(lcm, "DEPTH", bytes, (unsigned)size);
      sleep_ms(period);
    }
  } else { /* p BYTES COUNT PERIOD_MS CHUNK_BYTES PACE_MS COPIES: clouds, whole or in chunks */
    size_t size = (size_t)atoi(argv[2]);
    int count = atoi(argv[3]);
    double period = atof(argv[4]);
    size_t chunk = (size_t)atoi(argv[5]);
    double pace = atof(argv[6]);
    int copies = atoi(argv[7]);
    char* bytes = calloc(size, 1);
    for (int i = 0; i < count; ++i) {
      int nchunks = chunk == 0 ? 1 : (int)((size + chunk - 1) / chunk);
      if (chunk == 0) {
        int h[3] = {i, 0, 1};
        memcpy(bytes, h, sizeof h);
        lcm_publish(lcm, "CLOUD", bytes, (unsigned)size);
      } else {
        for (int c = 0; c < copies; ++c)
          for (size_t off = 0; off < size; off += chunk) {
            size_t n = size - off < chunk ? size - off : chunk;
            int h[3] = {i, (int)(off / chunk), nchunks};
            memcpy(bytes + off, h, sizeof h);
            lcm_publish(lcm, "CLOUD", bytes + off, (unsigned)n);
            if (pace > 0) sleep_ms(pace);
          }
      }
      sleep_ms(period);
    }
  }
  lcm_destroy(lcm);
  return 0;
}
C
cc -O2 "$TMP/probe.c" -o "$TMP/probe" -llcm
cat >"$TMP/row.sh" <<'R'
P=$TMP/probe
depth=$1 load=$2 chunk=$3 pace=$4 copies=$5
subs=
for k in 1 2 3; do $P s 13 CLOUD >"$TMP/sub$k.out" & subs="$subs $!"; done
sleep 0.5
dp=
[ "$depth" = 1 ] && { $P d 137000 30 11 & dp=$!; }
busy=
if [ "$load" = 1 ]; then for k in 1 2 3; do sh -c 'while :; do :; done' & busy="$busy $!"; done; fi
$P p 145000 30 333 $chunk $pace $copies
for p in $subs; do wait $p; done
for p in $busy; do kill $p; done
[ -n "$dp" ] && wait $dp
row="| $depth | $load | $chunk | $pace | $copies |"
for k in 1 2 3; do row="$row $(tr ' ' / <"$TMP/sub$k.out") |"; done
echo "$row"
R
export TMP
unset LCM_DEFAULT_URL
unshare -n sh -c '
  ip link set lo up && ip route add 224.0.0.0/4 dev lo
  echo "net.core.rmem_default = $(cat /proc/sys/net/core/rmem_default)"
  echo "| depth traffic | CPU load | slice [bytes] (0: whole) | gap [ms] | rounds | subscriber 1 | 2 | 3 |"
  echo "|---|---|---|---|---|---|---|---|"
  for depth in 0 1; do
    for load in 0 1; do
      sh "$TMP/row.sh" $depth $load 0 0 1
      sh "$TMP/row.sh" $depth $load 60000 0 1
      sh "$TMP/row.sh" $depth $load 60000 10 1
    done
  done
  for rerun in 1 2; do
    sh "$TMP/row.sh" 1 1 0 0 1
    sh "$TMP/row.sh" 1 1 60000 5 1
    sh "$TMP/row.sh" 1 1 60000 10 1
    sh "$TMP/row.sh" 1 1 60000 10 2
  done
'
