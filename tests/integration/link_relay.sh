#!/usr/bin/env bash
# bench/link_relay.py on a bridge of three hosts made as fly_three_hosts.sh
# makes them (network namespaces, veth ports, IGMP snooping off): multicast
# from host a to hosts b and c while the relay impairs a -> b only.
#  1. delay 50 ms +- 10, 20 % duplication: c hears every datagram once; b
#     hears every one, none sooner than 40 ms after it was sent, and the
#     relay's duplicated frames as second copies; a 20 KB datagram (14 IP
#     fragments, each a frame) crosses whole.
#  2. all of a -> b lost: b hears nothing, c everything.
#  3. the relay stopped: its nftables table is gone and b hears a again.
# Lower bounds on the delay only: a busy machine can make it longer, never
# shorter.
source "$(dirname "$0")/common.sh"
skip_without_named_netns
command -v nft > /dev/null || fail "nft is missing: run 'make test-deps' (the Makefile installs nftables)"

tag="ofn-relay-$$"
br="$tag-br"
cleanup_hosts() {
  for ns in "$tag-a" "$tag-b" "$tag-c" "$br"; do ip netns del "$ns" 2> /dev/null || true; done
}
trap 'cleanup_hosts; rm -rf "$WORK"' EXIT
ip netns add "$br"
ip -n "$br" link set lo up
ip -n "$br" link add br0 type bridge mcast_snooping 0 stp_state 0 forward_delay 0
ip -n "$br" link set br0 up
n=1
for h in a b c; do
  ip netns add "$tag-$h"
  # Ports named p<host>: "ip link add a" would read "a" as "address".
  ip -n "$br" link add "p$h" type veth peer name eth0 netns "$tag-$h"
  ip -n "$br" link set "p$h" master br0 up
  ip -n "$tag-$h" link set lo up
  ip -n "$tag-$h" addr add "10.77.0.$n/24" dev eth0
  ip -n "$tag-$h" link set eth0 up multicast on
  ip -n "$tag-$h" route add 224.0.0.0/4 dev eth0
  n=$((n + 1))
done

# listen HOST SECONDS OUT: every datagram to the group, as "seq sent_ns arrived_ns size"
listen() {
  ip netns exec "$tag-$1" /usr/bin/python3 - "$2" "$3" <<'PY' &
import socket, struct, sys, time
span, out = float(sys.argv[1]), sys.argv[2]
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
s.bind(("239.255.77.77", 7777))
s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
             socket.inet_aton("239.255.77.77") + socket.inet_aton("0.0.0.0"))
end = time.monotonic() + span
with open(out, "w") as f:
    while True:
        left = end - time.monotonic()
        if left <= 0:
            break
        s.settimeout(left)
        try:
            d = s.recv(65535)
        except socket.timeout:
            break
        seq, sent = struct.unpack("!Iq", d[:12])
        f.write("%d %d %d %d\n" % (seq, sent, time.monotonic_ns(), len(d)))
PY
}
# send COUNT: small datagrams, then one of 20 KB, 20 ms apart
send() {
  ip netns exec "$tag-a" /usr/bin/python3 - "$1" <<'PY'
import socket, struct, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
count = int(sys.argv[1])
for seq in range(count + 1):
    pad = 20000 if seq == count else 40
    s.sendto(struct.pack("!Iq", seq, time.monotonic_ns()) + b"x" * pad, ("239.255.77.77", 7777))
    time.sleep(0.02)
PY
}
relay() {
  ip netns exec "$br" /usr/bin/python3 "$REPO/bench/link_relay.py" --ports pa,pb,pc --links pa:pb \
    --seed 3 --stats "$WORK/stats.json" "$@" > "$WORK/relay.txt" 2>&1 &
  relay_pid=$!
  for _ in $(seq 50); do
    grep -q "^link_relay: relaying" "$WORK/relay.txt" 2> /dev/null && return 0
    kill -0 "$relay_pid" 2> /dev/null || { cat "$WORK/relay.txt"; fail "the relay did not start"; }
    sleep 0.1
  done
  cat "$WORK/relay.txt"
  fail "the relay did not say it was relaying within 5 s"
}
stop_relay() {
  kill -TERM "$relay_pid"
  wait "$relay_pid" || fail "the relay exited with $?"
  cat "$WORK/relay.txt"
}

count=100
# 1. delay, jitter, duplication on a -> b
relay --delay 0.05 --jitter 0.01 --duplicate 0.2
listen b 5 "$WORK/b1.txt"; lb=$!
listen c 5 "$WORK/c1.txt"; lc=$!
sleep 0.5
send "$count"
wait "$lb" "$lc"
stop_relay
/usr/bin/python3 - "$WORK" "$count" <<'PY' || fail "delay and duplication on a -> b"
import collections, json, sys
work, count = sys.argv[1], int(sys.argv[2])
def rows(name):
    return [tuple(map(int, line.split())) for line in open("%s/%s" % (work, name))]
b, c = rows("b1.txt"), rows("c1.txt")
stats = json.load(open(work + "/stats.json"))
every = set(range(count + 1))
c_seen = collections.Counter(r[0] for r in c)
b_seen = collections.Counter(r[0] for r in b)
print("c: %d datagrams, %d distinct; b: %d datagrams, %d distinct; relay: %s" % (
    len(c), len(c_seen), len(b), len(b_seen), stats))
assert set(c_seen) == every and max(c_seen.values()) == 1, "c must hear each datagram once"
assert set(b_seen) == every, "b must hear every datagram: missing %s" % sorted(every - set(b_seen))
earliest = min((r[2] - r[1]) / 1e6 for r in b)
print("b: earliest arrival %.1f ms after sending" % earliest)
assert earliest >= 40.0, "a datagram reached b %.1f ms after sending, under 50 - 10 ms" % earliest
big = [r for r in b if r[0] == count]
assert big and all(r[3] == 20012 for r in big), "the 20 KB datagram must reach b whole"
small_twice = sum(1 for seq, n in b_seen.items() if seq < count and n == 2)
assert stats["duplicated"] > 0 and small_twice > 0, "20 % duplication must show twice at b"
assert stats["dropped"] == 0 and stats["send_errors"] == 0, stats
print("b: %d small datagrams heard twice; the relay duplicated %d frames" % (
    small_twice, stats["duplicated"]))
PY

# 2. everything on a -> b lost
relay --loss 1.0
listen b 4 "$WORK/b2.txt"; lb=$!
listen c 4 "$WORK/c2.txt"; lc=$!
sleep 0.5
send 50
wait "$lb" "$lc"
stop_relay
[[ ! -s "$WORK/b2.txt" ]] || fail "b heard $(wc -l < "$WORK/b2.txt") datagrams through a link that loses all"
[[ $(wc -l < "$WORK/c2.txt") == 51 ]] || fail "c heard $(wc -l < "$WORK/c2.txt") of 51 datagrams"

# 3. the relay gone: the bridge forwards a -> b again
ip netns exec "$br" nft list tables | grep -q ofn_link_relay && fail "the relay left its nftables table"
listen b 3 "$WORK/b3.txt"; lb=$!
sleep 0.5
send 20
wait "$lb"
[[ $(wc -l < "$WORK/b3.txt") == 21 ]] || fail "after the relay, b heard $(wc -l < "$WORK/b3.txt") of 21 datagrams"
pass "link relay: delay, duplication and loss on a -> b only; c untouched; the bridge restored after it"
