#!/usr/bin/env bash
# The open course flown on the three-host split through
# deploy/fly_three_hosts.sh: gcs, onboard1 and onboard2 in network namespaces
# joined by a bridge, LCM with ttl=1, the bus authenticated with a keyring
# made for the run. A stranger on the ground station's host floods the bus
# with garbage and forgeries, some signed with gcs's key; the onboard
# services refuse them as unauthenticated and the flight succeeds. The
# onboard hosts' heartbeats reach the recording made on gcs, which only the
# bridge can carry; the bus latency is measured; and afterwards no namespace
# of the run and no process inside one is left.
source "$(dirname "$0")/common.sh"
skip_without_named_netns

scenario="$REPO/sim/scenarios/open.yaml"
status=0
"$REPO/deploy/fly_three_hosts.sh" --scenario "$scenario" --rtf 2 --timeout 150 --no-pin \
  --bin "$BIN" --out "$WORK/run" > "$WORK/fly.txt" 2>&1 &
fly=$!
# Once the flight is under way, a stranger on the ground station's host
# (holding gcs's key, as a compromised ground station would) floods the
# authenticated bus: garbage, unsigned messages, and a plan at five times
# the speed limit, a DONE, a clock jump and an actuator command signed with
# gcs's key, none of which gcs may publish.
for _ in $(seq 600); do
  [[ -f "$WORK/run/latest_log" ]] && break
  kill -0 $fly 2> /dev/null || break
  sleep 0.1
done
sleep 5
tag=$(sed -n 's/^fly3: three hosts: network namespaces \([^{]*\)-{.*/\1/p' "$WORK/fly.txt")
fuzz_status=0
if [[ -n $tag ]] && kill -0 $fly 2> /dev/null; then
  ip netns exec "$tag-gcs" "$BIN/ofn_bus_fuzz" --lcm-url 'udpm://239.255.76.67:7667?ttl=1' \
    --messages 1500 --forgery-every 30 --sign-as gcs --bus-keys "$WORK/run/keyring/gcs" \
    --expect controller --expect vehicle_sim --expect rh_optimizer --expect mapper \
    > "$WORK/fuzz.txt" 2>&1 || fuzz_status=$?
fi
wait $fly || status=$?
grep -v "^[a-z0-9]* *| \[" "$WORK/fly.txt" | tail -60
cat "$WORK/fuzz.txt" 2> /dev/null || true
[[ -n $tag ]] || fail "the script did not name its namespaces"
[[ -f "$WORK/fuzz.txt" ]] || fail "the flight ended before the stranger could flood the bus"
[[ $fuzz_status == 0 ]] || fail "a service died or rejected nothing under the flood (exit $fuzz_status)"
grep -q "^fly3: bus: authenticated" "$WORK/fly.txt" || fail "the three-host bus was not authenticated"

