"""The README's command examples, as written.

Every `sh` block of README.md is read. The examples that work on files
(`build/bin/...` programs and the plotting script) are run in order, in a
scratch folder that links the repository's folders and the build, with
the README's placeholders filled in from the examples run before them
(`FILE.lcm` is the log the lockstep example wrote, `DIR` a new folder);
each must exit 0. The others start flights on the bus, a browser or
lcm-spy, or are `make` targets; for those the program or target must exist
and every option the example names must be in the program's `--help`.

Run from the repository root, with the build folder in OFN_BUILD_DIR
(default `build`):
    /usr/bin/python3 -m unittest tests/integration/test_readme_examples.py
"""

import os
import re
import shlex
import subprocess
import tempfile
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD_DIR = os.path.abspath(os.environ.get("OFN_BUILD_DIR", os.path.join(REPO_ROOT, "build")))
LINKED = ("bench", "config", "deploy", "lcmtypes", "services", "sim", "Makefile")

# What the README writes for a value the reader supplies, and what stands
# in for it here: the lockstep example's log, its course, a new folder.
PLACEHOLDERS = {
    "FILE.lcm": "results/lockstep/flight.lcm",
    "DIR": "report",
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


def runs_on_files(command):
    return command.startswith("build/bin/") or command.startswith(
        "/usr/bin/python3 services/tools/")


def named_options(command):
    """The long options an example names, optional ones in [...] included."""
    return sorted(set(re.findall(r"(--[a-z][a-z0-9-]*)", command)))


def program_of(command):
    return shlex.split(command.replace("[", " ").replace("]", " "))[0]


class ReadmeExamples(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(os.path.join(REPO_ROOT, "README.md")) as f:
            cls.commands = readme_commands(f.read())

    def test_the_readme_has_examples_of_both_kinds(self):
        self.assertGreaterEqual(sum(runs_on_files(c) for c in self.commands), 4, self.commands)
        self.assertGreaterEqual(sum(not runs_on_files(c) for c in self.commands), 4, self.commands)

    def test_file_examples_run_as_written(self):
        with tempfile.TemporaryDirectory(prefix="ofn-readme-") as scratch:
            for name in LINKED:
                os.symlink(os.path.join(REPO_ROOT, name), os.path.join(scratch, name))
            os.symlink(BUILD_DIR, os.path.join(scratch, "build"))
            ran = 0
            for command in self.commands:
                if not runs_on_files(command):
                    continue
                for placeholder, value in PLACEHOLDERS.items():
                    command = re.sub(r"(?<![\w/.-])" + re.escape(placeholder) + r"(?![\w/.-])",
                                     value, command)
                with self.subTest(command=command):
                    result = subprocess.run(command, shell=True, cwd=scratch, text=True,
                                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                            timeout=300)
                    self.assertEqual(result.returncode, 0,
                                     f"{command}\n{result.stdout[-3000:]}")
                    ran += 1
            self.assertGreaterEqual(ran, 4)
            # What the examples say they make.
            for made in ("results/lockstep/summary.txt", "run1/replay", "report/flight.png",
                         "report/tracking.png"):
                self.assertTrue(os.path.exists(os.path.join(scratch, made)), made)

    def test_bus_and_make_examples_name_real_programs_and_options(self):
        with open(os.path.join(REPO_ROOT, "Makefile")) as f:
            makefile = f.read()
        targets = set(re.findall(r"^([a-z][a-z-]*):", makefile, re.M))
        checked = 0
        for command in self.commands:
            if runs_on_files(command):
                continue
            with self.subTest(command=command):
                if command.startswith("make "):
                    target = command.split()[1]
                    self.assertIn(target, targets)
                    for variable in re.findall(r"\b([A-Z][A-Z0-9_]*)=", command):
                        self.assertIn(f"$({variable})", makefile, f"make {target} {variable}=")
                    checked += 1
                    continue
                program = program_of(command)
                path = os.path.join(REPO_ROOT, program)
                self.assertTrue(os.access(path, os.X_OK), f"{program} is not an executable")
                result = subprocess.run([path, "--help"], cwd=REPO_ROOT, text=True,
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        timeout=60)
                self.assertEqual(result.returncode, 0, result.stdout)
                for option in named_options(command):
                    self.assertIn(option, result.stdout, f"{program} --help lacks {option}")
                checked += 1
        self.assertGreaterEqual(checked, 4)


if __name__ == "__main__":
    unittest.main()
