# SPDX-License-Identifier: BSD-3-Clause
# Sourced by the namespace scripts.

# Returns 1 (after saying why, as a SKIP line) unless this machine can run
# them: unshare, ip and lcm-logplayer installed, and a network namespace of
# our own allowed. Multicast is never tried on the host's network.
require_private_network() {
  if ! command -v unshare >/dev/null 2>&1 || ! command -v ip >/dev/null 2>&1 ||
     ! command -v lcm-logplayer >/dev/null 2>&1; then
    echo "SKIP: needs unshare (util-linux), ip (iproute2) and lcm-logplayer (liblcm-bin)"
    return 1
  fi
  if ! unshare -n true 2>/dev/null; then
    echo "SKIP: cannot create a network namespace; multicast is never tried on the host network"
    return 1
  fi
}

# Inside the namespace: brings loopback up with a multicast route on it,
# for LCM's udpm. Returns non-zero if either step fails.
loopback_multicast_up() {
  ip link set lo up && ip route add 224.0.0.0/4 dev lo
}

# wait_lcm_subscribed PID: waits until process $1 has bound LCM's
# UDP multicast port (LCM binds it with the first subscription), so that
# nothing is published before the subscriber listens. A fixed sleep was
# not enough on a loaded 2-core machine. Returns 1 after 20 s.
wait_lcm_subscribed() {
  i=0
  while [ $i -lt 200 ]; do
    ss -ulnp 2>/dev/null | grep -q ":7667 .*pid=$1," && return 0
    kill -0 "$1" 2>/dev/null || return 1
    sleep 0.1
    i=$((i + 1))
  done
  return 1
}
