#!/usr/bin/python3
"""Bus fuzz: a course flown by every service while ofn_bus_fuzz floods every channel, judged.

Usage: bus_fuzz.py [--messages N] [--rate R] [--scenario FILE] [--rtf X] [--out DIR]
                   [--bin DIR] [--rss-bound MB] [--seed N] [--keep-log]

Flies the scenario with deploy/launch.py (every service of
deploy/processes.yaml, the bus recorded, each service's memory sampled once a
second into resources.csv) in a private network namespace, and once every
service's heartbeat is heard, puts N fuzz messages on the bus at R a second
with ofn_bus_fuzz: every channel of the channel table, every field of a valid
message of its type made wrong in turn (cut short, a wrong fingerprint, sizes
up to 2^31, NaN and Inf in every float, stamps far in the past and future,
random bytes, oversized; docs/TESTING.md#the-bus-fuzz). Then asserts:

  - every message was sent;
  - no service crashed, hung or was restarted: the launcher's table shows
    each stopped by the launcher at the end (the flight monitor: ended the
    run itself), with no restart, and its pid in resources.csv never changed;
  - every service is heard after the flood with the pid it had before, and
    its heartbeat's rejection counter rose;
  - no service holds more than --rss-bound MB of resident memory beyond what
    it holds in the same flight without the fuzz (flown first, its samples
    compared at the end and at the peaks; with --no-control, beyond what it
    held before the flood);
  - the run was ended by the flight monitor (arrived, or its own limit), not
    by the launcher's.

The flight's verdict (ofn_flight_report, on the recording without the fuzz's
own messages that pass decoding and validation, which an open bus records
beside the flight's) is reported, not asserted: those messages are valid but
for a stamp or an extreme number, which the command gate, not the decoders,
must judge. Writes OUT/report.md and
OUT/results.json; the flight's folder is OUT/run (its log deleted after the
report unless --keep-log). Exit code 0 when every assertion holds, 1 when one
does not, 2 for bad arguments.
"""
import datetime
import glob
import json
import os
import re
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "services", "tools"))
sys.path.insert(0, os.path.join(REPO, "deploy"))

import ofn_cli  # noqa: E402

PROG = "bench/bus_fuzz.py"
LAUNCH = os.path.join(REPO, "deploy", "launch.py")
NETNS = os.path.join(REPO, "deploy", "netns.sh")


def build_parser():
    parser = ofn_cli.ArgumentParser(
        PROG, __doc__.splitlines()[0],
        epilog="Examples:\n"
               "  bench/bus_fuzz.py                      # 10^6 messages on out_and_back (make fuzz)\n"
               "  bench/bus_fuzz.py --messages 30000 --rate 3000 --scenario sim/scenarios/open.yaml \\\n"
               "      --rtf 2 --out /tmp/fuzz           # the short version (integration.bus_fuzz)\n"
               "\n"
               "Exit codes: 0 when every assertion holds; 1 when one does not; 2 for bad\n"
               "arguments or input.")
    parser.add_argument("--messages", type=int, default=1000000, metavar="N",
                        help="fuzz messages to send (default: 1000000)")
    parser.add_argument("--rate", type=float, default=5000.0, metavar="R",
                        help="messages per second (default: 5000)")
    parser.add_argument("--scenario", default=os.path.join(REPO, "sim", "scenarios",
                                                           "out_and_back.yaml"),
                        metavar="FILE", help="course to fly (default: sim/scenarios/out_and_back.yaml)")
    parser.add_argument("--rtf", type=float, default=0.5, metavar="X",
                        help="real-time factor; at 0.5 out_and_back lasts the 200 s of the "
                             "default flood (default: 0.5)")
    parser.add_argument("--out", metavar="DIR",
                        help="results folder (default: results/fuzz-YYYYmmdd-HHMMSS)")
    ofn_cli.add_bin_option(parser, "the service executables and ofn_bus_fuzz")
    parser.add_argument("--rss-bound", type=float, default=16.0, metavar="MB",
                        help="largest growth of any service's resident memory from before the "
                             "flood to the end of the flight (default: 16)")
    parser.add_argument("--seed", type=int, default=42, metavar="N",
                        help="seed of the fuzz's random parts (default: 42)")
    parser.add_argument("--no-control", action="store_true",
                        help="skip the flight without the fuzz that memory is compared with; "
                             "compare with memory before the flood (default: fly it first)")
    parser.add_argument("--keep-log", action="store_true",
                        help="keep the flight's LCM log (default: deleted after the report)")
    return parser


