"""What the project's Python programs share on their command lines.

Imported by every Python entry point (deploy/launch.py, bench/*.py,
services/tools/plot_flight.py, examples/python/nav_track.py); it uses
only the standard library, so --help, --version and the argument checks
work on a machine without PyYAML, numpy or matplotlib.

- project_version(): the version in the top-level CMakeLists.txt.
- ArgumentParser: argparse with one-line usage errors (exit code 2),
  the description and epilog shown as written, and --version.
- need(name): a third-party module imported when first needed; when it
  cannot be, MissingModule names the Debian package.
- InputError: a missing or unusable input file; one line, exit code 2.
- run_main(prog, main): sys.exit(main()), with MissingModule and
  InputError reported in one line (exit code 2) and Ctrl-C as 130.
- add_bin_option() / bin_dir(): `--bin DIR`, the folder of the programs,
  with the bench scripts' old `--build DIR` still accepted.

Option names are the same in every script: `--bin DIR` the folder of the
programs (default build/bin), `--out DIR` where results go, `--timeout S`
a wall-clock limit, `--rtf X` the real-time factor, `--scenario FILE`,
`--config-dir DIR`. (The lockstep runner's `--max-time S` is simulated
time, a different quantity.)
"""
import argparse
import importlib
import os
import re
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_BIN = os.path.join(REPO, "build", "bin")

EXIT_USAGE = 2
DEBIAN_PACKAGES = {"yaml": "python3-yaml", "numpy": "python3-numpy",
                   "matplotlib": "python3-matplotlib", "PIL": "python3-pil"}


class MissingModule(Exception):
    """A third-party module a task needs cannot be imported; exit code 2."""


class InputError(Exception):
    """A missing or unusable input (a file, a folder, a column); exit code 2."""


def need(name):
    """The module `name`, imported now; MissingModule when it cannot be."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        missing = (getattr(exc, "name", None) or name).split(".")[0]
        package = DEBIAN_PACKAGES.get(missing, DEBIAN_PACKAGES.get(name.split(".")[0]))
        raise MissingModule("the Python module %s is needed but cannot be imported (%s)%s"
                            % (missing, " ".join(str(exc).split()),
                               "; Debian: apt-get install %s" % package if package else ""))


def project_version():
    """The project's version, defined in one place: project(... VERSION x.y.z)
    in the top-level CMakeLists.txt."""
    try:
        with open(os.path.join(REPO, "CMakeLists.txt"), encoding="utf-8") as f:
            match = re.search(r"^\s*project\s*\([^)]*\bVERSION\s+([0-9][0-9A-Za-z.+-]*)", f.read(),
                              re.MULTILINE | re.IGNORECASE)
    except OSError:
        match = None
    return match.group(1) if match else "unknown"


class ArgumentParser(argparse.ArgumentParser):
    """argparse with one-line usage errors (exit code 2), the description and
    epilog shown as written, and --version."""

    def __init__(self, prog, description, epilog=None):
        super().__init__(prog=prog, description=description, epilog=epilog,
                         formatter_class=argparse.RawDescriptionHelpFormatter)
        self.add_argument("--version", action="version", version="%(prog)s " + project_version())

    def error(self, message):
        self.exit(EXIT_USAGE, "%s: error: %s (see --help)\n" % (self.prog, message))


def add_bin_option(parser, what="the ofn_* programs"):
    """--bin DIR, the folder of the programs (default build/bin), and the
    bench scripts' old spelling `--build DIR` (programs in DIR/bin), hidden
    from the help and still accepted; resolve them with bin_dir()."""
    parser.add_argument("--bin", metavar="DIR",
                        help="folder of %s (default: build/bin)" % what)
    parser.add_argument("--build", dest="build_dir", metavar="DIR", help=argparse.SUPPRESS)


def bin_dir(parser, args):
    """The absolute folder of the programs from --bin DIR or the old
    --build DIR (DIR/bin); both at once is a usage error."""
    if getattr(args, "build_dir", None):
        if args.bin:
            parser.error("--build DIR is the old spelling of --bin DIR/bin: give one of them")
        return os.path.abspath(os.path.join(os.path.expanduser(args.build_dir), "bin"))
    return os.path.abspath(os.path.expanduser(args.bin or DEFAULT_BIN))


def run_main(prog, main):
    """sys.exit(main()), with a missing module or input reported in one line
    (exit code 2)."""
    try:
        code = main()
    except (MissingModule, InputError) as exc:
        sys.stderr.write("%s: error: %s\n" % (prog, exc))
        code = EXIT_USAGE
    except KeyboardInterrupt:
        sys.stderr.write("%s: interrupted\n" % prog)
        code = 130
    sys.exit(code)
