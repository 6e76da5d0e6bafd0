#!/usr/bin/python3
"""Link relay: delay, jitter, loss, duplication and reordering between bridge ports, in user space.

Usage: link_relay.py --ports P1,P2[,P...] [--links FROM:TO[,FROM:TO]] [--delay S] [--jitter S]
                     [--loss P] [--duplicate P] [--reorder P] [--seed N] [--stats FILE]

Runs in the network namespace of a Linux bridge (deploy/fly_three_hosts.sh's
"<tag>-bridge"), whose ports are the veth ends of the hosts' links. For each
impaired direction FROM -> TO (every ordered pair of --ports unless --links
names some) it makes the bridge drop what it would forward from FROM to TO
(an nftables bridge table of its own, "ofn_link_relay"), reads each frame
arriving on FROM with a packet socket, and sends it out of TO itself, as
netem would on that link:

  --loss P        a share P of the frames is dropped
  --duplicate P   a share P is sent twice
  --delay S       each frame leaves S seconds after it came
  --jitter S      ... S plus a uniform draw in [-S, +S] (never below 0), so
                  frames overtake each other when the jitter exceeds their
                  spacing, as with netem
  --reorder P     a share P leaves at once, ahead of the delayed ones

Frames are relayed whole (an IP fragment is a frame), with their source
addresses: the hosts see the same datagrams, only later, fewer, twice or out
of order. One field changes: an IPv4 UDP datagram leaves with its checksum
0 ("none"), because a veth leaves small datagrams' checksums to an offload
that never runs on a relayed frame. Directions not impaired are forwarded by the bridge as before.

The kernel this project is developed on has neither sch_netem nor
nftables' queue statement (docs/TESTING.md#the-fault-suite); packet sockets
and nftables' bridge family are all this needs. Needs root (CAP_NET_RAW,
CAP_NET_ADMIN) and nft.

Runs until SIGINT or SIGTERM; then removes its table, prints one line of
counts (frames in, sent, dropped, duplicated, sent ahead, send errors, the
largest lag of a send behind its time) and writes them to --stats as JSON.
Exit code 0, 1 when the table or a socket cannot be made, 2 for bad
arguments.

Example (in the bridge's namespace of a fly_three_hosts.sh run):
  ip netns exec ofn3h-123-bridge bench/link_relay.py --ports gcs,onboard1,onboard2 \\
      --delay 0.05 --jitter 0.02
"""
import argparse
import heapq
import json
import os
import random
import select
import signal
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "services", "tools"))

import ofn_cli  # noqa: E402

PROG = "bench/link_relay.py"
TABLE = "ofn_link_relay"
ETH_P_ALL = 0x0003


def share(text):
    value = float(text)
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError("expected a share in [0, 1], got %s" % text)
    return value


def seconds(text):
    value = float(text)
    if not 0.0 <= value <= 10.0:
        raise argparse.ArgumentTypeError("expected seconds in [0, 10], got %s" % text)
    return value


def port_list(text):
    names = [p for p in text.split(",") if p]
    for name in names:
        if not name.replace("-", "").replace("_", "").isalnum() or len(name) > 15:
            raise argparse.ArgumentTypeError("not an interface name: %r" % name)
    if len(names) != len(set(names)):
        raise argparse.ArgumentTypeError("a port is named twice in %r" % text)
    return names


