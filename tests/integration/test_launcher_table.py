"""Tests of deploy/launch.py: table and input checks, core clamping, supervision.

Needs no network and no LCM: every run uses --no-record and --no-pin and
small shell commands in place of the flight services.

Run from the repository root:
    /usr/bin/python3 -m unittest tests/integration/test_launcher_table.py
"""

import csv
import glob
import importlib.util
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LAUNCHER = os.path.join(REPO_ROOT, "deploy", "launch.py")
REAL_TABLE = os.path.join(REPO_ROOT, "deploy", "processes.yaml")


def import_launcher():
    # deploy/ is not a package; load the script as a module.
    spec = importlib.util.spec_from_file_location("ofn_launch", LAUNCHER)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


launch = import_launcher()


class LauncherTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ofn-launch-test-")
        self.dir = self.tmp.name
        self.scenario = os.path.join(self.dir, "scenario.yaml")
        with open(self.scenario, "w") as f:
            f.write("# dummy scenario: the launcher only checks that it is a YAML mapping\n"
                    "name: dummy\n")
        self.log_dir = os.path.join(self.dir, "results")

    def tearDown(self):
        self.tmp.cleanup()

    def write_table(self, text):
        path = os.path.join(self.dir, "table.yaml")
        with open(path, "w") as f:
            f.write(textwrap.dedent(text))
        return path

    def run_launcher(self, table, *extra, timeout=60):
        cmd = [sys.executable, LAUNCHER, "--table", table, "--scenario", self.scenario,
               "--out", self.log_dir, "--no-record", "--no-pin"] + list(extra)
        return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, timeout=timeout, cwd=REPO_ROOT)


