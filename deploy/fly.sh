#!/usr/bin/env bash
# Flies a scenario through the real service processes on LCM udpm:// (in a
# private network namespace when possible), records the bus, and writes the
# flight report: CSV per channel, summary.json/.txt and the flight figure.
# `make run` is this script with the Makefile's SCENARIO and RTF.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
program=fly.sh
# shellcheck source=deploy/flight_common.sh
source "$repo/deploy/flight_common.sh"
# shellcheck source=deploy/version.sh
source "$repo/deploy/version.sh"
scenario="$repo/sim/scenarios/bench3.yaml"
rtf=1.0
timeout=300
out=""
netns=1
watch=0
port=8765

usage() {
  cat <<EOF
usage: deploy/fly.sh [--scenario FILE] [--rtf X] [--out DIR] [--timeout S] [--host-network]
                     [--watch] [--port N]

Flies a scenario through the real service processes (deploy/launch.py) on
LCM multicast, records the bus, and writes the flight report: a CSV per
channel, summary.json, summary.txt and the figures flight.png, tracking.png.

  --scenario FILE   scenario to fly (default: sim/scenarios/bench3.yaml)
  --rtf X           simulation real-time factor (default: 1.0)
  --out DIR         results folder (default: results/run-YYYYmmdd-HHMMSS)
  --timeout S       wall-clock run limit in seconds (default: 300)
  --host-network    run on the host network instead of a private network
                    namespace (default: a namespace when one can be made)
  --watch           watch the flight live in a browser: the viewer
                    (deploy/watch.sh) joins the flight's bus and serves the
                    page on 127.0.0.1; its URL is printed (default: off)
  --port N          the page's HTTP port with --watch (default: 8765)
  -h, --help        show this help
  --version         show the version

The flight's LCM log is named in DIR/latest_log; replay the most recent
flight with 'deploy/replay.sh latest'.

Example:
  deploy/fly.sh --scenario sim/scenarios/popup.yaml --rtf 2

Exit codes: 1 when the flight's outcome is failure; 2 for bad arguments or
input, or when a service reported a configuration or usage error; otherwise
the launcher's (0 when the run ended normally, 3 when the run limit ended
it, 128+N when stopped by signal N).
EOF
}

while [[ $# -gt 0 ]]; do
  case "$1" in
    --host-network) netns=0; shift ;;
    --watch) watch=1; shift ;;
    --port) need_value "$1" $#; port=$2; shift 2 ;;
    --port=*) port=${1#*=}; shift ;;
    -h|--help) usage; exit 0 ;;
    --version) echo "fly.sh $(project_version "$repo")"; exit 0 ;;
    *) flight_option "$@"; shift "$taken" ;;
  esac
done
check_flight_options "$scenario" "$rtf" "$timeout" "$repo/build/bin"
if [[ $watch == 1 ]]; then
  [[ $port =~ ^[0-9]+$ ]] && ((port >= 1 && port <= 65535)) ||
    die_usage "--port must be a port number 1-65535, got '$port'"
  [[ -x "$repo/build/bin/ofn_viewer" ]] || die_usage "--watch needs ofn_viewer: run 'make build'"
fi
[[ -n "$out" ]] || out="$repo/results/run-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$out"

launch=(/usr/bin/python3 "$repo/deploy/launch.py" --scenario "$scenario" --rtf "$rtf"
        --out "$out" --timeout "$timeout")
echo "fly: scenario $scenario, real-time factor $rtf, results in $out"
status=0
if [[ $watch == 1 ]]; then
  watch_args=(--port "$port" --log "$out/viewer.log")
  [[ $netns == 1 ]] || watch_args+=(--host-network)
  "$repo/deploy/watch.sh" "${watch_args[@]}" -- "${launch[@]}" || status=$?
elif [[ $netns == 1 ]]; then
  "$repo/deploy/netns.sh" --fallback "${launch[@]}" || status=$?
else
  "${launch[@]}" || status=$?
fi
exit_if_no_flight "$status"
[[ -f "$out/latest_log" ]] || { echo "fly: no flight log was recorded" >&2; exit 1; }
log=$(cat "$out/latest_log")
echo
report_flight "$repo/build/bin" "$out" "$scenario" "$log"
[[ $watch == 1 ]] ||
  echo "  watch live        : make run WATCH=1 (deploy/fly.sh --watch) shows the flight in a browser"
finish_flight "$out" "$log" "$status"
