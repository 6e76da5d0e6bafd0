#!/usr/bin/python3
"""Benchmark campaign: every course of BENCHMARKS.md flown, compared with its baseline, reported.

Usage: campaign.py [--bin DIR] [--out DIR] [--courses bench1,...] [--jobs N]
                   [--multiprocess COURSE|none] [--rtf X] [--quick]

1. Flies every course (sim/scenarios/bench1..bench6, tree) in the lockstep
   runner, N at a time, and times this part (the goal is < 5 min).
2. Flies one course through the multi-process deployment (nine processes on
   LCM multicast in a private network namespace), alone, at --rtf.
3. Computes the time-optimal baseline of every course with ofn_baseline when
   the build has it (cached per scenario content and ofn_baseline binary).
4. Writes OUT/report.md, OUT/results.json (machine-readable) and one figure
   per course, OUT/fig-COURSE.png.

Each flight's folder (OUT/COURSE/, OUT/multiprocess-COURSE/) keeps the
runner's CSVs, summary.json and LCM log. Exit code 1 when any flight fails
the benchmark verdict (the report is written anyway), 2 for bad arguments.
"""
import concurrent.futures
import datetime
import hashlib
import json
import os
import resource
import shutil
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import campaign_report as cr  # noqa: E402

COURSES = ["bench1", "bench2", "bench3", "bench4", "bench5", "bench6", "tree"]
QUICK_COURSES = ["bench1", "bench4"]
SENSOR_COURSES = {"tree"}  # drawn with front and side views of the LIDAR hits
# Flight test 2 / time-optimal baseline, INTOPTOA paper Table 2.
PAPER_FT2_RATIO = {"bench3": 1.043, "bench4": 0.998, "bench5": 1.055, "bench6": 1.005}
RATIO_LIMIT = 1.055
RATIO_GOAL = 1.03
DEFAULT_CONFIG = os.path.join(REPO, "config")
LOCKSTEP_BUDGET_S = 300.0
LOCKSTEP_TIMEOUT_S = 900.0
BASELINE_TIMEOUT_S = 900.0
MULTIPROCESS_SLACK_S = 60.0  # launcher start-up and shutdown beyond the flight itself

_print_lock = threading.Lock()


def say(msg):
    with _print_lock:
        print(msg, flush=True)


def scenario_path(course):
    return os.path.join(REPO, "sim", "scenarios", course + ".yaml")


def bin_path(bin_dir, name):
    return os.path.join(bin_dir, name)


def timed_obstacles(scenario):
    """Number of the scenario's obstacles with an appear_time or a disappear_time (pop-ups)."""
    yaml = cr.need("yaml")
    try:
        with open(scenario) as f:
            doc = yaml.safe_load(f) or {}
    except (OSError, yaml.YAMLError):
        return 0
    return sum(1 for o in doc.get("obstacles") or []
               if isinstance(o, dict) and ("appear_time" in o or "disappear_time" in o))


# ofn_baseline (sim/src/time_optimal.cpp) builds its world from every
# obstacle the scenario ever has, whatever its appear and disappear times.
BASELINE_POPUP_NOTE = (
    "the time-optimal baseline knows the pop-up obstacles from the start: ofn_baseline counts every "
    "obstacle the course ever has as present for the whole flight (one that appears later as if it "
    "were there from the start, one that is removed as if it stayed), so on such a course the ratio "
    "compares a reacting vehicle with a planner that knew the future")


# --------------------------------------------------------------------------- machine

def machine_info():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cores": os.cpu_count(), "cpu": model}


def default_jobs():
    """--jobs default: one flight per core."""
    return max(1, os.cpu_count() or 1)


