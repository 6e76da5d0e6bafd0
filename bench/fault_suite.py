#!/usr/bin/python3
"""Fault suite: a course flown on the three-host split under one fault at a time, judged and tabled.

Usage: fault_suite.py [--scenario FILE] [--rtf X] [--out DIR] [--only NAME[,NAME]] [--list]
                      [--bin DIR] [--open-bus]

Each row flies the scenario (default bench3, the wall) with
deploy/fly_three_hosts.sh: gcs, onboard1 and onboard2 in network namespaces
joined by a bridge, the bus authenticated. The fault is applied from this
script, in the run's own namespaces only:

  none                    the reference flight
  loss-10/30/50           that share of the datagrams dropped on every link
                          between hosts, the whole flight (nftables numgen in
                          the bridge's namespace)
  blackout-2s             nothing from onboard2 reaches onboard1 for 2 s, once
                          avoidance has engaged
  kill-SERVICE            kill -9 of the service once avoidance has engaged
                          (the launcher restarts it)
  stop-SERVICE            SIGSTOP of the service for 3 s, then SIGCONT
  starve-onboard2         a busy process on onboard2's core for 10 s
  delay-20/50/100         every link between hosts delays each frame by 20 ms
                          +- 5, 50 ms +- 20 or 100 ms +- 20 (jitter that
                          reorders), the whole flight
  duplicate-10            every link sends 10 % of the frames twice
  reorder-10              every link delays frames by 20 ms and sends 10 %
                          at once, ahead of them

The last five go through bench/link_relay.py in the bridge's namespace (a
user-space link: packet sockets on the bridge's ports, the bridge told to
drop what the relay forwards), stopped when the ground station's run ends;
its counts are in the row's "applied" and in OUT/<name>/relay.json.

Every flight is judged by the benchmark rules (ofn_flight_report: true speed
and clearance, the verdict success / safe stop / failure). Writes
OUT/report.md and OUT/results.json; each row's run is in OUT/<name>/.
Progress is printed per row. Exit code 1 when any row's outcome is failure,
2 for bad arguments. Needs root (network namespaces) and nftables
(`make faults` installs it).

This kernel has neither sch_netem nor nftables' queue statement: hence
the user-space relay for delay, jitter, duplication and reordering
(docs/TESTING.md#the-fault-suite).
"""
import datetime
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import campaign_report as cr  # noqa: E402

PROG = "bench/fault_suite.py"
FLY3 = os.path.join(REPO, "deploy", "fly_three_hosts.sh")
RELAY = os.path.join(HERE, "link_relay.py")
# fly_three_hosts.sh's hosts, and the names of their ports on its bridge.
HOSTS = ("gcs", "onboard1", "onboard2")
ENDED = "the ground station's run ended"

sys.path.insert(0, os.path.join(REPO, "deploy"))
import launch  # noqa: E402

_process_table = None


def process_table():
    """The process table the flight is launched with: the services, their
    hosts, cores and executables (read at first use: it needs PyYAML)."""
    global _process_table
    if _process_table is None:
        _process_table = launch.load_table(os.path.join(REPO, "deploy", "processes.yaml"))
    return _process_table


def services():
    """Every service but the one that ends the run when it exits (the
    flight monitor), which is not killed here."""
    return [p.name for p in process_table().processes if not p.ends_run]
ENGAGED = "avoidance engages"
FT = 0.3048


def spec_of(service):
    return next(p for p in process_table().processes if p.name == service)


def comm_of(service):
    """The executable's name as the kernel shows it (cut to 15 characters)."""
    return os.path.basename(spec_of(service).command[0])[:15]


def rows():
    """Every row: name -> (description, trigger, action). The trigger is
    "start" (the recording has begun) or "engaged" (the RH optimiser has
    taken over in front of the obstacle, plus 1 s)."""
    table = {"none": ("no fault", "start", None)}
    for share in (10, 30, 50):
        table["loss-%d" % share] = ("%d %% of datagrams dropped on every link" % share, "start",
                                    ("loss", share))
    table["blackout-2s"] = ("onboard2 -> onboard1 cut for 2 s", "engaged", ("blackout", 2.0))
    for service in services():
        table["kill-" + service] = ("kill -9 " + service, "engaged", ("kill", service))
    for service in services():
        table["stop-" + service] = ("SIGSTOP " + service + " for 3 s", "engaged", ("stop", service))
    table["starve-onboard2"] = ("busy process on onboard2's core for 10 s", "engaged",
                                ("starve", "onboard2"))
    for delay_ms, jitter_ms in ((20, 5), (50, 20), (100, 20)):
        table["delay-%d" % delay_ms] = (
            "%d ms +- %d ms delay on every link" % (delay_ms, jitter_ms), "start",
            ("relay", ["--delay", str(delay_ms / 1000.0), "--jitter", str(jitter_ms / 1000.0)]))
    table["duplicate-10"] = ("10 % of frames duplicated on every link", "start",
                             ("relay", ["--duplicate", "0.1"]))
    table["reorder-10"] = ("20 ms delay, 10 % of frames sent ahead, on every link", "start",
                           ("relay", ["--delay", "0.02", "--reorder", "0.1"]))
    return table


