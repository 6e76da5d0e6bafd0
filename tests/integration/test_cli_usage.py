"""Command lines of the deploy scripts and of every Python program: help,
usage errors, versions, defaults in the help, and `deploy/replay.sh latest`
after a flight flown by deploy/fly.sh.

Every Python entry point of the repository (a .py file outside tests/ with
a `__main__` block, found by walking the tree, so that a new one cannot be
left out) must answer --help and --version without numpy, matplotlib or
PyYAML, show every option's default, and turn an unknown option, a missing
or bad input file and a missing module into one line with exit code 2; its
bad inputs are listed in PythonEntryPointTest.bad_inputs, which must name
every entry point found.

Needs no build, no network and no LCM: flights use a small process table of
shell commands, and lcm-logger, lcm-logplayer, ofn_flight_report and
plot_flight.py are replaced by stand-ins in a scratch copy of the
repository.  Third-party modules are hidden by stub packages that fail to
import.

Run from the repository root:
    /usr/bin/python3 -m unittest tests/integration/test_cli_usage.py
"""

import importlib.util
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEPLOY = os.path.join(REPO_ROOT, "deploy")
BENCH = os.path.join(REPO_ROOT, "bench")
BENCH_SCRIPTS = ("monte_carlo.py", "campaign.py", "random_field.py", "campaign_report.py",
                 "fault_suite.py")
HIDDEN_MODULES = ("numpy", "matplotlib", "yaml")


def project_version():
    with open(os.path.join(REPO_ROOT, "CMakeLists.txt")) as f:
        return re.search(r"project\([^)]*VERSION\s+([0-9.]+)", f.read()).group(1)


def run(cmd, env=None, cwd=REPO_ROOT, timeout=60):
    return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          env=env, cwd=cwd, timeout=timeout)


def write_executable(path, text):
    with open(path, "w") as f:
        f.write(textwrap.dedent(text))
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return path


def python_entry_points():
    """Every Python program of the repository, as paths relative to it: a
    .py file outside tests/ with an `if __name__ == "__main__":` block.
    Build trees (a folder holding CMakeCache.txt), results/ and hidden
    folders are not searched."""
    found = []
    for root, dirs, files in os.walk(REPO_ROOT):
        top = os.path.samefile(root, REPO_ROOT)
        dirs[:] = sorted(d for d in dirs
                         if not d.startswith(".") and d != "__pycache__"
                         and not (top and d in ("tests", "results"))
                         and not os.path.isfile(os.path.join(root, d, "CMakeCache.txt")))
        for name in sorted(files):
            if not name.endswith(".py"):
                continue
            path = os.path.join(root, name)
            with open(path, encoding="utf-8") as f:
                if re.search(r"^if __name__ == .__main__.:", f.read(), re.MULTILINE):
                    found.append(os.path.relpath(path, REPO_ROOT))
    return found


def hide_modules(folder, names=HIDDEN_MODULES):
    """Stub packages in `folder` that fail to import as the missing module
    would; put `folder` first on PYTHONPATH to hide the real ones."""
    for name in names:
        os.makedirs(os.path.join(folder, name))
        with open(os.path.join(folder, name, "__init__.py"), "w") as f:
            f.write("raise ModuleNotFoundError(\"No module named '%s'\", name=%r)\n" % (name, name))
    return dict(os.environ, PYTHONPATH=folder)


class ScratchTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ofn-cli-test-")
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def assert_one_line_error(self, result, code, *fragments):
        self.assertEqual(result.returncode, code, result.stdout + result.stderr)
        message = result.stderr.strip()
        self.assertEqual(len(message.splitlines()), 1, "not one line: %r" % result.stderr)
        self.assertNotIn("Traceback", message)
        self.assertNotIn("unbound variable", message)
        for fragment in fragments:
            self.assertIn(fragment, message)


# ---------------------------------------------------------------------------
# deploy/*.sh
# ---------------------------------------------------------------------------

