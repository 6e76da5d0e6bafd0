#!/usr/bin/env bash
# Dense fields and trap courses in their short form: two dense random
# fields of fixed seeds (bench/random_field.py --dense, which may be sealed)
# and sim/scenarios/trap_closing_gap.yaml (a pop-up closes the gap the
# vehicle is heading for), each flown once in lockstep for at most 100 s of
# simulated time, and sim/scenarios/trap_cul_de_sac.yaml (a U of walls too
# tall to climb) for its whole time, and sim/scenarios/trap_yard.yaml (walls
# all round the start whose tops the scanner cannot see from below) for
# 160 s, two at a time. What must hold on every
# flight, whether it reaches the goal or not: no clearance violation (least
# true clearance to the real obstacles >= 0.8 R_s) and no envelope excursion
# (speed, vertical speed, forward speed and commanded acceleration within
# their limits + 2 %, the flight verdict's limit failures). Whether a dense
# field's goal is reached is the Monte Carlo's business: a sealed field may
# end in a safe stop. The cul-de-sac has a route round the outside: the
# vehicle must get out of the U by the dead-end recovery (it looks around)
# and reach the goal. Out of the yard there is only the way over a wall:
# after a look that finds no route the recovery climbs to look over them;
# the vehicle must have crossed the start gate, outside the yard, by 160 s.
# Dense seed 24 gets stuck in front of gaps its global route runs through
# and its RH optimiser cannot fly: the optimiser must have told the planner
# of at least one such passage (NARROW_PASSAGES) by 100 s (7 on
# 2026-12-03; seed 158, the field of this check before, has flown past its
# gap without stopping since unseen space near the vehicle counts as
# obstacle).
source "$(dirname "$0")/common.sh"
SEEDS="1 24"
# Simulated seconds per flight: the course takes 60 s unobstructed and the
# avoidance happens within the first 100 s; a flight that stops hovers until
# the scenario's 200 s limit, which would cost minutes of wall time for
# nothing. A violation later than this is for the Monte Carlo to find.
MAX_TIME=100
# Two flights at a time load both cores (like campaign_short).
JOBS=2
scenarios=()
for seed in $SEEDS; do
  /usr/bin/python3 "$REPO/bench/random_field.py" --dense --seed "$seed" --out "$WORK/dense-$seed.yaml" ||
    fail "random_field.py --dense --seed $seed"
  scenarios+=("$WORK/dense-$seed.yaml")
done
scenarios+=("$REPO/sim/scenarios/trap_closing_gap.yaml" "$REPO/sim/scenarios/trap_yard.yaml")
# First: the longest flight here, its wall time overlaps the others.
scenarios=("$REPO/sim/scenarios/trap_cul_de_sac.yaml" "${scenarios[@]}")
fly() {
  local name code=0 limit=(--max-time "$MAX_TIME")
  name=$(basename "$1" .yaml)
  # The way out of the cul-de-sac takes minutes: its own time limit.
  [[ $name == trap_cul_de_sac ]] && limit=()
  [[ $name == trap_yard ]] && limit=(--max-time 160)
  "$BIN/ofn_sim_runner" --scenario "$1" --config-dir "$REPO/config" --out "$WORK/$name" \
    "${limit[@]}" --quiet > "$WORK/$name.txt" 2>&1 || code=$?
  echo "$code" > "$WORK/$name.code"
}
running=0
for scenario in "${scenarios[@]}"; do
  fly "$scenario" &
  running=$((running + 1))
  if (( running >= JOBS )); then wait -n; running=$((running - 1)); fi
done
wait
for scenario in "${scenarios[@]}"; do
  name=$(basename "$scenario" .yaml)
  code=$(cat "$WORK/$name.code")
  # Exit code 1 is the runner's verdict (e.g. the goal not reached), judged below.
  [[ $code == 0 || $code == 1 ]] || { tail -20 "$WORK/$name.txt"; fail "$name: runner exit code $code"; }
  [[ -f "$WORK/$name/summary.json" ]] || { tail -20 "$WORK/$name.txt"; fail "$name: no summary.json"; }
done
names=()
for scenario in "${scenarios[@]}"; do names+=("$(basename "$scenario" .yaml)"); done
/usr/bin/python3 - "$REPO" "$WORK" "${names[@]}" <<'PY' || fail "a flight came within 0.8 R_s of an obstacle or exceeded a limit"
import json, os, sys
repo, work, names = sys.argv[1], sys.argv[2], sys.argv[3:]
sys.path.insert(0, os.path.join(repo, "bench"))
import monte_carlo  # the Monte Carlo's own reading of the verdict
ok = True
for name in names:
    s = json.load(open(os.path.join(work, name, "summary.json")))
    k = 1.0 / s["metres_per_unit"]
    unit = s["display_unit"]
    rs = s["clearance_required"]
    least = s.get("min_clearance")
    if least is None:
        print("%s: no least clearance in the summary" % name)
        ok = False
        continue
    excursions = monte_carlo.envelope_excursions(s.get("failures") or [])
    outcome = s.get("outcome") or ("success" if s.get("success") else "failure")
    print("%s: %s%s, least clearance %.1f %s = %.2f R_s, max speed %.2f %s/s, %s" % (
        name, outcome, "" if not s.get("failures") else " (%s)" % "; ".join(s["failures"]),
        least * k, unit, least / rs, s["max_speed"] * k, unit,
        "limits kept" if not excursions else "limit exceeded: " + "; ".join(excursions)))
    if least < 0.8 * rs:
        print("%s: clearance violation, %.2f R_s < 0.8 R_s" % (name, least / rs))
        ok = False
    if excursions:
        ok = False
    if name == "trap_cul_de_sac":
        if s.get("rh_looking_around", 0) <= 0:
            print("%s: the dead-end recovery never looked around" % name)
            ok = False
        if outcome != "success":
            print("%s: %s, but a route exists round the outside" % (name, outcome))
            ok = False
    if name == "dense-24" and s.get("narrow_passages", 0) < 1:
        print("%s: no passage too narrow to fly was told to the planner" % name)
        ok = False
    if name == "trap_yard" and s.get("gate_start_t") is None:
        print("%s: %s, still inside the yard (start gate not crossed)" % (name, outcome))
        ok = False
sys.exit(0 if ok else 1)
PY
pass "two dense fields, the closing gap, the cul-de-sac and the yard flown with no clearance violation and no envelope excursion; out of the cul-de-sac to the goal, out of the yard over a wall, a narrow passage told to the planner"