class Run:
    """One fly_three_hosts.sh run, its output read line by line."""

    def __init__(self, out_dir, args):
        self.out_dir = out_dir
        self.lines = []
        self.tag = None
        self.engaged = threading.Event()
        self.ended = threading.Event()  # the ground station's run has ended
        self.relay_done = None  # a thread that stops the link relay at the end
        cmd = [FLY3, "--scenario", args.scenario, "--rtf", str(args.rtf), "--out", out_dir,
               "--timeout", str(args.timeout), "--bin", args.bin]
        if args.open_bus:
            cmd.append("--open-bus")
        self.output = open(os.path.join(out_dir, "fly.txt"), "w")
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, cwd=REPO)
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.output.write(line)
            self.lines.append(line)
            m = re.match(r"fly3: three hosts: network namespaces (\S+)-\{", line)
            if m:
                self.tag = m.group(1)
            if ENGAGED in line:
                self.engaged.set()
            if ENDED in line:
                self.ended.set()
        self.ended.set()
        self.output.close()

    def namespace(self, host):
        return "%s-%s" % (self.tag, host)

    def pids(self, host, comm):
        """Processes named `comm` inside the run's namespace of `host`."""
        listed = subprocess.run(["ip", "netns", "pids", self.namespace(host)],
                                capture_output=True, text=True).stdout.split()
        found = []
        for pid in listed:
            try:
                with open("/proc/%s/comm" % pid) as f:
                    if f.read().strip() == comm:
                        found.append(int(pid))
            except OSError:
                pass
        return found

    def alive(self):
        return self.proc.poll() is None


def nft(run, *commands):
    for command in commands:
        subprocess.run(["ip", "netns", "exec", run.namespace("bridge"), "nft"] + command,
                       check=True, capture_output=True, text=True)


def add_fault_table(run):
    nft(run, ["add", "table", "bridge", "ofn_faults"],
        ["add", "chain", "bridge", "ofn_faults", "forward",
         "{ type filter hook forward priority 0; policy accept; }"])


def apply(run, action):
    """Applies the fault; returns a short record of what was done."""
    kind, value = action
    if kind == "loss":
        add_fault_table(run)
        nft(run, ["add", "rule", "bridge", "ofn_faults", "forward", "numgen", "random", "mod",
                  "100", "<", str(value), "drop"])
        return "dropping %d %% on every link" % value
    if kind == "blackout":
        add_fault_table(run)
        nft(run, ["add", "rule", "bridge", "ofn_faults", "forward", "iifname", "onboard2",
                  "oifname", "onboard1", "drop"])
        time.sleep(value)
        nft(run, ["flush", "chain", "bridge", "ofn_faults", "forward"])
        return "onboard2 -> onboard1 cut for %.1f s" % value
    if kind == "relay":
        return start_relay(run, value)
    if kind in ("kill", "stop"):
        pids = run.pids(spec_of(value).host, comm_of(value))
        if not pids:
            return "no %s process found" % value
        if kind == "kill":
            for pid in pids:
                os.kill(pid, signal.SIGKILL)
            return "killed %s (pid %s)" % (value, ",".join(map(str, pids)))
        for pid in pids:
            os.kill(pid, signal.SIGSTOP)
        time.sleep(3.0)
        for pid in pids:
            try:
                os.kill(pid, signal.SIGCONT)
            except ProcessLookupError:
                pass
        return "stopped %s (pid %s) for 3 s" % (value, ",".join(map(str, pids)))
    if kind == "starve":
        # The table's core of onboard2's planner: its busiest service.
        core = core_of("rh_optimizer")
        busy = subprocess.Popen(["ip", "netns", "exec", run.namespace(value), "taskset", "-c",
                                 str(core), "/bin/sh", "-c", "while :; do :; done"])
        time.sleep(10.0)
        busy.kill()
        busy.wait()
        return "busy loop on core %d in %s for 10 s" % (core, value)
    raise ValueError(kind)


