#!/usr/bin/env bash
# Flies a scenario on the three-host split of deploy/processes.yaml (gcs,
# onboard1, onboard2) on one machine: each host is a network namespace with
# one veth link to a bridge that lives in a fourth namespace, so nothing
# touches the machine's own network. LCM multicast crosses the bridge with
# ttl=1; each namespace runs its host's share with `deploy/launch.py --host
# NAME`, the bus is recorded on gcs, a probe measures the bus latency between
# the hosts, and when the ground station's run ends the onboard hosts are
# stopped and the namespaces deleted. Then the flight report of deploy/fly.sh.
# `make run HOSTS=3` is this script with the Makefile's SCENARIO and RTF.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
program=fly_three_hosts.sh
# shellcheck source=deploy/flight_common.sh
source "$repo/deploy/flight_common.sh"
# shellcheck source=deploy/version.sh
source "$repo/deploy/version.sh"
scenario="$repo/sim/scenarios/bench3.yaml"
rtf=1.0
timeout=300
out=""
bin="$repo/build/bin"
no_pin=()
probe_rate=20
bus_keys=""
open_bus=0

usage() {
  cat <<EOF
usage: deploy/fly_three_hosts.sh [--scenario FILE] [--rtf X] [--out DIR] [--timeout S]
                                 [--bin DIR] [--no-pin] [--probe-rate HZ]
                                 [--bus-keys DIR | --open-bus]

Flies a scenario on three hosts emulated on this machine: the network
namespaces gcs, onboard1 and onboard2, joined by a bridge in a fourth
namespace (veth links, IGMP snooping off), LCM multicast with ttl=1 and a
multicast route on each host. Each runs 'deploy/launch.py --host NAME';
lcm-logger records the bus on gcs. While they fly, a UDP multicast probe
measures the latency between the hosts. When the ground station's run ends
(its flight monitor ends it), the onboard hosts are stopped and the
namespaces deleted (also on Ctrl-C, SIGTERM and errors); then the flight
report and figures are written as deploy/fly.sh writes them. Needs root.

  --scenario FILE   scenario to fly (default: sim/scenarios/bench3.yaml)
  --rtf X           simulation real-time factor (default: 1.0)
  --out DIR         results folder (default: results/run-YYYYmmdd-HHMMSS)
  --timeout S       wall-clock run limit in seconds (default: 300)
  --bin DIR         service executables (default: build/bin)
  --no-pin          do not pin the services to the table's cores
  --probe-rate HZ   latency probes each host sends per second (default: 20)
  --bus-keys DIR    authenticate the bus with this keyring (ofn_bus_keygen); the
                    same directory serves all three hosts
                    (default: a new keyring for the run in DIR/keyring, each
                    host given policy.yaml, the public keys and its own key)
  --open-bus        no authentication: the bus as on one host
  -h, --help        show this help
  --version         show the version

Besides fly.sh's files, DIR holds onboard1/ and onboard2/ (those hosts'
service logs; gcs's are in DIR/flight-<date>/ next to the recording),
bus_latency.csv (every probe: from, to, seq, latency_ms) and
bus_latency.txt (median and p99 per direction). docs/DEPLOYMENT.md
describes the set-up and the same on real hosts.

Example:
  deploy/fly_three_hosts.sh --scenario sim/scenarios/open.yaml --rtf 2

Exit codes, as deploy/fly.sh's: 1 when the flight's outcome is failure, no
log was recorded or the namespaces could not be made; 2 for bad arguments
or input, or when a service reported a configuration or usage error;
otherwise the ground station's launcher's (0 when the run ended normally,
3 when the run limit ended it, 128+N when stopped by signal N).
EOF
}

while [[ $# -gt 0 ]]; do
  case "$1" in
    --bin) need_value "$1" $#; bin=$2; shift 2 ;;
    --bin=*) bin=${1#*=}; shift ;;
    --no-pin) no_pin=(--no-pin); shift ;;
    --probe-rate) need_value "$1" $#; probe_rate=$2; shift 2 ;;
    --probe-rate=*) probe_rate=${1#*=}; shift ;;
    --bus-keys) need_value "$1" $#; bus_keys=$2; shift 2 ;;
    --bus-keys=*) bus_keys=${1#*=}; shift ;;
    --open-bus) open_bus=1; shift ;;
    -h|--help) usage; exit 0 ;;
    --version) echo "fly_three_hosts.sh $(project_version "$repo")"; exit 0 ;;
    *) flight_option "$@"; shift "$taken" ;;
  esac
