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


if __name__ == "__main__":
    unittest.main()
