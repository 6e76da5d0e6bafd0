#!/usr/bin/env bash
# The whole stack over a bad link, in the lockstep runner: bench3 with 10 %
# of the datagrams between hosts lost (about half the scans and two plans
# in three, being several datagrams long). The flight must cross the finish
# gate within every rule of the report, and a lossy run must repeat to the
# bit like a clean one.
source "$(dirname "$0")/common.sh"
fly() {  # seed, output name
  "$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/bench3.yaml" --config-dir "$REPO/config" \
    --process-table "$REPO/deploy/processes.yaml" --link-loss 0.1 --link-seed "$1" \
    --out "$WORK/$2" --quiet > "$WORK/$2.txt" 2>&1 ||
    { cat "$WORK/$2.txt"; fail "seed $1: the flight failed"; }
  grep -E "^link loss|outcome|max speed|least clearance" "$WORK/$2.txt"
  grep -q "outcome *: success" "$WORK/$2.txt" || fail "seed $1: not a success"
  lost=$(sed -n 's/^link loss .*: \([0-9]*\) of \([0-9]*\) messages.*/\1/p' "$WORK/$2.txt")
  [[ -n "$lost" && "$lost" -gt 1000 ]] || fail "seed $1: the link lost only '${lost}' messages"
}
fly 1 a
fly 1 b
fly 2 c
for f in nav_state control_status ref_traj; do
  cmp "$WORK/a/$f.csv" "$WORK/b/$f.csv" || fail "$f differs between two runs with the same seed"
done
cmp -s "$WORK/a/nav_state.csv" "$WORK/c/nav_state.csv" && fail "another seed lost the same messages"
pass "bench3 over a link losing 10 % of its datagrams: success on two seeds, repeatable"
