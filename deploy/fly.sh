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
scenario="$repo/sim/scenarios/bench3.yaml"
rtf=1.0
timeout=300
out=""
netns=1

usage() {
  cat <<EOF
usage: deploy/fly.sh [--scenario FILE] [--rtf X] [--out DIR] [--timeout S] [--host-network]

Flies a scenario through the real service processes (deploy/launch.py) on
LCM multicast, records the bus, and writes the flight report: a CSV per
channel, summary.json, summary.txt and the figures flight.png, tracking.png.

  --scenario FILE   scenario to fly (default: sim/scenarios/bench3.yaml)
  --rtf X           simulation real-time factor (default: 1.0)
  --out DIR         results folder (default: results/run-YYYYmmdd-HHMMSS)
  --timeout S       wall-clock run limit in seconds (default: 300)
  --host-network    run on the host network instead of a private network
                    namespace (default: a namespace when one can be made)
  -h, --help        show this help

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
    -h|--help) usage; exit 0 ;;
    *) flight_option "$@"; shift "$taken" ;;
  esac
done
check_flight_options "$scenario" "$rtf" "$timeout" "$repo/build/bin"
[[ -n "$out" ]] || out="$repo/results/run-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$out"

launch=(/usr/bin/python3 "$repo/deploy/launch.py" --scenario "$scenario" --rtf "$rtf"
        --log-dir "$out" --timeout "$timeout")
echo "fly: scenario $scenario, real-time factor $rtf, results in $out"
status=0
if [[ $netns == 1 ]]; then
  "$repo/deploy/netns.sh" --fallback "${launch[@]}" || status=$?
else
  "${launch[@]}" || status=$?
fi
exit_if_no_flight "$status"
[[ -f "$out/latest_log" ]] || { echo "fly: no flight log was recorded" >&2; exit 1; }
log=$(cat "$out/latest_log")
echo
report_flight "$repo/build/bin" "$out" "$scenario" "$log"
finish_flight "$out" "$log" "$status"
