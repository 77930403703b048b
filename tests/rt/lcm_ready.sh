# Sourced by the namespace scripts: waits until process $1 has bound LCM's
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