def build_parser():
    parser = ofn_cli.ArgumentParser(PROG, __doc__.splitlines()[0],
                                    epilog=__doc__[__doc__.index("Runs until"):])
    parser.add_argument("--ports", type=port_list, required=True, metavar="P1,P2[,P...]",
                        help="the bridge's ports, comma-separated (required)")
    parser.add_argument("--links", default="", metavar="FROM:TO[,FROM:TO]",
                        help="impaired directions, comma-separated "
                             "(default: every ordered pair of --ports)")
    parser.add_argument("--delay", type=seconds, default=0.0, metavar="S",
                        help="seconds each frame is held (default: 0)")
    parser.add_argument("--jitter", type=seconds, default=0.0, metavar="S",
                        help="uniform +- seconds on the delay (default: 0)")
    parser.add_argument("--loss", type=share, default=0.0, metavar="P",
                        help="share of the frames dropped (default: 0)")
    parser.add_argument("--duplicate", type=share, default=0.0, metavar="P",
                        help="share of the frames sent twice (default: 0)")
    parser.add_argument("--reorder", type=share, default=0.0, metavar="P",
                        help="share of the frames sent at once, ahead of the delayed ones "
                             "(default: 0)")
    parser.add_argument("--seed", type=int, default=1, metavar="N",
                        help="seed of the random draws (default: 1)")
    parser.add_argument("--stats", default="", metavar="FILE",
                        help="file the counts are written to as JSON at the end (default: none)")
    return parser


def parse_args(argv):
    parser = build_parser()
    args = parser.parse_args(argv)
    if len(args.ports) < 2:
        parser.error("--ports needs at least two ports, got %d" % len(args.ports))
    if args.reorder > 0 and args.delay <= 0:
        parser.error("--reorder needs a --delay: frames are sent ahead of delayed ones")
    if args.links:
        links = []
        for item in args.links.split(","):
            ends = item.split(":")
            if len(ends) != 2 or ends[0] == ends[1] or any(e not in args.ports for e in ends):
                parser.error("--links: %r is not FROM:TO of two different --ports" % item)
            links.append((ends[0], ends[1]))
        args.links = sorted(set(links))
    else:
        args.links = [(a, b) for a in args.ports for b in args.ports if a != b]
    return args


def nft(*command):
    return subprocess.run(["nft"] + list(command), capture_output=True, text=True)


def install_table(links):
    """The bridge drops what it would forward on the impaired directions:
    the relay sends those frames itself."""
    nft("delete", "table", "bridge", TABLE)  # one left by a relay that was killed
    steps = [["add", "table", "bridge", TABLE],
             ["add", "chain", "bridge", TABLE, "forward",
              "{ type filter hook forward priority -10; policy accept; }"]]
    for source, target in links:
        steps.append(["add", "rule", "bridge", TABLE, "forward", "iifname", source, "oifname",
                      target, "drop"])
    for step in steps:
        done = nft(*step)
        if done.returncode != 0:
            raise OSError("nft %s: %s" % (" ".join(step), done.stderr.strip()))


def without_udp_checksum(frame):
    """An IPv4 UDP frame with its UDP checksum set to 0 ("none", which
    IPv4 allows). A veth leaves the checksum of a small datagram to the
    receiver's offload, so the frame read here carries a partial sum the
    receiving host would drop the datagram for; the first fragment of a
    large one carries a full checksum, equally valid as 0. Other frames
    (ARP, IGMP, later fragments) as they are; TCP is not fixed up (the bus
    is UDP)."""
    if len(frame) < 42 or frame[12:14] != b"\x08\x00":
        return frame
    ihl = (frame[14] & 0x0F) * 4
    fragment_offset = ((frame[20] & 0x1F) << 8) | frame[21]
    if frame[23] != 17 or fragment_offset != 0 or len(frame) < 14 + ihl + 8:
        return frame
    at = 14 + ihl + 6
    return frame[:at] + b"\x00\x00" + frame[at + 2:]


def open_port(name):
    sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETH_P_ALL))
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
    sock.bind((name, 0))
    sock.setblocking(False)
    return sock


