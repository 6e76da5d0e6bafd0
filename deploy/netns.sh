#!/usr/bin/env bash
# Runs a command in a private network namespace whose loopback carries LCM
# multicast, so simulation and test traffic never leaves the machine and
# parallel runs never hear each other. Needs root (or unprivileged user
# namespaces); with --fallback it runs the command directly when a
# namespace cannot be made (LCM's ttl=0 still keeps multicast on the host).
set -euo pipefail
fallback=0
if [[ "${1:-}" == "--fallback" ]]; then fallback=1; shift; fi
if [[ $# -eq 0 ]]; then
  echo "usage: deploy/netns.sh [--fallback] COMMAND [ARGS...]" >&2
  exit 2
fi
setup='ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo'
if unshare -n true 2>/dev/null; then
  exec unshare -n bash -c "$setup && exec \"\$@\"" netns "$@"
elif unshare -rn true 2>/dev/null; then
  exec unshare -rn bash -c "$setup && exec \"\$@\"" netns "$@"
elif [[ $fallback == 1 ]]; then
  echo "netns: cannot create a private network namespace; running on the host network" >&2
  exec "$@"
else
  echo "netns: cannot create a private network namespace (needs root or user namespaces)" >&2
  exit 1
fi