def check_args(parser, args):
    if args.messages < 1:
        parser.error("--messages must be >= 1")
    if not args.rate > 0:
        parser.error("--rate must be > 0")
    if not args.rtf > 0:
        parser.error("--rtf must be > 0")
    if not args.rss_bound > 0:
        parser.error("--rss-bound must be > 0")
    if not os.path.isfile(args.scenario):
        parser.error("--scenario: no file %s" % args.scenario)
    args.scenario = os.path.abspath(args.scenario)
    args.bin = ofn_cli.bin_dir(parser, args)
    for program in ("ofn_bus_fuzz", "ofn_flight_report"):
        if not os.access(os.path.join(args.bin, program), os.X_OK):
            parser.error("no %s in %s: build it (make build)" % (program, args.bin))


def in_private_namespace():
    return os.environ.get("OFN_IN_NETNS") == "1"


def scenario_max_time(path):
    yaml = ofn_cli.need("yaml")
    with open(path) as f:
        doc = yaml.safe_load(f) or {}
    return float(doc.get("max_time", 300.0))


class Marks:
    """The resources.csv time (the launcher's clock) when the flood began
    and ended, read from the file as the fuzz reports them."""

    def __init__(self, run_dir):
        self.run_dir = run_dir
        self.start = None
        self.end = None

    def csv(self):
        found = sorted(glob.glob(os.path.join(self.run_dir, "flight-*", "resources.csv")))
        return found[-1] if found else None

    def now(self):
        path = self.csv()
        last = None
        if path:
            with open(path) as f:
                for line in f:
                    head = line.split(",", 1)[0]
                    try:
                        last = float(head)
                    except ValueError:
                        pass
        return last


def run_fuzz(args, services, out, marks):
    """ofn_bus_fuzz on the flight's bus; its lines to fuzz.txt, the flood's
    start and end marked. Returns its exit code."""
    cmd = [os.path.join(args.bin, "ofn_bus_fuzz"), "--messages", str(args.messages),
           "--rate", str(args.rate), "--seed", str(args.seed), "--forgery-every", "0",
           "--wait", "60", "--listen", "%g" % (1.0 + 2.0 / args.rtf),
           "--after", "%g" % (2.0 + 2.0 / args.rtf), "--report", os.path.join(out, "fuzz.json"),
           "--valid-log", os.path.join(out, "valid.bin")]
    for s in services:
        cmd += ["--expect", s]
    with open(os.path.join(out, "fuzz.txt"), "w") as log:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                errors="replace")
        for line in proc.stdout:
            log.write(line)
            log.flush()
            print("  " + line.rstrip())
            if line.startswith("fuzz: flooding"):
                marks.start = marks.now()
            elif line.startswith("fuzz: flood done"):
                marks.end = marks.now()
        return proc.wait()


def fly(args, run_dir, out, timeout, during=None):
    """One flight with deploy/launch.py into `run_dir`, its output in
    OUT/launch.txt; `during()` runs while it flies. Returns the launcher's
    exit code and what `during` returned."""
    with open(os.path.join(out, "launch.txt"), "w") as launcher_out:
        launcher = subprocess.Popen([sys.executable, LAUNCH, "--scenario", args.scenario, "--rtf",
                                     str(args.rtf), "--bin", args.bin, "--out", run_dir,
                                     "--timeout", "%g" % timeout, "--max-restarts", "0"],
                                    stdout=launcher_out, stderr=subprocess.STDOUT, cwd=REPO)
        result = during() if during else None
        return launcher.wait(), result


def read_resources(path):
    """service -> [(t, pid, rss MB)] from resources.csv."""
    rows = {}
    with open(path) as f:
        next(f)
        for line in f:
            t, service, pid, rss, _ = line.strip().split(",")
            rows.setdefault(service, []).append((float(t), int(pid), float(rss)))
    return rows


SUMMARY_RE = re.compile(r"^launcher:   (\S+)\s+\S+\s+restarts (\S+)(, hung \d+)?\s+(.*?)(; rss .*)?$")


def read_launcher_summary(text):
    """service -> (restarts field, hung text, final state) from the
    launcher's closing table."""
    rows = {}
    in_summary = False
    for line in text.splitlines():
        if line.startswith("launcher: summary:"):
            in_summary = True
            continue
        if in_summary:
            m = SUMMARY_RE.match(line)
            if m:
                rows[m.group(1)] = (m.group(2), m.group(3) or "", m.group(4))
    return rows


