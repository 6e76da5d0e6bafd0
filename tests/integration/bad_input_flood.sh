#!/usr/bin/env bash
# Random bytes, NaN-filled messages and well-formed forgeries (a clock jump,
# a DONE, a plan at five times the speed limit, a cyclic beyond its range)
# on every channel during a flight: nothing crashes (the live viewer
# included, which still serves its page afterwards), the rejection counters
# rise, the run is not ended by the forged DONE, the controller never flies
# a reference faster than the limit, and the flight completes.
source "$(dirname "$0")/common.sh"
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/open.yaml" \
  --bin "$BIN" --rtf 4 --out "$WORK/run" --timeout 150 --no-pin --max-restarts 0 \
  > "$WORK/launch.txt" 2>&1 &
launcher=$!
# The live viewer listens to the same flood.
"$BIN/ofn_viewer" --port 0 --url-file "$WORK/viewer_url" > "$WORK/viewer.txt" 2>&1 &
viewer=$!
sleep 3
"$BIN/ofn_bus_fuzz" --expect vehicle_sim --expect controller --expect flight_monitor \
  --expect viewer ||
  { kill -INT $launcher; wait $launcher || true; kill $viewer; fail "a service died or rejected nothing"; }
# After the flood the viewer still serves the flight it watches.
/usr/bin/python3 - "$(cat "$WORK/viewer_url")" <<'PY' ||
import json, sys, urllib.request
s = json.load(urllib.request.urlopen(sys.argv[1] + "api/snapshot", timeout=10))
print("viewer: %d rejected, %d of them by the view's stamp order; vehicle at north %.1f m"
      % (s["bus"]["rejected"], s["counters"]["rejected_total"], s["vehicle"]["position"][0]))
sys.exit(0 if s["bus"]["rejected"] > 0 and s["vehicle"] is not None else 1)
PY
  { kill -INT $launcher; wait $launcher || true; kill $viewer; fail "the viewer stopped serving or rejected nothing"; }
kill -INT $viewer
wait $viewer || fail "the viewer did not stop cleanly after the flood"
wait $launcher || { tail -40 "$WORK/launch.txt"; fail "launcher exit code $? after the flood"; }
if grep -qi "restarting" "$WORK/launch.txt"; then fail "a service had to be restarted"; fi
log=$(cat "$WORK/run/latest_log")
# Exit 1 is the report's verdict of failure; this test asks for completion.
"$BIN/ofn_flight_report" --log "$log" --scenario "$REPO/sim/scenarios/open.yaml" \
  --out "$WORK/report" > "$WORK/report.txt" || [[ $? == 1 ]] || fail "report failed"
grep -q "reached the last waypoint" "$WORK/report.txt" || fail "flight did not complete"
grep -q "monitor: DONE not taken" "$WORK/launch.txt" || fail "the forged DONE went unnoticed"
# The forged plan at five times the speed limit was never flown: the
# controller's reference (waypoint or trajectory mode; the forged statuses
# in the log are DONE or NaN) stayed within the limit. (The flown speed
# depends on the load of a machine running other tests beside this one.)
/usr/bin/python3 - "$WORK/report" <<'PY' || fail "the controller flew a reference beyond the speed limit"
import csv, json, math, sys
limit = json.load(open(sys.argv[1] + "/summary.json"))["limits"]["max_speed"]
fastest = 0.0
for r in csv.DictReader(open(sys.argv[1] + "/control_status.csv")):
    row = {k.split(" [")[0]: v for k, v in r.items()}  # "ref_vn [m/s]" -> "ref_vn"
    v = [float(row[k]) for k in ("ref_vn", "ref_ve", "ref_vd")]
    if row["mode"] in ("1", "2") and all(math.isfinite(x) for x in v):
        fastest = max(fastest, math.sqrt(sum(x * x for x in v)))
print("fastest reference %.3f m/s, limit %.3f m/s" % (fastest, limit))
sys.exit(0 if 0 < fastest <= 1.02 * limit else 1)
PY
pass "flood rejected and counted; flight completed"
