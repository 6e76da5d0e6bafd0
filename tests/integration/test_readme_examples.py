"""The README's command examples, as written.

Every command of README.md's `sh` blocks is of one of three kinds, taken in
README order in a scratch folder that links the repository's folders and
the build (so `results/` is the scratch folder's own):

- On files (`build/bin/...` programs and the plotting script): run, with
  the README's placeholders filled in from the examples before them
  (PLACEHOLDERS); each must exit 0.
- On the bus (BUS_EXAMPLES): run on the test's private network namespace
  with short time limits, and what each says it does is checked: the
  launcher flies the open course for 8 s (`--timeout 8`; the vehicle moves
  and the run ends by the monitor's time limit, no service restarted);
  `deploy/replay.sh` plays the lockstep flight at 8x (`--speed 8` for the
  README's 2) with `--channels 'NAV_STATE|SIM_CLOCK'`, and a recording of
  the bus holds those two channels only, every message of them;
  `deploy/replay.sh latest` finds the launcher's flight in `results/` and
  plays all of it; `make replay LOG=latest` (SPEED=2, the build and the
  Debian packages taken as they are: `make -o deps -o flight`) serves the
  page, whose snapshot shows the vehicle where the flight ended, until
  Ctrl-C; `make replay ... RERUN=` with the flight's own scenario runs the
  planners again, whose route reaches the viewer although the recorded one
  is not replayed.
- Checked only (CHECKED_ONLY, each with its reason: a long flight, a
  display, the whole test suite): the program or make target exists,
  every option the example names is in the program's `--help`, and a make
  example's recipe, printed by `make -n`, gives its programs only options
  their `--help` lists.

A command of none of these kinds fails the test, so that a new README
example is either run here or given its reason. Commands in the README's
prose (inline code starting with `make `, `deploy/`, `bench/` or naming an
`ofn_` program) are checked the same way as the checked-only ones.

The module re-runs itself inside a private network namespace
(deploy/netns.sh, as tests/integration/common.sh does for the shell
tests), so the multicast of the bus examples never leaves the machine.

Run from the repository root, with the build folder in OFN_BUILD_DIR
(default `build`):
    /usr/bin/python3 -m unittest tests/integration/test_readme_examples.py
"""

import json
import os
import re
import shlex
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.error
import urllib.request

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD_DIR = os.path.abspath(os.environ.get("OFN_BUILD_DIR", os.path.join(REPO_ROOT, "build")))
LINKED = ("bench", "config", "deploy", "examples", "lcmtypes", "services", "sim", "CMakeLists.txt",
          "Makefile")
LCM_URL = "udpm://239.255.76.67:7667?ttl=0"


def _enter_private_network_namespace():
    """Runs this test again under deploy/netns.sh, once (OFN_IN_NETNS)."""
    if os.environ.get("OFN_IN_NETNS"):
        return
    os.environ["OFN_IN_NETNS"] = "1"
    argv = sys.argv if sys.argv[0].endswith(".py") else ["-m", "unittest"] + sys.argv[1:]
    sys.stdout.flush()
    sys.stderr.flush()
    netns = os.path.join(REPO_ROOT, "deploy", "netns.sh")
    os.execv(netns, [netns, sys.executable] + argv)


_enter_private_network_namespace()

sys.path.insert(0, os.path.join(REPO_ROOT, "examples", "python"))
import nav_track  # noqa: E402  (reads LCM logs with the standard library)

# What the README writes for a value the reader supplies, and what stands
# in for it here: the lockstep example's log, a new folder.
PLACEHOLDERS = {
    "FILE.lcm": "results/lockstep/flight.lcm",
    "results/run-<date>/flight-<date>.lcm": "results/lockstep/flight.lcm",
    "DIR": "report",
}

