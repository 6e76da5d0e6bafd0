#!/usr/bin/python3
"""Summarise the vehicle's track in an LCM log with ofn's generated Python types.

Reads the log file directly (no python3-lcm: Debian has none) and decodes each
NAV_STATE message with ofn.nav_state_t.decode(data), from the types that
`cmake --install` puts in <prefix>/share/ofn/python (docs/INSTALL.md):

    PYTHONPATH=<prefix>/share/ofn/python /usr/bin/python3 nav_track.py flight.lcm
    /usr/bin/python3 nav_track.py --types build/lcmtypes/python flight.lcm

Prints the number of navigation messages, the first and last positions and
the top speed (world NED, metres), or the same as JSON with --json.

Exit codes: 0 done; 1 when the log holds no decodable message on the channel;
2 for bad arguments, an unreadable file or missing types.
"""

import io
import json
import math
import os
import struct
import sys

# The command-line helpers of the project's Python programs (--version,
# one-line usage errors with exit code 2), from the same checkout.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "services", "tools"))
from ofn_cli import ArgumentParser, run_main  # noqa: E402

PROG = "examples/python/nav_track.py"

# An LCM log is a sequence of events, each: sync word 0xEDA1DA01, int64 event
# number, int64 timestamp (microseconds), int32 channel length, int32 data
# length, the channel name, the data. Everything big-endian.
SYNC = 0xEDA1DA01
HEADER = struct.Struct(">IqqII")
SYNC_BYTES = struct.pack(">I", SYNC)
MAX_CHANNEL = 1000  # bytes; a longer "channel" is a corrupt header


def find_sync(stream):
    """Moves the stream to the next sync word; False when there is none."""
    while True:
        start = stream.tell()
        chunk = stream.read(1 << 16)
        if len(chunk) < len(SYNC_BYTES):
            return False
        found = chunk.find(SYNC_BYTES)
        if found >= 0:
            stream.seek(start + found)
            return True
        stream.seek(start + len(chunk) - len(SYNC_BYTES) + 1)


def read_events(stream):
    """Yields (event_number, timestamp_us, channel, data) for every whole event.

    After a corrupt header it searches for the next sync word, as LCM's own
    reader does; a last event cut short (a log still being written) ends the
    iteration.
    """
    while True:
        header = stream.read(HEADER.size)
        if len(header) < HEADER.size:
            return
        sync, number, timestamp, channel_len, data_len = HEADER.unpack(header)
        if sync != SYNC or channel_len > MAX_CHANNEL:
            stream.seek(1 - HEADER.size, io.SEEK_CUR)
            if not find_sync(stream):
                return
            continue
        channel = stream.read(channel_len)
        data = stream.read(data_len)
        if len(channel) < channel_len or len(data) < data_len:
            return
        yield number, timestamp, channel.decode("utf-8", "replace"), data


def summarise(path, channel, nav_state_t):
    count = 0
    skipped = 0
    first = last = None
    top_speed = -1.0
    top = None
    with open(path, "rb") as stream:
        for _, timestamp, event_channel, data in read_events(stream):
            if event_channel != channel:
                continue
            try:
                msg = nav_state_t.decode(data)
            except (ValueError, struct.error):
                skipped += 1  # another type on this channel, or a cut message
                continue
            count += 1
            if first is None:
                first = msg
            last = msg
            speed = math.sqrt(sum(v * v for v in msg.velocity))
            if speed > top_speed:
                top_speed, top = speed, msg
    if count == 0:
        return None
    return {
        "channel": channel,
        "messages": count,
        "undecodable": skipped,
        "duration_s": (last.utime - first.utime) / 1e6,
        "first_position": list(first.position),
        "last_position": list(last.position),
        "top_speed": top_speed,
        "top_speed_time_s": (top.utime - first.utime) / 1e6,
        "frame": first.frame,
    }


def build_parser():
    parser = ArgumentParser(
        PROG,
        "First and last positions and top speed of the NAV_STATE track in an LCM log,\n"
        "decoded with ofn's generated Python types (no python3-lcm needed).",
        epilog="Examples:\n"
               "  PYTHONPATH=<prefix>/share/ofn/python /usr/bin/python3 examples/python/nav_track.py flight.lcm\n"
               "  /usr/bin/python3 examples/python/nav_track.py --types build/lcmtypes/python flight.lcm\n"
               "\n"
               "Exit codes: 0 done; 1 when the log holds no decodable message on the channel;\n"
               "2 for bad arguments, an unreadable file or missing types.")
    parser.add_argument("log", metavar="LOG", help="LCM log file, e.g. a flight's flight.lcm (required)")
    parser.add_argument("--channel", default="NAV_STATE",
                        help="channel of ofn.nav_state_t (default: %(default)s)")
    parser.add_argument("--types", metavar="DIR",
                        help="folder holding the generated package ofn/, e.g. "
                             "<prefix>/share/ofn/python or build/lcmtypes/python (default: from PYTHONPATH)")
    parser.add_argument("--json", action="store_true",
                        help="print the summary as one JSON object (default: text)")
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)

    if args.types:
        sys.path.insert(0, args.types)
    try:
        from ofn import nav_state_t
    except ImportError as error:
        print(f"{PROG}: error: ofn's Python types not found ({error}): pass --types "
              "<prefix>/share/ofn/python or set PYTHONPATH", file=sys.stderr)
        return 2
    try:
        summary = summarise(args.log, args.channel, nav_state_t)
    except OSError as error:
        print(f"{PROG}: error: cannot read {args.log}: {error.strerror}", file=sys.stderr)
        return 2
    if summary is None:
        print(f"{PROG}: no decodable {args.channel} message in {args.log}", file=sys.stderr)
        return 1

    if args.json:
        print(json.dumps(summary))
        return 0

    def fmt(p):
        return "(" + ", ".join(f"{x:.2f}" for x in p) + ")"

    print(f"{summary['messages']} {args.channel} messages over {summary['duration_s']:.2f} s "
          f"(frame {summary['frame']}, metres)")
    print(f"first position: {fmt(summary['first_position'])}")
    print(f"last position : {fmt(summary['last_position'])}")
    print(f"top speed     : {summary['top_speed']:.2f} m/s at t = {summary['top_speed_time_s']:.2f} s")
    if summary["undecodable"]:
        print(f"({summary['undecodable']} messages on {args.channel} did not decode as ofn.nav_state_t)")
    return 0


if __name__ == "__main__":
    run_main(PROG, main)