class TableValidationTest(LauncherTestCase):
    GOOD_TABLE = """\
        hosts:
          gcs:      {cores: [0]}
          onboard1: {cores: [1]}
        processes:
          - name: worker
            host: onboard1
            core: 1
            command: ["/bin/sh", "-c", "echo {rtf} {timeout}"]
            restart: true
          - name: monitor
            host: gcs
            core: 0
            command: ["sleep", "1"]
            ends_run: true
        """

    def test_correct_table_parses(self):
        table = launch.load_table(self.write_table(self.GOOD_TABLE))
        self.assertEqual(table.names(), ["worker", "monitor"])
        self.assertEqual(table.hosts, {"gcs": [0], "onboard1": [1]})
        worker, monitor = table.processes
        self.assertEqual((worker.host, worker.core, worker.restart, worker.ends_run),
                         ("onboard1", 1, True, False))
        self.assertEqual((monitor.restart, monitor.ends_run), (False, True))

    def test_project_table_parses(self):
        table = launch.load_table(REAL_TABLE)
        self.assertEqual(table.names()[:4],
                         ["vehicle_sim", "controller", "mission_uplink", "flight_monitor"])
        ends_run = [p.name for p in table.processes if p.ends_run]
        self.assertEqual(ends_run, ["flight_monitor"])

    def test_missing_field_is_named(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gcs
                command: ["sleep", "1"]
            """)
        with self.assertRaisesRegex(launch.TableError, r"monitor.*missing field 'core'"):
            launch.load_table(table)
        result = self.run_launcher(table)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("'core'", result.stderr)
        self.assertIn("table.yaml", result.stderr)
        self.assertIn("monitor", result.stderr)

    def test_unknown_host_is_named(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gsc
                core: 0
                command: ["sleep", "1"]
            """)
        result = self.run_launcher(table)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("field 'host'", result.stderr)
        self.assertIn("unknown host 'gsc'", result.stderr)

    def test_ill_typed_field_is_named(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gcs
                core: 0
                command: "sleep 1"
            """)
        with self.assertRaisesRegex(launch.TableError, r"field 'command' must be a list"):
            launch.load_table(table)

    def test_unknown_placeholder_is_rejected(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gcs
                core: 0
                command: ["sleep", "{duration}"]
            """)
        with self.assertRaisesRegex(launch.TableError, r"unknown placeholder \{duration\}"):
            launch.load_table(table)

    def test_missing_executable_says_build_first(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gcs
                core: 0
                command: ["{bin}/ofn_does_not_exist"]
            """)
        result = self.run_launcher(table, "--bin", self.dir)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("make build", result.stderr)
        self.assertIn("ofn_does_not_exist", result.stderr)

    def test_unknown_only_name_is_rejected(self):
        result = self.run_launcher(self.write_table(self.GOOD_TABLE), "--only", "mapper")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("mapper", result.stderr)

    def test_placeholders_and_config_are_expanded(self):
        spec = launch.ProcessSpec("sim", "onboard1", 1, ["{bin}/ofn_vehicle_sim", "--rtf", "{rtf}"],
                                  config="/abs/config/vehicle_sim.yaml")
        argv = launch.expand_command(spec, {"bin": "/b", "rtf": "2"})
        self.assertEqual(argv, ["/b/ofn_vehicle_sim", "--rtf", "2",
                                "--config", "/abs/config/vehicle_sim.yaml"])

    def test_authenticated_bus_gives_the_project_programs_their_host_role(self):
        sim = launch.ProcessSpec("sim", "onboard1", 1, ["{bin}/ofn_vehicle_sim"])
        other = launch.ProcessSpec("probe", "gcs", 0, ["/bin/sh", "-c", "true"])
        values = {"bin": "/b", "bus_keys": "/keys"}
        self.assertEqual(launch.expand_command(sim, values),
                         ["/b/ofn_vehicle_sim", "--bus-keys", "/keys", "--bus-role", "onboard1"])
        self.assertEqual(launch.expand_command(other, values), ["/bin/sh", "-c", "true"])
        self.assertEqual(launch.expand_command(sim, {"bin": "/b", "bus_keys": ""}),
                         ["/b/ofn_vehicle_sim"])

    def test_selection_by_host_and_only(self):
        table = launch.load_table(self.write_table(self.GOOD_TABLE))
        self.assertEqual([p.name for p in launch.select_processes(table, host="gcs")], ["monitor"])
        self.assertEqual([p.name for p in launch.select_processes(table, only=["worker"])],
                         ["worker"])


class PreflightTest(LauncherTestCase):
    """Scenario, config files, placeholders and executables are checked once,
    before anything starts: one line on stderr, exit code 2, nothing run."""

    def table_with_marker(self, config=None):
        # The process leaves a marker file when it runs, so a test can tell
        # that nothing was started.
        self.marker = os.path.join(self.dir, "started")
        return self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: worker
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "touch %s", "{scenario}", "{lcm_url}"]
            %s""" % (self.marker, "    config: %s\n" % config if config else ""))

    def assert_rejected(self, result, *fragments):
        self.assertEqual(result.returncode, 2, result.stdout + result.stderr)
        message = result.stderr.strip()
        self.assertEqual(len(message.splitlines()), 1, "not one line: %r" % result.stderr)
        self.assertTrue(message.startswith("launch.py: error: "), message)
        for fragment in fragments:
            self.assertIn(fragment, message)
        self.assertFalse(os.path.exists(self.marker), "a process was started")
        self.assertFalse(os.path.exists(self.log_dir), "the run was set up")

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def test_scenario_that_is_not_yaml(self):
        table = self.table_with_marker()
        self.write("scenario.yaml", "name: broken\nobstacles: [1, 2\n")
        self.assert_rejected(self.run_launcher(table), "--scenario", "scenario.yaml",
                             "not valid YAML: line 3")

    def test_scenario_that_is_empty_or_not_a_mapping(self):
        table = self.table_with_marker()
        self.write("scenario.yaml", "# nothing here\n")
        self.assert_rejected(self.run_launcher(table), "scenario.yaml is empty")
        self.write("scenario.yaml", "- 1\n- 2\n")
        self.assert_rejected(self.run_launcher(table), "top level must be a mapping")

    def test_scenario_that_is_missing_or_a_directory(self):
        table = self.table_with_marker()
        self.scenario = os.path.join(self.dir, "nope.yaml")
        self.assert_rejected(self.run_launcher(table), "--scenario", "nope.yaml not found")
        self.scenario = self.dir
        self.assert_rejected(self.run_launcher(table), "--scenario", "not a regular file")

    @unittest.skipIf(os.geteuid() == 0, "root reads any file")
    def test_scenario_that_is_unreadable(self):
        table = self.table_with_marker()
        os.chmod(self.scenario, 0)
        self.assert_rejected(self.run_launcher(table), "cannot read", "Permission denied")

    def test_config_that_is_not_yaml(self):
        config = self.write("worker.yaml", "rate_hz: 10\ngains: [1, 2\n")
        table = self.table_with_marker(config)
        self.assert_rejected(self.run_launcher(table), "process 'worker'", "field 'config'",
                             "worker.yaml is not valid YAML: line 3")

    def test_config_that_is_not_a_mapping(self):
        table = self.table_with_marker(self.write("worker.yaml", "just a string\n"))
        self.assert_rejected(self.run_launcher(table), "field 'config'",
                             "top level must be a mapping of fields, got a string")

    def test_config_of_comments_only_is_accepted(self):
        table = self.table_with_marker(self.write("worker.yaml", "# all defaults\n"))
        result = self.run_launcher(table, "--timeout", "30")
        # The worker runs and exits 0; nothing else is left, so the run ends.
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertTrue(os.path.exists(self.marker))

    def test_placeholder_without_value(self):
        table = self.table_with_marker()
        self.assert_rejected(self.run_launcher(table, "--lcm-url", ""),
                             "process 'worker'", "{lcm_url} has no value", "--lcm-url")

    def test_missing_bin_directory(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: worker
                host: gcs
                core: 0
                command: ["{bin}/ofn_worker"]
            """)
        self.marker = os.path.join(self.dir, "started")
        self.assert_rejected(self.run_launcher(table, "--bin", os.path.join(self.dir, "no-build")),
                             "--bin: directory", "no-build not found", "make build")

    def test_keyring_without_the_host_key_is_named(self):
        table = self.table_with_marker()
        keyring = os.path.join(self.dir, "keyring")
        os.makedirs(keyring)
        self.write("keyring/policy.yaml", "publishers: {gcs: [X]}\n")
        self.assert_rejected(self.run_launcher(table, "--bus-keys", keyring),
                             "--bus-keys", "gcs.key", "docs/DEPLOYMENT.md")
        self.assert_rejected(self.run_launcher(table, "--bus-keys", os.path.join(self.dir, "none")),
                             "--bus-keys: directory", "ofn_bus_keygen")

    def test_missing_lcm_logger_names_the_debian_package(self):
        table = self.table_with_marker()
        empty = os.path.join(self.dir, "empty-path")
        os.mkdir(empty)
        cmd = [sys.executable, LAUNCHER, "--table", table, "--scenario", self.scenario,
               "--out", self.log_dir, "--no-pin"]
        result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                timeout=60, cwd=REPO_ROOT, env=dict(os.environ, PATH=empty))
        self.assert_rejected(result, "lcm-logger not found", "apt-get install liblcm-bin",
                             "--no-record")
        self.assertNotIn("install lcm)", result.stderr)


class CommandLineTest(LauncherTestCase):
    def test_version_is_the_cmake_project_version(self):
        with open(os.path.join(REPO_ROOT, "CMakeLists.txt")) as f:
            version = re.search(r"project\([^)]*VERSION\s+([0-9.]+)", f.read()).group(1)
        result = subprocess.run([sys.executable, LAUNCHER, "--version"], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, timeout=60)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.strip(), "deploy/launch.py " + version)

    def test_out_and_its_old_spelling_log_dir(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "echo {log_dir}"]
                ends_run: true
            """)
        for option in ("--out", "--log-dir"):
            with self.subTest(option=option):
                results = os.path.join(self.dir, option.strip("-"))
                cmd = [sys.executable, LAUNCHER, "--table", table, "--scenario", self.scenario,
                       option, results, "--no-record", "--no-pin", "--timeout", "30"]
                result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True, timeout=60, cwd=REPO_ROOT)
                self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
                self.assertRegex(result.stdout, r"\[monitor\]\s+" + re.escape(results) + r"\n")
                self.assertEqual(len([d for d in os.listdir(results) if d.startswith("flight-")]), 1)

    def test_usage_error_is_one_line(self):
        for args in (["--scenario", self.scenario, "--rtf"], ["--scenario", self.scenario, "--bogus"],
                     ["--scenario", self.scenario, "--healthy-after", "-1"], []):
            result = subprocess.run([sys.executable, LAUNCHER] + args, stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True, timeout=60)
            self.assertEqual(result.returncode, 2, args)
            self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)

    def test_help_shows_the_healthy_period_default_and_existing_examples(self):
        result = subprocess.run([sys.executable, LAUNCHER, "--help"], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, timeout=60)
        self.assertEqual(result.returncode, 0, result.stderr)
        text = " ".join(result.stdout.split())
        self.assertRegex(text, r"--healthy-after S .*\(default: 30\)")
        self.assertNotIn("hover.yaml", text)
        examples = re.findall(r"--scenario (\S+\.yaml)", text)
        self.assertTrue(examples)
        for path in examples:
            self.assertTrue(os.path.isfile(os.path.join(REPO_ROOT, path)), path)


