#!/usr/bin/env bash
# Runs a command (a flight, a replay) on a private LCM bus and the live
# viewer beside it, so that a browser on this machine can watch. The
# command's network namespace has only its own loopback; the viewer binds
# its HTTP socket here, on the host's loopback, and then joins the bus in
# the command's namespace (ofn_viewer --lcm-netns). The viewer is on the bus
# before the command starts, so it sees the mission and the map from the
# first message.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=deploy/version.sh
source "$repo/deploy/version.sh"
bin="$repo/build/bin"
port=8765
keep=0
host_network=0
log=""

usage() {
  cat <<EOF
usage: deploy/watch.sh [--port N] [--keep] [--log FILE] [--bin DIR] [--host-network]
                       [--] COMMAND [ARGS...]

Runs COMMAND in a private network namespace (as deploy/netns.sh does) and
the live viewer (ofn_viewer) beside it, then prints the page's URL and
opens it when a browser and a display are available.

  --port N          HTTP port of the page on 127.0.0.1 (default: 8765)
  --keep            keep serving the page after COMMAND ends, until Ctrl-C
                    (default: stop the viewer with COMMAND)
  --log FILE        the viewer's log (default: /tmp/ofn_viewer-<port>.log)
  --bin DIR         where ofn_viewer is (default: build/bin)
  --host-network    run COMMAND and the viewer on the host network instead
                    (default: a namespace when one can be made)
  -h, --help        show this help
  --version         show the version

Joining another namespace needs root (CAP_SYS_ADMIN). Without it, or when
no namespace can be made, COMMAND and the viewer share the host network
(LCM's ttl=0 keeps the traffic on this machine).

Example:
  deploy/watch.sh --keep -- deploy/replay.sh latest

Exit codes: COMMAND's; 2 for bad arguments; 1 when the viewer cannot start.
EOF
}

die_usage() {
  echo "watch.sh: error: $* (see --help)" >&2
  exit 2
}

while [[ $# -gt 0 ]]; do
  case "$1" in
    --port) [[ $# -ge 2 ]] || die_usage "--port needs a value"; port=$2; shift 2 ;;
    --port=*) port=${1#*=}; shift ;;
    --log) [[ $# -ge 2 ]] || die_usage "--log needs a value"; log=$2; shift 2 ;;
    --log=*) log=${1#*=}; shift ;;
    --bin) [[ $# -ge 2 ]] || die_usage "--bin needs a value"; bin=$2; shift 2 ;;
    --bin=*) bin=${1#*=}; shift ;;
    --keep) keep=1; shift ;;
    --host-network) host_network=1; shift ;;
    -h | --help) usage; exit 0 ;;
    --version) echo "watch.sh $(project_version "$repo")"; exit 0 ;;
    --) shift; break ;;
    -*) die_usage "unknown option '$1'" ;;
    *) break ;;
  esac
done
[[ $# -gt 0 ]] || die_usage "missing COMMAND"
[[ $port =~ ^[0-9]+$ ]] && ((port >= 1 && port <= 65535)) ||
  die_usage "--port must be a port number 1-65535, got '$port'"
[[ -x "$bin/ofn_viewer" ]] || {
  echo "watch.sh: error: $bin/ofn_viewer not built yet: run 'make build'" >&2
  exit 2
}
[[ -n "$log" ]] || log="/tmp/ofn_viewer-$port.log"

holder="" viewer="" command_pid="" url_file=""
cleanup() {
  # Only the processes started here, by their ids.
  for pid in $command_pid $viewer $holder; do kill "$pid" 2> /dev/null || true; done
  wait 2> /dev/null || true
  [[ -z $url_file ]] || rm -f "$url_file"
}
trap cleanup EXIT
# A stop signal goes on to COMMAND, which ends its run cleanly.
stop_signal=""
on_stop() {
  stop_signal=$1
  [[ -z $command_pid ]] || kill -"$1" -- "-$command_pid" 2> /dev/null || true
  [[ -n $command_pid ]] || exit $((128 + $2))
}
trap 'on_stop INT 2' INT
trap 'on_stop TERM 15' TERM

# The namespace: held open by a sleeping process under deploy/netns.sh,
# which also routes multicast on its loopback. Ready once that route is in.
netns_path=""
if [[ $host_network == 0 && $(id -u) == 0 ]] && command -v nsenter > /dev/null; then
  "$repo/deploy/netns.sh" sleep infinity &
  holder=$!
  for _ in $(seq 100); do
    kill -0 "$holder" 2> /dev/null || break
    if [[ $(readlink "/proc/$holder/ns/net" 2> /dev/null) != "$(readlink /proc/self/ns/net)" ]] &&
      nsenter --net="/proc/$holder/ns/net" ip route show 224.0.0.0/4 2> /dev/null | grep -q .; then
      netns_path="/proc/$holder/ns/net"
      break
    fi
    sleep 0.1
  done
  if [[ -z $netns_path ]]; then
    kill "$holder" 2> /dev/null || true
    holder=""
  fi
fi
[[ -n $netns_path || $host_network == 1 ]] ||
  echo "watch: no private network namespace to join (needs root and unshare); the bus is the host's (ttl=0)" >&2

url_file=$(mktemp /tmp/ofn_viewer_url.XXXXXX)
viewer_args=(--port "$port" --url-file "$url_file")
[[ -z $netns_path ]] || viewer_args+=(--lcm-netns "$netns_path")
"$bin/ofn_viewer" "${viewer_args[@]}" > "$log" 2>&1 &
viewer=$!
# The viewer writes its URL once it serves the page and listens on the bus.
for _ in $(seq 100); do
  [[ -s $url_file ]] && break
  kill -0 "$viewer" 2> /dev/null || break
  sleep 0.1
done
if [[ ! -s $url_file ]]; then
  echo "watch.sh: error: the viewer did not start; the end of its log, $log:" >&2
  tail -n 5 "$log" >&2 || true
  exit 1
fi
url=$(head -n 1 "$url_file")
echo "watch: the flight live at $url (viewer log: $log)"
if [[ -n ${DISPLAY:-}${WAYLAND_DISPLAY:-} ]] && command -v xdg-open > /dev/null; then
  xdg-open "$url" > /dev/null 2>&1 &
fi

status=0
# COMMAND runs in a process group of its own (job control on), where the
# terminal's Ctrl-C does not reach it but SIGINT is not ignored either, as
# it would be for a background command of a script: the one stop signal its
# group gets is the one forwarded above, which it handles as a Ctrl-C.
set -m
if [[ -n $netns_path ]]; then
  nsenter --net="$netns_path" -- "$@" &
else
  "$@" &
fi
command_pid=$!
set +m
# A trapped signal interrupts `wait`; wait again until COMMAND has ended.
while :; do
  status=0
  wait "$command_pid" || status=$?
  kill -0 "$command_pid" 2> /dev/null || break
done
command_pid=""
if [[ $keep == 1 && -z $stop_signal ]]; then
  echo "watch: $1 ended (exit code $status); the page stays at $url until Ctrl-C"
  wait "$viewer" || true
fi
exit "$status"
