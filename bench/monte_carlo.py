#!/usr/bin/python3
"""Monte Carlo over seeded random obstacle fields: success rate, clearance and time ratio.

Usage: monte_carlo.py [--bin DIR] [--runs N] [--seed-base S] [--jobs N] [--out DIR]
                      [--dense | --trap] [--wind KT] [--turbulence LEVEL]
                      [--keep-failures] [--keep-all] [--quick]

Field i is bench/random_field.py's field of seed S + i: a fair one (a route
always exists) by default, a dense one with --dense (10-25 obstacles, may be
sealed), a trap field with --trap (a dead end, a wall wider than the map or
a narrow pocket, clutter, sometimes a pop-up; may be sealed); the rules of
all three are in that file. --wind and --turbulence give every field
random_field.py's weather (a steady wind from a direction drawn from the
seed, MIL-F-8785C turbulence; the baseline flies in calm air, so its time
ratio is against a calm flight). Each field is flown in the
lockstep runner, N at a time, and, when the build has ofn_baseline, given
its time-optimal baseline. Writes OUT/report.md, OUT/results.json (every
run), OUT/fields.jsonl (each field's record as it finishes, so a run cut
short keeps what it flew; Ctrl-C stops it, reports the fields that had
finished and exits 130), OUT/clearance.png, OUT/time_ratio.png, OUT/fields/field-SEED.yaml
(dense-SEED.yaml with --dense, trap-SEED.yaml with --trap) and, for failed runs, a figure
OUT/failure-figures/fig-seed-SEED.png.

Every flight ends in one outcome (../shared/BENCHMARKS.md): success (finish
gate crossed, no violation), safe_stop (stopped and hovering because no
route exists) or failure. A field is passed when it ends in success, or in
a safe stop where the baseline finds no route either.

Kept on disk: the folder OUT/runs/seed-SEED/ of every failed run (CSVs,
summary.json, runner output; with --keep-failures also its LCM log, tens of
MB each); successful runs' folders are deleted unless --keep-all, since
hundreds of flight logs would take gigabytes. Every run is deterministic
given the seed, so any of them can be flown again alone: the report gives
the command for each failure.

Exit code: fair fields, 1 when the success rate is below 99 % (the goal);
dense and trap fields, 1 when any field fails (a failure outcome, a safe stop
although the baseline finds a route, a clearance below 0.8 R_s or a limit
exceeded); 2 for bad arguments; 130 after Ctrl-C. The report is written
either way (after Ctrl-C, of the fields that had finished).
"""
import json
import math
import os
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import campaign  # noqa: E402
import campaign_report as cr  # noqa: E402
import random_field  # noqa: E402

SUCCESS_GOAL = 0.99
# Dense fields: share of those whose baseline finds a route that must succeed.
DENSE_SUCCESS_GOAL = 0.97
OUTCOMES = ("success", "safe_stop", "failure")
# Words of the flight verdict's limit failures (services/tools/src/flight_analysis.cpp
# judge_flight): speed, vertical speed, commanded (reference) acceleration,
# forward speed and, where the verdict checks it, the controller's command
# against the bound the controller states.
ENVELOPE_FAILURE_WORDS = ("over the limit", "over 1.02", "forward speed", "over the bound")
QUICK_RUNS = 4
MAX_FAILURE_FIGURES = 30
PROGRESS_STEP = 0.05  # share of the runs between progress lines when stderr is not a terminal


class Progress:
    """Count, passes, outcomes and ETA on stderr: one redrawn line on a
    terminal, a line every ~5 % of the runs otherwise (logs, CI)."""

    def __init__(self, total, stream=sys.stderr):
        self.total, self.stream = total, stream
        self.tty = stream.isatty()
        self.t0 = time.monotonic()
        self.done = self.ok = 0
        self.outcomes = dict.fromkeys(OUTCOMES, 0)
        self.next_line = 0

    def update(self, passed, outcome):
        self.done += 1
        self.ok += 1 if passed else 0
        self.outcomes[outcome] += 1
        elapsed = time.monotonic() - self.t0
        eta = elapsed / self.done * (self.total - self.done)
        text = "%d/%d fields, %d passed, %d failed (%s), %s elapsed, ETA %s" % (
            self.done, self.total, self.ok, self.done - self.ok,
            ", ".join("%d %s" % (self.outcomes[o], o.replace("_", " ")) for o in OUTCOMES),
            clock(elapsed), clock(eta))
        if self.tty:
            width = 30
            filled = int(width * self.done / self.total)
            self.stream.write("\r[%s%s] %s " % ("#" * filled, "." * (width - filled), text))
            if self.done == self.total:
                self.stream.write("\n")
        elif self.done >= self.next_line or self.done == self.total:
            self.stream.write("monte_carlo: %s\n" % text)
            self.next_line = self.done + max(1, int(math.ceil(PROGRESS_STEP * self.total)))
        self.stream.flush()