def start_relay(run, options):
    """bench/link_relay.py on every link between the hosts, in the bridge's
    namespace, until the ground station's run ends (before the hosts'
    namespaces go). Its last line of counts is kept in run.relay_summary."""
    stats = os.path.join(run.out_dir, "relay.json")
    log = open(os.path.join(run.out_dir, "relay.txt"), "w")
    relay = subprocess.Popen(["ip", "netns", "exec", run.namespace("bridge"), "/usr/bin/python3",
                              RELAY, "--ports", ",".join(HOSTS), "--stats", stats] + options,
                             stdout=log, stderr=subprocess.STDOUT)
    started = time.monotonic()
    while time.monotonic() - started < 5 and relay.poll() is None:
        with open(log.name) as f:
            if "link_relay: relaying" in f.read():
                break
        time.sleep(0.1)
    if relay.poll() is not None:
        log.close()
        with open(log.name) as f:
            raise OSError("the link relay exited with %d: %s" % (relay.returncode, f.read().strip()))
    run.relay_summary = "the relay did not report"

    def stop_at_end():
        run.ended.wait()
        relay.send_signal(signal.SIGTERM)
        try:
            relay.wait(timeout=10)
        except subprocess.TimeoutExpired:
            relay.kill()
            relay.wait()
        log.close()
        with open(log.name) as f:
            lines = [line.strip() for line in f if line.startswith("link_relay: ")]
        if lines and "frames in" in lines[-1]:
            run.relay_summary = lines[-1][len("link_relay: "):]

    run.relay_done = threading.Thread(target=stop_at_end, daemon=True)
    run.relay_done.start()
    what = " ".join(options).replace("--", "")
    return "relaying every link (%s)" % what


def core_of(service):
    """The core the process table pins `service` to, clamped to this machine."""
    return min(spec_of(service).core, (os.cpu_count() or 1) - 1)


def fly_row(name, row, args):
    description, trigger, action = row
    out_dir = os.path.join(args.out, name)
    shutil.rmtree(out_dir, ignore_errors=True)
    os.makedirs(out_dir)
    begin = time.monotonic()
    run = Run(out_dir, args)
    applied = "none"
    # Wait for the moment of the fault (gcs records: the flight is starting;
    # or avoidance has engaged), or the end of the run.
    def due():
        if trigger == "start":
            return os.path.exists(os.path.join(out_dir, "latest_log"))
        return run.engaged.is_set()

    while run.alive() and not due():
        time.sleep(0.2)
    if action is not None and run.alive() and run.tag:
        if trigger == "engaged":
            time.sleep(1.0)
        try:
            applied = apply(run, action)
        except (subprocess.CalledProcessError, OSError) as e:
            applied = "could not apply: %s" % (getattr(e, "stderr", None) or e)
    elif action is not None:
        applied = "not applied: the run ended first" if not run.alive() else \
            "not applied: no %s" % ("namespaces" if not run.tag else trigger)
    code = run.proc.wait()
    run.reader.join()
    if run.relay_done is not None:
        run.relay_done.join()
        applied += ": " + run.relay_summary
    result = {"name": name, "fault": description, "applied": applied, "exit_code": code,
              "wall_s": round(time.monotonic() - begin, 1)}
    summary_path = os.path.join(out_dir, "summary.json")
    if os.path.exists(summary_path):
        with open(summary_path) as f:
            s = json.load(f)
        result.update({
            "outcome": s["outcome"], "failures": s.get("failures", []),
            "max_speed_ft_s": s["max_speed"] / FT,
            "speed_limit_ft_s": s["limits"]["max_speed"] / FT,
            "min_clearance_ft": s["min_clearance"] / FT,
            "clearance_required_ft": s["clearance_required"] / FT,
            "gate_to_gate_s": s.get("gate_to_gate"),
        })
    else:
        result.update({"outcome": "no report", "failures": ["no flight report (exit %d)" % code]})
    restarts = sum(1 for line in run.lines if "restarting" in line.lower())
    result["restarts"] = restarts
    return result


def fmt(value, spec):
    return "-" if value is None else spec % value