class CoreClampTest(unittest.TestCase):
    def test_clamps_to_last_core(self):
        ncpu = os.cpu_count()
        self.assertEqual(launch.clamp_core(7, ncpu), min(7, ncpu - 1))
        self.assertEqual(launch.clamp_core(7, 2), 1)
        self.assertEqual(launch.clamp_core(7, 1), 0)

    def test_keeps_existing_core(self):
        self.assertEqual(launch.clamp_core(1, 4), 1)
        self.assertEqual(launch.clamp_core(0, 1), 0)


class SupervisionTest(LauncherTestCase):
    def test_restarts_then_ends_run_exit_code(self):
        # flapper dies at 0.2 s, restarts after 0.5 s and 1 s backoff, then is
        # given up (max 2 restarts); the monitor ends the run with code 4.
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
              onboard1: {cores: [1]}
            processes:
              - name: flapper
                host: onboard1
                core: 1
                command: ["/bin/sh", "-c", "echo flapper up; sleep 0.2; exit 1"]
                restart: true
              - name: monitor
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "sleep 3; echo verdict; exit 4"]
                ends_run: true
            """)
        result = self.run_launcher(table, "--max-restarts", "2", "--timeout", "30")
        out = result.stdout
        self.assertEqual(result.returncode, 4, out + result.stderr)
        self.assertIn("launcher: flapper exited with code 1; restarting in 0.5 s (restart 1/2)", out)
        self.assertIn("launcher: flapper exited with code 1; restarting in 1 s (restart 2/2)", out)
        self.assertRegex(out, r"flapper exited with code 1; GIVING UP after 2 restarts")
        self.assertIn("monitor exited with code 4; it ends the run", out)
        self.assertRegex(out, r"\[flapper\]\s+flapper up")
        self.assertRegex(out, r"\[monitor\]\s+verdict")
        self.assertRegex(out, r"launcher:\s+flapper\s+onboard1\s+restarts 2/2")

        # Output also lands in <log_dir>/<flight stem>/<name>.log.
        runs = [d for d in os.listdir(self.log_dir) if d.startswith("flight-")]
        self.assertEqual(len(runs), 1)
        with open(os.path.join(self.log_dir, runs[0], "flapper.log")) as f:
            lines = f.read().splitlines()
        # One "=== launcher ... start #k" header per start, then the output.
        self.assertEqual(lines.count("flapper up"), 3)
        self.assertEqual(len([l for l in lines if l.startswith("=== launcher")]), 3)

    def test_flight_dir_is_the_flights_own_and_outlives_a_restart(self):
        # What a restarted service resumes from (vehicle_sim's checkpoint)
        # lives in {flight_dir}: the same directory for every start of the
        # flight, a new one for the next flight.
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: saver
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "echo start >> {flight_dir}/state; sleep 0.2; exit 1"]
                restart: true
              - name: monitor
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "sleep 3"]
                ends_run: true
            """)
        for flight in (1, 2):
            result = self.run_launcher(table, "--max-restarts", "2", "--timeout", "30")
            self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        runs = sorted(d for d in os.listdir(self.log_dir) if d.startswith("flight-"))
        self.assertEqual(len(runs), 2)
        for run in runs:
            with open(os.path.join(self.log_dir, run, "state")) as f:
                starts = f.read().split()
            # Restarted at least once within the flight, and each flight's
            # file holds its own starts only (at most 1 + 2 restarts).
            self.assertGreaterEqual(len(starts), 2, run)
            self.assertLessEqual(len(starts), 3, run)

    def test_sleep_ends_run_with_code_zero(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: flapper
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "sleep 0.2; exit 1"]
                restart: true
              - name: monitor
                host: gcs
                core: 0
                command: ["sleep", "1.5"]
                ends_run: true
            """)
        result = self.run_launcher(table, "--max-restarts", "2")
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("restarting in 0.5 s (restart 1/2)", result.stdout)

    def test_timeout_ends_run_and_leaves_no_orphans(self):
        pid_file = os.path.join(self.dir, "sleeper.pid")
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: sleeper
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "echo $$ > %s; exec sleep 60"]
            """ % pid_file)
        start = time.monotonic()
        result = self.run_launcher(table, "--timeout", "1")
        self.assertEqual(result.returncode, 3, result.stdout + result.stderr)
        self.assertIn("run limit of 1 s reached", result.stdout)
        self.assertLess(time.monotonic() - start, 15)
        self.assert_process_gone(pid_file)

    def test_sigint_stops_children(self):
        pid_file = os.path.join(self.dir, "sleeper.pid")
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: sleeper
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "echo $$ > %s; exec sleep 60"]
                restart: true
            """ % pid_file)
        cmd = [sys.executable, LAUNCHER, "--table", table, "--scenario", self.scenario,
               "--out", self.log_dir, "--no-record", "--no-pin"]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            deadline = time.monotonic() + 10
            while not os.path.exists(pid_file) and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(0.2)
            proc.send_signal(signal.SIGINT)
            out, _ = proc.communicate(timeout=15)
        finally:
            if proc.poll() is None:
                proc.kill()
        self.assertEqual(proc.returncode, 128 + signal.SIGINT, out)
        self.assertIn("received SIGINT", out)
        # Stopped by the launcher, not restarted.
        self.assertNotIn("restarting", out)
        self.assertRegex(out, r"sleeper\s+gcs\s+restarts 0/5\s+.*stopped by launcher")
        self.assert_process_gone(pid_file)

    def test_exit_code_2_is_not_restarted_and_ends_the_run(self):
        # A configuration error fails the same way on every restart: the
        # launcher must stop at once, not restart with backoff and then wait
        # for the monitor (60 s here) or the run limit.
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: misconfigured
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "echo 'misconfigured: configuration error: bad field' >&2; exit 2"]
                restart: true
              - name: monitor
                host: gcs
                core: 0
                command: ["sleep", "60"]
                ends_run: true
            """)
        start = time.monotonic()
        result = self.run_launcher(table, "--timeout", "120")
        out = result.stdout
        self.assertEqual(result.returncode, 2, out + result.stderr)
        self.assertLess(time.monotonic() - start, 40, out)
        self.assertNotIn("restarting", out)
        lines = [l for l in out.splitlines() if "misconfigured exited with code 2" in l]
        self.assertEqual(len(lines), 1, out)
        self.assertIn("configuration or usage error", lines[0])
        self.assertIn("not restarted: ending the run (exit code 2)", lines[0])
        self.assertRegex(out, r"monitor\s+gcs\s+restarts -\s+.*stopped by launcher")
        runs = [d for d in os.listdir(self.log_dir) if d.startswith("flight-")]
        with open(os.path.join(self.log_dir, runs[0], "misconfigured.log")) as f:
            self.assertEqual(f.read().count("=== launcher"), 1)

    def test_exit_code_2_of_a_service_without_restart_ends_the_run(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: oneshot
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "exit 2"]
              - name: monitor
                host: gcs
                core: 0
                command: ["sleep", "60"]
                ends_run: true
            """)
        result = self.run_launcher(table, "--timeout", "120")
        self.assertEqual(result.returncode, 2, result.stdout + result.stderr)
        self.assertIn("oneshot exited with code 2, a configuration or usage error", result.stdout)

    def test_other_exit_codes_are_still_restarted(self):
        # Exit code 3 (or a signal) is an ordinary crash.
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: crasher
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "exit 3"]
                restart: true
            """)
        result = self.run_launcher(table, "--max-restarts", "1", "--timeout", "60")
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertIn("crasher exited with code 3; restarting in 0.5 s (restart 1/1)", result.stdout)
        self.assertIn("GIVING UP after 1 restart", result.stdout)

    def test_restart_count_resets_after_a_healthy_period(self):
        # Starts 1, 2, 4 and 5 exit at once; start 3 runs 4 s, well past
        # --healthy-after 1.5.  With --max-restarts 2 and no reset the
        # launcher would give up when start 3 exits; with the reset, start 3
        # earns the budget back and the launcher gives up only after start 5.
        count_file = os.path.join(self.dir, "starts")
        script = os.path.join(self.dir, "flaky.sh")
        with open(script, "w") as f:
            f.write(textwrap.dedent("""\
                #!/bin/sh
                n=$(cat %s 2>/dev/null || echo 0); n=$((n + 1)); echo $n > %s
                echo "flaky start $n"
                [ "$n" -eq 3 ] && sleep 4
                exit 1
                """ % (count_file, count_file)))
        os.chmod(script, 0o755)
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: flaky
                host: gcs
                core: 0
                command: ["%s"]
                restart: true
            """ % script)
        result = self.run_launcher(table, "--max-restarts", "2", "--healthy-after", "1.5",
                                   "--timeout", "100")
        out = result.stdout
        self.assertEqual(result.returncode, 1, out + result.stderr)
        with open(count_file) as f:
            self.assertEqual(f.read().strip(), "5", out)
        self.assertIn("flaky has run 1.5 s since its last restart; restart count reset (0/2)", out)
        restarts = re.findall(r"flaky exited with code 1; restarting in \S+ s \(restart (\d)/2\)", out)
        self.assertEqual(restarts, ["1", "2", "1", "2"], out)
        self.assertIn("GIVING UP after 2 restarts", out)
        self.assertRegex(out, r"flaky\s+gcs\s+restarts 2/2 \(4 in all\)")

    def test_healthy_after_0_keeps_the_budget_for_the_whole_run(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: flaky
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "sleep 0.3; exit 1"]
                restart: true
            """)
        result = self.run_launcher(table, "--max-restarts", "1", "--healthy-after", "0",
                                   "--timeout", "60")
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertNotIn("restart count reset", result.stdout)

    def test_memory_and_cpu_of_each_service_are_sampled(self):
        # One service that grows by 8 MB every 0.3 s and burns CPU, and one
        # that sleeps: resources.csv has both once a second, and the summary
        # shows the first one's growth and the second one's idleness.
        grower = ("import time\n"
                  "blocks = []\n"
                  "end = time.monotonic() + 3.2\n"
                  "while time.monotonic() < end:\n"
                  "    blocks.append(bytearray(8 * 1024 * 1024))\n"
                  "    stop = time.monotonic() + 0.3\n"
                  "    while time.monotonic() < stop:\n"
                  "        pass\n")
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: sleeper
                host: gcs
                core: 0
                command: ["sleep", "60"]
              - name: grower
                host: gcs
                core: 0
                command: ["%s", "-c", %s]
                ends_run: true
            """ % (sys.executable, json.dumps(grower)))
        result = self.run_launcher(table, "--timeout", "30")
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        found = glob.glob(os.path.join(self.log_dir, "*", "resources.csv"))
        self.assertEqual(len(found), 1, result.stdout)
        with open(found[0]) as f:
            rows = list(csv.DictReader(f))
        by_service = {}
        for row in rows:
            by_service.setdefault(row["service"], []).append(row)
        self.assertEqual(set(by_service), {"sleeper", "grower"})
        grown = [float(r["rss_mb"]) for r in by_service["grower"]]
        self.assertGreaterEqual(len(grown), 3)
        self.assertGreater(grown[-1] - grown[0], 40.0, grown)
        grower_cpu = [float(r["cpu_s"]) for r in by_service["grower"]]
        self.assertGreater(grower_cpu[-1] - grower_cpu[0], 1.0, grower_cpu)
        sleeper_cpu = [float(r["cpu_s"]) for r in by_service["sleeper"]]
        self.assertLess(sleeper_cpu[-1] - sleeper_cpu[0], 0.1, sleeper_cpu)
        self.assertRegex(result.stdout, r"grower .*; rss \d+\.\d MB \(peak \d+\.\d\), cpu \d+ %")
        # The sleeper's first sample may fall before its exec is done, so the
        # start-up of a loaded machine can show as a per cent or two.
        idle = re.search(r"sleeper .*; rss \d+\.\d MB \(peak \d+\.\d\), cpu (\d+) %", result.stdout)
        self.assertIsNotNone(idle, result.stdout)
        self.assertLessEqual(int(idle.group(1)), 3, result.stdout)
        self.assertIn("resources.csv", result.stdout)

    def test_proc_resources_of_a_process_that_is_gone(self):
        proc = subprocess.Popen(["true"])
        proc.wait()
        self.assertIsNone(launch.read_proc_resources(proc.pid))
        rss, cpu_s = launch.read_proc_resources(os.getpid())
        self.assertGreater(rss, 1e6)
        self.assertGreaterEqual(cpu_s, 0.0)

    def assert_process_gone(self, pid_file):
        with open(pid_file) as f:
            pid = int(f.read().strip())
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return
        os.kill(pid, signal.SIGKILL)
        self.fail("child process %d outlived the launcher" % pid)



class HangWatchTest(unittest.TestCase):
    """The watchdog's decisions, with given times and heartbeats."""

    def watch(self, timeout=5.0, rtf=1.0, groups=None):
        groups = groups or {}
        watch = launch.HangWatch(timeout, rtf, start_allowance=10.0, probe_silence=3.0,
                                 group_of=lambda pid: groups.get(pid))
        return watch

    @staticmethod
    def beat(watch, name, pid, stamp, now):
        watch.heard(launch.heartbeat_channel(name), pid, stamp, now)

    def test_an_own_clock_process_silent_for_the_timeout_is_hung(self):
        watch = self.watch()
        watch.started("vehicle_sim", "own", 100, 0.0)
        for t in range(11):
            self.beat(watch, "vehicle_sim", 100, float(t), float(t))
        for t in range(11, 16):
            watch.tick(float(t))
        self.assertIsNone(watch.verdict("vehicle_sim", 14.9))
        why = watch.verdict("vehicle_sim", 15.0)
        self.assertEqual(why, "no heartbeat on HEARTBEAT_VEHICLE_SIM for 5.0 s")

    def test_a_slow_simulation_master_gets_its_heartbeat_period(self):
        # At half real time its heartbeats come 2 s apart: 10 s of silence
        # is 5 s of its time.
        watch = self.watch(rtf=0.5)
        watch.started("vehicle_sim", "own", 100, 0.0)
        self.beat(watch, "vehicle_sim", 100, 0.0, 0.0)
        for t in range(1, 11):
            watch.tick(float(t))
        self.assertIsNone(watch.verdict("vehicle_sim", 9.9))
        self.assertIsNotNone(watch.verdict("vehicle_sim", 10.0))

    def test_followers_are_not_hung_while_the_simulation_stands_still(self):
        # vehicle_sim stopped: every follower falls silent with it. Only the
        # master counts as hung; the followers would all be killed otherwise.
        watch = self.watch()
        watch.started("vehicle_sim", "own", 100, 0.0)
        watch.started("mapper", "sim_clock", 200, 0.0)
        for t in range(6):
            self.beat(watch, "vehicle_sim", 100, float(t), float(t))
            self.beat(watch, "mapper", 200, float(t), float(t) + 0.01)
        for t in range(6, 60):
            watch.tick(float(t))
        self.assertIsNotNone(watch.verdict("vehicle_sim", 59.0))
        self.assertIsNone(watch.verdict("mapper", 59.0))

    def test_a_follower_silent_while_the_simulation_runs_on_is_hung(self):
        watch = self.watch()
        watch.started("controller", "sim_clock", 300, 0.0)
        watch.started("mapper", "sim_clock", 200, 0.0)
        for t in range(4):
            self.beat(watch, "mapper", 200, float(t), float(t))
            self.beat(watch, "controller", 300, float(t), float(t))
        # The mapper stops at 3 s; the controller's heartbeats go on.
        verdicts = {}
        for t in range(4, 12):
            self.beat(watch, "controller", 300, float(t), float(t))
            verdicts[t] = watch.verdict("mapper", float(t))
            self.assertIsNone(watch.verdict("controller", float(t)))
        self.assertEqual([t for t, v in verdicts.items() if v is None], [4, 5, 6, 7])
        self.assertEqual(verdicts[8], "no heartbeat on HEARTBEAT_MAPPER for 5.0 s while the "
                                      "simulation ran 5.0 s on")

    def test_a_follower_at_a_fast_simulation_waits_for_the_wall_time_too(self):
        # At 4x real time 5 s of simulation pass in 1.25 s: a step that
        # blocks 1.5 s is no hang.
        watch = self.watch(rtf=4.0)
        watch.started("controller", "sim_clock", 300, 0.0)
        watch.started("mapper", "sim_clock", 200, 0.0)
        self.beat(watch, "mapper", 200, 10.0, 0.0)
        hung_at = None
        for i in range(1, 40):
            self.beat(watch, "controller", 300, 10.0 + i, i * 0.25)
            if hung_at is None and watch.verdict("mapper", i * 0.25) is not None:
                hung_at = i * 0.25
        # 5 s of simulation were over at 1.25 s; 5 s of wall time at 5 s.
        self.assertEqual(hung_at, 5.0)

    def test_heartbeats_of_another_process_do_not_count_those_of_its_group_do(self):
        # Pid 555 is the previous instance (still on the way after a
        # restart); pid 201 a process in the new instance's group 200.
        watch = self.watch(groups={201: 200, 555: 555})
        watch.started("mapper", "own", 200, 0.0)
        for t in range(1, 30):
            self.beat(watch, "mapper", 555, float(t), float(t))
        self.assertIsNotNone(watch.verdict("mapper", 15.0))
        watch.started("mapper", "own", 200, 20.0)
        for t in range(20, 30):
            self.beat(watch, "mapper", 201, float(t), float(t))
        for t in range(30, 35):
            watch.tick(float(t))
        self.assertIsNone(watch.verdict("mapper", 33.9))
        self.assertIsNotNone(watch.verdict("mapper", 34.0))

    def test_a_strangers_heartbeats_neither_condemn_nor_save(self):
        # A stranger's heartbeats, stamped 2^63 us ahead, on a service's
        # channel and on one of its own: no evidence that the simulation ran
        # on (the mapper, silent with the simulation, is not hung) and no
        # sign of life (the controller, silent while vehicle_sim runs on, is).
        watch = self.watch(groups={999: 999})
        watch.started("vehicle_sim", "own", 100, 0.0)
        watch.started("mapper", "sim_clock", 200, 0.0)
        watch.started("controller", "sim_clock", 300, 0.0)
        self.beat(watch, "mapper", 200, 1.0, 1.0)
        self.beat(watch, "controller", 300, 1.0, 1.0)
        self.beat(watch, "vehicle_sim", 100, 1.0, 1.0)
        for t in range(2, 20):
            for name in ("mapper", "controller", "fuzz"):
                self.beat(watch, name, 999, 9.2e12, float(t))
        self.assertIsNone(watch.verdict("mapper", 19.0))
        self.assertIsNone(watch.verdict("controller", 19.0))
        self.assertIsNotNone(watch.verdict("vehicle_sim", 19.0))  # its own clock: silence is enough
        for t in range(20, 30):
            self.beat(watch, "vehicle_sim", 100, float(t - 18), float(t))
            self.beat(watch, "controller", 999, 9.2e12, float(t))
        self.assertEqual(watch.verdict("controller", 29.0),
                         "no heartbeat on HEARTBEAT_CONTROLLER for 28.0 s while the simulation "
                         "ran 10.0 s on")

    def test_a_process_never_heard_gets_the_start_allowance(self):
        watch = self.watch()
        watch.started("mapper", "own", 200, 0.0)
        for t in range(1, 20):
            watch.tick(float(t))
        self.assertIsNone(watch.verdict("mapper", 14.9))
        self.assertEqual(watch.verdict("mapper", 15.0),
                         "no heartbeat on HEARTBEAT_MAPPER in the 15.0 s since its start")

    def test_a_follower_never_heard_is_hung_once_the_simulation_ran_on(self):
        watch = self.watch()
        watch.started("vehicle_sim", "own", 100, 0.0)
        watch.started("mapper", "sim_clock", 200, 0.0)
        # Nothing runs for 20 s (the simulator loads), then it does.
        for t in range(20):
            watch.tick(float(t))
        self.assertIsNone(watch.verdict("mapper", 19.0))
        hung_at = None
        for t in range(20, 30):
            self.beat(watch, "vehicle_sim", 100, float(t - 20), float(t))
            if hung_at is None and watch.verdict("mapper", float(t)) is not None:
                hung_at = t
        # From the first stamp heard after its start (0 s at 20 s): 5 s of it.
        self.assertEqual(hung_at, 25)

    def test_a_deaf_watch_judges_nobody(self):
        watch = self.watch()
        watch.started("vehicle_sim", "own", 100, 0.0)
        self.beat(watch, "vehicle_sim", 100, 0.0, 0.0)
        watch.tick(10.0)
        self.assertIsNotNone(watch.verdict("vehicle_sim", 12.0))
        # The probe's last tick 3.5 s ago: it may be the one that hangs.
        self.assertIsNone(watch.verdict("vehicle_sim", 13.5))
        self.assertIsNone(watch.verdict("unknown", 12.0))

    def test_bad_arguments_are_refused(self):
        with self.assertRaises(ValueError):
            launch.HangWatch(0.0)
        with self.assertRaises(ValueError):
            launch.HangWatch(5.0).started("x", "wall", 1, 0.0)

    def test_probe_lines(self):
        watch = self.watch()
        watch.started("mapper", "own", 200, 0.0)
        sink = launch.probe_line_sink(watch, clock=lambda: 1.0)
        self.assertTrue(sink(b"tick\n"))
        self.assertTrue(sink(b"heartbeat HEARTBEAT_MAPPER 200 2500000\n"))
        self.assertFalse(sink(b"heartbeat HEARTBEAT_MAPPER x 1\n"))
        self.assertFalse(sink(b"refused 1 heartbeat message(s) so far; the last: ...\n"))
        # Heard at 1.0 s: hung 5 s later.
        watch.tick(6.0)
        self.assertIsNone(watch.verdict("mapper", 5.9))
        self.assertIsNotNone(watch.verdict("mapper", 6.0))

    def test_the_heartbeat_channel_is_the_services(self):
        self.assertEqual(launch.heartbeat_channel("rh_optimizer"), "HEARTBEAT_RH_OPTIMIZER")


