"""bench/monte_carlo.py keeps what it has flown: each field's record goes to
OUT/fields.jsonl as it finishes, and Ctrl-C (SIGINT to its process group, as
a terminal sends it) stops the fields under way, drops those not begun,
writes the report of the finished ones, says so, and exits 130.

No build needed: a stand-in ofn_sim_runner writes a summary.json and, for
every field after the first, sleeps long enough for the interrupt to land.
Needs Debian's /usr/bin/python3 with PyYAML, numpy and matplotlib (the
report's). Run from the repository root:
    /usr/bin/python3 -m unittest -v tests/integration/test_monte_carlo_interrupt.py
"""

import json
import os
import signal
import stat
import subprocess
import tempfile
import textwrap
import time
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# The stand-in: the first field it flies finishes at once, the others take
# a minute (the interrupt ends them). Its summary is a hover short of
# nothing: a success within every rule.
RUNNER = r"""#!/usr/bin/python3
import json, os, sys, time
args = sys.argv[1:]
out = args[args.index("--out") + 1]
os.makedirs(out, exist_ok=True)
marker = os.path.join(os.path.dirname(os.path.dirname(out)), "first-done")
if os.path.exists(marker):
    time.sleep(60)
summary = {"success": True, "outcome": "success", "failures": [], "gate_to_gate": 41.0,
           "reached_last_waypoint": True, "min_clearance": 7.0, "clearance_required": 6.096,
           "max_speed": 3.0, "display_unit": "ft", "metres_per_unit": 0.3048}
with open(os.path.join(out, "summary.json"), "w") as f:
    json.dump(summary, f)
open(marker, "w").close()
"""


class InterruptedMonteCarlo(unittest.TestCase):
    def test_ctrl_c_reports_the_fields_that_finished(self):
        with tempfile.TemporaryDirectory(prefix="ofn-mc-interrupt-") as tmp:
            bin_dir = os.path.join(tmp, "bin")
            os.makedirs(bin_dir)
            runner = os.path.join(bin_dir, "ofn_sim_runner")
            with open(runner, "w") as f:
                f.write(RUNNER)
            os.chmod(runner, os.stat(runner).st_mode | stat.S_IXUSR)
            out = os.path.join(tmp, "out")
            proc = subprocess.Popen(
                ["/usr/bin/python3", os.path.join(REPO_ROOT, "bench", "monte_carlo.py"),
                 "--dense", "--seeds", "1,2,3,4", "--jobs", "1", "--bin", bin_dir, "--out", out],
                cwd=REPO_ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                start_new_session=True)
            jsonl = os.path.join(out, "fields.jsonl")
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline and proc.poll() is None:
                if os.path.isfile(jsonl):
                    with open(jsonl) as f:
                        if f.read().count("\n") >= 1:
                            break
                time.sleep(0.2)
            self.assertIsNone(proc.poll(), "monte_carlo ended before the interrupt")
            time.sleep(1.0)  # the second field's stand-in is asleep now
            os.killpg(proc.pid, signal.SIGINT)
            stdout, stderr = proc.communicate(timeout=120)
            self.assertEqual(proc.returncode, 130, stdout + stderr)
            self.assertIn("interrupted: 1 of 4 fields had finished", stderr)
            self.assertNotIn("Traceback", stderr)
            with open(jsonl) as f:
                records = [json.loads(line) for line in f]
            self.assertEqual([r["seed"] for r in records], [1])
            with open(os.path.join(out, "results.json")) as f:
                doc = json.load(f)
            self.assertTrue(doc["interrupted"])
            self.assertEqual(doc["seeds_flown"], [1])
            self.assertEqual(doc["runs"], 1)
            with open(os.path.join(out, "report.md")) as f:
                report = f.read()
            self.assertIn("**interrupted**: 1 of the 4 fields had finished", report)


if __name__ == "__main__":
    unittest.main()
