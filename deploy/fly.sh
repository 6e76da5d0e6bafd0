#!/usr/bin/env bash
# Flies a scenario through the real service processes on LCM udpm:// (in a
# private network namespace when possible), records the bus, and writes the
# flight report: CSV per channel, summary.json/.txt and the flight figure.
#
#   deploy/fly.sh [--scenario FILE] [--rtf X] [--out DIR] [--timeout S] [--host-network]
#
# Exit code: 1 when the flight's outcome is failure, else the launcher's
# (0 when the run ended normally); 2 for bad arguments.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
scenario="$repo/sim/scenarios/bench3.yaml"
rtf=1.0
timeout=300
out=""
netns=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenario) scenario=$2; shift 2 ;;
    --rtf) rtf=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --timeout) timeout=$2; shift 2 ;;
    --host-network) netns=0; shift ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "fly.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ -f "$scenario" ]] || { echo "fly.sh: scenario file '$scenario' not found" >&2; exit 2; }
[[ -x "$repo/build/bin/ofn_flight_report" ]] || { echo "fly.sh: not built yet: run 'make build'" >&2; exit 2; }
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
[[ -f "$out/latest_log" ]] || { echo "fly: no flight log was recorded" >&2; exit 1; }
log=$(cat "$out/latest_log")
echo
# The report's exit code is the verdict (1: the flight failed); the figure is
# drawn either way, since a failed flight is the one to look at.
report_status=0
"$repo/build/bin/ofn_flight_report" --log "$log" --scenario "$scenario" \
  --controller-config "$repo/config/controller.yaml" --out "$out" || report_status=$?
/usr/bin/python3 "$repo/services/tools/plot_flight.py" "$out" >/dev/null &&
  echo "  figures           : $out/flight.png, $out/tracking.png"
if [[ $report_status == 1 ]]; then
  echo "fly: the flight failed (see the outcome above)" >&2
  exit 1
elif [[ $report_status != 0 ]]; then
  echo "fly: the flight report could not be written (exit code $report_status)" >&2
  exit $report_status
fi
if [[ $status != 0 ]]; then
  echo "fly: the flight did not complete (launcher exit code $status)" >&2
fi
exit $status
