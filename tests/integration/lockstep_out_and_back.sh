#!/usr/bin/env bash
# End to end in the lockstep runner: out_and_back flies bench6's baffle out
# to x = 500 ft and back over the same line. The controller's guidance, the
# global planner and the RH optimiser must agree on which of the two legs
# is flown; the flight must reach the turn, come back to the start through
# the baffle, and keep R_s from the blocks both ways.
source "$(dirname "$0")/common.sh"
"$BIN/ofn_sim_runner" --scenario "$REPO/sim/scenarios/out_and_back.yaml" \
  --config-dir "$REPO/config" --out "$WORK/run" --quiet > "$WORK/run.txt" ||
  { cat "$WORK/run.txt"; fail "the vehicle did not fly out and back"; }
grep -E "outcome|gate-to-gate|max speed|least clearance|RH optimiser" "$WORK/run.txt"
/usr/bin/python3 - "$WORK/run" <<'PY' || fail "the route was not flown out and back, or too close"
import csv, json, sys
run = sys.argv[1]
ft = 0.3048
s = json.load(open(run + "/summary.json"))
def rows(name):
    return [{k.split(" [")[0]: v for k, v in r.items()} for r in csv.DictReader(open("%s/%s.csv" % (run, name)))]
nav = rows("nav_state")
status = rows("control_status")
north = [float(r["north"]) for r in nav]
turn = max(range(len(north)), key=lambda i: north[i])
waypoints = [int(r["active_waypoint"]) for r in status]
ok = True
print("outcome %s, least clearance %.2f m (R_s %.2f m), furthest %.1f ft, end %.1f ft, legs flown %s"
      % (s["outcome"], s["min_clearance"], s["clearance_required"], north[turn] / ft,
         north[-1] / ft, sorted(set(waypoints))))
if s["outcome"] != "success":
    print("the flight was not a success"); ok = False
if s["min_clearance"] < s["clearance_required"]:
    print("inside R_s of a block"); ok = False
if north[turn] < (500 - 10) * ft:
    print("never reached the turn at x = 500 ft"); ok = False
if abs(north[-1] - (-100 * ft)) > 10 * ft + 0.5:
    print("did not come back to the start"); ok = False
# Through the baffle on the way back too: after the turn the vehicle
# crossed x = 150 ft (the first pair of blocks) going home.
if not any(n < 150 * ft for n in north[turn:]):
    print("the way back did not pass the baffle"); ok = False
if 2 not in waypoints or waypoints[-1] != 2:
    print("the controller never flew the way back (waypoint 2)"); ok = False
sys.exit(0 if ok else 1)
PY
pass "out to the turn and back to the start through the baffle, outside R_s both ways"