def judge(args, services, out, marks, fuzz_code, launcher_code, launcher_text,
          control_csv=None):
    failures = []
    fuzz = {}
    try:
        with open(os.path.join(out, "fuzz.json")) as f:
            fuzz = json.load(f)
    except (OSError, ValueError):
        failures.append("ofn_bus_fuzz wrote no report (exit code %d)" % fuzz_code)
    if fuzz and fuzz.get("messages") != args.messages:
        failures.append("sent %s of %d messages" % (fuzz.get("messages"), args.messages))
    if fuzz_code != 0:
        failures.append("ofn_bus_fuzz exit code %d (a service dead, restarted or deaf)" % fuzz_code)

    summary = read_launcher_summary(launcher_text)
    for s in services:
        if s not in summary:
            failures.append("%s: not in the launcher's table" % s)
            continue
        restarts, hung, final = summary[s]
        if restarts not in ("-", "0/0") and not restarts.startswith("0/"):
            failures.append("%s: restarted (%s)" % (s, restarts))
        if hung:
            failures.append("%s: hung%s" % (s, hung))
        ended_by_monitor = s == "flight_monitor" and re.match(r"^code [01]$", final)
        if "stopped by launcher" not in final and not ended_by_monitor:
            failures.append("%s: %s" % (s, final))
    if launcher_code not in (0, 1):
        failures.append("the run was not ended by the flight monitor (launcher exit code %d)"
                        % launcher_code)

    rss = {}
    csv = marks.csv()
    resources = read_resources(csv) if csv else {}
    control_resources = read_resources(control_csv) if control_csv else {}
    if marks.start is None or marks.end is None:
        failures.append("the flood's start or end was not marked in resources.csv")
    for s in services:
        samples = resources.get(s, [])
        if not samples:
            failures.append("%s: no memory samples" % s)
            continue
        pids = sorted({p for _, p, _ in samples})
        if len(pids) > 1:
            failures.append("%s: pid changed during the flight (%s)" % (s, pids))
        start = marks.start if marks.start is not None else samples[0][0]
        end = marks.end if marks.end is not None else samples[-1][0]
        before = [r for t, _, r in samples if t <= start] or [samples[0][2]]
        during = [r for t, _, r in samples if start <= t <= end] or [before[-1]]
        entry = {"before_mb": before[-1], "peak_during_mb": max(during),
                 "after_mb": samples[-1][2], "peak_mb": max(r for _, _, r in samples),
                 "last_sample_s": samples[-1][0]}
        entry["growth_mb"] = entry["after_mb"] - entry["before_mb"]
        control = control_resources.get(s)
        if control:
            # The same flight without the fuzz: what the service grows by
            # itself (the mapper's map, the optimiser's field) is no excess.
            entry["control_after_mb"] = control[-1][2]
            entry["control_peak_mb"] = max(r for _, _, r in control)
            entry["excess_mb"] = max(entry["after_mb"] - entry["control_after_mb"],
                                     entry["peak_mb"] - entry["control_peak_mb"])
            judged, against = entry["excess_mb"], "the flight without the fuzz"
        else:
            judged = max(entry["growth_mb"], entry["peak_during_mb"] - entry["before_mb"])
            against = "before the flood"
        rss[s] = entry
        if judged > args.rss_bound:
            failures.append("%s: %.1f MB more resident memory than %s, over the bound of %g MB"
                            % (s, judged, against, args.rss_bound))

    for s in services:
        entry = fuzz.get("services", {}).get(s)
        if entry is None:
            continue
        if not entry.get("alive"):
            failures.append("%s: no heartbeat after the flood" % s)
        elif entry.get("pid_after") != entry.get("pid_before"):
            failures.append("%s: pid %s before the flood, %s after" % (s, entry.get("pid_before"),
                                                                     entry.get("pid_after")))
        elif not entry.get("rejected_after", 0) > entry.get("rejected_before", 0):
            failures.append("%s: its heartbeat counted no rejection" % s)
    return failures, fuzz, rss


LOG_HEADER = struct.Struct(">IqqII")  # sync word, event number, time, channel and data lengths


def read_valid_messages(path):
    """(channel, bytes) of every fuzz message its type would accept, as
    ofn_bus_fuzz --valid-log wrote them."""
    found = set()
    if not os.path.exists(path):
        return found
    with open(path, "rb") as f:
        data = f.read()
    i = 0
    while i + 2 <= len(data):
        (n,) = struct.unpack_from(">H", data, i)
        channel = data[i + 2:i + 2 + n]
        (size,) = struct.unpack_from(">I", data, i + 2 + n)
        start = i + 6 + n
        found.add((channel, data[start:start + size]))
        i = start + size
    return found