def git_commit():
    try:
        out = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, timeout=10)
        commit = out.stdout.strip() or "unknown"
        dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return commit + (" (with uncommitted changes)" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def children_cpu_s():
    """CPU seconds used by finished child processes so far; on an otherwise
    idle machine a part's wall time is about its CPU time over the jobs."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def now_text():
    return datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")


# --------------------------------------------------------------------------- flights

def tail(text, lines=8):
    return "\n".join((text or "").strip().splitlines()[-lines:])


def run_lockstep(bin_dir, scenario, out_dir, config_dir=DEFAULT_CONFIG, timeout=LOCKSTEP_TIMEOUT_S,
                 extra_args=()):
    """Fly one scenario in the lockstep runner (`extra_args` appended to its
    command). Returns a record with the summary (None when the runner left
    none) and, if it broke, an error text."""
    if os.path.isdir(out_dir):
        shutil.rmtree(out_dir)  # a stale summary must never stand in for this flight's
    os.makedirs(out_dir)
    cmd = [bin_path(bin_dir, "ofn_sim_runner"), "--scenario", scenario, "--config-dir", config_dir,
           "--out", out_dir, "--quiet"] + list(extra_args)
    t0 = time.monotonic()
    rec = {"dir": out_dir, "scenario": scenario, "command": cmd, "exit_code": None, "error": None}
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        rec["exit_code"] = proc.returncode
        with open(os.path.join(out_dir, "runner.txt"), "w") as f:
            f.write(proc.stdout + proc.stderr)
        if proc.returncode < 0:
            rec["error"] = "runner killed by signal %d" % -proc.returncode
        elif proc.returncode not in (0, 1):
            rec["error"] = "runner exit code %d: %s" % (proc.returncode, tail(proc.stderr, 2))
    except subprocess.TimeoutExpired:
        rec["error"] = "runner still going after %.0f s wall" % timeout
    except OSError as exc:
        rec["error"] = "cannot start the runner: %s" % exc
    rec["wall_s"] = time.monotonic() - t0
    rec["summary"] = cr.read_json(os.path.join(out_dir, "summary.json"))
    if rec["summary"] is None and rec["error"] is None:
        rec["error"] = "no summary.json (exit code %s)" % rec["exit_code"]
    return rec


def flight_ok(rec):
    """The flight succeeded: its outcome is success and the run did not break."""
    s = rec.get("summary")
    return bool(s and s.get("success") and rec.get("error") is None)


def flight_outcome(rec):
    """"success", "safe_stop" or "failure": the report's outcome; a summary
    from before the outcome field gives success or failure from its success
    flag, and a run that broke (or left no summary) is a failure."""
    s = rec.get("summary")
    if not s or rec.get("error") is not None:
        return "failure"
    outcome = s.get("outcome")
    if outcome in ("success", "safe_stop", "failure"):
        return outcome
    return "success" if s.get("success") else "failure"


def process_table(config_dir, out_dir):
    """deploy/processes.yaml, pointed at config_dir when that is not the repository's."""
    table = os.path.join(REPO, "deploy", "processes.yaml")
    if os.path.realpath(config_dir) == os.path.realpath(DEFAULT_CONFIG):
        return table
    yaml = cr.need("yaml")
    with open(table) as f:
        doc = yaml.safe_load(f)
    for entry in doc.get("processes", doc) if isinstance(doc, dict) else doc:
        if isinstance(entry, dict) and entry.get("config"):
            entry["config"] = os.path.join(config_dir, os.path.basename(entry["config"]))
    path = os.path.join(out_dir, "processes.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(doc, f, sort_keys=False)
    return path


def run_multiprocess(bin_dir, scenario, out_dir, rtf, config_dir=DEFAULT_CONFIG):
    """Fly one scenario through the real processes on udpm:// in a private
    network namespace (as deploy/fly.sh does, but with this build's binaries)
    and turn the recorded bus into the same report files as the runner."""
    if os.path.isdir(out_dir):
        shutil.rmtree(out_dir)
    os.makedirs(out_dir)
    yaml = cr.need("yaml")
    with open(scenario) as f:
        max_time = float((yaml.safe_load(f) or {}).get("max_time", 600))
    timeout = max_time / rtf + MULTIPROCESS_SLACK_S
    launch = [os.path.join(REPO, "deploy", "netns.sh"), "--fallback", "/usr/bin/python3",
              os.path.join(REPO, "deploy", "launch.py"), "--table", process_table(config_dir, out_dir),
              "--scenario", scenario, "--rtf", str(rtf),
              "--bin", bin_dir, "--out", out_dir, "--timeout", "%.0f" % timeout]
    rec = {"dir": out_dir, "scenario": scenario, "command": launch, "exit_code": None, "error": None,
           "rtf": rtf}
    t0 = time.monotonic()
    try:
        with open(os.path.join(out_dir, "launch.txt"), "w") as log:
            proc = subprocess.run(launch, stdout=log, stderr=subprocess.STDOUT,
                                  timeout=timeout + MULTIPROCESS_SLACK_S)
        rec["exit_code"] = proc.returncode
        if proc.returncode != 0:
            rec["error"] = "launcher exit code %d (see %s/launch.txt)" % (proc.returncode, out_dir)
    except subprocess.TimeoutExpired:
        rec["error"] = "launcher still going after %.0f s" % (timeout + MULTIPROCESS_SLACK_S)
    except OSError as exc:
        rec["error"] = "cannot start the launcher: %s" % exc
    rec["wall_s"] = time.monotonic() - t0
    latest = os.path.join(out_dir, "latest_log")
    if os.path.isfile(latest):
        with open(latest) as f:
            log_path = f.read().strip()
        report = [bin_path(bin_dir, "ofn_flight_report"), "--log", log_path, "--scenario", scenario,
                  "--out", out_dir]
        controller_config = os.path.join(config_dir, "controller.yaml")
        if os.path.isfile(controller_config):  # the controller flew with its defaults otherwise
            report += ["--controller-config", controller_config]
        proc = subprocess.run(report, capture_output=True, text=True)
        with open(os.path.join(out_dir, "report.txt"), "w") as f:
            f.write(proc.stdout + proc.stderr)
    elif rec["error"] is None:
        rec["error"] = "no flight log was recorded"
    rec["summary"] = cr.read_json(os.path.join(out_dir, "summary.json"))
    if rec["summary"] is None and rec["error"] is None:
        rec["error"] = "no summary.json from ofn_flight_report"
    return rec


# --------------------------------------------------------------------------- baselines

def _file_digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def run_baseline(bin_dir, scenario, cache_dir, timeout=BASELINE_TIMEOUT_S):
    """Time-optimal baseline of a scenario from ofn_baseline, cached under
    cache_dir by the scenario's content and the binary's content (a rebuilt
    planner recomputes). Returns {available, status, baseline_time, dir, ...}."""
    exe = bin_path(bin_dir, "ofn_baseline")
    if not os.access(exe, os.X_OK):
        return {"available": False, "status": "n/a", "note": "ofn_baseline is not in %s" % bin_dir,
                "baseline_time": None, "dir": None}
    key = _file_digest(scenario)[:16] + "-" + _file_digest(exe)[:8]
    out_dir = os.path.join(cache_dir, key)
    result_path = os.path.join(out_dir, "baseline.json")
    status_path = os.path.join(out_dir, "status.json")
    cached = cr.read_json(status_path)
    if cached is None:
        os.makedirs(out_dir, exist_ok=True)
        cmd = [exe, "--scenario", scenario, "--out", out_dir, "--quiet"]
        t0 = time.monotonic()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
            code, text = proc.returncode, proc.stdout + proc.stderr
        except subprocess.TimeoutExpired:
            code, text = None, "still going after %.0f s" % timeout
        cached = {"exit_code": code, "output": tail(text, 6), "wall_s": time.monotonic() - t0,
                  "scenario": scenario}
        if code in (0, 1):  # a crash or bad input is not worth remembering
            with open(status_path, "w") as f:
                json.dump(cached, f, indent=1)
    data = cr.read_json(result_path) or {}
    code = cached["exit_code"]
    rec = {"available": True, "dir": out_dir, "exit_code": code, "wall_s": cached.get("wall_s"),
           "baseline_time": None, "lower_bound_time": data.get("lower_bound_time"),
           "path_length_lower_bound": data.get("path_length_lower_bound"),
           "worst_violation": data.get("worst_violation"), "route": data.get("route")}
    if code == 0 and data.get("feasible", True) and data.get("baseline_time"):
        rec.update(status="ok", baseline_time=float(data["baseline_time"]))
    elif code == 1 or (code == 0 and data.get("feasible") is False):
        rec.update(status="infeasible", note="ofn_baseline found no feasible trajectory")
    else:
        rec.update(status="error", note="ofn_baseline failed (exit %s): %s" % (code, cached["output"]))
    return rec


# --------------------------------------------------------------------------- parallel

def longest_first(courses, out):
    """Courses ordered by their wall time in the previous results in `out`,
    longest first, so that the slowest flight does not start last."""
    prev = cr.read_json(os.path.join(out, "results.json")) or {}
    wall = {c.get("course"): c.get("wall_s") or 0.0 for c in prev.get("courses") or []}
    return sorted(courses, key=lambda c: -wall.get(c, 0.0))


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during run_all: `results` holds the runs that had finished
    before it ({key: result}); the ones under way were cut short (their
    processes got the same SIGINT) and the ones not begun never ran."""

    def __init__(self, results):
        super().__init__()
        self.results = results


def run_all(tasks, jobs, on_done=None):
    """Run callables [(key, fn)] N at a time; returns {key: result} and calls
    on_done(key, result, finished_count) as each one ends. On Ctrl-C the runs
    not begun are dropped and Interrupted carries those that finished."""
    results = {}
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs))
    try:
        futures = {pool.submit(fn): key for key, fn in tasks}
        for n, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            key = futures[fut]
            results[key] = fut.result()
            if on_done:
                on_done(key, results[key], n)
    except KeyboardInterrupt:
        pool.shutdown(wait=True, cancel_futures=True)
        raise Interrupted(dict(results)) from None
    pool.shutdown(wait=True)
    return results


# --------------------------------------------------------------------------- report

def flight_row(label, rec, baseline, paper_ratio):
    s = rec.get("summary")
    m = cr.course_metrics(s) if s else None
    if m is not None and rec.get("error"):
        m["success"] = False
        m["failures"] = m["failures"] + [rec["error"]]
    bt = baseline.get("baseline_time") if baseline else None
    return {"label": label, "metrics": m, "error": rec.get("error"), "baseline_time": bt,
            "paper_ratio": paper_ratio,
            "baseline_knows_popups": bool(bt) and timed_obstacles(rec["scenario"]) > 0,
            "ratio": cr.ratio_of(m["gate_to_gate_s"], bt) if m else None,
            "success": bool(m and m["success"]), "dir": rec.get("dir"), "wall_s": rec.get("wall_s"),
            "baseline_status": baseline.get("status") if baseline else "n/a"}


def evaluate_goals(rows, mp_row, lockstep_s, baselines_available):
    goals = []
    bad = [r["label"] for r in rows if not r["success"]]
    close = [r["label"] for r in rows if r["metrics"] and r["metrics"]["min_clearance"] is not None
             and r["metrics"]["min_clearance"] < r["metrics"]["clearance_required"]]
    goals.append({"goal": "every course succeeds with no clearance violation (least clearance >= R_s)",
                  "met": not bad and not close,
                  "detail": "all %d succeed, all outside R_s" % len(rows) if not bad and not close else
                  "; ".join(x for x in ("failed: " + ", ".join(bad) if bad else "",
                                        "inside R_s: " + ", ".join(close) if close else "") if x)})
    ratios = {r["label"]: r["ratio"] for r in rows}
    for limit, what in ((RATIO_LIMIT, "every ratio <= %.3f" % RATIO_LIMIT),
                        (RATIO_GOAL, "every ratio <= %.2f (project goal)" % RATIO_GOAL)):
        if not baselines_available:
            goals.append({"goal": what, "met": None, "detail": "not assessed: no baseline (ofn_baseline missing)"})
            continue
        missing = [c for c, v in ratios.items() if v is None]
        over = ["%s %.3f" % (c, v) for c, v in ratios.items() if v is not None and v > limit]
        goals.append({"goal": what, "met": not over and not missing,
                      "detail": ", ".join(over) if over else
                      ("no ratio for " + ", ".join(missing) if missing else
                       "worst %.3f" % max(ratios.values()))})
    goals.append({"goal": "lockstep campaign < %.0f min" % (LOCKSTEP_BUDGET_S / 60),
                  "met": lockstep_s < LOCKSTEP_BUDGET_S, "detail": "%.0f s for %d courses" % (lockstep_s, len(rows))})
    if mp_row is not None:
        goals.append({"goal": "multi-process flight succeeds", "met": mp_row["success"],
                      "detail": mp_row["label"]})
    return goals


def mark(met):
    return {True: "met", False: "**not met**", None: "not assessed"}[met]


def write_report(out, ctx):
    rows, mp_row, goals, timing = ctx["rows"], ctx["mp_row"], ctx["goals"], ctx["timing"]
    unit = next((r["metrics"]["display_unit"] for r in rows + ([mp_row] if mp_row else []) if r["metrics"]), "ft")
    lines = [
        "# Benchmark campaign",
        "",
        "- date: %s" % ctx["date"],
        "- machine: %d cores, %s" % (ctx["machine"]["cores"], ctx["machine"]["cpu"]),
        "- commit: %s" % ctx["commit"],
        "- binaries: %s, configuration %s" % (ctx["bin"], ctx["config_dir"]),
        "",
        cr.RECONSTRUCTION_NOTE + " Comparisons with the paper are of ratios (achieved time / "
        "time-optimal baseline), never of absolute times.",
        "",
        "## Courses",
        "",
        "Lockstep runner (all services in one process, deterministic), %d at a time; the machine's "
        "1-minute load average was %.1f before and %.1f after the lockstep part (other work on the "
        "machine lengthens the wall times only: in lockstep an RH solve is bounded by its "
        "evaluation count, not by wall time, so the results repeat to the bit)." % (ctx["jobs"], ctx["load"]["before"], ctx["load"]["after"]),
        "",
        cr.course_table(rows + ([mp_row] if mp_row else []), unit),
        "",
        "A run fails if it misses the finish gate, comes closer than 0.8 R_s to a real obstacle "
        "surface, or exceeds a limit by more than 2 %. Clearance is to the true obstacle surfaces "
        "over the whole flight; the commanded acceleration is the reference acceleration the "
        "controller was given; tracking error is reference minus flown position.",
    ]
    popup_rows = [r["label"] for r in rows + ([mp_row] if mp_row else []) if r.get("baseline_knows_popups")]
    if popup_rows:
        lines += ["", "Ratios marked \"pop-ups known to the baseline\" (%s): %s." % (
            ", ".join(popup_rows), BASELINE_POPUP_NOTE)]
    if not ctx["baselines_available"]:
        lines += ["", "**Baseline: n/a.** %s; the baseline and ratio columns and the ratio goals "
                  "are not assessed." % ctx["baseline_note"]]
    else:
        notes = ["%s: %s" % (r["label"], r.get("baseline_note")) for r in rows if r.get("baseline_note")]
        if notes:
            lines += ["", "Baselines missing: " + "; ".join(notes) + "."]
    if mp_row is not None:
        lines += ["", "The row `%s` is the same course flown through the multi-process deployment "
                  "(nine processes on LCM multicast in a private network namespace) at %.2gx real "
                  "time, with the baseline of its lockstep row." % (mp_row["label"], ctx["rtf"])]
    lines += ["", "## Goals", "", "| goal | result | detail |", "|---|---|---|"]
    lines += ["| %s | %s | %s |" % (g["goal"], mark(g["met"]), g["detail"]) for g in goals]
    lines += ["", "## Wall time", "", "| part | s |", "|---|---|"]
    lines += ["| %s | %.1f |" % (k[:-2].replace("_", " ") + (" (sum over the flights)" if "cpu" in k else ""), v)
              for k, v in timing.items()]
    lines += ["", "## Figures", "",
              "Per course: top view (obstacles, flown path, the baseline dashed when available), "
              "altitude, speed against the limit, commanded against actual acceleration against the "
              "limit; for the tree also the front (y-h) and side (x-h) views with the LIDAR hits.", ""]
    for r in rows + ([mp_row] if mp_row else []):
        if r.get("figure"):
            lines.append("### %s\n\n![%s](%s)\n" % (r["label"], r["label"], os.path.basename(r["figure"])))
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_results_json(out, ctx):
    def row_json(r):
        doc = dict(r["metrics"] or {})
        doc.update(course=r["label"], success=r["success"], error=r.get("error"), dir=r.get("dir"),
                   wall_s=r.get("wall_s"), baseline_time_s=r["baseline_time"],
                   baseline_status=r["baseline_status"], ratio=r["ratio"],
                   baseline_knows_popups=r.get("baseline_knows_popups", False),
                   paper_ft2_ratio=r["paper_ratio"], figure=r.get("figure"))
        return doc
    doc = {"date": ctx["date"], "machine": ctx["machine"], "commit": ctx["commit"], "bin": ctx["bin"],
           "baselines_available": ctx["baselines_available"],
           "courses": [row_json(r) for r in ctx["rows"]],
           "multiprocess": row_json(ctx["mp_row"]) if ctx["mp_row"] else None,
           "goals": ctx["goals"], "timing": ctx["timing"], "load_average": ctx["load"],
           "all_succeeded": all(r["success"] for r in ctx["rows"] + ([ctx["mp_row"]] if ctx["mp_row"] else []))}
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(doc, f, indent=1)


def describe(label, rec):
    s = rec.get("summary")
    if s is None:
        return "%s: FAILED (%s), %.1f s wall" % (label, rec.get("error"), rec.get("wall_s", 0))
    m = cr.course_metrics(s)
    verdict = "ok" if flight_ok(rec) else "FAILED (%s)" % "; ".join(m["failures"] + ([rec["error"]] if rec.get("error") else []))
    return "%s: %s, gate-to-gate %s s, least clearance %s %s (R_s %s), %.1f s wall" % (
        label, verdict, cr.fmt(m["gate_to_gate_s"]), cr.fmt(m["min_clearance"]), m["display_unit"],
        cr.fmt(m["clearance_required"], 0), rec["wall_s"])


# --------------------------------------------------------------------------- main

PROG = "bench/campaign.py"


def build_parser():
    ap = cr.ArgumentParser(
        PROG, __doc__.splitlines()[0],
        epilog="Flies every course in the lockstep runner, one course through the nine\n"
               "processes, computes the time-optimal baselines when the build has\n"
               "ofn_baseline, and writes OUT/report.md, OUT/results.json and a figure per\n"
               "course.\n"
               "\n"
               "Examples:\n"
               "  bench/campaign.py --quick\n"
               "  bench/campaign.py --courses bench3,tree --multiprocess none --jobs 1\n"
               "\n"
               "Exit codes: 0 when every flight passes; 1 when any fails the benchmark\n"
               "verdict (the report is written anyway); 2 for bad arguments, a missing\n"
               "build or a missing Python module (PyYAML, numpy, matplotlib).")
    cr.add_bin_option(ap)
    ap.add_argument("--out", default=os.path.join(REPO, "results", "campaign"), metavar="DIR",
                    help="results folder (default: results/campaign)")
    ap.add_argument("--courses", metavar="NAME[,NAME]",
                    help="comma-separated courses of sim/scenarios/ (default: %s; with --quick %s)"
                         % (",".join(COURSES), ",".join(QUICK_COURSES)))
    ap.add_argument("--jobs", type=int, default=default_jobs(), metavar="N",
                    help="lockstep flights at a time (default: the number of cores, %d here)"
                         % default_jobs())
    ap.add_argument("--multiprocess", default=None, metavar="COURSE|none",
                    help="course flown through the multi-process deployment "
                         "(default: bench3; with --quick none)")
    ap.add_argument("--rtf", type=float, default=1.0, metavar="X",
                    help="real-time factor of the multi-process flight (default: 1.0)")
    ap.add_argument("--config-dir", default=DEFAULT_CONFIG, metavar="DIR",
                    help="services' config files (default: config)")
    ap.add_argument("--baseline-cache", metavar="DIR", help="baseline cache folder (default: OUT/baselines)")
    ap.add_argument("--quick", action="store_true",
                    help="bench1 and bench4 only, no multi-process flight (default: off)")
    return ap


def parse_args(argv):
    ap = build_parser()
    args = ap.parse_args(argv)
    courses = args.courses.split(",") if args.courses else (QUICK_COURSES if args.quick else COURSES)
    args.courses = [c.strip() for c in courses if c.strip()]
    if not args.courses:
        ap.error("--courses: no course given")
    if args.multiprocess is None:
        args.multiprocess = "none" if args.quick else "bench3"
    for c in args.courses + ([] if args.multiprocess == "none" else [args.multiprocess]):
        if not os.path.isfile(scenario_path(c)):
            ap.error("no scenario file %s" % cr.rel(scenario_path(c)))
    if args.jobs < 1 or not args.rtf > 0:
        ap.error("--jobs must be >= 1 and --rtf > 0")
    args.bin = cr.bin_dir(ap, args)
    args.out = os.path.abspath(args.out)
    args.config_dir = os.path.abspath(args.config_dir)
    if not os.path.isdir(args.config_dir):
        ap.error("--config-dir: no folder %s" % args.config_dir)
    if not os.access(bin_path(args.bin, "ofn_sim_runner"), os.X_OK):
        ap.error("no ofn_sim_runner in %s (build first, or pass --bin)" % args.bin)
    return args


def main(argv=None):
    args = parse_args(argv)
    # Everything the report needs, before minutes of flying.
    cr.need("yaml")
    cr.need_plotting()
    os.makedirs(args.out, exist_ok=True)
    cache = os.path.abspath(args.baseline_cache or os.path.join(args.out, "baselines"))
    t_start = time.monotonic()
    timing = {}
    say("campaign: %d courses in lockstep, %d at a time; binaries %s; results in %s"
        % (len(args.courses), args.jobs, args.bin, args.out))

    t0 = time.monotonic()
    load_before = os.getloadavg()[0]
    cpu_before = children_cpu_s()
    tasks = [(c, (lambda c=c: run_lockstep(args.bin, scenario_path(c), os.path.join(args.out, c), args.config_dir)))
             for c in longest_first(args.courses, args.out)]
    flights = run_all(tasks, args.jobs, lambda c, rec, n: say(
        "[%d/%d] %s" % (n, len(tasks), describe(c, rec))))
    timing["lockstep_s"] = time.monotonic() - t0
    timing["lockstep_cpu_s"] = children_cpu_s() - cpu_before
    load = {"before": load_before, "after": os.getloadavg()[0]}
    say("lockstep part: %.1f s wall for %d courses (budget %.0f s), %.1f s of CPU"
        % (timing["lockstep_s"], len(args.courses), LOCKSTEP_BUDGET_S, timing["lockstep_cpu_s"]))

    mp = None
    if args.multiprocess != "none":
        say("multi-process: %s at %.2gx real time through the nine processes (alone; about %.0f s)"
            % (args.multiprocess, args.rtf, 80 / args.rtf))
        t0 = time.monotonic()
        mp = run_multiprocess(args.bin, scenario_path(args.multiprocess),
                              os.path.join(args.out, "multiprocess-" + args.multiprocess), args.rtf,
                              args.config_dir)
        timing["multiprocess_s"] = time.monotonic() - t0
        say("multi-process %s" % describe(args.multiprocess, mp))

    t0 = time.monotonic()
    needed = sorted(set(args.courses + ([args.multiprocess] if mp else [])))
    if os.access(bin_path(args.bin, "ofn_baseline"), os.X_OK):
        say("baselines: %d courses with ofn_baseline (cache %s)" % (len(needed), cache))
    baselines = run_all([(c, (lambda c=c: run_baseline(args.bin, scenario_path(c), cache))) for c in needed],
                        args.jobs, lambda c, b, n: say("  baseline %s: %s%s" % (
                            c, b["status"], "" if b["baseline_time"] is None else ", %.1f s" % b["baseline_time"])))
    timing["baselines_s"] = time.monotonic() - t0
    available = any(b["available"] for b in baselines.values())

    t0 = time.monotonic()
    rows = []
    for c in args.courses:
        row = flight_row(c, flights[c], baselines[c], PAPER_FT2_RATIO.get(c))
        row["baseline_note"] = baselines[c].get("note") if baselines[c]["status"] != "ok" else None
        rows.append(row)
    mp_row = None
    if mp is not None:
        mp_row = flight_row("%s (multi-process)" % args.multiprocess, mp, baselines[args.multiprocess],
                            PAPER_FT2_RATIO.get(args.multiprocess))
        mp_row["rtf"] = args.rtf
    say("figures ...")
    for row in rows + ([mp_row] if mp_row else []):
        course = row["label"].split(" ")[0]
        name = "fig-%s%s.png" % (course, "-multiprocess" if row is mp_row else "")
        b = baselines.get(course)
        try:
            row["figure"] = cr.course_figure(row["dir"], os.path.join(args.out, name), title=row["label"],
                                             baseline_dir=b["dir"] if b and b["status"] == "ok" else None,
                                             tree_views=course in SENSOR_COURSES)
        except Exception as exc:  # a broken figure must not cost the report
            say("  figure %s failed: %s" % (name, exc))
            row["figure"] = None
    timing["report_s"] = time.monotonic() - t0
    timing["total_s"] = time.monotonic() - t_start
    ctx = {"date": now_text(), "machine": machine_info(), "commit": git_commit(), "bin": args.bin,
           "config_dir": args.config_dir, "load": load,
           "jobs": args.jobs, "rows": rows, "mp_row": mp_row, "rtf": args.rtf, "timing": timing,
           "baselines_available": available,
           "baseline_note": next((b.get("note") for b in baselines.values() if b.get("note")), ""),
           "goals": evaluate_goals(rows, mp_row, timing["lockstep_s"], available)}
    write_report(args.out, ctx)
    write_results_json(args.out, ctx)

    say("")
    for g in ctx["goals"]:
        say("goal %-75s %s (%s)" % (g["goal"], mark(g["met"]).replace("*", ""), g["detail"]))
    say("wall time: " + ", ".join("%s %.1f s" % (k[:-2].replace("_", " "), v) for k, v in timing.items()))
    say("report: %s" % os.path.join(args.out, "report.md"))
    failed = [r["label"] for r in rows + ([mp_row] if mp_row else []) if not r["success"]]
    if failed:
        say("FAILED: %s" % ", ".join(failed))
        return 1
    return 0


if __name__ == "__main__":
    cr.run_main(PROG, main)
