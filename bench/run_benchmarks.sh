#!/usr/bin/env bash
# make bench: core step costs (Google Benchmark) and the lockstep real-time
# factor of the no-obstacle course. Writes results/bench/ and prints a table
# ready for the README.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
[[ "$build" = /* ]] || build="$repo/$build"
out="$repo/results/bench"
mkdir -p "$out"

echo "== core step costs (Google Benchmark) =="
"$build/bin/ofn_benchmarks" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
  --benchmark_out="$out/core.json" --benchmark_out_format=json | tee "$out/core.txt"

echo
echo "== lockstep runner, open course (5 runs) =="
rtf_list=()
for i in 1 2 3 4 5; do
  line=$("$build/bin/ofn_sim_runner" --scenario "$repo/sim/scenarios/open.yaml" \
           --config-dir "$repo/config" --quiet | grep '^lockstep:')
  echo "$line"
  rtf_list+=("$(sed -E 's/.*\(([0-9.]+)x real time\).*/\1/' <<< "$line")")
done
sorted=$(printf '%s\n' "${rtf_list[@]}" | sort -n)
median=$(sed -n 3p <<< "$sorted")
{
  echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
  echo "lockstep real-time factor, open course (median of 5): ${median}x (goal >= 50x)"
} | tee "$out/lockstep.txt"

echo
echo "== tracking sweep: adaptive vs non-adaptive (airframe errors x crosswinds) =="
"$build/bin/ofn_tracking_sweep" --out "$out" | tail -n 1
cat "$out/tracking_sweep.md"
/usr/bin/python3 "$repo/bench/plot_tracking_sweep.py" "$out/tracking_sweep.csv" "$out/tracking_sweep.png" ||
  echo "(plot skipped: python3 with matplotlib needed)"

echo
echo "== planners in the loop: bench1 and bench4 in lockstep (RH solve times from the flight) =="
for course in bench1 bench4; do
  "$build/bin/ofn_sim_runner" --scenario "$repo/sim/scenarios/$course.yaml" \
    --config-dir "$repo/config" --out "$out/flight-$course" --quiet > "$out/flight-$course.txt" || true
  echo "$course:"
  grep -E "^lockstep:|gate-to-gate|least clearance|RH optimiser|max speed|max commanded" \
    "$out/flight-$course.txt" | sed 's/^/  /'
done

echo
echo "== benchmark campaign: seven courses in lockstep, bench3 through the processes (results/campaign) =="
/usr/bin/python3 "$repo/bench/campaign.py" --bin "$build/bin" || echo "(campaign: not every goal met, see results/campaign/report.md)"

echo
echo "== Monte Carlo: ${MC_RUNS:-300} random fields in lockstep (results/monte_carlo; MC_RUNS=N to change) =="
/usr/bin/python3 "$repo/bench/monte_carlo.py" --bin "$build/bin" --runs "${MC_RUNS:-300}" ||
  echo "(Monte Carlo: success below the 99 % goal, see results/monte_carlo/report.md)"