done
bin=$(cd "$bin" 2>/dev/null && pwd) || bin=/nonexistent
check_flight_options "$scenario" "$rtf" "$timeout" "$bin"
[[ $probe_rate =~ ^([0-9]+\.?[0-9]*|\.[0-9]+)$ ]] &&
  awk -v x="$probe_rate" 'BEGIN { exit !(x > 0 && x <= 1000) }' ||
  die_usage "--probe-rate must be a number in (0, 1000], got '$probe_rate'"
for tool in ip setsid setpriv; do
  command -v "$tool" >/dev/null ||
    { echo "fly_three_hosts.sh: error: '$tool' not found (apt-get install iproute2 util-linux)" >&2; exit 1; }
done
if [[ $(id -u) != 0 ]]; then
  echo "fly_three_hosts.sh: error: making the hosts' network namespaces needs root" \
       "(deploy/fly.sh flies on one namespace without)" >&2
  exit 1
fi
[[ -n $bus_keys && $open_bus == 1 ]] && die_usage "--bus-keys and --open-bus exclude each other"
if [[ -n $bus_keys ]]; then
  [[ -f "$bus_keys/policy.yaml" ]] || die_usage "--bus-keys: $bus_keys holds no policy.yaml (make a keyring with ofn_bus_keygen)"
  bus_keys=$(cd "$bus_keys" && pwd)
fi
[[ -n "$out" ]] || out="$repo/results/run-$(date +%Y%m%d-%H%M%S)"
mkdir -p "$out"
out=$(cd "$out" && pwd)