def write_report(results, args, started):
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump({"scenario": args.scenario, "rtf": args.rtf, "open_bus": args.open_bus,
                   "started": started, "rows": results}, f, indent=1)
    lines = ["# Fault suite", "",
             "Scenario %s at real-time factor %s on three hosts (network namespaces on a bridge), "
             "bus %s; started %s on %s (%d cores)." % (
                 os.path.relpath(args.scenario, REPO), args.rtf,
                 "open" if args.open_bus else "authenticated", started, os.uname().nodename,
                 os.cpu_count() or 0), "",
             "| fault | outcome | max speed (ft/s) | least clearance (ft) | gate to gate (s) "
             "| restarts | applied | failures |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        lines.append("| %s | %s | %s | %s | %s | %d | %s | %s |" % (
            r["fault"], r["outcome"], fmt(r.get("max_speed_ft_s"), "%.2f"),
            fmt(r.get("min_clearance_ft"), "%.1f"), fmt(r.get("gate_to_gate_s"), "%.2f"),
            r["restarts"], r["applied"], "; ".join(r["failures"]) or "-"))
    with open(os.path.join(args.out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def build_parser():
    parser = cr.ArgumentParser(
        PROG, __doc__.splitlines()[0],
        epilog="Each row flies the course with deploy/fly_three_hosts.sh under one fault,\n"
               "applied in that run's network namespaces only, and is judged by the\n"
               "flight report's rules; OUT/report.md and OUT/results.json table them.\n"
               "\n"
               "Examples:\n"
               "  bench/fault_suite.py --list\n"
               "  bench/fault_suite.py --only loss-30,kill-rh_optimizer --out /tmp/faults\n"
               "\n"
               "Exit codes: 0 when no row's outcome is failure; 1 when any is; 2 for bad\n"
               "arguments, without root, or without nft for the loss rows.")
    parser.add_argument("--scenario", default=os.path.join(REPO, "sim", "scenarios", "bench3.yaml"),
                        metavar="FILE", help="course to fly (default: sim/scenarios/bench3.yaml)")
    parser.add_argument("--rtf", type=float, default=1.0, metavar="X",
                        help="real-time factor; the faults last wall-clock time (default: 1)")
    parser.add_argument("--out", metavar="DIR",
                        help="results folder (default: results/faults-YYYYmmdd-HHMMSS)")
    parser.add_argument("--only", metavar="NAME[,NAME]", help="rows to fly, see --list (default: all)")
    parser.add_argument("--list", action="store_true", help="list the rows and exit (default: off)")
    cr.add_bin_option(parser, "the service executables")
    parser.add_argument("--timeout", type=float, default=300.0, metavar="S",
                        help="wall-clock limit of each flight (default: 300)")
    parser.add_argument("--open-bus", action="store_true",
                        help="fly without authentication (default: the bus authenticated)")
    return parser


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    table = rows()
    if args.list:
        for name, (description, trigger, _) in table.items():
            print("%-26s %s (%s)" % (name, description,
                                     "from the start" if trigger == "start" else
                                     "once avoidance engages"))
        return 0
    names = list(table)
    if args.only:
        names = [n.strip() for n in args.only.split(",") if n.strip()]
        unknown = [n for n in names if n not in table]
        if unknown:
            parser.error("unknown row(s) %s; --list lists them" % ", ".join(unknown))
    if not args.rtf > 0:
        parser.error("--rtf must be > 0")
    if not os.path.isfile(args.scenario):
        parser.error("--scenario: no file %s" % args.scenario)
    args.bin = cr.bin_dir(parser, args)
    if os.geteuid() != 0:
        parser.error("the hosts' network namespaces need root")
    needs_nft = ("loss", "blackout", "delay", "duplicate", "reorder")
    if shutil.which("nft") is None and any(n.startswith(needs_nft) for n in names):
        parser.error("nft not found (apt-get install nftables, or make faults)")
    args.scenario = os.path.abspath(args.scenario)
    if not args.out:
        args.out = os.path.join(REPO, "results",
                                "faults-" + datetime.datetime.now().strftime("%Y%m%d-%H%M%S"))
    os.makedirs(args.out, exist_ok=True)
    args.out = os.path.abspath(args.out)
    started = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    results = []
    for i, name in enumerate(names, 1):
        print("[%d/%d] %s: %s ..." % (i, len(names), name, table[name][0]), flush=True)
        result = fly_row(name, table[name], args)
        results.append(result)
        print("    %s; max speed %s ft/s, least clearance %s ft, %d restarts; %s (%.0f s)" % (
            result["outcome"], fmt(result.get("max_speed_ft_s"), "%.2f"),
            fmt(result.get("min_clearance_ft"), "%.1f"), result["restarts"], result["applied"],
            result["wall_s"]), flush=True)
        write_report(results, args, started)
    print("report: %s" % os.path.join(args.out, "report.md"))
    return 1 if any(r["outcome"] not in ("success", "safe_stop") for r in results) else 0


if __name__ == "__main__":
    cr.run_main(PROG, main)
