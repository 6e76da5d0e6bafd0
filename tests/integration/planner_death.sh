#!/usr/bin/env bash
# The planner's death is not the vehicle's: on bench3, once the RH optimiser
# has taken over in front of the wall, it is stopped (SIGSTOP) for 3 s and
# then killed (kill -9). The controller must fly the last plan's stop and
# hover rather than waypoint guidance into the wall; the restarted optimiser
# takes over again. The flight must keep 0.8 R_s from the wall, stay in its
# envelope (the benchmark verdict's rules) and finish.
# The ground station's flight monitor must say the optimiser fell silent
# (its heartbeats stop while it is stopped; the monitor here reports a
# silence of 2 s of wall time, the default is 3) and heard again.
source "$(dirname "$0")/common.sh"
scenario="$REPO/sim/scenarios/bench3.yaml"
sed '/ofn_flight_monitor/ s|"--scenario", "{scenario}"\]|"--scenario", "{scenario}", "--silence", "2"]|' \
  "$REPO/deploy/processes.yaml" > "$WORK/processes.yaml"
grep -q -- '"--silence", "2"' "$WORK/processes.yaml" || fail "the monitor's command line was not found in deploy/processes.yaml"
/usr/bin/python3 "$REPO/deploy/launch.py" --table "$WORK/processes.yaml" --scenario "$scenario" \
  --bin "$BIN" --rtf 2 --out "$WORK/run" --timeout 200 --no-pin > "$WORK/launch.txt" 2>&1 &
launcher=$!
# Wait for the optimiser to engage (its log line reaches the launcher's output).
for _ in $(seq 1 120); do
  grep -q "avoidance engages" "$WORK/launch.txt" && break
  sleep 0.5
done
grep -q "avoidance engages" "$WORK/launch.txt" || { kill $launcher; fail "avoidance never engaged"; }
sleep 1
# Only this launcher's optimiser: tests share the process table.
pid=$(pgrep -P $launcher -f "$BIN/ofn_rh_optimizer" | head -1) || true
[[ -n "$pid" ]] || { kill $launcher; fail "no rh_optimizer process"; }
kill -STOP "$pid"
echo "stopped the RH optimiser for 3 s"
sleep 3
kill -CONT "$pid"
sleep 1
kill -KILL "$pid"
echo "killed the RH optimiser"
wait $launcher || { tail -40 "$WORK/launch.txt"; fail "launcher exit code $?"; }
grep -q "flying its stop" "$WORK/launch.txt" || fail "the controller never flew the plan's stop"
grep "monitor: no heartbeat\|monitor: heartbeats again" "$WORK/launch.txt" || true
grep -q "monitor: no heartbeat for 2 s (wall) from: .*rh_optimizer" "$WORK/launch.txt" ||
  fail "the flight monitor never reported the stopped optimiser silent"
grep -q "monitor: heartbeats again from: .*rh_optimizer" "$WORK/launch.txt" ||
  fail "the flight monitor never heard the optimiser again"
log=$(cat "$WORK/run/latest_log")
"$BIN/ofn_flight_report" --log "$log" --scenario "$scenario" --out "$WORK/report" \
  > "$WORK/report.txt" || true
cat "$WORK/report.txt"
/usr/bin/python3 - "$WORK/report/summary.json" <<'PY' || fail "the flight broke a rule of the verdict or did not finish"
import json, sys
s = json.load(open(sys.argv[1]))
print("least clearance %.2f m (0.8 R_s = %.2f m), max speed %.2f m/s (limit %.2f m/s)" % (
    s["min_clearance"], 0.8 * s["clearance_required"], s["max_speed"], s["limits"]["max_speed"]))
print("outcome %s %s" % (s["outcome"], "; ".join(s["failures"])))
# The planner's death costs neither the clearance nor the envelope: the
# benchmark verdict's every rule (0.8 R_s, speeds and the reference's
# acceleration within the limit + 2 %, the controller's command within its
# bound, no reference jump) and the finish gate. Before the controller's
# speed governor, resuming from the stop's hover overshot the speed limit
# by 14-19 % in about half the runs; on 2026-12-03 nine runs flew at most
# 3.07 m/s against 3.05.
ok = s["min_clearance"] >= 0.8 * s["clearance_required"]
ok = ok and s["crossed_finish"] and s["reached_last_waypoint"]
ok = ok and s["outcome"] == "success" and not s["failures"]
sys.exit(0 if ok else 1)
PY
pass "the optimiser stopped and killed mid-avoidance: the vehicle flew the stop, kept 0.8 R_s and the envelope, and finished"
