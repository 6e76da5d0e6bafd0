#!/usr/bin/env bash
# The open course flown on the three-host split through
# deploy/fly_three_hosts.sh: gcs, onboard1 and onboard2 in network namespaces
# joined by a bridge, LCM with ttl=1. The flight succeeds; the onboard hosts' heartbeats reach the recording made on gcs, which only
# the bridge can carry; the bus latency is measured; and afterwards no
# namespace of the run and no process inside one is left.
source "$(dirname "$0")/common.sh"
# Named network namespaces need root (a user namespace cannot make them).
probe_ns="ofn-it-probe-$$"
if ! ip netns add "$probe_ns" 2>/dev/null; then
  echo "SKIP: cannot create network namespaces here (needs root)"
  exit 77
fi
ip netns del "$probe_ns"

scenario="$REPO/sim/scenarios/open.yaml"
status=0
"$REPO/deploy/fly_three_hosts.sh" --scenario "$scenario" --rtf 2 --timeout 150 --no-pin \
  --bin "$BIN" --out "$WORK/run" > "$WORK/fly.txt" 2>&1 || status=$?
grep -v "^[a-z0-9]* *| \[" "$WORK/fly.txt" | tail -60

# Nothing of the run is left: its namespaces are deleted and no process
# lives in one (their inodes are printed when they are made).
tag=$(sed -n 's/^fly3: three hosts: network namespaces \([^{]*\)-{.*/\1/p' "$WORK/fly.txt")
[[ -n $tag ]] || fail "the script did not name its namespaces"
left=$(ip netns list | grep "^$tag-" || true)
[[ -z $left ]] || fail "network namespaces left behind: $left"
inodes=$(sed -n 's/^fly3: .*netns inode \([0-9]*\)$/\1/p' "$WORK/fly.txt")
[[ $(wc -w <<< "$inodes") == 3 ]] || fail "expected the inodes of 3 host namespaces, got '$inodes'"
for inode in $inodes; do
  for ns in /proc/[0-9]*/ns/net; do
    [[ $(readlink "$ns" 2>/dev/null) != "net:[$inode]" ]] ||
      fail "process ${ns//[^0-9]/} still runs in a namespace of the run"
  done
done
if pgrep -f -- "$WORK/run" > "$WORK/left.txt"; then
  ps -o pid,args -p "$(paste -sd, "$WORK/left.txt")" || true
  fail "processes of the run are still running"
fi

[[ $status != 2 ]] || fail "configuration or usage error (exit code 2)"
[[ -f "$WORK/run/summary.json" ]] || fail "no flight report (exit code $status)"
outcome=$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["outcome"])' \
  "$WORK/run/summary.json")
# The test runs alone (RUN_SERIAL): the flight must succeed, as the
# one-host flight of the same course does in integration.multiprocess_flight.
[[ $outcome == success ]] || { grep -A6 "^Flight " "$WORK/fly.txt" || true
  fail "three hosts: outcome $outcome (exit code $status)"; }
[[ $status == 0 ]] || fail "outcome success but exit code $status"

# The recording is made on gcs alone; everything from onboard1 and onboard2
# in it crossed the bridge.
compgen -G "$WORK/run/onboard1/*.lcm" > /dev/null && fail "onboard1 recorded a log"
compgen -G "$WORK/run/onboard2/*.lcm" > /dev/null && fail "onboard2 recorded a log"
for service in vehicle_sim controller sensor_interface mapper global_planner rh_optimizer; do
  n=$(grep -c ",$service," "$WORK/run/heartbeats.csv" || true)
  [[ $n -ge 3 ]] || fail "$service's heartbeats on gcs: $n"
done
grep -q "^  across the bridge : heartbeats recorded on gcs from onboard1" "$WORK/fly.txt" ||
  fail "no 'across the bridge' line"
# The onboard launchers were stopped by the script, not by their own limit.
for h in onboard1 onboard2; do
  grep -q "^$h *| launcher: received SIGINT; stopping" "$WORK/fly.txt" ||
    fail "$h's launcher was not stopped when the ground station's run ended"
done

# The latency between the hosts is measured in every direction.
grep -E "^  bus latency       : median [0-9.]+ ms, p99 [0-9.]+ ms" "$WORK/fly.txt" ||
  fail "no bus latency line"
/usr/bin/python3 - "$WORK/run/bus_latency.csv" <<'PY' || fail "probes missing between some hosts"
import csv, collections, sys
pairs = collections.Counter((r["from"], r["to"]) for r in csv.DictReader(open(sys.argv[1])))
print("probes per direction:", dict(pairs))
sys.exit(0 if len(pairs) == 6 and min(pairs.values()) >= 10 else 1)
PY
pass "three hosts on a bridge: outcome $outcome; heartbeats of onboard1 and onboard2 recorded on gcs; latency measured; nothing left behind"
