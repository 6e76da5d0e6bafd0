#!/usr/bin/env bash
# The launcher's hang watch on real services (deploy/processes.yaml's
# heartbeat settings): a SIGSTOPped mapper is found hung, killed and
# restarted, and the new one is heard; then a SIGSTOPped vehicle_sim, which
# stops every follower's heartbeats with it: only vehicle_sim is killed,
# and the restarted one resumes the flight from its checkpoint. Then, with
# the default hang timeout, a follower stopped for 3 s is not restarted.
source "$(dirname "$0")/common.sh"
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/open.yaml" \
  --only vehicle_sim,controller,mission_uplink,mapper --bin "$BIN" --rtf 1 --no-record \
  --log-dir "$WORK/run" --timeout 120 --no-pin --hang-timeout 2 > "$WORK/launch.txt" 2>&1 &
launcher=$!
stop_launcher() { kill -INT $launcher 2> /dev/null || true; wait $launcher || true; }
trap 'stop_launcher; [[ -n ${OFN_KEEP_WORK:-} ]] || rm -rf "$WORK"' EXIT
# This launcher's own child (tests side by side share the PID namespace).
child() { pgrep -P $launcher -f "$BIN/$1" | head -1; }
# Waits up to $2 s for a line matching $1 in the launcher's output ($out).
out="$WORK/launch.txt"
wait_for() {
  local deadline=$((SECONDS + $2))
  until grep -q -- "$1" "$out"; do
    ((SECONDS < deadline)) || { tail -30 "$out"; fail "no '$1' within $2 s"; }
    kill -0 $launcher 2> /dev/null || { tail -30 "$out"; fail "the launcher stopped"; }
    sleep 0.2
  done
}
hung_count() { grep -c "$1 is HUNG" "$WORK/launch.txt" || true; }

# Flying (the controller has the mission) before anything is stopped.
wait_for "hang watch: vehicle_sim (own), controller (sim_clock)" 10
sleep 5
mapper=$(child ofn_mapper)
[[ -n $mapper ]] || fail "no mapper process"
kill -STOP "$mapper"
echo "stopped the mapper (pid $mapper)"
wait_for "mapper is HUNG (no heartbeat on HEARTBEAT_MAPPER for" 20
wait_for "mapper exited with code 137 (signal SIGKILL) after it hung; restarting" 10
kill -0 "$mapper" 2> /dev/null && fail "the stopped mapper $mapper is still there"
sleep 3
restarted=$(child ofn_mapper)
[[ -n $restarted && $restarted != "$mapper" ]] || fail "the mapper was not restarted"
echo "mapper restarted (pid $restarted)"

vehicle_sim=$(child ofn_vehicle_sim)
[[ -n $vehicle_sim ]] || fail "no vehicle_sim process"
kill -STOP "$vehicle_sim"
echo "stopped vehicle_sim (pid $vehicle_sim)"
wait_for "vehicle_sim is HUNG (no heartbeat on HEARTBEAT_VEHICLE_SIM for" 20
wait_for "vehicle_sim exited with code 137 (signal SIGKILL) after it hung; restarting" 10
wait_for "resumed from the checkpoint" 15
# The followers were silent as long as the simulation stood, then heard again.
sleep 6
stop_launcher
trap '[[ -n ${OFN_KEEP_WORK:-} ]] || rm -rf "$WORK"' EXIT
grep "launcher:" "$WORK/launch.txt" | grep -v "note:" || true
[[ $(hung_count mapper) == 1 ]] || fail "the mapper was found hung $(hung_count mapper) times, not once"
[[ $(hung_count vehicle_sim) == 1 ]] || fail "vehicle_sim was found hung $(hung_count vehicle_sim) times"
for follower in controller mission_uplink; do
  [[ $(hung_count $follower) == 0 ]] || fail "$follower was killed while the simulation stood still"
done
grep -Eq "mapper +onboard2 +restarts 1/5, hung 1 " "$WORK/launch.txt" ||
  fail "the summary does not count the mapper's hang"
grep -Eq "vehicle_sim +onboard1 +restarts 1/5, hung 1 " "$WORK/launch.txt" ||
  fail "the summary does not count vehicle_sim's hang"
pass "a stopped mapper and a stopped vehicle_sim were found hung, killed and restarted; no follower was"

# A follower stopped for 3 s is not hung: resumed, it follows the time that
# ran on at once (SimClockGuard), so its heartbeats miss 3-4 s, under the
# default 5 s. (Its clock used to stand 2 s more, waiting to resync, and
# the hang watch restarted it.)
/usr/bin/python3 "$REPO/deploy/launch.py" --scenario "$REPO/sim/scenarios/open.yaml" \
  --only vehicle_sim,mission_uplink --bin "$BIN" --rtf 1 --no-record \
  --log-dir "$WORK/run2" --timeout 60 --no-pin > "$WORK/launch2.txt" 2>&1 &
launcher=$!
trap 'stop_launcher; [[ -n ${OFN_KEEP_WORK:-} ]] || rm -rf "$WORK"' EXIT
out="$WORK/launch2.txt"
wait_for "hang watch: .*mission_uplink (sim_clock)" 10
sleep 3
uplink=$(child ofn_mission_uplink)
[[ -n $uplink ]] || fail "no mission_uplink process"
kill -STOP "$uplink"
echo "stopped mission_uplink (pid $uplink) for 3 s"
sleep 3
kill -CONT "$uplink"
# Past the 5 s a frozen clock would have made of it (3 s + 2 s to resync).
sleep 7
stop_launcher
trap '[[ -n ${OFN_KEEP_WORK:-} ]] || rm -rf "$WORK"' EXIT
grep -q "mission_uplink is HUNG" "$WORK/launch2.txt" && fail "mission_uplink, stopped for 3 s, was found hung"
grep -Eq "mission_uplink +[a-z0-9]+ +restarts 0/5 " "$WORK/launch2.txt" ||
  { grep "launcher:" "$WORK/launch2.txt"; fail "mission_uplink was restarted"; }
grep -q "SIM_CLOCK jumps ahead by .* after a silence of" "$WORK/launch2.txt" ||
  fail "mission_uplink did not say it followed the time that ran on"
pass "mission_uplink stopped for 3 s followed the simulation's time on its resumption and was not restarted"
