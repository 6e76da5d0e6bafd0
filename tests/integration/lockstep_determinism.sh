#!/usr/bin/env bash
# The lockstep runner is deterministic: two runs of the same scenario give
# identical navigation, control and actuator streams, and the flight arrives.
source "$(dirname "$0")/common.sh"
for run in a b; do
  "$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/open.yaml" --config-dir "$REPO/config" \
    --out "$WORK/$run" --quiet > "$WORK/$run.txt" || { cat "$WORK/$run.txt"; fail "run $run did not arrive"; }
done
# Heartbeats carry wall-clock load figures and the pid; everything the
# flight is made of must match to the bit.
for f in nav_state control_status actuator_cmd waypoints; do
  cmp "$WORK/a/$f.csv" "$WORK/b/$f.csv" || fail "$f differs between the two runs"
done
n=$(wc -l < "$WORK/a/nav_state.csv")
[[ $n -gt 1000 ]] || fail "only $n navigation samples"
grep -q "reached the last waypoint" "$WORK/a.txt" || fail "summary does not report arrival"
pass "two lockstep runs identical ($n navigation samples)"
