"""Tests of deploy/launch.py: table validation, core clamping, supervision.

Needs no network and no LCM: every run uses --no-record and --no-pin and
small shell commands in place of the flight services.

Run from the repository root:
    /usr/bin/python3 -m unittest tests/integration/test_launcher_table.py
"""

import importlib.util
import os
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
            f.write("# dummy scenario\n")
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
               "--log-dir", self.log_dir, "--no-record", "--no-pin"] + list(extra)
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

    def test_selection_by_host_and_only(self):
        table = launch.load_table(self.write_table(self.GOOD_TABLE))
        self.assertEqual([p.name for p in launch.select_processes(table, host="gcs")], ["monitor"])
        self.assertEqual([p.name for p in launch.select_processes(table, only=["worker"])],
                         ["worker"])


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
               "--log-dir", self.log_dir, "--no-record", "--no-pin"]
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