hosts=(gcs onboard1 onboard2)
# The authenticated bus (docs/DEPLOYMENT.md#authenticated-bus): by default a
# keyring made for this run and handed out as on real hosts, each host
# holding only its own secret key.
declare -A host_keys=()
if [[ $open_bus != 1 ]]; then
  if [[ -z $bus_keys ]]; then
    "$bin/ofn_bus_keygen" --policy "$repo/config/bus_policy.yaml" --out "$out/keyring" --force \
      > /dev/null || { echo "fly_three_hosts.sh: error: could not make the run's keyring" >&2; exit 1; }
    for h in "${hosts[@]}"; do
      mkdir -m 700 -p "$out/keyring/$h"
      cp "$out/keyring/policy.yaml" "$out"/keyring/*.pub "$out/keyring/$h/"
      mv "$out/keyring/$h.key" "$out/keyring/$h/"
      host_keys[$h]="$out/keyring/$h"
    done
  else
    for h in "${hosts[@]}"; do host_keys[$h]=$bus_keys; done
  fi
fi
# ttl=1: one hop, across the bridge (a switch on real hosts) and no further.
lcm_url='udpm://239.255.76.67:7667?ttl=1'
# The probe uses LCM's group on its own port: the same path, not on the bus.
probe_group=239.255.76.67
probe_port=7668
subnet=10.76.67
hosts_csv=$(IFS=,; echo "${hosts[*]}")
# Namespaces of an earlier run whose script was killed outright (SIGKILL
# leaves no chance to delete them): its script is gone and nothing runs in
# them any more.
for ns in $(ip netns list | awk '{print $1}' | grep -E '^ofn3h-[0-9]+(-[0-9]+)?-[a-z0-9]+$' || true); do
  pid=${ns#ofn3h-}
  pid=${pid%%-*}
  if ! kill -0 "$pid" 2>/dev/null && [[ -z $(ip netns pids "$ns" 2>/dev/null) ]]; then
    ip netns del "$ns" 2>/dev/null && echo "fly3: deleted $ns, left by a run that was killed"
  fi
done
tag="ofn3h-$$"
while ip netns list | grep -q "^$tag-"; do tag="ofn3h-$$-$RANDOM"; done
bridge_ns="$tag-bridge"
tmp=$(mktemp -d /tmp/ofn-hosts.XXXXXX)

say() { echo "fly3: $*"; }
warn() { echo "fly3: $*" >&2; }

# Process ids of what this script started: the launchers and the probes.
declare -A launcher_pid=() probe_pid=()
namespaces=()   # in creation order
interrupted=""

# A Ctrl-C reaches the whole foreground process group: a sleep it ends must
# not end this script (set -e) before the hosts are stopped.
nap() { sleep "$1" || true; }

live_pids() {  # the given pids that are still running
  local pid
  for pid in "$@"; do kill -0 "$pid" 2>/dev/null && echo "$pid"; done
  return 0
}

stop_and_wait() {  # stop_and_wait SIGNAL GRACE_S PID...: signal, wait, SIGKILL stragglers
  local sig=$1 grace=$2 pid
  shift 2
  [[ $# -gt 0 ]] || return 0
  for pid in "$@"; do kill "-$sig" "$pid" 2>/dev/null || true; done
  local deadline=$((SECONDS + grace))
  while [[ -n $(live_pids "$@") && $SECONDS -lt $deadline ]]; do nap 0.1; done
  for pid in $(live_pids "$@"); do
    warn "process $pid did not stop within $grace s of SIG$sig; sending SIGKILL"
    kill -KILL "$pid" 2>/dev/null || true
  done
  for pid in "$@"; do wait "$pid" 2>/dev/null || true; forget "$pid"; done
}

forget() {  # forget PID: a process that has ended is no longer ours to signal
  local k
  for k in "${!launcher_pid[@]}"; do [[ ${launcher_pid[$k]} != "$1" ]] || unset "launcher_pid[$k]"; done
  for k in "${!probe_pid[@]}"; do [[ ${probe_pid[$k]} != "$1" ]] || unset "probe_pid[$k]"; done
}

cleanup() {
  trap - INT TERM HUP
  local pids ns i
  # Error paths: launchers and probes still running are stopped in order.
  pids=$(live_pids "${launcher_pid[@]}" "${probe_pid[@]}")
  # shellcheck disable=SC2086
  [[ -z $pids ]] || stop_and_wait INT 20 $pids
  for ns in "${namespaces[@]}"; do
    pids=$(ip netns pids "$ns" 2>/dev/null || true)
    if [[ -n $pids ]]; then
      warn "processes left in namespace $ns: ${pids//$'\n'/ }; sending SIGKILL"
      # shellcheck disable=SC2086
      kill -KILL $pids 2>/dev/null || true
    fi
  done
  # Deleting the bridge's namespace deletes its veth ends and with them the
  # hosts' ends.
  for ((i = ${#namespaces[@]} - 1; i >= 0; i--)); do
    ip netns del "${namespaces[i]}" 2>/dev/null ||
      warn "could not delete network namespace ${namespaces[i]}"
  done
  [[ ${#namespaces[@]} == 0 ]] || say "network namespaces $tag-{$hosts_csv,bridge} deleted"
  namespaces=()
  rm -rf "$tmp"
}
trap cleanup EXIT

on_signal() {  # on_signal NAME: pass the signal on; the run then ends as usual
  interrupted=$1
  warn "received SIG$1; stopping the hosts"
  local pid
  for pid in $(live_pids "${launcher_pid[@]}" "${probe_pid[@]}"); do
    kill "-$1" "$pid" 2>/dev/null || true
  done
}
trap 'on_signal INT' INT
trap 'on_signal TERM' TERM
trap 'on_signal HUP' HUP

must() {  # must COMMAND...: a failed step of the set-up ends the run (exit code 1)
  "$@" || { warn "cannot make the hosts' network: '$*' failed"; exit 1; }
}

make_namespaces() {
  must ip netns add "$bridge_ns"
  namespaces+=("$bridge_ns")
  must ip -n "$bridge_ns" link set lo up
  # IGMP snooping off: the bridge floods multicast to every port, as a
  # switch without an IGMP querier must be told to.
  must ip -n "$bridge_ns" link add br0 type bridge mcast_snooping 0 stp_state 0 forward_delay 0
  must ip -n "$bridge_ns" link set br0 up
  local n=1 h ns
  for h in "${hosts[@]}"; do
    ns="$tag-$h"
    must ip netns add "$ns"
    namespaces+=("$ns")
    must ip -n "$bridge_ns" link add "$h" type veth peer name eth0 netns "$ns"
    must ip -n "$bridge_ns" link set "$h" master br0 up
    must ip -n "$ns" link set lo up
    must ip -n "$ns" addr add "$subnet.$n/24" dev eth0
    must ip -n "$ns" link set eth0 up multicast on
    # LCM's group leaves through eth0, the host's link to the others.
    must ip -n "$ns" route add 224.0.0.0/4 dev eth0
    n=$((n + 1))
  done
}

# ---------------------------------------------------------------------------
# Latency probe: one per host; sends a stamped datagram to the group
# --probe-rate times a second and stamps every datagram from the other hosts
# on arrival. The namespaces share the kernel's CLOCK_MONOTONIC, so arrival
# minus send time is the one-way latency, sender's and receiver's scheduling
# included, as an LCM message would see it.
cat > "$tmp/bus_probe.py" <<'PY'
import os, select, signal, socket, struct, sys, time
host, group, port, rate, samples_path, heard_path = sys.argv[1:7]
port, period = int(port), 1.0 / float(rate)
others = set(sys.argv[7:])
FMT = "!16sQq"  # sending host, sequence number, CLOCK_MONOTONIC ns at send
stop = []
for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
    signal.signal(s, lambda signum, frame: stop.append(signum))
rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
rx.bind((group, port))
rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
              socket.inet_aton(group) + socket.inet_aton("0.0.0.0"))
rx.setblocking(False)
tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 0)
samples, heard, seq = [], set(), 0
next_send = time.monotonic()
end = None
while True:
    now = time.monotonic()
    if stop and end is None:
        end = now + 0.3  # stop sending; take what is still on its way
    if end is not None and now >= end:
        break
    if end is None and now >= next_send:
        tx.sendto(struct.pack(FMT, host.encode(), seq, time.monotonic_ns()), (group, port))
        seq += 1
        next_send = max(next_send + period, now)
    wake = end if end is not None else next_send
    if select.select([rx], [], [], max(0.0, wake - time.monotonic()))[0]:
        while True:
            try:
                data = rx.recv(256)
            except BlockingIOError:
                break
            arrived = time.monotonic_ns()
            if len(data) != struct.calcsize(FMT):
                continue
            src, n, sent = struct.unpack(FMT, data)
            src = src.rstrip(b"\0").decode("ascii", "replace")
            if src == host:
                continue
            samples.append("%s,%s,%d,%.4f\n" % (src, host, n, (arrived - sent) / 1e6))
            if src not in heard:
                heard.add(src)
                with open(heard_path + ".new", "w") as f:
                    f.write("\n".join(sorted(heard)) + "\n")
                os.replace(heard_path + ".new", heard_path)
with open(samples_path, "w") as f:
    f.write("# %s sent %d\n" % (host, seq))
    f.writelines(samples)
PY

# Median and p99 per direction and overall; writes bus_latency.{csv,txt}.
summarise_latency() {
  /usr/bin/python3 - "$out" "$probe_rate" "$tmp"/*.samples <<'PY'
import math, os, sys
out, rate, paths = sys.argv[1], sys.argv[2], sys.argv[3:]
rows = []
for path in filter(os.path.exists, paths):
    with open(path) as f:
        rows += [line.strip().split(",") for line in f if not line.startswith("#")]
with open(out + "/bus_latency.csv", "w") as f:
    f.write("from,to,seq,latency_ms\n")
    f.writelines(",".join(r) + "\n" for r in rows)
def pct(values, p):  # nearest rank
    return values[max(0, math.ceil(p * len(values)) - 1)]
def line(values, seqs):
    values = sorted(values)
    lost = sum(max(s) - min(s) + 1 - len(set(s)) for s in seqs)
    return "median %.3f ms, p99 %.3f ms, max %.3f ms (%d probes, %d lost)" % (
        pct(values, 0.5), pct(values, 0.99), values[-1], len(values), lost)
pairs = {}
for src, dst, seq, ms in rows:
    pairs.setdefault((src, dst), ([], []))
    pairs[(src, dst)][0].append(float(ms))
    pairs[(src, dst)][1].append(int(seq))
text = []
if rows:
    text.append("  bus latency       : %s between the hosts (UDP multicast, ttl 1, %s Hz from "
                "each host during the flight)" % (
                    line([v for vs, _ in pairs.values() for v in vs], [s for _, s in pairs.values()]),
                    rate))
    for (src, dst), (values, seqs) in sorted(pairs.items()):
        text.append("      %-8s -> %-8s: %s" % (src, dst, line(values, [seqs])))
else:
    text.append("  bus latency       : no probe crossed the bridge")
with open(out + "/bus_latency.txt", "w") as f:
    f.write("\n".join(text) + "\n")
print("\n".join(text))
PY
}

# Heartbeats of each onboard host's services in gcs's recording: every one
# crossed the bridge.
bridge_traffic() {
  /usr/bin/python3 - "$repo/deploy/processes.yaml" "$out/heartbeats.csv" <<'PY'
import collections, csv, sys, yaml
table = yaml.safe_load(open(sys.argv[1]))
host_of = {p["name"]: p["host"] for p in table["processes"]}
counts = collections.Counter(row["service"] for row in csv.DictReader(open(sys.argv[2])))
parts = []
for host in ("onboard1", "onboard2"):
    names = [n for n in host_of if host_of[n] == host]
    parts.append("%s (%s)" % (host, ", ".join("%s %d" % (n, counts[n]) for n in names)))
print("  across the bridge : heartbeats recorded on gcs from " + "; ".join(parts))
PY
}

# ---------------------------------------------------------------------------
echo "fly: scenario $scenario, real-time factor $rtf, results in $out"
say "three hosts: network namespaces $tag-{$hosts_csv} on a bridge in $bridge_ns, LCM $lcm_url"
if [[ $open_bus == 1 ]]; then
  say "bus: open (--open-bus), no authentication"
else
  say "bus: authenticated, keyring ${bus_keys:-$out/keyring (made for this run, one directory per host)}"
fi
make_namespaces
for h in "${hosts[@]}"; do
  say "  $h: $(ip -n "$tag-$h" -4 -o addr show dev eth0 | awk '{print $4}') on eth0," \
      "route $(ip -n "$tag-$h" route show 224.0.0.0/4 | sed "s/ *$//"), netns inode" \
      "$(stat -L -c %i "/run/netns/$tag-$h")"
done

for h in "${hosts[@]}"; do
  mapfile -t others < <(printf '%s\n' "${hosts[@]}" | grep -vx "$h")
  setsid setpriv --pdeathsig TERM ip netns exec "$tag-$h" /usr/bin/python3 "$tmp/bus_probe.py" \
    "$h" "$probe_group" "$probe_port" "$probe_rate" "$tmp/$h.samples" "$tmp/$h.heard" \
    "${others[@]}" &
  probe_pid[$h]=$!
done
# Every host must hear the other two before the flight starts.
deadline=$((SECONDS + 10))
while :; do
  deaf=()
  for h in "${hosts[@]}"; do
    [[ -f "$tmp/$h.heard" && $(wc -l < "$tmp/$h.heard") -ge 2 ]] || deaf+=("$h")
  done
  [[ ${#deaf[@]} -gt 0 && $SECONDS -lt $deadline && -z $interrupted ]] || break
  nap 0.1
done
[[ -z $interrupted ]] || exit $((128 + $(kill -l "$interrupted")))
if [[ ${#deaf[@]} -gt 0 ]]; then
  warn "multicast does not cross the bridge: ${deaf[*]} did not hear the other hosts within 10 s"
  exit 1
fi
say "multicast crosses the bridge: every host hears the other two"

rm -f "$out/latest_log"
start_host() {  # start_host NAME LAUNCHER_OPTIONS...
  local h=$1
  shift
  # Own session: a Ctrl-C reaches this script, which passes it on once.
  # pdeathsig: should this script be killed outright, the launcher still
  # stops its services.
  setsid setpriv --pdeathsig TERM ip netns exec "$tag-$h" \
    /usr/bin/python3 "$repo/deploy/launch.py" --host "$h" --scenario "$scenario" --rtf "$rtf" \
    --bin "$bin" --lcm-url "$lcm_url" "${no_pin[@]}" \
    ${host_keys[$h]:+--bus-keys "${host_keys[$h]}"} "$@" \
    > >(trap '' INT TERM HUP; exec sed -u "s/^/$(printf '%-8s' "$h") | /") 2>&1 &
  launcher_pid[$h]=$!
}
# The ground station first: its lcm-logger records the whole flight.
start_host gcs --out "$out" --timeout "$timeout"
deadline=$((SECONDS + 30))
while [[ ! -f "$out/latest_log" && $SECONDS -lt $deadline && -z $interrupted ]] &&
      kill -0 "${launcher_pid[gcs]}" 2>/dev/null; do
  nap 0.1
done
if [[ ! -f "$out/latest_log" && -z $interrupted ]] && kill -0 "${launcher_pid[gcs]}" 2>/dev/null; then
  warn "gcs's launcher did not start recording within 30 s; stopping it"
  kill -INT "${launcher_pid[gcs]}" 2>/dev/null || true
fi
# The onboard hosts record nothing (--no-record) and have no ends_run
# process: they run until stopped. Their own limit is only a backstop.
onboard_limit=$(awk -v t="$timeout" 'BEGIN { print (t > 0) ? t + 60 : 0 }')
if [[ -f "$out/latest_log" && -z $interrupted ]]; then
  for h in onboard2 onboard1; do
    start_host "$h" --no-record --out "$out/$h" --timeout "$onboard_limit"
  done
fi

# The run is the ground station's: it ends when its flight monitor ends it.
config_error=""
while kill -0 "${launcher_pid[gcs]}" 2>/dev/null; do
  for h in onboard1 onboard2; do
    [[ -n ${launcher_pid[$h]:-} ]] || continue
    kill -0 "${launcher_pid[$h]}" 2>/dev/null && continue
    rc=0
    wait "${launcher_pid[$h]}" || rc=$?
    forget "${launcher_pid[$h]}"
    if [[ $rc == 2 ]]; then
      warn "$h's launcher ended with exit code 2 (a configuration or usage error); stopping gcs"
      config_error=$h
      kill -INT "${launcher_pid[gcs]}" 2>/dev/null || true
    else
      warn "$h's launcher ended on its own with exit code $rc while gcs flies on"
    fi
  done
  nap 0.2
done
status=0
wait "${launcher_pid[gcs]}" || status=$?
forget "${launcher_pid[gcs]}"
say "the ground station's run ended (launcher exit code $status); stopping onboard1 and onboard2"
onboard=()
for h in onboard1 onboard2; do
  [[ -z ${launcher_pid[$h]:-} ]] || onboard+=("${launcher_pid[$h]}")
done
stop_and_wait TERM 5 "${probe_pid[@]}"
# After Ctrl-C or SIGTERM the launchers have had the signal already; a
# second one would make them kill their services without the grace period.
stop_signal=INT
[[ -z $interrupted ]] || stop_signal=0
# shellcheck disable=SC2068
stop_and_wait "$stop_signal" 20 ${onboard[@]}
latency=$(summarise_latency)
cleanup
left=$(ip netns list | grep -c "^$tag-" || true)
[[ $left == 0 ]] || warn "$left of the run's network namespaces are still there"

exit_if_no_flight "$status" "$config_error"
if [[ ! -f "$out/latest_log" ]]; then
  echo "$latency"
  echo "fly: no flight log was recorded" >&2
  exit 1
fi
log=$(cat "$out/latest_log")
echo
report_flight "$bin" "$out" "$scenario" "$log" "${host_keys[gcs]:-}"
echo "$latency"
[[ -f "$out/heartbeats.csv" ]] && { bridge_traffic || true; }
echo "  hosts' logs       : $(dirname "$log")/$(basename "$log" .lcm)/ (gcs), $out/onboard1/, $out/onboard2/"
finish_flight "$out" "$log" "$status"