class FlyUsageTest(ScratchTestCase):
    FLY = os.path.join(DEPLOY, "fly.sh")

    def test_help_is_a_usage_text(self):
        result = run([self.FLY, "--help"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(result.stdout.startswith("usage: deploy/fly.sh "), result.stdout)
        for option, default in (("--scenario FILE", "sim/scenarios/bench3.yaml"), ("--rtf X", "1.0"),
                                ("--timeout S", "300"), ("--out DIR", "results/run-")):
            line = next((l for l in result.stdout.splitlines() if l.strip().startswith(option)), "")
            self.assertIn("(default: " + default, line, option)
        self.assertIn("deploy/replay.sh latest", result.stdout)
        self.assertFalse([l for l in result.stdout.splitlines() if l.startswith("#")],
                         "raw comments in the help")

    def test_option_without_value(self):
        for option in ("--rtf", "--scenario", "--out", "--timeout"):
            self.assert_one_line_error(run([self.FLY, option]), 2,
                                       "fly.sh: error: %s needs a value" % option)

    def test_unknown_option(self):
        self.assert_one_line_error(run([self.FLY, "--speed", "2"]), 2, "unknown option '--speed'")

    def test_bad_values(self):
        self.assert_one_line_error(run([self.FLY, "--rtf", "0"]), 2, "--rtf must be a positive number")
        self.assert_one_line_error(run([self.FLY, "--rtf", "fast"]), 2, "--rtf must be a positive number")
        self.assert_one_line_error(run([self.FLY, "--timeout", "-5"]), 2, "--timeout must be")
        self.assert_one_line_error(run([self.FLY, "--scenario", os.path.join(self.dir, "none.yaml")]),
                                   2, "none.yaml' not found")


class ReplayUsageTest(ScratchTestCase):
    REPLAY = os.path.join(DEPLOY, "replay.sh")

    def test_help(self):
        result = run([self.REPLAY, "--help"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(result.stdout.startswith("usage: deploy/replay.sh LOGFILE"))
        self.assertIn("results/*/latest_log", result.stdout)

    def test_usage_errors(self):
        log = os.path.join(self.dir, "flight.lcm")
        with open(log, "wb") as f:
            f.write(b"LCM")
        empty = os.path.join(self.dir, "empty.lcm")
        open(empty, "wb").close()
        for args, fragment in (([log, "--speed"], "--speed needs a value"),
                               ([log, "--lcm-url"], "--lcm-url needs a value"),
                               ([log, "--channels"], "--channels needs a value"),
                               ([log, "--rewind"], "unknown option '--rewind'"),
                               ([], "missing LOGFILE"),
                               ([log, log], "only one LOGFILE"),
                               ([os.path.join(self.dir, "nope.lcm")], "nope.lcm' not found"),
                               ([self.dir], "is not a regular file"),
                               ([empty], "is empty"),
                               ([log, "--speed", "0"], "--speed must be a positive number"),
                               ([log, "--speed", "x2"], "--speed must be a positive number"),
                               ([log, "--rerun"], "--rerun needs a value"),
                               ([log, "--rerun", os.path.join(self.dir, "none.yaml")],
                                "none.yaml' not found"),
                               ([log, "--rerun", log, "--channels", "NAV_STATE"],
                                "leave out --channels"),
                               ([log, "--rerun", log, "--loop"], "leave out --loop")):
            self.assert_one_line_error(run([self.REPLAY] + args), 2, "replay.sh: error: ", fragment)

    def test_missing_player_names_the_debian_package(self):
        log = os.path.join(self.dir, "flight.lcm")
        with open(log, "wb") as f:
            f.write(b"LCM")
        # A PATH with the shell tools the script uses, but no lcm-logplayer.
        tools = os.path.join(self.dir, "tools")
        os.mkdir(tools)
        for tool in ("bash", "dirname", "head", "awk"):
            os.symlink(shutil.which(tool), os.path.join(tools, tool))
        result = run(["/bin/bash", self.REPLAY, log], env=dict(os.environ, PATH=tools))
        self.assert_one_line_error(result, 1, "lcm-logplayer not found", "apt-get install liblcm-bin")
        self.assertNotRegex(result.stderr, r"install lcm\b")


class WatchUsageTest(ScratchTestCase):
    WATCH = os.path.join(DEPLOY, "watch.sh")

    def test_help(self):
        result = run([self.WATCH, "--help"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(result.stdout.startswith("usage: deploy/watch.sh"), result.stdout)
        port = next((l for l in result.stdout.splitlines() if l.strip().startswith("--port N")), "")
        self.assertIn("(default: 8765)", port)

    def test_usage_errors(self):
        for args, fragment in (([], "missing COMMAND"),
                               (["--port"], "--port needs a value"),
                               (["--log"], "--log needs a value"),
                               (["--port", "0", "true"], "--port must be a port number"),
                               (["--port", "http", "true"], "--port must be a port number"),
                               (["--frobnicate", "true"], "unknown option '--frobnicate'")):
            self.assert_one_line_error(run([self.WATCH] + args), 2, "watch.sh: error: ", fragment)


class SpyAndNetnsUsageTest(ScratchTestCase):
    def test_spy(self):
        spy = os.path.join(DEPLOY, "spy.sh")
        result = run([spy, "--help"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(result.stdout.startswith("usage: deploy/spy.sh"))
        self.assert_one_line_error(run([spy, "--lcm-url"]), 2, "--lcm-url needs a URL")
        self.assert_one_line_error(run([spy, "--verbose"]), 2, "unknown argument '--verbose'")

    def test_netns(self):
        netns = os.path.join(DEPLOY, "netns.sh")
        result = run([netns, "--help"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(result.stdout.startswith("usage: deploy/netns.sh"))
        self.assert_one_line_error(run([netns]), 2, "missing COMMAND")
        self.assert_one_line_error(run([netns, "--fallback"]), 2, "missing COMMAND")


class DeployScriptVersionTest(ScratchTestCase):
    """Every executable deploy script (found by listing deploy/, so that a
    new one cannot be left out) prints its name and the project's version
    for --version and lists --version in its help."""

    def test_every_script_has_version(self):
        scripts = sorted(name for name in os.listdir(DEPLOY)
                         if name.endswith(".sh")
                         and os.access(os.path.join(DEPLOY, name), os.X_OK))
        self.assertGreaterEqual(len(scripts), 6, scripts)
        for name in scripts:
            with self.subTest(script=name):
                result = run([os.path.join(DEPLOY, name), "--version"])
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stdout.strip(), "%s %s" % (name, project_version()))
                self.assertIn("--version", run([os.path.join(DEPLOY, name), "--help"]).stdout)


class FlyThenReplayTest(ScratchTestCase):
    """`make run` (deploy/fly.sh) then `deploy/replay.sh latest`, in a scratch
    copy of the repository with stand-ins for LCM and the build."""

    def setUp(self):
        super().setUp()
        self.repo = os.path.join(self.dir, "repo")
        for sub in ("deploy", "build/bin", "services/tools", "config", "sim/scenarios"):
            os.makedirs(os.path.join(self.repo, sub))
        for name in ("fly.sh", "flight_common.sh", "launch.py", "netns.sh", "replay.sh",
                     "version.sh"):
            shutil.copy2(os.path.join(DEPLOY, name), os.path.join(self.repo, "deploy", name))
        shutil.copy2(os.path.join(REPO_ROOT, "services", "tools", "ofn_cli.py"),
                     os.path.join(self.repo, "services", "tools", "ofn_cli.py"))
        with open(os.path.join(self.repo, "sim/scenarios/bench3.yaml"), "w") as f:
            f.write("name: stand-in\n")
        open(os.path.join(self.repo, "config/controller.yaml"), "w").close()
        self.report_marker = os.path.join(self.dir, "report-ran")
        write_executable(os.path.join(self.repo, "build/bin/ofn_flight_report"), """\
            #!/bin/sh
            touch %s
            echo "report: $*"
            """ % self.report_marker)
        write_executable(os.path.join(self.repo, "services/tools/plot_flight.py"), """\
            #!/usr/bin/python3
            """)
        self.fake_bin = os.path.join(self.dir, "fake-bin")
        os.mkdir(self.fake_bin)
        # lcm-logger: writes its file and runs until the launcher stops it.
        write_executable(os.path.join(self.fake_bin, "lcm-logger"), """\
            #!/bin/sh
            for arg in "$@"; do out=$arg; done
            printf 'LCM stand-in log\\n' > "$out"
            trap 'exit 0' INT TERM
            while :; do sleep 0.1; done
            """)
        # lcm-logplayer: says which file it was given.
        write_executable(os.path.join(self.fake_bin, "lcm-logplayer"), """\
            #!/bin/sh
            for arg in "$@"; do last=$arg; done
            echo "played $last"
            """)
        self.env = dict(os.environ, PATH=self.fake_bin + os.pathsep + os.environ.get("PATH", ""))

    def write_table(self, service_command):
        with open(os.path.join(self.repo, "deploy/processes.yaml"), "w") as f:
            f.write(textwrap.dedent("""\
                hosts:
                  gcs: {cores: [0]}
                processes:
                  - name: service
                    host: gcs
                    core: 0
                    command: %s
                    restart: true
                  - name: monitor
                    host: gcs
                    core: 0
                    command: ["sleep", "1"]
                    ends_run: true
                """ % service_command))

    def fly(self, *args):
        # --host-network: the stand-ins send nothing, so no namespace is needed.
        return run([os.path.join(self.repo, "deploy/fly.sh"), "--host-network", "--timeout", "30"]
                   + list(args), env=self.env, cwd=self.repo, timeout=120)

    def replay_latest(self):
        return run([os.path.join(self.repo, "deploy/replay.sh"), "latest"], env=self.env,
                   cwd=self.repo)

    def test_replay_latest_plays_the_flight_of_fly_sh(self):
        self.write_table('["sleep", "30"]')
        flown = self.fly()
        self.assertEqual(flown.returncode, 0, flown.stdout + flown.stderr)
        self.assertIn("deploy/replay.sh latest", flown.stdout)
        self.assertIn("make run WATCH=1 (deploy/fly.sh --watch) shows the flight in a browser",
                      flown.stdout)
        runs = [d for d in os.listdir(os.path.join(self.repo, "results")) if d.startswith("run-")]
        self.assertEqual(len(runs), 1)
        with open(os.path.join(self.repo, "results", runs[0], "latest_log")) as f:
            log = f.read().strip()
        self.assertTrue(os.path.isfile(log), log)

        replayed = self.replay_latest()
        self.assertEqual(replayed.returncode, 0, replayed.stdout + replayed.stderr)
        self.assertIn("played " + log, replayed.stdout)

        # A later flight of deploy/launch.py (results/latest_log) is newer.
        time.sleep(1.1)
        direct = os.path.join(self.repo, "results", "direct.lcm")
        with open(direct, "w") as f:
            f.write("LCM\n")
        with open(os.path.join(self.repo, "results", "latest_log"), "w") as f:
            f.write(direct + "\n")
        self.assertIn("played " + direct, self.replay_latest().stdout)

    def test_replay_latest_without_any_flight(self):
        self.assert_one_line_error(self.replay_latest(), 2, "no flight recorded yet")

    def test_fly_stops_on_a_configuration_error(self):
        self.write_table('["/bin/sh", "-c", "echo bad config >&2; exit 2"]')
        flown = self.fly()
        self.assertEqual(flown.returncode, 2, flown.stdout + flown.stderr)
        self.assertIn("configuration or usage error", flown.stderr)
        self.assertFalse(os.path.exists(self.report_marker), "a report was made of no flight")


# ---------------------------------------------------------------------------
# bench/*.py
# ---------------------------------------------------------------------------

class BenchScriptTest(ScratchTestCase):
    def setUp(self):
        super().setUp()
        # Stub packages that fail to import, first on the module path.
        self.no_modules = hide_modules(os.path.join(self.dir, "stubs"))
        # A build with an ofn_sim_runner that is never run.
        self.build = os.path.join(self.dir, "build")
        self.bin = os.path.join(self.build, "bin")
        os.makedirs(self.bin)
        write_executable(os.path.join(self.bin, "ofn_sim_runner"), "#!/bin/sh\nexit 1\n")

    def bench(self, script, *args, env=None):
        return run([sys.executable, os.path.join(BENCH, script)] + list(args), env=env)

    def test_stubs_hide_the_modules(self):
        for name in HIDDEN_MODULES:
            result = run([sys.executable, "-c", "import %s" % name], env=self.no_modules)
            self.assertNotEqual(result.returncode, 0, name)

    def test_missing_module_at_use_time_is_one_line(self):
        out = os.path.join(self.dir, "out")
        result = self.bench("random_field.py", "--seed", "1", "--out", os.path.join(out, "f.yaml"),
                            env=self.no_modules)
        self.assert_one_line_error(result, 2, "bench/random_field.py: error:", "yaml",
                                   "apt-get install python3-yaml")
        results_dir = os.path.join(self.dir, "flight")
        os.mkdir(results_dir)
        with open(os.path.join(results_dir, "summary.json"), "w") as f:
            f.write("{}\n")
        with open(os.path.join(results_dir, "nav_state.csv"), "w") as f:
            f.write("t,north,east,down\n0,0,0,0\n")
        result = self.bench("campaign_report.py", results_dir, env=self.no_modules)
        self.assert_one_line_error(result, 2, "numpy", "python3-numpy")
        # Checked before any flight, not after hours of them; --build DIR (the
        # old spelling of --bin DIR/bin) finds the same programs.
        for script in ("monte_carlo.py", "campaign.py"):
            for programs in (["--bin", self.bin], ["--build", self.build]):
                result = self.bench(script, *programs, "--out", out, "--quick", env=self.no_modules)
                self.assert_one_line_error(result, 2, "bench/%s: error:" % script, "apt-get install")
        self.assertFalse(os.path.exists(out), "work was started")

    def test_usage_and_input_errors_are_one_line(self):
        broken = os.path.join(self.dir, "broken.yaml")
        with open(broken, "w") as f:
            f.write("units: ft\nstart: [1, 2\n")
        listed = os.path.join(self.dir, "list.yaml")
        with open(listed, "w") as f:
            f.write("- 1\n")
        out = os.path.join(self.dir, "f.yaml")
        cases = [
            ("monte_carlo.py", ["--bin", self.bin, "--runs", "0"], "--runs and --jobs must be >= 1"),
            ("monte_carlo.py", ["--bin", self.bin, "--seeds", "1,x"], "--seeds"),
            ("monte_carlo.py", ["--bin", os.path.join(self.dir, "none")], "no ofn_sim_runner"),
            # --build DIR, the old spelling of --bin DIR/bin, still works, but not with --bin.
            ("campaign.py", ["--build", os.path.join(self.dir, "none")], "no ofn_sim_runner in %s/none/bin" % self.dir),
            ("campaign.py", ["--build", self.build, "--bin", self.bin], "old spelling of --bin"),
            ("monte_carlo.py", ["--bin", self.bin, "--template", broken + ".missing"], "--template"),
            ("monte_carlo.py", ["--bin", self.bin, "--config-dir", self.dir + "/none"], "--config-dir"),
            ("monte_carlo.py", ["--jobs"], "expected one argument"),
            ("campaign.py", ["--bin", self.bin, "--courses", "bench9"], "no scenario file"),
            ("campaign.py", ["--bin", self.bin, "--rtf", "0"], "--rtf > 0"),
            ("campaign.py", ["--fast"], "unrecognized arguments: --fast"),
            ("random_field.py", [], "required"),
            ("random_field.py", ["--seed", "one", "--out", out], "invalid int value"),
            ("random_field.py", ["--seed", "1", "--out", out, "--template", broken + ".missing"],
             "No such file"),
            ("random_field.py", ["--seed", "1", "--out", out, "--template", broken], "not valid YAML: line 3"),
            ("random_field.py", ["--seed", "1", "--out", out, "--template", listed], "not a scenario"),
            ("random_field.py", ["--seed", "1", "--out", os.path.join(listed, "f.yaml")], "list.yaml"),
            ("random_field.py", ["--seed", "1", "--out", out, "--dense", "--trap"],
             "--trap: not allowed with argument --dense"),
            ("monte_carlo.py", ["--bin", self.bin, "--trap", "--dense"],
             "--dense: not allowed with argument --trap"),
            ("campaign_report.py", [], "required"),
            ("campaign_report.py", [os.path.join(self.dir, "none")], "no folder"),
            ("campaign_report.py", [self.dir], "no summary.json"),
        ]
        for script, args, fragment in cases:
            with self.subTest(script=script, args=args):
                result = self.bench(script, *args)
                self.assert_one_line_error(result, 2, "bench/%s: error:" % script, fragment)
                self.assertEqual(result.stdout, "")


def load_module(path):
    name = "entry_" + os.path.splitext(os.path.basename(path))[0]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# ---------------------------------------------------------------------------
# Every Python entry point
# ---------------------------------------------------------------------------

SWEEP_HEADER = ("mass_scale,airframe,wind [kt],turbulence,adaptive_rms [m],adaptive_max [m],"
                "baseline_rms [m],baseline_max [m]\n")


class PythonEntryPointTest(ScratchTestCase):
    def setUp(self):
        super().setUp()
        self.entry_points = python_entry_points()
        self.no_modules = hide_modules(os.path.join(self.dir, "stubs"))
        self.plain_env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(textwrap.dedent(text))
        return path

    def bad_inputs(self):
        """{entry point: [(arguments, what the one-line error says, hide the
        third-party modules)]}: a missing file, a bad file, a missing module."""
        d = self.dir
        missing = os.path.join(d, "none")
        empty_dir = os.path.join(d, "empty")
        os.makedirs(empty_dir)
        broken = self.write("broken.yaml", "units: ft\nstart: [1, 2\n")
        results = os.path.join(d, "results")
        for name, text in (("summary.json", "{}\n"), ("nav_state.csv", "t [s],north [m]\n"),
                           ("control_status.csv", "t [s],mode\n"), ("waypoints.csv", "t [s]\n")):
            self.write(os.path.join("results", name), text)
        self.write("unreadable/summary.json", "{not json\n")
        sweep = self.write("sweep.csv", SWEEP_HEADER + '1.2,"nominal",10,light,0.5,1.1,0.9,2.0\n')
        wrong_sweep = self.write("wrong.csv", "a,b\n1,2\n")
        bad_number = self.write("bad.csv", SWEEP_HEADER + '1.2,"nominal",ten,light,0.5,1.1,0.9,2.0\n')
        bin_dir = os.path.join(d, "bin")
        os.makedirs(bin_dir)
        for program in ("ofn_sim_runner", "ofn_bus_fuzz", "ofn_flight_report"):
            write_executable(os.path.join(bin_dir, program), "#!/bin/sh\nexit 1\n")
        types = os.path.join(d, "types")
        self.write("types/ofn/__init__.py", "class nav_state_t:\n    pass\n")
        log = self.write("flight.lcm", "not a log\n")
        scenario = os.path.join(REPO_ROOT, "sim", "scenarios", "open.yaml")
        field = os.path.join(d, "field.yaml")
        return {
            "bench/campaign.py": [
                (["--bin", missing], "no ofn_sim_runner in " + missing, False),
                (["--bin", bin_dir, "--config-dir", missing], "--config-dir", False),
                (["--bin", bin_dir, "--quick", "--out", missing], "python3-yaml", True),
            ],
            "bench/bus_fuzz.py": [
                (["--bin", bin_dir, "--scenario", missing], "--scenario: no file", False),
                (["--bin", bin_dir, "--messages", "0"], "--messages must be >= 1", False),
                (["--bin", bin_dir, "--rate", "-5"], "--rate must be > 0", False),
                (["--bin", missing], "no ofn_bus_fuzz in " + missing, False),
                (["--bin", bin_dir, "--out", missing], "python3-yaml", True),
            ],
            "bench/campaign_report.py": [
                ([missing], "no folder", False),
                ([empty_dir], "no summary.json", False),
                ([results], "python3-numpy", True),
            ],
            "bench/fault_suite.py": [
                (["--scenario", missing], "--scenario: no file", False),
                (["--only", "no-such-row"], "unknown row", False),
                (["--list"], "python3-yaml", True),
            ],
            "bench/link_relay.py": [
                (["--ports", "pa"], "--ports needs at least two ports", False),
                (["--ports", "pa,pb", "--loss", "2"], "expected a share in [0, 1]", False),
                (["--ports", "pa,pb", "--links", "pa:pc"], "is not FROM:TO", False),
                (["--ports", "pa,pb", "--reorder", "0.1"], "--reorder needs a --delay", False),
            ],
            "bench/monte_carlo.py": [
                (["--bin", missing], "no ofn_sim_runner", False),
                (["--bin", bin_dir, "--template", missing], "--template", False),
                (["--bin", bin_dir, "--quick", "--out", missing], "python3-yaml", True),
            ],
            "bench/plot_tracking_sweep.py": [
                ([missing], "cannot read " + missing, False),
                ([wrong_sweep], "has no column mass_scale", False),
                ([bad_number], "line 2: wind is 'ten', not a number", False),
                ([sweep, os.path.join(missing, "sweep.png")], "cannot write", False),
                ([sweep], "python3-matplotlib", True),
            ],
            "bench/random_field.py": [
                (["--seed", "1", "--out", field, "--template", missing], "No such file", False),
                (["--seed", "1", "--out", field, "--template", broken], "not valid YAML", False),
                (["--seed", "1", "--out", field], "python3-yaml", True),
            ],
            "deploy/launch.py": [
                (["--scenario", missing], "not found", False),
                (["--scenario", broken], "not valid YAML: line 3", False),
                (["--scenario", scenario, "--table", missing], "process table not found", False),
                (["--scenario", scenario], "python3-yaml", True),
            ],
            "examples/python/nav_track.py": [
                ([log], "Python types not found", False),
                (["--types", types, missing], "cannot read " + missing, False),
                (["--types", types, empty_dir], "cannot read " + empty_dir, False),
            ],
            "services/tools/plot_flight.py": [
                ([missing], "results folder not found", False),
                ([empty_dir], "required file missing", False),
                ([os.path.join(d, "unreadable")], "cannot read", False),
                ([results, "--scenario", missing], "--scenario: no file", False),
                ([results, "--scenario", broken], "not valid YAML", False),
                ([results], "python3-numpy", True),
            ],
        }

    def program(self, entry_point, *args, env=None):
        return run([sys.executable, os.path.join(REPO_ROOT, entry_point)] + list(args),
                   env=env or self.plain_env)

    def test_the_walk_finds_the_entry_points(self):
        for known in ("deploy/launch.py", "bench/monte_carlo.py", "services/tools/plot_flight.py",
                      "bench/plot_tracking_sweep.py", "examples/python/nav_track.py"):
            self.assertIn(known, self.entry_points)
        self.assertNotIn("services/tools/ofn_cli.py", self.entry_points)  # a module, no program
        self.assertFalse([e for e in self.entry_points if e.startswith(("tests/", "build/"))])

    def test_help_and_version_without_numpy_matplotlib_yaml(self):
        version = project_version()
        for entry_point in self.entry_points:
            with self.subTest(entry_point=entry_point):
                result = self.program(entry_point, "--help", env=self.no_modules)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertTrue(result.stdout.startswith("usage: " + entry_point), result.stdout)
                result = self.program(entry_point, "--version", env=self.no_modules)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stdout.strip(), "%s %s" % (entry_point, version))

    def test_unknown_option_is_one_line(self):
        for entry_point in self.entry_points:
            with self.subTest(entry_point=entry_point):
                result = self.program(entry_point, "--no-such-option", env=self.no_modules)
                self.assert_one_line_error(result, 2, entry_point + ": error: ")

    def test_help_shows_every_default(self):
        for entry_point in self.entry_points:
            module = load_module(os.path.join(REPO_ROOT, entry_point))
            self.assertTrue(hasattr(module, "build_parser"), entry_point + " has no build_parser()")
            for action in module.build_parser()._actions:
                if action.dest in ("help", "version") or action.help == "==SUPPRESS==":
                    continue
                with self.subTest(entry_point=entry_point,
                                  option=action.option_strings or action.dest):
                    shown = (action.help or "") % dict(vars(action), prog=entry_point)
                    self.assertRegex(shown, r"\((default: [^)]+|required)\)$")

    def test_bad_inputs_are_one_line_errors(self):
        table = self.bad_inputs()
        self.assertEqual(sorted(table), sorted(self.entry_points),
                         "every Python entry point needs its bad inputs in bad_inputs()")
        for entry_point, cases in table.items():
            # The two that import no third-party module.
            self.assertTrue(any(hidden for _, _, hidden in cases) or
                            entry_point in ("examples/python/nav_track.py", "bench/link_relay.py"),
                            entry_point + ": no missing-module case")
            for args, fragment, hidden in cases:
                with self.subTest(entry_point=entry_point, args=args):
                    result = self.program(entry_point, *args,
                                          env=self.no_modules if hidden else None)
                    self.assert_one_line_error(result, 2, fragment)
                    self.assertRegex(result.stderr, "^(%s|%s): error: " % (
                        re.escape(entry_point), re.escape(os.path.basename(entry_point))))


# ---------------------------------------------------------------------------
# Every help text
# ---------------------------------------------------------------------------

# Repository paths a help text names: dir/.../name.yaml|.py|.sh, relative.
HELP_PATH_RE = re.compile(r"(?<![\w./*$<{-])((?:[\w.-]+/)+[\w.-]+\.(?:yaml|py|sh))(?![\w/])")


class HelpExamplesTest(unittest.TestCase):
    def test_files_named_in_help_texts_exist(self):
        commands = [[sys.executable, os.path.join(REPO_ROOT, p), "--help"]
                    for p in python_entry_points()]
        commands += [[os.path.join(DEPLOY, s), "--help"]
                     for s in ("fly.sh", "replay.sh", "spy.sh", "netns.sh", "watch.sh")]
        for cmd in commands:
            result = run(cmd)
            self.assertEqual(result.returncode, 0, result.stderr)
            paths = HELP_PATH_RE.findall(result.stdout)
            self.assertTrue(paths, "%s names no file" % cmd[-2])
            for path in paths:
                if any(part.isupper() for part in re.split(r"[/.-]", path)):
                    continue  # a placeholder such as OUT/... or DIR/...
                with self.subTest(help=os.path.basename(cmd[-2]), path=path):
                    self.assertTrue(os.path.exists(os.path.join(REPO_ROOT, path)),
                                    "%s --help names %s, which does not exist" % (cmd[-2], path))


if __name__ == "__main__":
    unittest.main()