# The README's sh-block commands that are not run, and why.
CHECKED_ONLY = {
    r"make run$": "a 70 s flight after the build (fly.sh's own steps are run by the "
                  "launcher and replay examples and by integration.cli_usage)",
    r"make test$": "the whole test suite, of which this test is a part",
    r"make run WATCH=1$": "the 70 s flight of make run; the viewer beside a flight in its "
                          "namespace is integration.viewer_live's",
    r"make spy$": "lcm-spy needs a display",
    r"deploy/spy\.sh\b": "lcm-spy needs a display",
}


def readme_commands(text):
    """The commands of the README's sh blocks, continuation lines joined and
    comments dropped."""
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        joined = re.sub(r"\\\n\s*", " ", block)
        for line in joined.splitlines():
            line = re.sub(r"\s+#.*$", "", line).strip()
            if line and not line.startswith("#"):
                commands.append(line)
    return commands


def readme_prose_commands(text):
    """Inline code of the README's prose that names a command: `make ...`,
    `deploy/...`, `bench/...`, `build/bin/ofn_...` or an `ofn_...` program."""
    prose = re.sub(r"```.*?```", "", text, flags=re.S)
    prose = re.sub(r"(?<!\n)\n(?!\n)", " ", prose)
    spans = re.findall(r"`([^`]+)`", prose)
    return [s for s in spans
            if re.match(r"(make( |$)|deploy/\S+\.(sh|py)|bench/\S+\.(sh|py)|build/bin/ofn_|ofn_)", s)]


def runs_on_files(command):
    return command.startswith("build/bin/") or command.startswith(
        "/usr/bin/python3 services/tools/")