def clock(seconds):
    seconds = int(round(seconds))
    return "%dm%02ds" % (seconds // 60, seconds % 60) if seconds >= 60 else "%ds" % seconds


def rerun_commands(args, seed):
    """Two exact ways to fly one field again alone."""
    me = os.path.join(HERE, "monte_carlo.py")
    gen = os.path.join(HERE, "random_field.py")
    tpl = "" if os.path.realpath(args.template) == os.path.realpath(random_field.DEFAULT_TEMPLATE) \
        else " --template " + os.path.abspath(args.template)
    kind = KIND_FLAGS[args.kind] + random_field.weather_flags(args.wind, args.turbulence)
    name = field_name(args, seed)
    link = "".join(" --%s %g" % (flag, value) for flag, value in
                   (("link-loss", args.link_loss), ("link-delay", args.link_delay),
                    ("link-jitter", args.link_jitter)) if value > 0)
    one = "%s --bin %s --config-dir %s%s%s%s --seed %d --runs 1 --keep-all --out /tmp/mc-%s" % (
        me, args.bin, args.config_dir, tpl, kind, link, seed, name)
    two = ("%s%s --seed %d%s --out /tmp/%s.yaml && %s --scenario /tmp/%s.yaml --config-dir %s%s "
           "--out /tmp/%s" % (gen, kind, seed, tpl, name, campaign.bin_path(args.bin, "ofn_sim_runner"),
                              name, args.config_dir, " ".join([""] + runner_link_args(args, seed)),
                              name))
    return one, two


def weather_text(args):
    if args.wind <= 0 and args.turbulence == "none":
        return "calm"
    return ", ".join(([("%g kt of wind from a direction drawn from each field's seed" % args.wind)]
                      if args.wind > 0 else [])
                     + ([args.turbulence + " turbulence"] if args.turbulence != "none" else []))


def link_faulty(args):
    return args.link_loss > 0 or args.link_delay > 0 or args.link_jitter > 0


def runner_link_args(args, seed):
    """The runner's link-fault options for a field: its seed draws the faults."""
    if not link_faulty(args):
        return []
    return ["--link-loss", "%g" % args.link_loss, "--link-delay", "%g" % args.link_delay,
            "--link-jitter", "%g" % args.link_jitter, "--link-seed", str(seed),
            "--process-table", os.path.join(REPO, "deploy", "processes.yaml")]


def field_name(args, seed):
    return "%s-%d" % ({"fair": "field"}.get(args.kind, args.kind), seed)


def envelope_excursions(failures):
    """The verdict's failures that are limits exceeded by more than the tolerance."""
    return [f for f in failures if any(w in f for w in ENVELOPE_FAILURE_WORDS)]


def judge_field(r):
    """Adds the field's verdict to its record r: 'route' (does the baseline
    find one: True, False, or None when it could not tell), 'clearance_violation',
    'envelope_excursion', 'passed' and, when not passed, 'why'."""
    r["route"] = {"ok": True, "infeasible": False}.get(r["baseline_status"])
    c = r["min_clearance_over_rs"]
    r["clearance_violation"] = c is not None and c < cr.FAIL_LINE
    r["envelope_excursion"] = bool(envelope_excursions(r["failures"]))
    why = []
    if r["outcome"] == "failure":
        why.append("failure outcome")
    elif r["outcome"] == "safe_stop" and r["route"] is not False:
        why.append("safe stop although %s" % ("the baseline finds a route" if r["route"]
                                               else "no baseline says the field is sealed"))
    if r["clearance_violation"]:
        why.append("clearance below %.1f R_s" % cr.FAIL_LINE)
    if r["envelope_excursion"]:
        why.append("limit exceeded")
    r["passed"] = not why
    if why:
        r["why"] = why
    return r


def fly_field(args, seed, template):
    """Generate, fly and (if possible) baseline one field; tidy its folder."""
    field = os.path.join(args.out, "fields", field_name(args, seed) + ".yaml")
    obstacles = random_field.write_field(seed, field, template, args.kind, wind_kt=args.wind,
                                         turbulence=args.turbulence)
    run_dir = os.path.join(args.out, "runs", "seed-%d" % seed)
    rec = campaign.run_lockstep(args.bin, field, run_dir, args.config_dir,
                                extra_args=runner_link_args(args, seed))
    base = campaign.run_baseline(args.bin, field, args.baseline_cache)
    s = rec.get("summary") or {}
    rs = s.get("clearance_required")
    unit, k = cr.unit_scale(s)
    out = {
        "seed": seed, "field": field, "obstacles": len(obstacles),
        "tall_obstacles": sum(1 for o in obstacles if random_field.is_tall(o)),
        "success": campaign.flight_ok(rec), "outcome": campaign.flight_outcome(rec),
        "failures": list(s.get("failures") or []) + ([rec["error"]] if rec.get("error") else []),
        "gate_to_gate_s": s.get("gate_to_gate"),
        # The verdict times the gates; whether the flight then also reached
        # its last waypoint (a hover short of it would pass unseen).
        "reached_last_waypoint": s.get("reached_last_waypoint"),
        "min_clearance_over_rs": s["min_clearance"] / rs if rs and s.get("min_clearance") is not None else None,
        "min_clearance": s["min_clearance"] * k if s.get("min_clearance") is not None else None,
        "max_speed": s["max_speed"] * k if s.get("max_speed") is not None else None,
        # Share of the controller's commands with a cyclic at its stop: the
        # authority the weather used up (none from a runner without it).
        "cyclic_at_stop": (s.get("controls_at_stop") or {}).get("cyclic"),
        "display_unit": unit,
        "baseline_status": base["status"], "baseline_time_s": base.get("baseline_time"),
        "wall_s": rec["wall_s"], "dir": run_dir,
    }
    out["ratio"] = cr.ratio_of(out["gate_to_gate_s"], out["baseline_time_s"])
    judge_field(out)
    # A dense or trap field fails on its verdict; a fair one on the flight alone, as always.
    out["failed"] = not out["passed"] if args.judged else not out["success"]
    if not out["failed"] and not args.keep_all:
        shutil.rmtree(run_dir, ignore_errors=True)
        out["dir"] = None
    elif out["failed"]:
        if not args.keep_failures and not args.keep_all:
            log = os.path.join(run_dir, "flight.lcm")
            if os.path.isfile(log):
                os.remove(log)
        if len(os.listdir(os.path.join(args.out, "failure-figures"))) < MAX_FAILURE_FIGURES:
            try:
                out["figure"] = cr.course_figure(run_dir, os.path.join(args.out, "failure-figures",
                                                                       "fig-seed-%d.png" % seed),
                                                 title="field %d" % seed,
                                                 baseline_dir=base["dir"] if base["status"] == "ok" else None)
            except Exception as exc:  # the run's record matters more than its picture
                out["figure_error"] = str(exc)
    return out


def straight_time(template):
    """Gate-to-gate time of unobstructed straight flight at the speed limit."""
    g, lim = template["gates"], template["limits"]
    return (float(g["finish_x"]) - float(g["start_x"])) / float(lim["max_speed"])


FAIR_DESCRIPTION = (
    "Each field has 2-5 boxes and cylinders between x = 60 and 360 ft, low ones (top 40-150 ft) "
    "to climb over and tall ones (250-300 ft) to pass beside, drawn so that a route with R_s "
    "clearance always exists (the rules are in bench/random_field.py). A run fails if it misses "
    "the finish gate, comes closer than 0.8 R_s to a real obstacle, or exceeds a limit by more "
    "than 2 %.")
DENSE_DESCRIPTION = (
    "Dense fields: each has 10-25 boxes and cylinders between x = 40 and 380 ft and within 160 ft "
    "of the course line, tops 40-300 ft (40 % tall, 250-300 ft), surfaces down to 15 ft apart; "
    "dead ends and gaps too narrow for R_s are kept, so a field may be sealed (the rules are in "
    "bench/random_field.py). Whether a route exists is what ofn_baseline finds: a field it finds "
    "no feasible trajectory for counts as sealed, although its optimiser could miss a route that "
    "exists. A field passes when it ends in success, or in a safe stop where the baseline finds no "
    "route. It fails on a failure outcome, a safe stop although the baseline finds a route, a least "
    "true clearance below 0.8 R_s (clearance violation) or a speed, vertical speed, forward speed, "
    "commanded acceleration or controller command beyond its limit by more than 2 % (envelope "
    "excursion).")
TRAP_DESCRIPTION = (
    "Trap fields: each has one trap, drawn at random (a dead end of three thin walls open towards "
    "the start, a wall across the course 500-1000 ft long with or without a gap, or a narrow deep "
    "pocket; walls 60 % tall), 0-8 dense obstacles as clutter and, in a third of the fields, a "
    "pop-up that appears while the vehicle cannot yet be near it (the rules are in "
    "bench/random_field.py); max_time 300 s. A field may be sealed. Fields are judged as dense "
    "ones: a field passes when it ends in success, or in a safe stop where the baseline finds no "
    "route; it fails on a failure outcome, a safe stop although the baseline finds a route, a "
    "clearance violation or an envelope excursion.")
DESCRIPTIONS = {"fair": FAIR_DESCRIPTION, "dense": DENSE_DESCRIPTION, "trap": TRAP_DESCRIPTION}
KIND_FLAGS = {"fair": "", "dense": " --dense", "trap": " --trap"}


def write_report(args, runs, ctx):
    """Writes report.md and results.json; returns the results document."""
    n = len(runs)
    ok = sum(1 for r in runs if r["success"])
    lo, hi = cr.wilson_interval(ok, n)
    rate = ok / n if n else 0.0
    outcomes = {o: sum(1 for r in runs if r["outcome"] == o) for o in OUTCOMES}
    have_baseline = any(r["baseline_status"] != "n/a" for r in runs)
    clear = [r["min_clearance_over_rs"] for r in runs]
    cr.histogram(os.path.join(args.out, "clearance.png"), clear, "least true clearance / R_s",
                 "least clearance to the real obstacles, %d fields" % n,
                 lines=[(cr.FAIL_LINE, "0.8 R_s (fail)", "red"), (1.0, "R_s", "orange")])
    t_ref = straight_time(ctx["template"])
    # Dense fields: the time ratio means something only for the flights that succeed.
    timed = [r for r in runs if r["outcome"] == "success"] if args.judged else runs
    if have_baseline:
        ratios = [r["ratio"] for r in timed]
        popup_fields = [r["seed"] for r in runs if campaign.timed_obstacles(r["field"])]
        ratio_label = "gate-to-gate time / time-optimal baseline"
        ratio_note = "Time ratio: %s; %s." % (
            campaign.BASELINE_POPUP_NOTE,
            "none of these fields has a pop-up, so no ratio here is affected" if not popup_fields else
            "the fields with pop-ups (seeds %s) are affected" % ", ".join(str(v) for v in popup_fields))
    else:
        ratios = [r["gate_to_gate_s"] / t_ref if r["gate_to_gate_s"] else None for r in timed]
        ratio_label = "gate-to-gate time / unobstructed straight flight (%.1f s)" % t_ref
        ratio_note = ("ofn_baseline is not in the build, so the time-ratio histogram divides by "
                      "the unobstructed straight flight (%.1f s) instead of each field's baseline; "
                      "the baseline columns read n/a." % t_ref)
    cr.histogram(os.path.join(args.out, "time_ratio.png"), ratios, ratio_label,
                 "time ratio, %d fields" % len(timed),
                 lines=[(campaign.RATIO_LIMIT, "%.3f" % campaign.RATIO_LIMIT, "red"),
                        (campaign.RATIO_GOAL, "%.2f" % campaign.RATIO_GOAL, "orange")] if have_baseline else [])
    finite = [v for v in ratios if v is not None]
    ratio_basis = "baseline" if have_baseline else "straight flight"
    lines = [
        "# Monte Carlo: %s random obstacle fields" % args.kind,
        "",
        "- date: %s" % ctx["date"],
        "- machine: %d cores, %s" % (ctx["machine"]["cores"], ctx["machine"]["cpu"]),
        "- commit: %s" % ctx["commit"],
        "- binaries: %s, configuration %s" % (args.bin, args.config_dir),
        "- fields: seeds %s (bench/random_field.py%s, course from %s), %d flown %d at a time"
        % (seeds_text(args.seeds),
           KIND_FLAGS[args.kind] + random_field.weather_flags(args.wind, args.turbulence),
           os.path.relpath(ctx["template_path"], REPO), n, args.jobs),
        "- weather: %s" % weather_text(args),
    ] + ([
        "- **interrupted**: %d of the %d fields had finished; every figure below is of those"
        % ctx["interrupted"]] if ctx.get("interrupted") else []) + [
        "- link: %s" % ("between hosts (deploy/processes.yaml), %g %% of the datagrams lost, "
                         "every message %g +- %g s late, drawn from each field's seed"
                         % (100 * args.link_loss, args.link_delay, args.link_jitter)
                         if link_faulty(args) else "no faults"),
        "- wall time: %.0f s in all, %.1f s per field (%.1f s per flight on one core); 1-minute "
        "load average %.1f before, %.1f after" % (ctx["wall_s"], ctx["wall_s"] / max(n, 1),
                                                  sum(r["wall_s"] for r in runs) / max(n, 1),
                                                  ctx["load"][0], ctx["load"][1]),
        "",
        DESCRIPTIONS[args.kind],
        "",
        "## Result",
        "",
        "| | |",
        "|---|---|",
        "| outcomes | %s |" % ", ".join("%s %d" % (o.replace("_", " "), outcomes[o]) for o in OUTCOMES),
    ]
    doc = {"date": ctx["date"], "machine": ctx["machine"], "commit": ctx["commit"], "bin": args.bin,
           "mode": args.kind, "runs": n, "outcomes": outcomes,
           "baselines_available": have_baseline, "wall_s": ctx["wall_s"], "load_average": ctx["load"],
           "seed_base": args.seed_base, "seeds": args.seeds, "link_loss": args.link_loss,
           "link_delay": args.link_delay, "link_jitter": args.link_jitter, "wind_kt": args.wind,
           "turbulence": args.turbulence, "interrupted": bool(ctx.get("interrupted")),
           "seeds_flown": [r["seed"] for r in runs]}
    clear_known = [c for c in clear if c is not None]
    if args.judged:
        routed = [r for r in runs if r["route"] is True]
        routed_ok = sum(1 for r in routed if r["outcome"] == "success")
        sealed = [r for r in runs if r["route"] is False]
        unknown = [r for r in runs if r["route"] is None]
        r_lo, r_hi = cr.wilson_interval(routed_ok, len(routed))
        r_rate = routed_ok / len(routed) if routed else None
        violations = sum(1 for r in runs if r["clearance_violation"])
        excursions = sum(1 for r in runs if r["envelope_excursion"])
        failed_n = sum(1 for r in runs if r["failed"])
        reached = [r for r in runs if r.get("reached_last_waypoint")]
        short = [r for r in runs if not r.get("reached_last_waypoint")]
        goal_met = r_rate is not None and r_rate >= DENSE_SUCCESS_GOAL
        lines += [
            "| fields whose baseline finds a route | %d of %d |" % (len(routed), n),
            "| of those, succeeded | **%s** (%d of %d; 95 %% Wilson interval %.1f %% .. %.1f %%) |"
            % ("n/a" if r_rate is None else "%.1f %%" % (100 * r_rate), routed_ok, len(routed),
               100 * r_lo, 100 * r_hi),
            "| goal | >= %.0f %% of the fields with a route succeed: %s |"
            % (100 * DENSE_SUCCESS_GOAL, "met" if goal_met else "**not met**"),
            "| fields the baseline finds sealed | %d; of those, safe stops %d, successes %d |"
            % (len(sealed), sum(1 for r in sealed if r["outcome"] == "safe_stop"),
               sum(1 for r in sealed if r["outcome"] == "success")),
            "| fields without a baseline verdict | %d |" % len(unknown),
            "| clearance violations (least true clearance < 0.8 R_s) | **%d** |" % violations,
            "| envelope excursions (a limit exceeded by more than 2 %%) | **%d** |" % excursions,
            "| least clearance / R_s | min %s, median %s |" % (cr.fmt(min(clear_known, default=None), 2),
                                                          cr.fmt(median(clear_known), 2)),
            "| time ratio over the %d successes (%s) | median %s, 95th percentile %s, max %s |" % (
                len(finite), ratio_basis, cr.fmt(median(finite), 3), cr.fmt(percentile(finite, 0.95), 3),
                cr.fmt(max(finite, default=None), 3)),
            "| fields failed | **%d** of %d |" % (failed_n, n),
            "| last waypoint reached | %d of %d%s |" % (
                len(reached), n, "" if not short else " (not: seeds %s)" % ", ".join(
                    str(r["seed"]) for r in short)),
        ]
        doc.update(routed=len(routed), routed_successes=routed_ok, routed_success_rate=r_rate,
                   routed_wilson95=[r_lo, r_hi], goal=DENSE_SUCCESS_GOAL, goal_met=goal_met,
                   sealed=len(sealed), no_baseline_verdict=len(unknown),
                   clearance_violations=violations, envelope_excursions=excursions, failed=failed_n,
                   reached_last_waypoint=len(reached), ratio_median=median(finite), ratio_p95=percentile(finite, 0.95))
    else:
        lines += [
            "| success rate | **%.1f %%** (%d of %d) |" % (100 * rate, ok, n),
            "| 95 %% confidence interval (Wilson) | %.1f %% .. %.1f %% |" % (100 * lo, 100 * hi),
            "| goal | >= %.0f %%: %s |" % (100 * SUCCESS_GOAL, "met" if rate >= SUCCESS_GOAL else "**not met**"),
            "| least clearance / R_s | min %s, median %s |" % (
                cr.fmt(min(clear_known, default=None), 2), cr.fmt(median(clear_known), 2)),
            "| runs inside R_s | %d |" % sum(1 for c in clear_known if c < 1.0),
            "| time ratio (%s) | median %s, max %s |" % (ratio_basis, cr.fmt(median(finite), 3),
                                                       cr.fmt(max(finite, default=None), 3)),
        ]
        doc.update(successes=ok, success_rate=rate, wilson95=[lo, hi], goal=SUCCESS_GOAL,
                   goal_met=rate >= SUCCESS_GOAL)
    at_stop = [(r["cyclic_at_stop"], r["seed"]) for r in runs if r.get("cyclic_at_stop") is not None]
    if at_stop:
        worst = max(at_stop)
        typical = median([v for v, _ in at_stop])
        lines.append("| cyclic at its stop (share of the controller's commands) | median %.1f %%, most "
                     "%.1f %% (seed %d) |" % (100 * typical, 100 * worst[0], worst[1]))
        doc.update(cyclic_at_stop_median=typical, cyclic_at_stop_max=worst[0])
    if ratio_note:
        lines += ["", ratio_note]
    lines += ["", "![least clearance](clearance.png)", "", "![time ratio](time_ratio.png)", "",
              "## Failures", ""]
    failed = [r for r in runs if r["failed"]]
    if not failed:
        lines.append("None.")
    else:
        unit = next((r["display_unit"] for r in failed if r.get("display_unit")), "ft")
        lines += ["Folders kept in `runs/` (LCM log %s). Each command flies that field again, alone; "
                  "the lockstep runner is deterministic given the field, whatever the machine's load "
                  "(an RH solve there is bounded by its evaluation count, not by wall time)."
                  % ("kept" if args.keep_failures or args.keep_all else "deleted; --keep-failures keeps it"),
                  "", "| seed | obstacles (tall) | outcome | baseline | least clearance (%s) / R_s "
                  "| max speed (%s/s) | reason | re-run alone |" % (unit, unit),
                  "|---|---|---|---|---|---|---|---|"]
        for r in failed:
            one, two = rerun_commands(args, r["seed"])
            fig = " ([figure](failure-figures/%s))" % os.path.basename(r["figure"]) if r.get("figure") else ""
            reasons = (r.get("why") or []) + r["failures"] if args.judged else r["failures"]
            lines.append("| %d | %d (%d) | %s | %s | %s / %s | %s | %s%s | `%s` <br> or `%s` |" % (
                r["seed"], r["obstacles"], r["tall_obstacles"], r["outcome"].replace("_", " "),
                {"ok": "route", "infeasible": "sealed"}.get(r["baseline_status"], r["baseline_status"]),
                cr.fmt(r["min_clearance"]), cr.fmt(r["min_clearance_over_rs"], 2), cr.fmt(r["max_speed"], 2),
                "; ".join(reasons) or "unknown", fig, one, two))
    with open(os.path.join(args.out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    doc["results"] = runs
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump(doc, f, indent=1)
    return doc


def seeds_text(seeds):
    """'1..300' for a run of consecutive seeds, else the list."""
    if len(seeds) > 1 and seeds == list(range(seeds[0], seeds[-1] + 1)):
        return "%d..%d" % (seeds[0], seeds[-1])
    return ", ".join(str(s) for s in seeds)


def percentile(values, q):
    """The q-quantile (0..1), interpolated linearly between the sorted values; None when empty."""
    vals = sorted(values)
    if not vals:
        return None
    pos = q * (len(vals) - 1)
    low = int(math.floor(pos))
    high = min(low + 1, len(vals) - 1)
    return vals[low] + (pos - low) * (vals[high] - vals[low])


def median(values):
    vals = sorted(values)
    if not vals:
        return None
    mid = len(vals) // 2
    return vals[mid] if len(vals) % 2 else 0.5 * (vals[mid - 1] + vals[mid])


PROG = "bench/monte_carlo.py"
DEFAULT_RUNS = 300


def build_parser():
    ap = cr.ArgumentParser(
        PROG, __doc__.splitlines()[0],
        epilog="Field i is bench/random_field.py's field of seed S + i (fair, dense with\n"
               "--dense, trap with --trap), flown in the lockstep runner; writes OUT/report.md, OUT/results.json,\n"
               "histograms and, for failed runs, a figure each.  The rules are in this\n"
               "file's docstring and in bench/random_field.py.\n"
               "\n"
               "Examples:\n"
               "  bench/monte_carlo.py --quick\n"
               "  bench/monte_carlo.py --dense --runs 50 --out /tmp/dense\n"
               "  bench/monte_carlo.py --trap --runs 30 --out /tmp/trap\n"
               "  bench/monte_carlo.py --seeds 64,131,257 --keep-all\n"
               "\n"
               "Exit codes: fair fields, 1 when the success rate is below %.0f %%; dense and trap fields,\n"
               "1 when any field fails; 2 for bad arguments, a missing build or a missing\n"
               "Python module (PyYAML, numpy, matplotlib); 130 after Ctrl-C.  The report is written\n"
               "either way (after Ctrl-C, of the fields that had finished; OUT/fields.jsonl holds\n"
               "each field's record as it finished)."
               % (100 * SUCCESS_GOAL))
    cr.add_bin_option(ap)
    ap.add_argument("--runs", type=int, default=None, metavar="N",
                    help="number of fields (default: %d; with --quick %d)" % (DEFAULT_RUNS, QUICK_RUNS))
    ap.add_argument("--seed-base", "--seed", dest="seed_base", type=int, default=1, metavar="S",
                    help="seed of the first field; field i has seed S + i (default: 1)")
    ap.add_argument("--seeds", metavar="S[,S]",
                    help="comma-separated seeds to fly, e.g. 64,131,257 "
                         "(default: --seed-base and --runs)")
    ap.add_argument("--jobs", type=int, default=campaign.default_jobs(), metavar="N",
                    help="flights at a time (default: the number of cores, %d here)"
                         % campaign.default_jobs())
    ap.add_argument("--out", default=os.path.join(REPO, "results", "monte_carlo"), metavar="DIR",
                    help="results folder (default: results/monte_carlo)")
    ap.add_argument("--config-dir", default=campaign.DEFAULT_CONFIG, metavar="DIR",
                    help="services' config files (default: config)")
    ap.add_argument("--template", default=random_field.DEFAULT_TEMPLATE, metavar="FILE",
                    help="scenario whose course the fields use (default: %s)"
                         % cr.rel(random_field.DEFAULT_TEMPLATE))
    kind = ap.add_mutually_exclusive_group()
    kind.add_argument("--dense", action="store_true",
                      help="dense fields (10-25 obstacles, 15 ft gaps, may be sealed) instead of fair ones; "
                      "exit code 1 when any field fails (default: fair fields)")
    kind.add_argument("--trap", action="store_true",
                      help="trap fields (a dead end, a wall wider than the map or a narrow pocket, clutter, "
                      "sometimes a pop-up; may be sealed), judged as dense ones (default: fair fields)")
    ap.add_argument("--baseline-cache", metavar="DIR",
                    help="baseline cache folder (default: OUT/baselines)")
    ap.add_argument("--keep-failures", action="store_true",
                    help="also keep the LCM logs of failed runs; their CSVs are always kept (default: off)")
    ap.add_argument("--keep-all", action="store_true",
                    help="keep every run's folder, log included (default: off)")
    ap.add_argument("--quick", action="store_true", help="%d fields (default: off)" % QUICK_RUNS)
    ap.add_argument("--link-loss", type=float, default=0.0, metavar="P",
                    help="fly every field over a link that loses this fraction of the datagrams "
                         "between hosts, e.g. 0.1, as ofn_sim_runner --link-loss (default: 0, no loss)")
    ap.add_argument("--link-delay", type=float, default=0.0, metavar="S",
                    help="and delay every message between hosts by S seconds (default: 0)")
    ap.add_argument("--link-jitter", type=float, default=0.0, metavar="S",
                    help="give that delay a uniform +-S jitter (default: 0)")
    random_field.add_weather_arguments(ap)
    return ap


def parse_args(argv):
    ap = build_parser()
    args = ap.parse_args(argv)
    args.kind = random_field.field_kind(args)
    # Dense and trap fields may be sealed: each is judged on its verdict.
    args.judged = args.kind != "fair"
    if args.seeds is not None:
        try:
            args.seeds = [int(v) for v in args.seeds.split(",") if v.strip()]
        except ValueError:
            ap.error("--seeds: expected comma-separated integers, got %r" % args.seeds)
        if not args.seeds:
            ap.error("--seeds: no seed given")
        if len(set(args.seeds)) != len(args.seeds):
            ap.error("--seeds: a seed is given twice")
        args.runs = len(args.seeds)
    if args.runs is None:
        args.runs = QUICK_RUNS if args.quick else DEFAULT_RUNS
    if args.runs < 1 or args.jobs < 1:
        ap.error("--runs and --jobs must be >= 1")
    if not 0.0 <= args.link_loss <= 0.99:
        ap.error("--link-loss: expected a fraction in [0, 0.99], got %g" % args.link_loss)
    for flag, value in (("--link-delay", args.link_delay), ("--link-jitter", args.link_jitter)):
        if not 0.0 <= value <= 10.0:
            ap.error("%s: expected 0 to 10 s, got %g" % (flag, value))
    if args.seeds is None:
        args.seeds = list(range(args.seed_base, args.seed_base + args.runs))
    args.bin = cr.bin_dir(ap, args)
    args.out = os.path.abspath(args.out)
    args.config_dir = os.path.abspath(args.config_dir)
    args.baseline_cache = os.path.abspath(args.baseline_cache or os.path.join(args.out, "baselines"))
    if not os.path.isfile(args.template):
        ap.error("--template: no file %s" % args.template)
    if not os.path.isdir(args.config_dir):
        ap.error("--config-dir: no folder %s" % args.config_dir)
    if not os.access(campaign.bin_path(args.bin, "ofn_sim_runner"), os.X_OK):
        ap.error("no ofn_sim_runner in %s (build first, or pass --bin)" % args.bin)
    return args


def main(argv=None):
    args = parse_args(argv)
    # Everything the report needs, before hours of flying.
    cr.need("yaml")
    cr.need_plotting()
    try:
        template = random_field.load_template(args.template)
    except (OSError, ValueError) as exc:
        print("%s: error: --template: %s" % (PROG, exc), file=sys.stderr)
        return cr.EXIT_USAGE
    for sub in ("fields", "runs", "failure-figures"):
        path = os.path.join(args.out, sub)
        if sub != "fields" and os.path.isdir(path):
            shutil.rmtree(path)  # results of an earlier campaign must not mix in
        os.makedirs(path, exist_ok=True)
    seeds = args.seeds
    print("monte_carlo: %d fields (seeds %s), %d at a time; binaries %s; results in %s"
          % (len(seeds), seeds_text(seeds), args.jobs, args.bin, args.out), flush=True)
    if not os.access(campaign.bin_path(args.bin, "ofn_baseline"), os.X_OK):
        print("monte_carlo: no ofn_baseline in %s: baselines and ratios will read n/a" % args.bin,
              flush=True)
    load_before = os.getloadavg()[0]
    progress = Progress(len(seeds))
    t0 = time.monotonic()
    # Every field's record as it finishes, one JSON line each: a run cut
    # short (Ctrl-C, a lost machine) keeps what it had flown.
    flown_log = open(os.path.join(args.out, "fields.jsonl"), "w")

    def done(seed, rec, n):
        flown_log.write(json.dumps(rec) + "\n")
        flown_log.flush()
        progress.update(not rec["failed"], rec["outcome"])

    interrupted = False
    try:
        results = campaign.run_all([(s, (lambda s=s: fly_field(args, s, args.template)))
                                    for s in seeds], args.jobs, done)
    except campaign.Interrupted as stop:
        results, interrupted = stop.results, True
        print("\nmonte_carlo: interrupted: %d of %d fields had finished; reporting those"
              % (len(results), len(seeds)), file=sys.stderr, flush=True)
    finally:
        flown_log.close()
    runs = [results[s] for s in seeds if s in results]
    if not runs:
        print("monte_carlo: interrupted before any field finished: no report", file=sys.stderr)
        return 130
    ctx = {"date": campaign.now_text(), "machine": campaign.machine_info(), "commit": campaign.git_commit(),
           "template": template, "template_path": os.path.abspath(args.template),
           "wall_s": time.monotonic() - t0, "load": (load_before, os.getloadavg()[0]),
           "interrupted": (len(runs), len(seeds)) if interrupted else None}
    doc = write_report(args, runs, ctx)
    print("outcomes: %s" % ", ".join("%s %d" % (o, doc["outcomes"][o]) for o in OUTCOMES))
    if args.judged:
        print("fields with a route (baseline): %d, of which succeeded %d%s; sealed %d; no baseline verdict %d"
              % (doc["routed"], doc["routed_successes"],
                 "" if doc["routed_success_rate"] is None else " (%.1f %%)" % (100 * doc["routed_success_rate"]),
                 doc["sealed"], doc["no_baseline_verdict"]))
        print("last waypoint reached: %d of %d" % (doc["reached_last_waypoint"], len(runs)))
        print("clearance violations %d, envelope excursions %d, time ratio of the successes: median %s, "
              "95th percentile %s; %.0f s wall, %.1f s per field"
              % (doc["clearance_violations"], doc["envelope_excursions"], cr.fmt(doc["ratio_median"], 3),
                 cr.fmt(doc["ratio_p95"], 3), ctx["wall_s"], ctx["wall_s"] / len(runs)))
    else:
        lo, hi = doc["wilson95"]
        print("success rate %.1f %% (%d/%d), 95 %% CI %.1f..%.1f %%; %.0f s wall, %.1f s per field"
              % (100 * doc["success_rate"], doc["successes"], len(runs), 100 * lo, 100 * hi, ctx["wall_s"],
                 ctx["wall_s"] / len(runs)))
    for r in runs:
        if r["failed"]:
            print("  failed: seed %d: %s, least clearance %s R_s (%s %s), max speed %s %s/s: %s" % (
                r["seed"], r["outcome"], cr.fmt(r["min_clearance_over_rs"], 2), cr.fmt(r["min_clearance"]),
                r["display_unit"], cr.fmt(r["max_speed"], 2), r["display_unit"],
                "; ".join((r.get("why") or []) + r["failures"] if args.judged else r["failures"])))
    print("report: %s" % os.path.join(args.out, "report.md"))
    if interrupted:
        return 130
    if args.judged:
        return 1 if doc["failed"] else 0
    return 0 if doc["success_rate"] >= SUCCESS_GOAL else 1


if __name__ == "__main__":
    cr.run_main(PROG, main)
