#!/usr/bin/env bash
# Runs a command in a private network namespace whose loopback carries LCM
# multicast, so simulation and test traffic never leaves the machine and
# parallel runs never hear each other. Needs root (or unprivileged user
# namespaces); with --fallback it runs the command directly when a
# namespace cannot be made (LCM's ttl=0 still keeps multicast on the host).
set -euo pipefail
usage() {
  cat <<EOF
usage: deploy/netns.sh [--fallback] COMMAND [ARGS...]

Runs COMMAND in a private network namespace whose loopback carries LCM
multicast, so its traffic never leaves the machine.

  --fallback   run COMMAND on the host network when no namespace can be made
               (default: fail with exit code 1)
  -h, --help   show this help
  --version    show the version

Example:
  deploy/netns.sh --fallback deploy/launch.py --scenario sim/scenarios/bench3.yaml

Exit codes: COMMAND's; 2 for bad arguments; 1 when no namespace can be made
and --fallback is not given.
EOF
}
fallback=0
case "${1:-}" in
  -h|--help) usage; exit 0 ;;
  --version)
    # shellcheck source=deploy/version.sh
    source "$(dirname "$0")/version.sh"
    echo "netns.sh $(project_version "$(cd "$(dirname "$0")/.." && pwd)")"
    exit 0
    ;;
  --fallback) fallback=1; shift ;;
esac
if [[ $# -eq 0 ]]; then
  echo "netns.sh: error: missing COMMAND (see --help)" >&2
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
