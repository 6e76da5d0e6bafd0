#!/usr/bin/env bash
# The lockstep runner is deterministic: two runs of the same scenario give
# identical navigation, control, actuator and planning streams, and the
# flight arrives. bench4: every service is busy (mapping, global route,
# RH optimisation round the cube).
source "$(dirname "$0")/common.sh"
for run in a b; do
  "$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench4.yaml" --config-dir "$REPO/config" \
    --out "$WORK/$run" --quiet > "$WORK/$run.txt" || { cat "$WORK/$run.txt"; fail "run $run did not arrive"; }
done
# Heartbeats carry wall-clock load figures and the pid; everything the
# flight is made of must match to the bit.
for f in nav_state control_status actuator_cmd waypoints global_path ref_traj; do
  cmp "$WORK/a/$f.csv" "$WORK/b/$f.csv" || fail "$f differs between the two runs"
done
# Solver reports match except for the wall time each solve took.
cmp <(cut -d, -f1-3,5- "$WORK/a/solver_stats.csv") <(cut -d, -f1-3,5- "$WORK/b/solver_stats.csv") ||
  fail "solver reports differ between the two runs"
n=$(wc -l < "$WORK/a/nav_state.csv")
[[ $n -gt 1000 ]] || fail "only $n navigation samples"
grep -q "reached the last waypoint" "$WORK/a.txt" || fail "summary does not report arrival"
pass "two lockstep runs identical ($n navigation samples)"