class Relay:
    def __init__(self, args):
        self.args = args
        self.rng = random.Random(args.seed)
        self.targets = {}  # source port -> impaired target ports
        for source, target in args.links:
            self.targets.setdefault(source, []).append(target)
        self.counts = {"frames_in": 0, "sent": 0, "dropped": 0, "duplicated": 0,
                       "sent_ahead": 0, "send_errors": 0, "max_lag_ms": 0.0}
        self.queue = []  # (due, order, target, frame)
        self.order = 0
        self.sockets = {}

    def open(self):
        names = sorted(set(self.targets) | {t for ts in self.targets.values() for t in ts})
        for name in names:
            self.sockets[name] = open_port(name)
        self.by_fd = {s.fileno(): n for n, s in self.sockets.items()}

    def hold(self):
        """Seconds a frame is held, or 0 for one sent ahead."""
        a = self.args
        if a.reorder > 0 and self.rng.random() < a.reorder:
            self.counts["sent_ahead"] += 1
            return 0.0
        return max(0.0, a.delay + (self.rng.uniform(-a.jitter, a.jitter) if a.jitter else 0.0))

    def take(self, source, frame, now):
        self.counts["frames_in"] += 1
        frame = without_udp_checksum(frame)
        for target in self.targets.get(source, ()):
            if self.args.loss and self.rng.random() < self.args.loss:
                self.counts["dropped"] += 1
                continue
            copies = 1
            if self.args.duplicate and self.rng.random() < self.args.duplicate:
                copies = 2
                self.counts["duplicated"] += 1
            for _ in range(copies):
                self.order += 1
                heapq.heappush(self.queue, (now + self.hold(), self.order, target, frame))

    def send_due(self, now, late=True):
        """Sends every frame due by `now`; `late`: count how far behind its
        time each went (not for the flush at the end)."""
        while self.queue and self.queue[0][0] <= now:
            due, _, target, frame = heapq.heappop(self.queue)
            try:
                self.sockets[target].send(frame)
                self.counts["sent"] += 1
            except OSError:
                self.counts["send_errors"] += 1
            if late:
                self.counts["max_lag_ms"] = max(self.counts["max_lag_ms"], (now - due) * 1e3)

    def run(self, stop):
        readable = [s for n, s in self.sockets.items() if n in self.targets]
        while not stop:
            now = time.monotonic()
            wait = max(0.0, self.queue[0][0] - now) if self.queue else 0.5
            try:
                ready = select.select(readable, [], [], wait)[0]
            except InterruptedError:
                continue
            now = time.monotonic()
            for sock in ready:
                source = self.by_fd[sock.fileno()]
                while True:
                    try:
                        frame, address = sock.recvfrom(65535)
                    except (BlockingIOError, InterruptedError):
                        break
                    # Its own sends show on the port as outgoing frames.
                    if address[2] == socket.PACKET_OUTGOING:
                        continue
                    self.take(source, frame, now)
            self.send_due(time.monotonic())

    def summary(self):
        c = self.counts
        return ("link_relay: %d frames in, %d sent, %d dropped, %d duplicated, %d sent ahead, "
                "%d send errors, largest lag %.1f ms" % (
                    c["frames_in"], c["sent"], c["dropped"], c["duplicated"], c["sent_ahead"],
                    c["send_errors"], c["max_lag_ms"]))


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    stop = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda signum, frame: stop.append(signum))
    relay = Relay(args)
    try:
        relay.open()
        install_table(args.links)
        # What came before the table was forwarded by the bridge.
        for sock in relay.sockets.values():
            while select.select([sock], [], [], 0)[0]:
                sock.recv(65535)
    except OSError as error:
        print("%s: error: %s" % (PROG, error), file=sys.stderr)
        nft("delete", "table", "bridge", TABLE)
        return 1
    print("link_relay: relaying %s; delay %.3f s +- %.3f, loss %.3f, duplicate %.3f, "
          "reorder %.3f" % (", ".join("%s->%s" % link for link in args.links), args.delay,
                            args.jitter, args.loss, args.duplicate, args.reorder), flush=True)
    try:
        relay.run(stop)
    finally:
        # Frames still held go out now: the link's loss is --loss, not the
        # stop of the relay.
        nft("delete", "table", "bridge", TABLE)
        relay.send_due(float("inf"), late=False)
        print(relay.summary(), flush=True)
        if args.stats:
            with open(args.stats, "w") as f:
                json.dump(dict(relay.counts, links=["%s:%s" % l for l in args.links],
                               delay=args.delay, jitter=args.jitter, loss=args.loss,
                               duplicate=args.duplicate, reorder=args.reorder), f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