def without_fuzz(log, valid, filtered):
    """Copies the LCM log `log` to `filtered` without the fuzz's valid
    messages (an open bus records them beside the flight's own, and the
    report cannot tell them apart); returns how many were left out."""
    dropped = 0
    with open(log, "rb") as src, open(filtered, "wb") as dst:
        while True:
            head = src.read(LOG_HEADER.size)
            if len(head) < LOG_HEADER.size:
                break
            _, _, _, channel_length, data_length = LOG_HEADER.unpack(head)
            channel = src.read(channel_length)
            payload = src.read(data_length)
            if (channel, payload) in valid:
                dropped += 1
                continue
            dst.write(head)
            dst.write(channel)
            dst.write(payload)
    return dropped


def flight_report(args, out):
    """The flight's verdict from ofn_flight_report (outcome, its reasons),
    on the recording without the fuzz's valid messages; and the paths of
    the logs read."""
    run = os.path.join(out, "run")
    try:
        with open(os.path.join(run, "latest_log")) as f:
            recorded = f.read().strip()
    except OSError:
        return {"outcome": "no log"}, []
    valid_path = os.path.join(out, "valid.bin")
    log = recorded
    verdict = {}
    if os.path.exists(valid_path):
        log = recorded[:-len(".lcm")] + "-own.lcm"
        verdict["fuzz_messages_left_out"] = without_fuzz(recorded, read_valid_messages(valid_path),
                                                         log)
    report_dir = os.path.join(out, "report")
    started = time.monotonic()
    result = subprocess.run([os.path.join(args.bin, "ofn_flight_report"), "--log", log,
                             "--scenario", args.scenario, "--controller-config",
                             os.path.join(REPO, "config", "controller.yaml"), "--out", report_dir],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    with open(os.path.join(out, "flight_report.txt"), "w") as f:
        f.write(result.stdout)
    verdict.update({"report_exit_code": result.returncode,
                    "report_seconds": round(time.monotonic() - started, 1),
                    "log_mb": round(os.path.getsize(recorded) / 1e6, 1)
                    if os.path.exists(recorded) else None})
    try:
        with open(os.path.join(report_dir, "summary.json")) as f:
            summary = json.load(f)
        verdict["outcome"] = summary.get("outcome")
        verdict["failures"] = summary.get("failures", summary.get("rules_broken", []))
        verdict["messages_skipped"] = summary.get("messages_skipped")
    except (OSError, ValueError):
        verdict["outcome"] = "no report"
    return verdict, [recorded, log, valid_path]


def git_commit():
    try:
        return subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True).stdout.strip() or "unknown"
    except OSError:
        return "unknown"


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def write_report(args, out, services, results):
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    fuzz, rss = results["fuzz"], results["rss"]
    lines = ["# Bus fuzz", "",
             "%s messages at %s/s (%.1f s, %.1f MB) on %d channels while %s flew at real-time "
             "factor %s; %s, %s (%d cores), commit %s." % (
                 fuzz.get("messages", 0), args.rate, fuzz.get("seconds", 0.0),
                 fuzz.get("bytes", 0) / 1e6, len(fuzz.get("by_channel", {})),
                 os.path.relpath(args.scenario, REPO), args.rtf, results["started"],
                 results["cpu"], os.cpu_count() or 0, results["commit"]), "",
             "| kind | messages |", "|---|---|"]
    for kind, n in sorted(fuzz.get("by_kind", {}).items(), key=lambda kv: -kv[1]):
        lines.append("| %s | %d |" % (kind, n))
    def mb(r, key, spec="%.1f"):
        return spec % r[key] if key in r else "-"

    lines += ["", "RSS in MB: before the flood, its peak during it, at the end of the flight; "
              "the same flight without the fuzz at its end; the excess (the larger of the "
              "differences at the end and at the peaks).", "",
              "| service | alive, same pid | rejected during the flood | before | peak during "
              "| after | without the fuzz | excess |", "|---|---|---|---|---|---|---|---|"]
    for s in services:
        f = fuzz.get("services", {}).get(s, {})
        r = rss.get(s, {})
        same = f.get("alive") and f.get("pid_after") == f.get("pid_before")
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
            s, "yes" if same else "NO",
            f.get("rejected_after", 0) - f.get("rejected_before", 0) if f.get("alive") else "-",
            mb(r, "before_mb"), mb(r, "peak_during_mb"), mb(r, "after_mb"),
            mb(r, "control_after_mb"), mb(r, "excess_mb", "%+.1f")))
    def verdict(v):
        return "%s%s" % (v.get("outcome"),
                         " (%s)" % "; ".join(v["failures"]) if v.get("failures") else "")

    lines += ["", "Flight: %s%s; crashes %d, restarts %d." % (
        verdict(results["flight"]),
        "; without the fuzz: " + verdict(results["control_flight"])
        if results.get("control_flight") else "", results["crashes"], results["restarts"]),
              "", "Assertions: %s" % ("all hold" if not results["failures"] else
                                      "; ".join(results["failures"]))]
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return lines


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    check_args(parser, args)
    launch = ofn_cli.need("launch")  # needs PyYAML: checked before anything runs
    table = launch.load_table(os.path.join(REPO, "deploy", "processes.yaml"))
    services = [p.name for p in table.processes]
    max_time = scenario_max_time(args.scenario)
    if not in_private_namespace():
        # Everything below runs in a private network namespace of its own.
        env = dict(os.environ, OFN_IN_NETNS="1")
        argv = sys.argv[1:] if argv is None else argv
        return subprocess.call([NETNS, sys.executable, os.path.abspath(__file__)] + list(argv),
                               env=env)

    out = os.path.abspath(args.out or os.path.join(
        REPO, "results", "fuzz-" + datetime.datetime.now().strftime("%Y%m%d-%H%M%S")))
    os.makedirs(out, exist_ok=True)
    started = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    flood_s = args.messages / args.rate
    timeout = max(max_time / args.rtf + 30.0, flood_s + 90.0)
    wall_start = time.monotonic()
    control_csv = None
    control_verdict = None
    if not args.no_control:
        print("fuzz: the control flight: %s at rtf %g without the fuzz, in %s/control"
              % (os.path.relpath(args.scenario, REPO), args.rtf, out))
        control_dir = os.path.join(out, "control")
        os.makedirs(control_dir, exist_ok=True)
        code, _ = fly(args, os.path.join(control_dir, "run"), control_dir, timeout)
        control_csv = Marks(os.path.join(control_dir, "run")).csv()
        control_verdict, logs = flight_report(args, control_dir)
        print("fuzz: the control flight: %s%s" % (
            control_verdict.get("outcome"), " (%s)" % "; ".join(control_verdict["failures"])
            if control_verdict.get("failures") else ""))
        if not args.keep_log:
            for path in logs:
                if os.path.exists(path):
                    os.remove(path)
        if code not in (0, 1) or control_csv is None:
            print("fuzz: the control flight failed to run (launcher exit code %d)" % code)
            return 1
    print("fuzz: %d messages at %g/s (%.0f s) while %s flies at rtf %g; results in %s"
          % (args.messages, args.rate, flood_s, os.path.relpath(args.scenario, REPO), args.rtf,
             out))
    marks = Marks(os.path.join(out, "run"))
    launcher_code, fuzz_code = fly(args, os.path.join(out, "run"), out, timeout,
                                   lambda: run_fuzz(args, services, out, marks))
    with open(os.path.join(out, "launch.txt"), errors="replace") as f:
        launcher_text = f.read()
    failures, fuzz, rss = judge(args, services, out, marks, fuzz_code, launcher_code,
                                launcher_text, control_csv)
    verdict, logs = flight_report(args, out)
    if not args.keep_log:
        for path in logs:
            if os.path.exists(path):
                os.remove(path)
    summary = read_launcher_summary(launcher_text)
    crashes = sum(1 for s in services if s in summary and "signal" in summary[s][2]
                  and "stopped by launcher" not in summary[s][2])
    restarts = sum(1 for line in launcher_text.splitlines() if "restarting" in line.lower())
    results = {"started": started, "commit": git_commit(), "cpu": cpu_model(),
               "scenario": os.path.relpath(args.scenario, REPO), "rtf": args.rtf,
               "rate": args.rate, "rss_bound_mb": args.rss_bound,
               "wall_seconds": round(time.monotonic() - wall_start, 1),
               "fuzz": fuzz, "rss": rss, "flight": verdict, "control_flight": control_verdict,
               "crashes": crashes,
               "restarts": restarts, "launcher_exit_code": launcher_code,
               "failures": failures}
    for line in write_report(args, out, services, results):
        print(line)
    print("fuzz: %s in %.0f s; report in %s" % ("PASS" if not failures else "FAIL",
                                                results["wall_seconds"],
                                                os.path.join(out, "report.md")))
    return 0 if not failures else 1


if __name__ == "__main__":
    ofn_cli.run_main(PROG, main)