class HangSupervisionTest(LauncherTestCase):
    """The launcher with a stand-in probe that reports what a script says."""

    def fake_probe(self, script_body):
        bin_dir = os.path.join(self.dir, "bin")
        os.makedirs(bin_dir, exist_ok=True)
        path = os.path.join(bin_dir, "ofn_heartbeat_probe")
        with open(path, "w") as f:
            f.write("#!/bin/sh\n" + textwrap.dedent(script_body))
        os.chmod(path, 0o755)
        return bin_dir

    def test_project_table_watches_every_service_but_the_monitor(self):
        table = launch.load_table(REAL_TABLE)
        kinds = {p.name: p.heartbeat for p in table.processes}
        self.assertEqual(kinds.pop("vehicle_sim"), "own")
        self.assertIsNone(kinds.pop("flight_monitor"))
        self.assertEqual(set(kinds.values()), {"sim_clock"})

    def test_unknown_heartbeat_kind_is_named(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: worker
                host: gcs
                core: 0
                command: ["sleep", "1"]
                heartbeat: wall
            """)
        with self.assertRaisesRegex(launch.TableError,
                                    r"worker.*field 'heartbeat' must be one of own, sim_clock"):
            launch.load_table(table)

    def test_a_watched_table_needs_the_probe_unless_the_watch_is_off(self):
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: worker
                host: gcs
                core: 0
                command: ["sleep", "0.5"]
                heartbeat: own
                ends_run: true
            """)
        result = self.run_launcher(table, "--bin", self.dir)
        self.assertEqual(result.returncode, 2, result.stdout + result.stderr)
        self.assertIn("--hang-timeout: %s/ofn_heartbeat_probe not found" % self.dir, result.stderr)
        self.assertIn("--hang-timeout 0", result.stderr)
        result = self.run_launcher(table, "--bin", self.dir, "--hang-timeout", "0")
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("no hang watch (--hang-timeout 0)", result.stdout)

    def test_negative_hang_timeout_is_a_usage_error(self):
        result = self.run_launcher(self.write_table(TableValidationTest.GOOD_TABLE),
                                   "--hang-timeout", "-1")
        self.assertEqual(result.returncode, 2)
        self.assertIn("--hang-timeout must be >= 0", result.stderr)

    def test_a_silent_process_is_killed_as_hung_and_restarted(self):
        # The stand-in service ignores SIGTERM (so the SIGKILL is needed) and
        # writes its pid; the stand-in probe reports its heartbeats for its
        # first six ticks (1.5 s) after it reads a new pid, then only ticks.
        # Counting ticks from the probe's own first sight of the pid, not
        # seconds from the file's time, keeps the heartbeats coming however
        # late a loaded machine runs the probe. A process without a
        # heartbeat field beside it is never touched.
        pid_file = os.path.join(self.dir, "worker.pid")
        bin_dir = self.fake_probe("""\
            i=0
            seen=
            beats=0
            while :; do
              echo tick
              pid=$(cat %s 2>/dev/null)
              if [ -n "$pid" ] && [ "$pid" != "$seen" ]; then
                seen=$pid
                beats=6
              fi
              if [ "$beats" -gt 0 ]; then
                echo "heartbeat HEARTBEAT_WORKER $pid $i"
                beats=$((beats - 1))
              fi
              i=$((i + 250000))
              sleep 0.25
            done
            """ % pid_file)
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: worker
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "trap '' TERM; echo $$ > %s; exec sleep 60"]
                restart: true
                heartbeat: own
              - name: quiet
                host: gcs
                core: 0
                command: ["sleep", "60"]
                restart: true
            """ % pid_file)
        start = time.monotonic()
        result = self.run_launcher(table, "--bin", bin_dir, "--hang-timeout", "1.5",
                                   "--timeout", "12")
        out = result.stdout
        self.assertEqual(result.returncode, 3, out + result.stderr)
        self.assertLess(time.monotonic() - start, 40)
        self.assertIn("hang watch: worker (own), 1.5 s without a heartbeat", out)
        hung = re.findall(r"worker is HUNG \(no heartbeat on HEARTBEAT_WORKER for (\S+) s\)", out)
        self.assertGreaterEqual(len(hung), 1, out)
        # A restart the run limit cuts short may still be in its start
        # allowance; every HUNG line is one in the summary's count.
        hung_lines = re.findall(r"worker is HUNG \(", out)
        self.assertIn("worker still there 2 s after SIGTERM; sending SIGKILL", out)
        self.assertRegex(out, r"worker exited with code 137 \(signal SIGKILL\) after it hung; "
                              r"restarting in 0\.5 s \(restart 1/5\)")
        self.assertRegex(out, r"worker\s+gcs\s+restarts \d/5( \(\d in all\))?, hung %d\s"
                         % len(hung_lines))
        self.assertNotIn("quiet is HUNG", out)
        self.assertRegex(out, r"quiet\s+gcs\s+restarts 0/5\s+.*stopped by launcher")
        # The probe's lines are the watch's, not the log's.
        runs = [d for d in os.listdir(self.log_dir) if d.startswith("flight-")]
        with open(os.path.join(self.log_dir, runs[0], "ofn_heartbeat_probe.log")) as f:
            self.assertNotIn("heartbeat HEARTBEAT_WORKER", f.read())

    def test_a_probe_that_dies_is_reported_and_nobody_is_killed(self):
        bin_dir = self.fake_probe("echo tick; exit 1\n")
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: worker
                host: gcs
                core: 0
                command: ["sleep", "60"]
                restart: true
                heartbeat: own
            """)
        result = self.run_launcher(table, "--bin", bin_dir, "--hang-timeout", "0.5",
                                   "--timeout", "5")
        out = result.stdout
        self.assertEqual(result.returncode, 3, out + result.stderr)
        self.assertIn("WARNING: ofn_heartbeat_probe exited with code 1; hung services are no "
                      "longer found", out)
        self.assertNotIn("is HUNG", out)

    def test_a_hung_process_that_ends_the_run_ends_it_as_a_failure(self):
        bin_dir = self.fake_probe("while :; do echo tick; sleep 0.2; done\n")
        table = self.write_table("""\
            hosts:
              gcs: {cores: [0]}
            processes:
              - name: monitor
                host: gcs
                core: 0
                command: ["/bin/sh", "-c", "trap 'exit 0' TERM; while :; do sleep 0.1; done"]
                ends_run: true
                heartbeat: own
            """)
        result = self.run_launcher(table, "--bin", bin_dir, "--hang-timeout", "0.5",
                                   "--timeout", "60")
        out = result.stdout
        # It exits 0 on SIGTERM; that is no verdict.
        self.assertEqual(result.returncode, 1, out + result.stderr)
        self.assertIn("monitor exited with code 0 after it hung; it ends the run (exit code 1)",
                      out)


if __name__ == "__main__":
    unittest.main()