# Nothing of the run is left: its namespaces are deleted and no process
# lives in one (their inodes are printed when they are made).
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
# The report read the recording with the ground station's keyring: the
# stranger's messages in it were left out, as the services left them out.
skipped=$(/usr/bin/python3 -c 'import json, sys
print(json.load(open(sys.argv[1]))["messages_skipped"]["unauthenticated"])' "$WORK/run/summary.json")
[[ $skipped =~ ^[0-9]+$ && $skipped -gt 0 ]] ||
  fail "the report did not authenticate the recording (unauthenticated skipped: $skipped)"
grep -q "^  bus               : authenticated; read only what the keyring's roles signed" \
  "$WORK/fly.txt" || fail "no 'bus : authenticated' line in the report"

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

# The flood was refused as unauthenticated across the bridge, every kind
# of it: unsigned, and signed by a role that may not publish there.
/usr/bin/python3 - "$WORK/run/heartbeats.csv" <<'PY' || fail "the authenticated bus did not refuse the stranger"
import csv, sys
refused = {}
for row in csv.DictReader(open(sys.argv[1])):
    refused[row["service"]] = max(refused.get(row["service"], 0), int(row["unauthenticated"]))
print("refused as unauthenticated:", refused)
sys.exit(0 if all(refused.get(s, 0) > 0 for s in ("controller", "vehicle_sim", "rh_optimizer")) else 1)
PY
# (The services log one rejection a second; the fuzz reads each one's last
# reason from its heartbeat.)
for kind in "unauthenticated: not signed" "unauthenticated: role 'gcs' may not publish here"; do
  grep -rqF "$kind" "$WORK/run/onboard1" "$WORK/run/onboard2" "$WORK/fuzz.txt" ||
    fail "no onboard service reported a rejection '$kind'"
done

# The recording keeps the signed bytes, and the decoders of LCM's own tools
# read them: lcm-spy's Java types and the Python types ignore the trailer.
log=$(cat "$WORK/run/latest_log")
/usr/bin/python3 - "$log" "$WORK/nav_signed.bin" <<'PY' || fail "the recording holds no signed NAV_STATE"
import struct, sys
data, i = open(sys.argv[1], "rb").read(), 0
while i + 28 <= len(data):
    _, _, _, channel_length, data_length = struct.unpack(">IqqII", data[i:i + 28])
    channel = data[i + 28:i + 28 + channel_length].decode()
    payload = data[i + 28 + channel_length:i + 28 + channel_length + data_length]
    i += 28 + channel_length + data_length
    if channel == "NAV_STATE" and payload.endswith(b"OFA1"):
        open(sys.argv[2], "wb").write(payload)
        sys.exit(0)
sys.exit(1)
PY
PYTHONPATH="$BIN/../lcmtypes/python" /usr/bin/python3 -c '
import sys
from ofn.nav_state_t import nav_state_t
m = nav_state_t.decode(open(sys.argv[1], "rb").read())
print("Python types read a signed NAV_STATE: frame %s, north %.1f m" % (m.frame, m.position[0]))
' "$WORK/nav_signed.bin" || fail "the Python types cannot read a signed message"
jar="$BIN/../lcmtypes/ofn_lcmtypes.jar"
if [[ -f $jar ]] && command -v javac > /dev/null; then
  mkdir "$WORK/java"
  cat > "$WORK/java/ReadSigned.java" <<'JAVA'
public class ReadSigned {
  public static void main(String[] args) throws Exception {
    byte[] bytes = java.nio.file.Files.readAllBytes(java.nio.file.Paths.get(args[0]));
    ofn.nav_state_t m = new ofn.nav_state_t(bytes);  // as lcm-spy decodes
    System.out.printf("Java types (lcm-spy) read a signed NAV_STATE: frame %s, north %.1f m%n",
                      m.frame, m.position[0]);
  }
}
JAVA
  javac -d "$WORK/java" -cp "$jar:/usr/share/java/lcm.jar" "$WORK/java/ReadSigned.java" &&
    java -cp "$WORK/java:$jar:/usr/share/java/lcm.jar" ReadSigned "$WORK/nav_signed.bin" ||
    fail "lcm-spy's Java types cannot read a signed message"
else
  fail "no types jar or javac: run 'make deps'"
fi

# The latency between the hosts is measured in every direction.
grep -E "^  bus latency       : median [0-9.]+ ms, p99 [0-9.]+ ms" "$WORK/fly.txt" ||
  fail "no bus latency line"
/usr/bin/python3 - "$WORK/run/bus_latency.csv" <<'PY' || fail "probes missing between some hosts"
import csv, collections, sys
pairs = collections.Counter((r["from"], r["to"]) for r in csv.DictReader(open(sys.argv[1])))
print("probes per direction:", dict(pairs))
sys.exit(0 if len(pairs) == 6 and min(pairs.values()) >= 10 else 1)
PY
pass "three hosts on a bridge, authenticated bus: outcome $outcome; the stranger refused; heartbeats of onboard1 and onboard2 recorded on gcs; latency measured; nothing left behind"
