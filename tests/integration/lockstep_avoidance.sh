#!/usr/bin/env bash
# End to end in the lockstep runner, every service in the loop: bench1 goes
# over its wall, bench4 goes around its cube, both cross the finish gate,
# and neither comes closer than R_s to the real obstacle surfaces.
source "$(dirname "$0")/common.sh"
for course in bench1 bench4; do
  "$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/$course.yaml" --config-dir "$REPO/config" \
    --out "$WORK/$course" --quiet > "$WORK/$course.txt" ||
    { cat "$WORK/$course.txt"; fail "$course: the flight did not cross the finish gate"; }
  grep -E "gate-to-gate|least clearance|RH optimiser" "$WORK/$course.txt"
done
/usr/bin/python3 - "$WORK" <<'PY' || fail "a course was not flown the way its table says, or too close"
import csv, json, sys
work = sys.argv[1]
ft = 0.3048
ok = True
for course, way in (("bench1", "over"), ("bench4", "around")):
    s = json.load(open("%s/%s/summary.json" % (work, course)))
    rows = [{k.split(" [")[0]: v for k, v in r.items()}  # "down [m]" -> "down"
            for r in csv.DictReader(open("%s/%s/nav_state.csv" % (work, course)))]
    top = max(-float(r["down"]) for r in rows)
    wide = max(abs(float(r["east"])) for r in rows)
    print("%s: least clearance %.2f m (R_s %.2f m), highest %.1f m, widest %.1f m"
          % (course, s["min_clearance"], s["clearance_required"], top, wide))
    if s["min_clearance"] < s["clearance_required"]:
        print("%s: inside R_s of a real obstacle" % course)
        ok = False
    if way == "over" and not (top >= (140 + 20) * ft - 0.5 and wide < 20 * ft):
        print("bench1: did not climb over the 140 ft wall")
        ok = False
    if way == "around" and not (wide >= (30 + 20) * ft - 0.5 and top < (120 + 20) * ft):
        print("bench4: did not go around the 60 ft cube")
        ok = False
sys.exit(0 if ok else 1)
PY
pass "bench1 over the wall, bench4 around the cube, both outside R_s of the real obstacles"