def named_options(command):
    """The long options an example names, optional ones in [...] included."""
    return sorted(set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", command)))


def as_written(command):
    """The command with its optional [...] parts in and placeholders filled."""
    command = command.replace("[", "").replace("]", "")
    for placeholder, value in PLACEHOLDERS.items():
        command = re.sub(r"(?<![\w/.-])" + re.escape(placeholder) + r"(?![\w/.-])", value, command)
    return command


def run(command, cwd, timeout=300, env=None):
    return subprocess.run(command, shell=isinstance(command, str), cwd=cwd, text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout,
                          env=env)


def channel_counts(path):
    counts = {}
    with open(path, "rb") as stream:
        for _, _, channel, _ in nav_track.read_events(stream):
            counts[channel] = counts.get(channel, 0) + 1
    return counts


def nav_state_type():
    sys.path.insert(0, os.path.join(BUILD_DIR, "lcmtypes", "python"))
    from ofn import nav_state_t
    return nav_state_t


class Recording:
    """lcm-logger on the test's bus while a command runs."""

    def __init__(self, path):
        self.path = path

    def __enter__(self):
        self.proc = subprocess.Popen(["lcm-logger", "-q", "-f", "--lcm-url=" + LCM_URL, self.path],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(0.5)  # joined the group before anything is sent
        if self.proc.poll() is not None:
            raise AssertionError("lcm-logger did not start: " + self.proc.stderr.read())
        return self

    def __exit__(self, *exc):
        time.sleep(0.5)  # the last datagrams written
        self.proc.send_signal(signal.SIGINT)
        self.proc.wait(timeout=10)
        self.proc.stderr.close()
        self.counts = channel_counts(self.path)
        return False


def snapshot(url):
    with urllib.request.urlopen(url + "api/snapshot", timeout=5) as r:
        return json.load(r)


class ReadmeExamples(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(os.path.join(REPO_ROOT, "README.md")) as f:
            text = f.read()
        cls.commands = readme_commands(text)
        cls.prose = readme_prose_commands(text)
        with open(os.path.join(REPO_ROOT, "Makefile")) as f:
            cls.makefile = f.read()

    # ------------------------------------------------------------------ kinds

    def bus_example(self, command):
        """The method that runs this bus example, or None."""
        for pattern, method in BUS_EXAMPLES:
            if re.match(pattern, command):
                return getattr(self, method)
        return None

    def checked_only(self, command):
        return next((reason for pattern, reason in CHECKED_ONLY.items()
                     if re.match(pattern, command)), None)

    def test_every_example_is_run_or_says_why_not(self):
        kinds = {"files": 0, "bus": 0, "checked": 0}
        for command in self.commands:
            with self.subTest(command=command):
                if runs_on_files(command):
                    kinds["files"] += 1
                elif self.bus_example(command):
                    kinds["bus"] += 1
                elif self.checked_only(command):
                    kinds["checked"] += 1
                else:
                    self.fail("a README example that is neither run here (BUS_EXAMPLES) nor "
                              "checked only with a reason (CHECKED_ONLY): " + command)
        self.assertGreaterEqual(kinds["files"], 4, self.commands)
        self.assertGreaterEqual(kinds["bus"], 5, self.commands)

    # ------------------------------------------------------------------ running

    def test_examples_run_as_written(self):
        with tempfile.TemporaryDirectory(prefix="ofn-readme-") as scratch:
            self.scratch = scratch
            for name in LINKED:
                os.symlink(os.path.join(REPO_ROOT, name), os.path.join(scratch, name))
            os.symlink(BUILD_DIR, os.path.join(scratch, "build"))
            self.flight = {}  # what the launcher example flew, for the replays after it
            ran = []
            for command in self.commands:
                runner = self.bus_example(command)
                if not runs_on_files(command) and runner is None:
                    continue
                with self.subTest(command=command):
                    started = time.monotonic()
                    if runner is not None:
                        runner(as_written(command))
                    else:
                        self.run_on_files(as_written(command))
                    ran.append(command)
                    print("  %5.1f s  %s" % (time.monotonic() - started, command), file=sys.stderr)
            self.assertGreaterEqual(len(ran), 9, ran)
            # What the examples say they make.
            for made in ("results/lockstep/summary.txt", "run1/replay", "report/flight.png",
                         "report/tracking.png"):
                self.assertTrue(os.path.exists(os.path.join(scratch, made)), made)

    def run_on_files(self, command):
        result = run(command, self.scratch)
        self.assertEqual(result.returncode, 0, f"{command}\n{result.stdout[-3000:]}")

    def fly_launcher(self, command):
        """deploy/launch.py on the open course, ended by an 8 s run limit."""
        command = command.replace(" --host onboard1", "") + " --timeout 8"
        result = run(command, self.scratch, timeout=120)
        out = result.stdout
        self.assertEqual(result.returncode, 1, f"{command}\n{out[-3000:]}")
        self.assertIn("no arrival within 8 s", out)
        self.assertNotIn("restarting in", out)
        self.assertNotIn("configuration or usage error", out)
        with open(os.path.join(self.scratch, "results", "latest_log")) as f:
            log = f.read().strip()
        track = nav_track.summarise(log, "NAV_STATE", nav_state_type())
        self.assertIsNotNone(track, "no NAV_STATE in " + log)
        moved = track["last_position"][0] - track["first_position"][0]
        self.assertGreater(moved, 5.0, "the vehicle moved %.1f m north in 8 s" % moved)
        self.flight = {"log": log, "counts": channel_counts(log),
                       "last_position": track["last_position"]}

    def replay_a_log(self, command):
        """deploy/replay.sh on the lockstep log, two channels, at 8x."""
        command = re.sub(r"--speed \S+", "--speed 8", command)
        self.assertIn("--channels 'NAV_STATE|SIM_CLOCK'", command)
        log = os.path.join(self.scratch, PLACEHOLDERS["results/run-<date>/flight-<date>.lcm"])
        with Recording(os.path.join(self.scratch, "replayed.lcm")) as heard:
            result = run(command, self.scratch, timeout=120)
        self.assertEqual(result.returncode, 0, f"{command}\n{result.stdout[-3000:]}")
        recorded = channel_counts(log)
        self.assertGreater(len(recorded), 5, recorded)
        self.assertEqual(sorted(heard.counts), ["NAV_STATE", "SIM_CLOCK"], heard.counts)
        for channel in ("NAV_STATE", "SIM_CLOCK"):
            self.assert_all_heard(heard.counts[channel], recorded[channel], channel)

    def replay_latest(self, command):
        """deploy/replay.sh latest: the launcher's flight, all of it."""
        self.assertTrue(self.flight, "the launcher example did not fly first")
        with Recording(os.path.join(self.scratch, "latest.lcm")) as heard:
            result = run(command, self.scratch, timeout=120)
        out = result.stdout
        self.assertEqual(result.returncode, 0, f"{command}\n{out[-3000:]}")
        self.assertIn("latest flight, from %s/results/latest_log" % self.scratch, out)
        self.assertIn("replaying %s at 1.0x" % self.flight["log"], out)
        self.assertEqual(sorted(heard.counts), sorted(self.flight["counts"]))
        for channel, sent in self.flight["counts"].items():
            self.assert_all_heard(heard.counts[channel], sent, channel)

    def make_replay(self, command):
        """make replay LOG=latest: the page, until Ctrl-C."""
        self.assertTrue(self.flight, "the launcher example did not fly first")
        rerun = re.search(r"RERUN=(\S+)", command)
        if rerun:  # the scenario of the flight replayed, as the README asks
            command = command.replace(rerun.group(0), "RERUN=sim/scenarios/open.yaml")
        # The build and the Debian packages as they are; a replay at twice
        # real time (the flight is 8 s). At 8x the whole recording reaches the
        # viewer at eight times its rate, and beside another test on two cores
        # its socket once dropped a quarter of the NAV_STATEs (360 of 494).
        command = command.replace("make replay", "make -o deps -o flight replay", 1) + " SPEED=2"
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
        out_path = os.path.join(self.scratch, "make-replay.txt")
        with open(out_path, "w") as out:
            proc = subprocess.Popen(shlex.split(command), cwd=self.scratch, stdout=out,
                                    stderr=subprocess.STDOUT, env=env, start_new_session=True)
        try:
            output = self.wait_for(proc, out_path, "the page stays at", 90)
            url = re.search(r"the flight live at (\S+)", output).group(1)
            self.assertEqual(url, "http://127.0.0.1:8765/")
            with urllib.request.urlopen(url, timeout=5) as page:
                self.assertIn("<canvas", page.read().decode())
            s = self.settled_snapshot(url)
            self.assertIsNotNone(s["vehicle"], "no vehicle on the page")
            for got, want in zip(s["vehicle"]["position"], self.flight["last_position"]):
                self.assertAlmostEqual(got, want, delta=0.5)
            accepted = s["counters"]["accepted"]
            self.assert_all_heard(accepted.get("NAV_STATE", 0), self.flight["counts"]["NAV_STATE"],
                                  "NAV_STATE on the page")
            if rerun:
                # RERUN replays the planners' inputs only (replay.sh): the map and the
                # route on the page are those of the services run again.
                self.assertIn("into sensor_interface, mapper, global_planner, rh_optimizer", output)
                for channel in ("OBSTACLE_GRID", "GLOBAL_PATH"):
                    self.assertGreater(accepted.get(channel, 0), 0, accepted)
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                self.fail("make replay did not end on Ctrl-C")
        with self.assertRaises(urllib.error.URLError, msg="the viewer outlived make replay"):
            urllib.request.urlopen("http://127.0.0.1:8765/", timeout=2)

    def assert_all_heard(self, heard, sent, what):
        """All of `sent` heard, give or take the odd datagram a loaded machine
        drops on loopback (one in twenty at most)."""
        self.assertLessEqual(heard, sent, what)
        self.assertGreaterEqual(heard, sent - max(1, sent // 20), what)

    def wait_for(self, proc, path, text, limit):
        deadline = time.monotonic() + limit
        while time.monotonic() < deadline:
            with open(path) as f:
                output = f.read()
            if text in output:
                return output
            if proc.poll() is not None:
                self.fail("ended (exit code %s) before '%s':\n%s" % (proc.returncode, text,
                                                                     output[-3000:]))
            time.sleep(0.2)
        self.fail("no '%s' after %d s:\n%s" % (text, limit, output[-3000:]))

    def settled_snapshot(self, url):
        """The viewer's snapshot once its message counts stop growing."""
        s = snapshot(url)
        for _ in range(50):
            time.sleep(0.2)
            again = snapshot(url)
            if again["counters"]["accepted"] == s["counters"]["accepted"]:
                return again
            s = again
        return s

    # ------------------------------------------------------------------ checking

    def check_command(self, command, dry_run=True):
        """The program or make target exists and takes the options named;
        with dry_run, or when it sets variables, a make command's recipe too."""
        if command.startswith("make"):
            self.check_make(command, dry_run)
            return
        program = command.split()[0]
        if re.match(r"ofn_\w+$", program):
            program = "build/bin/" + program
        base = BUILD_DIR if program.startswith("build/") else REPO_ROOT
        path = os.path.join(base, program[len("build/"):] if base == BUILD_DIR else program)
        self.assertTrue(os.access(path, os.X_OK), f"{program} is not an executable")
        self.check_options(path, named_options(command))

    def check_options(self, path, options):
        """Every option in the program's --help; a program named without
        options is not started at all (a script may have no --help)."""
        if not options:
            return
        self.check_help(path, options)

    def check_help(self, path, options):
        result = run([path, "--help"], REPO_ROOT, timeout=60)
        self.assertEqual(result.returncode, 0, result.stdout)
        for option in options:
            self.assertRegex(result.stdout, r"(?<![\w-])%s(?![\w-])" % re.escape(option),
                             f"{os.path.basename(path)} --help lacks {option}")

    def check_make(self, command, dry_run):
        words = command.split()
        targets = set(re.findall(r"^([a-z][a-z-]*):", self.makefile, re.M))
        target = next((w for w in words[1:] if "=" not in w), None)
        if target is None:
            return  # plain `make`: the default target
        self.assertIn(target, targets)
        variables = [w for w in words[1:] if "=" in w]
        for variable in variables:
            name = variable.split("=")[0]
            self.assertIn(f"$({name})", self.makefile, f"make {target} {name}=")
        if not (dry_run or variables):
            return  # a target named in passing (`make replay` needs its LOG=)
        # The recipe as make would run it, the build and packages left out.
        dry = run(["make", "-n", "-o", "deps", "-o", "test-deps", "-o", "flight", "-o", "build",
                   target] + [v for v in variables if not v.endswith("=")], REPO_ROOT, timeout=60)
        self.assertEqual(dry.returncode, 0, dry.stdout)
        for line in dry.stdout.splitlines():
            for part in line.split(" -- "):
                words = part.split()
                if not words:
                    continue
                if words[0] == "/usr/bin/python3" and len(words) > 1:
                    words = words[1:]
                if re.match(r"(deploy|bench)/\S+\.(sh|py)$", words[0]):
                    self.check_options(os.path.join(REPO_ROOT, words[0]),
                                       named_options(" ".join(words[1:])))

    def test_checked_examples_name_real_programs_targets_and_options(self):
        checked = 0
        for command in self.commands:
            if runs_on_files(command):
                continue
            with self.subTest(command=command):
                self.check_command(command.replace("[", " ").replace("]", " "))
                checked += 1
        self.assertGreaterEqual(checked, 8)

    def test_commands_in_the_prose_name_real_programs_targets_and_options(self):
        for known in ("make run SCENARIO=path RTF=4", "make run HOSTS=3",
                      "deploy/fly.sh --host-network"):
            self.assertIn(known, self.prose)
        for command in self.prose:
            with self.subTest(command=command):
                self.check_command(command, dry_run=False)
        self.assertGreaterEqual(len(self.prose), 15)


# The README's bus examples run here, by the method that runs each.
BUS_EXAMPLES = [
    (r"deploy/launch\.py --scenario sim/scenarios/open\.yaml", "fly_launcher"),
    (r"deploy/replay\.sh results/run-<date>/flight-<date>\.lcm", "replay_a_log"),
    (r"deploy/replay\.sh latest$", "replay_latest"),
    (r"make replay LOG=latest( RERUN=\S+)?$", "make_replay"),
]


if __name__ == "__main__":
    unittest.main()
