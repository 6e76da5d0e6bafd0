#!/usr/bin/python3
"""Start, supervise and record the flight-software services of one run.

Reads the process table (deploy/processes.yaml), starts lcm-logger and then
every selected service in table order, pins each to its host's CPU core,
restarts crashed services with exponential backoff, and stops everything
cleanly when the run ends (ends_run process exits, a service exits with
code 2, --timeout, Ctrl-C or SIGTERM).

Before anything starts, the process table, the scenario and every selected
service's config file are read and parsed as YAML, the command placeholders
are filled in and the executables looked up; the first problem found is
reported in one line and nothing is started.

A service that exits with code 2 reports a configuration or usage error
(services/common/src/service_main.cpp, guarded_main): restarting it cannot
help, so the launcher ends the run at once instead.  Other exits of a
restart: true service are restarted up to --max-restarts times in a row;
a service that then runs --healthy-after seconds gets its budget back.

A service that hangs does not exit.  For the processes whose table entry
names how their heartbeats come (heartbeat: own or sim_clock), the launcher
listens to the heartbeats (through ofn_heartbeat_probe, which prints one
line per heartbeat; LCM has no Python bindings on Debian) and takes a
process whose heartbeats stop for --hang-timeout seconds as hung (HangWatch):
SIGTERM, SIGKILL after a grace, and its exit then goes the way of any other.

Each service's output goes to the terminal prefixed with [name] and to
<out>/<flight-stem>/<name>.log; the LCM traffic goes to
<out>/<flight-stem>.lcm, whose path is also written to <out>/latest_log
(--out DIR, the results folder; --log-dir DIR is its old spelling).

Exit codes: the ends_run process's exit code when it ends the run; 2 for bad
input (arguments, table, scenario or config files, missing executables) and
when a service exits with code 2; 3 when --timeout ends the run; 128+N when
stopped by signal N; 1 when the launcher could not run (e.g. lcm-logger
failed) or every service stopped without an ends_run process.

Only the Python standard library and PyYAML are used so that the launcher
runs unchanged on the onboard computers (Debian: python3-yaml).  PyYAML is
imported when first needed, so --help and --version work without it; the
command-line helpers are those every Python entry point shares
(services/tools/ofn_cli.py, in the same checkout).
"""

import datetime
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO_ROOT, "services", "tools"))
import ofn_cli  # noqa: E402
DEFAULT_TABLE = os.path.join(REPO_ROOT, "deploy", "processes.yaml")
DEFAULT_BIN = os.path.join(REPO_ROOT, "build", "bin")
DEFAULT_LOG_DIR = os.path.join(REPO_ROOT, "results")
FALLBACK_LCM_URL = "udpm://239.255.76.67:7667?ttl=0"

EXIT_BAD_INPUT = 2
EXIT_TIMEOUT = 3
EXIT_LAUNCHER_FAILURE = 1
# What a service returns for a configuration or usage error (guarded_main in
# services/common/src/service_main.cpp).  The same input fails the same way
# on every restart, so such an exit is never restarted: it ends the run.
EXIT_SERVICE_CONFIG_ERROR = 2

# A service that has run this long since its last restart is healthy again:
# its restart count starts over (--healthy-after).
DEFAULT_HEALTHY_AFTER_S = 30.0

# Restart backoff: 0.5 s, 1 s, 2 s, 4 s, 8 s, 8 s, ...  Short enough that a
# flaky service is back quickly, long enough that a service crashing at
# start-up does not spin the CPU the controller shares.
BACKOFF_START_S = 0.5
BACKOFF_CAP_S = 8.0

# Time each group of children gets to exit after SIGINT before SIGKILL.
STOP_GRACE_S = 3.0

# The hung-process watchdog (--hang-timeout, HangWatch). A service sends a
# heartbeat once a second of its clock; five missed ones is a hang, not a
# slow step (the longest planning step is a fraction of a second).
DEFAULT_HANG_TIMEOUT_S = 5.0
# A hung process gets SIGTERM, then SIGKILL this much later. A stopped
# (SIGSTOP) process cannot act on SIGTERM; the SIGKILL ends it.
HANG_KILL_GRACE_S = 2.0
# A process not heard since its start gets this much longer: its start-up
# (loading a scenario, a map) comes before its first heartbeat.
HANG_START_ALLOWANCE_S = 10.0
# The probe prints "tick" once a second; if it is not heard from for this
# long the watchdog is deaf and judges nobody.
PROBE_SILENCE_S = 3.0
PROBE_PROGRAM = "ofn_heartbeat_probe"
# How a process's heartbeats come (the table's heartbeat field).
HEARTBEAT_KINDS = ("own", "sim_clock")

# The ends_run process receives the same {timeout}; the launcher waits this
# much longer so that the monitor's own timeout verdict wins the race against
# the launcher's hard limit.
ENDS_RUN_TIMEOUT_GRACE_S = 5.0

# Time lcm-logger gets to join the multicast group before services publish.
LOGGER_SETTLE_S = 0.5

POLL_INTERVAL_S = 0.05

# Once a second each service's resident memory and CPU time are read from
# /proc and written to resources.csv: a leak shows as RSS that keeps growing
# over a long flight. Memory is compared from this long after a start to the
# end: in a ten-minute flight the mapper's map and the optimiser's field
# reach their working size within the first minute (mapper 6 -> 30 MB), then
# grow by less than 1 MB.
RESOURCE_PERIOD_S = 1.0
RESOURCE_SETTLE_S = 60.0

PLACEHOLDERS = ("bin", "scenario", "rtf", "lcm_url", "timeout", "log_dir", "flight_dir")
# The option that sets each placeholder, for error messages.
PLACEHOLDER_OPTIONS = {"bin": "--bin", "scenario": "--scenario", "rtf": "--rtf",
                       "lcm_url": "--lcm-url", "timeout": "--timeout", "log_dir": "--out",
                       "flight_dir": "--out"}
# "{name}" but not "${name}", so shell snippets in commands keep working.
PLACEHOLDER_RE = re.compile(r"(?<!\$)\{([A-Za-z_][A-Za-z0-9_]*)\}")
NAME_RE = re.compile(r"^[A-Za-z0-9_.-]+$")

REQUIRED_FIELDS = {"name": str, "host": str, "core": int, "command": list}
OPTIONAL_FIELDS = {"config": str, "restart": bool, "ends_run": bool, "priority": int,
                   "heartbeat": str}


class TableError(ofn_cli.InputError):
    """Invalid process table or launch input; reported with exit code 2."""


def _yaml():
    """PyYAML, imported on first use."""
    try:
        return ofn_cli.need("yaml")
    except ofn_cli.MissingModule as e:
        raise TableError(str(e))


def _yaml_error_text(error):
    """One line for a YAMLError: 'line L, column C: problem'."""
    mark = getattr(error, "problem_mark", None)
    problem = getattr(error, "problem", None)
    if mark is not None and problem:
        return "line %d, column %d: %s" % (mark.line + 1, mark.column + 1, problem)
    return " ".join(str(error).split())


class ProcessSpec:
    """One validated entry of the process table."""

    def __init__(self, name, host, core, command, config=None, restart=False,
                 ends_run=False, priority=None, heartbeat=None):
        self.name = name
        self.host = host
        self.core = core
        self.command = list(command)
        self.config = config          # absolute path or None
        self.restart = restart
        self.ends_run = ends_run
        self.priority = priority
        self.heartbeat = heartbeat    # one of HEARTBEAT_KINDS, or None: not watched

    def __repr__(self):
        return "ProcessSpec(%r, host=%r, core=%r)" % (self.name, self.host, self.core)


class ProcessTable:
    def __init__(self, path, hosts, processes):
        self.path = path
        self.hosts = hosts            # host name -> list of cores
        self.processes = processes    # list of ProcessSpec, in start order

    def names(self):
        return [p.name for p in self.processes]


# ---------------------------------------------------------------------------
# Table loading and validation
# ---------------------------------------------------------------------------

def _type_name(t):
    return {str: "a string", int: "an integer", list: "a list", bool: "true/false",
            dict: "a mapping"}.get(t, t.__name__)


def _is_type(value, expected):
    # bool is a subclass of int; "core: true" must not pass as core 1.
    if expected is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, expected)


def _display_path(path):
    try:
        rel = os.path.relpath(path)
    except ValueError:
        return path
    return rel if not rel.startswith("..") else path


def resolve_repo_path(path):
    """Paths in the table are relative to the repository root."""
    path = os.path.expanduser(path)
    return path if os.path.isabs(path) else os.path.normpath(os.path.join(REPO_ROOT, path))


def load_table(path):
    """Parse and validate a process table; raise TableError on any problem.

    Checks structure and types only; executables and config files are checked
    by check_files() for the processes actually being started.
    """
    shown = _display_path(path)
    yaml = _yaml()
    try:
        with open(path, "r", encoding="utf-8") as f:
            doc = yaml.safe_load(f)
    except FileNotFoundError:
        raise TableError("%s: process table not found" % shown)
    except OSError as e:
        raise TableError("%s: cannot read process table: %s" % (shown, e.strerror))
    except UnicodeDecodeError:
        raise TableError("%s: process table is not UTF-8 text" % shown)
    except yaml.YAMLError as e:
        raise TableError("%s: not valid YAML: %s" % (shown, _yaml_error_text(e)))

    if not isinstance(doc, dict):
        raise TableError("%s: top level must be a mapping with 'hosts' and 'processes'" % shown)
    for key in doc:
        if key not in ("hosts", "processes"):
            raise TableError("%s: unknown top-level field '%s' (expected 'hosts' and 'processes')"
                             % (shown, key))

    hosts_doc = doc.get("hosts")
    if hosts_doc is None:
        raise TableError("%s: missing field 'hosts'" % shown)
    if not isinstance(hosts_doc, dict) or not hosts_doc:
        raise TableError("%s: field 'hosts' must be a non-empty mapping of host name -> {cores: [...]}"
                         % shown)
    hosts = {}
    for host_name, host_doc in hosts_doc.items():
        where = "%s: hosts.%s" % (shown, host_name)
        if not isinstance(host_doc, dict) or "cores" not in host_doc:
            raise TableError("%s: missing field 'cores'" % where)
        for key in host_doc:
            if key != "cores":
                raise TableError("%s: unknown field '%s' (only 'cores' is allowed)" % (where, key))
        cores = host_doc["cores"]
        if (not isinstance(cores, list) or not cores
                or not all(_is_type(c, int) and c >= 0 for c in cores)):
            raise TableError("%s: field 'cores' must be a non-empty list of core numbers >= 0, got %r"
                             % (where, cores))
        hosts[str(host_name)] = cores

    procs_doc = doc.get("processes")
    if procs_doc is None:
        raise TableError("%s: missing field 'processes'" % shown)
    if not isinstance(procs_doc, list) or not procs_doc:
        raise TableError("%s: field 'processes' must be a non-empty list" % shown)

    processes = []
    seen = set()
    for index, entry in enumerate(procs_doc):
        label = "processes[%d]" % index
        if isinstance(entry, dict) and isinstance(entry.get("name"), str):
            label += " (%s)" % entry["name"]
        where = "%s: %s" % (shown, label)
        if not isinstance(entry, dict):
            raise TableError("%s: entry must be a mapping, got %r" % (where, entry))

        for field, expected in REQUIRED_FIELDS.items():
            if field not in entry:
                raise TableError("%s: missing field '%s'" % (where, field))
        for field, value in entry.items():
            expected = REQUIRED_FIELDS.get(field) or OPTIONAL_FIELDS.get(field)
            if expected is None:
                known = ", ".join(list(REQUIRED_FIELDS) + list(OPTIONAL_FIELDS))
                raise TableError("%s: unknown field '%s' (known fields: %s)" % (where, field, known))
            if not _is_type(value, expected):
                raise TableError("%s: field '%s' must be %s, got %r"
                                 % (where, field, _type_name(expected), value))

        name = entry["name"]
        if not NAME_RE.match(name):
            raise TableError("%s: field 'name': %r may only contain letters, digits, '_', '-', '.'"
                             % (where, name))
        if name in seen:
            raise TableError("%s: field 'name': duplicate process name '%s'" % (where, name))
        seen.add(name)

        host = entry["host"]
        if host not in hosts:
            raise TableError("%s: field 'host': unknown host '%s' (known hosts: %s)"
                             % (where, host, ", ".join(hosts)))
        core = entry["core"]
        if core not in hosts[host]:
            raise TableError("%s: field 'core': core %d is not one of host %s's cores %s"
                             % (where, core, host, hosts[host]))

        command = entry["command"]
        if not command or not all(isinstance(a, str) for a in command):
            raise TableError("%s: field 'command' must be a non-empty list of strings, got %r"
                             % (where, command))
        for arg in command:
            for placeholder in PLACEHOLDER_RE.findall(arg):
                if placeholder not in PLACEHOLDERS:
                    raise TableError("%s: field 'command': unknown placeholder {%s} (known: %s)"
                                     % (where, placeholder,
                                        ", ".join("{%s}" % p for p in PLACEHOLDERS)))

        priority = entry.get("priority")
        if priority is not None and not 1 <= priority <= 99:
            raise TableError("%s: field 'priority' must be a SCHED_FIFO priority 1..99, got %d"
                             % (where, priority))
        restart = entry.get("restart", False)
        ends_run = entry.get("ends_run", False)
        if restart and ends_run:
            raise TableError("%s: fields 'restart' and 'ends_run' cannot both be true "
                             "(the process that ends the run must not be restarted)" % where)

        heartbeat = entry.get("heartbeat")
        if heartbeat is not None and heartbeat not in HEARTBEAT_KINDS:
            raise TableError("%s: field 'heartbeat' must be one of %s, got %r"
                             % (where, ", ".join(HEARTBEAT_KINDS), heartbeat))

        config = entry.get("config")
        processes.append(ProcessSpec(
            name=name, host=host, core=core, command=command,
            config=resolve_repo_path(config) if config is not None else None,
            restart=restart, ends_run=ends_run, priority=priority, heartbeat=heartbeat))

    return ProcessTable(path, hosts, processes)


def select_processes(table, only=None, host=None):
    """Processes to start: table order, filtered by --only names and --host."""
    selected = list(table.processes)
    if host is not None:
        if host not in table.hosts:
            raise TableError("--host: unknown host '%s' (hosts in %s: %s)"
                             % (host, _display_path(table.path), ", ".join(table.hosts)))
        selected = [p for p in selected if p.host == host]
    if only:
        unknown = [n for n in only if n not in table.names()]
        if unknown:
            raise TableError("--only: unknown process name(s) %s (processes in %s: %s)"
                             % (", ".join(unknown), _display_path(table.path),
                                ", ".join(table.names())))
        selected = [p for p in selected if p.name in only]
    if not selected:
        raise TableError("no processes selected (check --only / --host)")
    return selected


def expand_command(spec, values):
    """Fill in placeholders; append --config <path> when the entry has one,
    and on an authenticated bus (values["bus_keys"]) the keyring and the
    process's host as its role, to the project's own programs (ofn_*)."""
    def substitute(arg):
        return PLACEHOLDER_RE.sub(lambda m: values.get(m.group(1), m.group(0)), arg)

    argv = [substitute(a) for a in spec.command]
    if spec.config is not None:
        argv += ["--config", spec.config]
    if values.get("bus_keys") and os.path.basename(argv[0]).startswith("ofn_"):
        argv += ["--bus-keys", values["bus_keys"], "--bus-role", spec.host]
    return argv


def check_keyring(keyring, specs):
    """The keyring of --bus-keys holds the policy, every public key and the
    secret key of each host started here: a TableError names what is not."""
    if not os.path.isdir(keyring):
        raise TableError("--bus-keys: directory %s not found (make one with ofn_bus_keygen)" % keyring)
    needed = ["policy.yaml"] + sorted({"%s.key" % s.host for s in specs})
    missing = [name for name in needed if not os.path.isfile(os.path.join(keyring, name))]
    if missing:
        raise TableError("--bus-keys: %s holds no %s (a host needs policy.yaml, every *.pub "
                         "and its own <host>.key; see docs/DEPLOYMENT.md)"
                         % (keyring, ", ".join(missing)))


def resolve_executable(program):
    """Absolute path of an executable, or None.

    Absolute paths (/bin/sh) are used as they are, paths with a slash are
    relative to the repository root, bare names are looked up on PATH.
    """
    if "/" in program:
        path = resolve_repo_path(program)
        return path if os.path.isfile(path) and os.access(path, os.X_OK) else None
    return shutil.which(program)


def check_yaml_file(path, what, allow_empty):
    """The file must be readable YAML whose top level is a mapping (or, with
    allow_empty, nothing but comments).  `what` names it in the message, e.g.
    "--scenario" or "<table>: process 'mapper': field 'config'"."""
    yaml = _yaml()
    if not os.path.exists(path):
        raise TableError("%s: file %s not found" % (what, path))
    if not os.path.isfile(path):
        raise TableError("%s: %s is not a regular file" % (what, path))
    try:
        with open(path, "r", encoding="utf-8") as f:
            doc = yaml.safe_load(f)
    except OSError as e:
        raise TableError("%s: cannot read %s: %s" % (what, path, e.strerror))
    except UnicodeDecodeError:
        raise TableError("%s: %s is not UTF-8 text" % (what, path))
    except yaml.YAMLError as e:
        raise TableError("%s: %s is not valid YAML: %s" % (what, path, _yaml_error_text(e)))
    if doc is None and not allow_empty:
        raise TableError("%s: %s is empty" % (what, path))
    if doc is not None and not isinstance(doc, dict):
        raise TableError("%s: %s: top level must be a mapping of fields, got %s"
                         % (what, path, _type_name(type(doc))))


def check_files(table, specs, values):
    """Everything the selected processes need, checked before any starts:
    every placeholder has a value, the executables exist and the config
    files are readable YAML."""
    shown = _display_path(table.path)
    for spec in specs:
        where = "%s: process '%s'" % (shown, spec.name)
        for arg in spec.command:
            for placeholder in PLACEHOLDER_RE.findall(arg):
                if not values.get(placeholder):
                    raise TableError("%s: field 'command': {%s} has no value (set it with %s)"
                                     % (where, placeholder, PLACEHOLDER_OPTIONS[placeholder]))
        if any("{bin}" in arg for arg in spec.command) and not os.path.isdir(values["bin"]):
            raise TableError("--bin: directory %s not found - build first: make build" % values["bin"])
        argv = expand_command(spec, values)
        if resolve_executable(argv[0]) is None:
            if "/" in argv[0]:
                path = resolve_repo_path(argv[0])
                # {bin} and work-tree executables come from the build.
                from_build = "{bin}" in spec.command[0] or path.startswith(REPO_ROOT + os.sep)
                hint = " - build first: make build" if from_build else ""
                raise TableError("%s: field 'command': executable %s not found or not executable%s"
                                 % (where, path, hint))
            raise TableError("%s: field 'command': executable '%s' not found on PATH"
                             % (where, argv[0]))
        if spec.config is not None:
            check_yaml_file(spec.config, "%s: field 'config'" % where, allow_empty=True)


# ---------------------------------------------------------------------------
# CPU pinning and priority
# ---------------------------------------------------------------------------

def clamp_core(core, ncpu):
    """Clamp a table core number to the cores this machine has.

    The table describes the real three-host split; on a smaller development
    machine the emulated hosts share the last core instead of failing.
    """
    ncpu = max(1, int(ncpu or 1))
    return max(0, min(int(core), ncpu - 1))


class Pinning:
    """Decides, once per run, how processes are pinned and prioritised."""

    def __init__(self, enabled, note):
        self.note = note
        self.ncpu = os.cpu_count() or 1
        try:
            self.allowed = os.sched_getaffinity(0)
        except (AttributeError, OSError):
            self.allowed = set(range(self.ncpu))
        self.taskset = shutil.which("taskset") if enabled else None
        if not enabled:
            note("CPU pinning disabled (--no-pin)")
        elif self.taskset is None:
            note("taskset not found (apt-get install util-linux); processes are not pinned")
        self._chrt_checked = {}

    def prefix(self, spec):
        """Command prefix (chrt/taskset) for one process."""
        prefix = []
        if spec.priority is not None and self._chrt_usable(spec.priority):
            prefix += [shutil.which("chrt"), "-f", str(spec.priority)]
            self.note("%s: real-time priority SCHED_FIFO %d" % (spec.name, spec.priority))
        if self.taskset is not None:
            core = clamp_core(spec.core, self.ncpu)
            if core != spec.core:
                self.note("%s: table core %d clamped to %d (this machine has %d CPU%s)"
                          % (spec.name, spec.core, core, self.ncpu, "" if self.ncpu == 1 else "s"))
            if core in self.allowed:
                prefix += [self.taskset, "-c", str(core)]
            else:
                self.note("%s: core %d is outside this launcher's allowed CPUs %s; not pinned"
                          % (spec.name, core, sorted(self.allowed)))
        return prefix

    def _chrt_usable(self, priority):
        if priority in self._chrt_checked:
            return self._chrt_checked[priority]
        usable = False
        chrt = shutil.which("chrt")
        if os.geteuid() != 0:
            self.note("priority %d (SCHED_FIFO) needs root; running with normal priority" % priority)
        elif chrt is None:
            self.note("chrt not found; priority %d not applied" % priority)
        else:
            # Containers and some kernels refuse SCHED_FIFO even to root; try it.
            try:
                rc = subprocess.run([chrt, "-f", str(priority), "true"], stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL, timeout=5).returncode
            except (OSError, subprocess.TimeoutExpired):
                rc = 1
            usable = rc == 0
            if not usable:
                self.note("chrt -f %d refused on this machine; running with normal priority"
                          % priority)
        self._chrt_checked[priority] = usable
        return usable


# ---------------------------------------------------------------------------
# Child processes
# ---------------------------------------------------------------------------

def describe_exit(returncode):
    """(shell-style exit code, human text) for a Popen return code."""
    if returncode is None:
        return None, "still running"
    if returncode < 0:
        signum = -returncode
        try:
            signame = signal.Signals(signum).name
        except ValueError:
            signame = "signal %d" % signum
        return 128 + signum, "exited with code %d (signal %s)" % (128 + signum, signame)
    return returncode, "exited with code %d" % returncode


class Console:
    """Serialises terminal output of the launcher and the reader threads."""

    def __init__(self, width):
        self.lock = threading.Lock()
        self.width = width
        # Once the terminal is gone (closed ssh session, "| head"), output
        # goes only to the log files; the run and the shutdown must go on.
        self.broken = False

    def _write(self, data):
        with self.lock:
            if self.broken:
                return
            try:
                sys.stdout.buffer.write(data)
                sys.stdout.buffer.flush()
            except (OSError, ValueError):
                self.broken = True

    def service_line(self, name, line):
        prefix = ("[%s]" % name).ljust(self.width + 2).encode()
        self._write(prefix + b" " + line)

    def say(self, text):
        self._write(("launcher: %s\n" % text).encode("utf-8", "replace"))

    def note(self, text):
        self.say("note: " + text)


class Child:
    """One supervised child process (a service or lcm-logger)."""

    RUNNING = "running"    # started (or being started); exit not yet handled
    WAITING = "waiting"    # exited, restart scheduled at restart_at
    DONE = "done"          # exited for good (no restart, gave up, ends_run)

    def __init__(self, name, argv, log_path, console, spec=None, file_only=None, line_sink=None):
        self.name = name
        self.file_only = file_only   # regex of lines kept out of the terminal
        # Takes each output line first; a line it returns True for goes
        # neither to the log nor to the terminal (the probe's heartbeats).
        self.line_sink = line_sink
        self.argv = argv
        self.log_path = log_path
        self.console = console
        self.spec = spec
        self.proc = None
        self.reader = None
        self.state = Child.RUNNING
        self.starts = 0
        self.restarts = 0            # restarts in a row: counted against --max-restarts
        self.total_restarts = 0      # restarts in the whole run
        self.started_at = None       # monotonic time of the latest start
        self.restart_at = None       # monotonic time of a pending restart
        self.gave_up = False
        self.last_returncode = None
        self.stopped_by_launcher = False
        self.hangs = 0               # times the watchdog found it hung, in the whole run
        self.killed_as_hung = False  # the current instance was found hung
        self.hang_kill_at = None     # monotonic time of its SIGKILL, once found hung

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def start(self, env):
        """Start the child; returns False if it could not be executed."""
        self.state = Child.RUNNING
        self.starts += 1
        self.started_at = time.monotonic()
        self.killed_as_hung = False
        self.hang_kill_at = None
        log = open(self.log_path, "ab")
        stamp = datetime.datetime.now().strftime("%Y-%m-%d %H:%M:%S")
        header = "=== launcher %s: start #%d: %s\n" % (stamp, self.starts, shlex.join(self.argv))
        log.write(header.encode())
        log.flush()
        try:
            # A new session per child: Ctrl-C in the terminal reaches only the
            # launcher, which then stops the children in a defined order (the
            # logger last), and killpg() also reaches anything a child forked.
            self.proc = subprocess.Popen(
                self.argv, cwd=REPO_ROOT, env=env, stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
        except OSError as e:
            log.write(("=== launcher: failed to start: %s\n" % e).encode())
            log.close()
            self.console.say("%s failed to start: %s" % (self.name, e))
            self.proc = None
            self.last_returncode = 127
            return False
        self.reader = threading.Thread(target=self._pump, args=(self.proc.stdout, log),
                                       name="reader-" + self.name, daemon=True)
        self.reader.start()
        return True

    def _pump(self, stream, log):
        try:
            for line in iter(stream.readline, b""):
                if not line.endswith(b"\n"):
                    line += b"\n"
                if self.line_sink is not None and self.line_sink(line):
                    continue
                log.write(line)
                log.flush()
                if self.file_only is None or not self.file_only.match(line):
                    self.console.service_line(self.name, line)
        except (OSError, ValueError):
            pass
        finally:
            stream.close()
            log.close()

    def finish_output(self, timeout=0.5):
        # Lets the last lines of a dead child reach the terminal before the
        # launcher's message about it.  Bounded: a forked grandchild may still
        # hold the pipe open.
        if self.reader is not None:
            self.reader.join(timeout)

    def signal_group(self, signum):
        if self.proc is None:
            return
        try:
            os.killpg(self.proc.pid, signum)
        except (ProcessLookupError, PermissionError):
            pass


def stop_children(children, console, state, grace=STOP_GRACE_S):
    """SIGINT every live child, wait up to `grace`, SIGKILL stragglers."""
    live = [c for c in children if c.alive()]
    if not live:
        return
    for child in live:
        child.stopped_by_launcher = True
        child.signal_group(signal.SIGINT)
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline and not state.force_kill:
        if not any(c.alive() for c in live):
            break
        time.sleep(POLL_INTERVAL_S)
    for child in live:
        if child.alive():
            console.say("%s did not stop within %.0f s of SIGINT; sending SIGKILL"
                        % (child.name, grace))
        # Also clears anything the child forked that outlived it.
        child.signal_group(signal.SIGKILL)
    for child in live:
        try:
            child.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            console.say("%s (pid %d) survived SIGKILL" % (child.name, child.proc.pid))
        child.last_returncode = child.proc.returncode
        child.finish_output()


def read_proc_resources(pid):
    """(resident bytes, CPU seconds) of a live process, from /proc; None when
    it is gone or /proc cannot be read."""
    try:
        rss_kb = None
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    rss_kb = int(line.split()[1])
                    break
        with open("/proc/%d/stat" % pid) as f:
            stat = f.read()
        # The command name may hold spaces and parentheses: the fields that
        # follow it start after its last ')'; utime and stime are the 14th
        # and 15th of the whole line.
        fields = stat[stat.rindex(")") + 2:].split()
        ticks = int(fields[11]) + int(fields[12])
    except (OSError, ValueError, IndexError):
        return None
    if rss_kb is None:  # a zombie has no memory left to report
        return None
    return rss_kb * 1024, ticks / float(os.sysconf("SC_CLK_TCK"))


class ResourceWatch:
    """Samples every live service once a period into a CSV, and keeps for
    each its memory after the settling time, its peak and its last sample,
    and its CPU time (for the run's summary). A restart starts the figures
    over (a new pid)."""

    class Figures:
        def __init__(self, pid, now, cpu_s):
            self.pid = pid
            self.settled_rss = None   # bytes, first sample RESOURCE_SETTLE_S after the start
            self.peak_rss = 0
            self.last_rss = 0
            self.first_cpu = cpu_s    # CPU time at the first sample (the start), and when
            self.first_at = now
            self.last_cpu = cpu_s
            self.last_at = now

    def __init__(self, path, period=RESOURCE_PERIOD_S, settle=RESOURCE_SETTLE_S):
        self.path = path
        self.period = period
        self.settle = settle
        self.next_at = 0.0
        self.t0 = None
        self.figures = {}
        self.file = open(path, "w")
        self.file.write("t_s,service,pid,rss_mb,cpu_s\n")

    def sample(self, children, now):
        if now < self.next_at:
            return
        self.next_at = now + self.period
        if self.t0 is None:
            self.t0 = now
        for child in children:
            if not child.alive():
                continue
            pid = child.proc.pid
            got = read_proc_resources(pid)
            if got is None:
                continue
            rss, cpu_s = got
            fig = self.figures.get(child.name)
            if fig is None or fig.pid != pid:
                fig = self.figures[child.name] = ResourceWatch.Figures(pid, now, cpu_s)
            if fig.settled_rss is None and now - fig.first_at >= self.settle:
                fig.settled_rss = rss
            fig.peak_rss = max(fig.peak_rss, rss)
            fig.last_rss = rss
            fig.last_cpu, fig.last_at = cpu_s, now
            self.file.write("%.1f,%s,%d,%.3f,%.2f\n" % (now - self.t0, child.name, pid, rss / 1e6,
                                                         cpu_s))
        self.file.flush()

    def describe(self, name):
        """One line of the summary: memory after settling and at the end, the
        peak, and the mean CPU load; empty when never sampled."""
        fig = self.figures.get(name)
        if fig is None:
            return ""
        span = fig.last_at - fig.first_at
        cpu = ("cpu %.0f %%" % (100.0 * (fig.last_cpu - fig.first_cpu) / span)) if span > 0 else "cpu -"
        if fig.settled_rss is None:
            memory = "rss %.1f MB (peak %.1f)" % (fig.last_rss / 1e6, fig.peak_rss / 1e6)
        else:
            memory = "rss %.1f -> %.1f MB (peak %.1f)" % (fig.settled_rss / 1e6, fig.last_rss / 1e6,
                                                          fig.peak_rss / 1e6)
        return "%s, %s" % (memory, cpu)

    def close(self):
        self.file.close()


def heartbeat_channel(name):
    """The heartbeat channel of a service: HEARTBEAT_<NAME> (heartbeat_channel
    in services/common/src/node.cpp); the table name is the service's name."""
    return "HEARTBEAT_" + name.upper()


def process_group(pid):
    """Process group of a local process, or None when there is none."""
    try:
        return os.getpgid(pid)
    except (OSError, OverflowError):
        return None


class HangWatch:
    """Which watched processes are hung, judged from the heartbeats the probe
    (ofn_heartbeat_probe) hears on the bus. Pure but for a lock (the probe's
    reader thread reports, the supervision loop asks): times are given,
    monotonic seconds; heartbeat stamps are seconds of the sender's clock.

    A heartbeat counts for a process when its pid is the process's or one
    of its process group's (a wrapper that forks); the previous instance's,
    still on the way after a restart, do not. A process is hung when none
    has come for `timeout` seconds (since its start, plus `start_allowance`,
    when none has come yet) and, by its kind:
      own        its clock runs by itself (the wall clock; the simulation
                 master's at `rtf` times real time, whose heartbeats come
                 1/rtf s apart, so at least timeout/rtf s): silence is enough;
      sim_clock  it follows SIM_CLOCK, and falls silent with every other
                 follower when the simulation stops: hung only when the
                 heartbeats of others heard since its last show the
                 simulation ran `timeout` s of its time on without it.
    Nobody is judged while the probe itself is not heard (its "tick" once a
    second): a deaf watchdog must not kill what it cannot hear. Heartbeats
    of processes it did not start (a stranger's, a replayed log's) are no
    evidence either way."""

    class Entry:
        def __init__(self, kind, group, now):
            self.kind = kind
            self.group = group        # the child's pid: its process group
            self.started_at = now
            self.last_at = None       # arrival of its last heartbeat
            self.ref_stamp = None     # stamp the simulation's progress is measured from

    def __init__(self, timeout, rtf=1.0, start_allowance=HANG_START_ALLOWANCE_S,
                 probe_silence=PROBE_SILENCE_S, group_of=process_group):
        if not timeout > 0 or not rtf > 0:
            raise ValueError("HangWatch: timeout and rtf must be > 0")
        self.timeout = timeout
        self.rtf = rtf
        self.start_allowance = start_allowance
        self.probe_silence = probe_silence
        self.group_of = group_of
        self.lock = threading.Lock()
        self.entries = {}   # heartbeat channel -> Entry
        self.latest = {}    # heartbeat channel -> (arrival, stamp) of the last one heard
        self.probe_at = None

    def started(self, name, kind, pid, now):
        """A (re)start of `name` as process `pid`: judged afresh from now."""
        if kind not in HEARTBEAT_KINDS:
            raise ValueError("HangWatch: unknown heartbeat kind %r" % kind)
        with self.lock:
            self.entries[heartbeat_channel(name)] = HangWatch.Entry(kind, pid, now)

    def tick(self, now):
        """The probe runs."""
        with self.lock:
            self.probe_at = now

    def heard(self, channel, pid, stamp, now):
        """A heartbeat the probe heard on `channel` from process `pid`,
        stamped `stamp` (s). Only a watched process's own heartbeats count,
        as its sign of life and as the simulation's progress: on an open
        bus anyone may send one, and a stranger's stamp 2^63 us ahead made
        every silent follower look hung at once (the bus fuzz)."""
        with self.lock:
            self.probe_at = now
            entry = self.entries.get(channel)
            if entry is None or not (pid == entry.group or self.group_of(pid) == entry.group):
                return
            self.latest[channel] = (now, stamp)
            entry.last_at = now
            entry.ref_stamp = stamp
            # A process not heard yet measures the simulation from the first
            # stamp of another heard since its start.
            for other_channel, other in self.entries.items():
                if other_channel != channel and other.ref_stamp is None:
                    other.ref_stamp = stamp

    def verdict(self, name, now):
        """Why `name` counts as hung now, or None when it does not."""
        channel = heartbeat_channel(name)
        with self.lock:
            entry = self.entries.get(channel)
            if entry is None or self.probe_at is None or now - self.probe_at > self.probe_silence:
                return None
            since = entry.last_at if entry.last_at is not None else entry.started_at
            needed = self.timeout * (max(1.0, 1.0 / self.rtf) if entry.kind == "own" else 1.0)
            if entry.last_at is None:
                needed += self.start_allowance
            silent = now - since
            if silent < needed:
                return None
            if entry.last_at is None:
                why = "no heartbeat on %s in the %.1f s since its start" % (channel, silent)
            else:
                why = "no heartbeat on %s for %.1f s" % (channel, silent)
            if entry.kind == "sim_clock":
                fresh = [stamp for other, (at, stamp) in self.latest.items()
                         if other != channel and at >= since]
                if entry.ref_stamp is None or not fresh:
                    return None
                ran = max(fresh) - entry.ref_stamp
                if ran < self.timeout:
                    return None
                why += " while the simulation ran %.1f s on" % ran
            return why


def probe_line_sink(hang_watch, clock=time.monotonic):
    """The probe's output lines into `hang_watch`: "tick" and "heartbeat
    <channel> <pid> <utime>" (True: consumed); anything else is left for the
    probe's log (False)."""
    def sink(line):
        words = line.split()
        if words == [b"tick"]:
            hang_watch.tick(clock())
            return True
        if len(words) == 4 and words[0] == b"heartbeat":
            try:
                channel = words[1].decode("ascii")
                pid, utime = int(words[2]), int(words[3])
            except (UnicodeDecodeError, ValueError):
                return False
            hang_watch.heard(channel, pid, utime * 1e-6, clock())
            return True
        return False
    return sink


class RunState:
    """Flags set from signal handlers and read by the supervision loop."""

    def __init__(self):
        self.stop_signal = None
        self.stopping = False
        self.force_kill = False


# ---------------------------------------------------------------------------
# Command line and main
# ---------------------------------------------------------------------------

def build_parser():
    parser = ofn_cli.ArgumentParser(
        "deploy/launch.py",
        "Start, supervise and record the flight-software services of one run.",
        epilog="Examples:\n"
               "  deploy/launch.py --scenario sim/scenarios/bench3.yaml\n"
               "  deploy/launch.py --scenario sim/scenarios/bench3.yaml --only mapper,global_planner \\\n"
               "      --no-record --timeout 0\n"
               "      (re-run planners on a flight replayed with deploy/replay.sh)\n"
               "  deploy/launch.py --scenario sim/scenarios/bench3.yaml --host onboard1 --timeout 0\n"
               "      (on the flight computer)\n"
               "\n"
               "Exit codes: the ends_run process's; 2 for bad input or a service that exits with\n"
               "code 2 (its configuration or usage error; never restarted); 3 when --timeout\n"
               "ends the run; 128+N on signal N; 1 when the launcher itself fails.")
    parser.add_argument("--table", default=DEFAULT_TABLE, metavar="FILE",
                        help="process table (default: deploy/processes.yaml)")
    parser.add_argument("--scenario", required=True, metavar="FILE",
                        help="scenario file, substituted for {scenario} (required)")
    parser.add_argument("--bin", default=DEFAULT_BIN, metavar="DIR",
                        help="directory of the service executables, {bin} (default: build/bin)")
    parser.add_argument("--rtf", type=float, default=1.0, metavar="X",
                        help="simulation real-time factor, {rtf} (default: 1.0)")
    parser.add_argument("--lcm-url", metavar="URL", default=os.environ.get("LCM_DEFAULT_URL") or FALLBACK_LCM_URL,
                        help="LCM URL, {lcm_url} (default: $LCM_DEFAULT_URL or %s)"
                             % FALLBACK_LCM_URL.replace("%", "%%"))
    parser.add_argument("--out", "--log-dir", dest="log_dir", default=DEFAULT_LOG_DIR, metavar="DIR",
                        help="results folder: the flight log, the services' logs and latest_log, "
                             "{log_dir}; --log-dir is its old spelling (default: results/)")
    parser.add_argument("--timeout", type=float, default=300.0, metavar="S",
                        help="overall wall-clock run limit in seconds, also {timeout}; "
                             "0 = no launcher limit, {timeout} then is 0 (default: 300)")
    parser.add_argument("--no-pin", action="store_true",
                        help="do not pin processes to cores (default: pin them)")
    parser.add_argument("--no-record", action="store_true",
                        help="do not start lcm-logger (default: record the bus)")
    parser.add_argument("--only", metavar="NAME[,NAME]",
                        help="start only these processes, comma-separated (default: all)")
    parser.add_argument("--host", help="start only the processes of this host (default: all hosts)")
    parser.add_argument("--bus-keys", metavar="DIR",
                        help="authenticated bus: the keyring made by ofn_bus_keygen; every "
                             "ofn_* process signs and checks as its host's role "
                             "(default: an open bus)")
    parser.add_argument("--max-restarts", type=int, default=5, metavar="N",
                        help="restarts in a row per service before giving up (default: 5)")
    parser.add_argument("--healthy-after", type=float, default=DEFAULT_HEALTHY_AFTER_S, metavar="S",
                        help="a service that has run S seconds since its last restart gets its "
                             "full --max-restarts budget back; 0 = never (default: %s)"
                             % format_number(DEFAULT_HEALTHY_AFTER_S))
    parser.add_argument("--hang-timeout", type=float, default=DEFAULT_HANG_TIMEOUT_S, metavar="S",
                        help="a process with a heartbeat field in the table whose heartbeats "
                             "stop for S seconds is hung: SIGTERM, SIGKILL after %s s, then "
                             "restarted as if it had died; 0 = off (default: %s)"
                             % (format_number(HANG_KILL_GRACE_S),
                                format_number(DEFAULT_HANG_TIMEOUT_S)))
    return parser


def parse_args(argv):
    parser = build_parser()
    args = parser.parse_args(argv)

    errors = []
    if not args.rtf > 0:
        errors.append("--rtf must be > 0")
    if not args.timeout >= 0:
        errors.append("--timeout must be >= 0")
    if args.max_restarts < 0:
        errors.append("--max-restarts must be >= 0")
    if not args.healthy_after >= 0:
        errors.append("--healthy-after must be >= 0")
    if not 0 <= args.hang_timeout < float("inf"):
        errors.append("--hang-timeout must be >= 0 (0 = off)")
    for message in errors:
        parser.error(message)  # exits with code 2
    args.only = [n.strip() for n in args.only.split(",") if n.strip()] if args.only else None
    return args


def format_number(value):
    """300.0 -> "300", 0.5 -> "0.5": services may parse {timeout} as an integer."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def unique_log_stem(log_dir):
    stem = "flight-" + datetime.datetime.now().strftime("%Y%m%d-%H%M%S")
    candidate, n = stem, 1
    # Two runs within the same second must not share (and clobber) a log.
    while (os.path.exists(os.path.join(log_dir, candidate + ".lcm"))
           or os.path.exists(os.path.join(log_dir, candidate))):
        n += 1
        candidate = "%s-%d" % (stem, n)
    return candidate


class Supervisor:
    """Starts the services in table order, restarts one that exits (with a
    back-off, within --max-restarts, the budget given back after
    --healthy-after seconds up), ends one the hang watch finds hung (SIGTERM,
    SIGKILL after HANG_KILL_GRACE_S; its exit then goes the same way) and
    decides when the run ends: a signal, the run limit, an ends_run
    service's exit, a configuration error, or no service left. Sets
    end_reason and exit_code when it does."""

    def __init__(self, services, env, console, state, max_restarts, healthy_after, timeout,
                 hang_watch=None):
        self.services = services
        self.env = env
        self.say = console.say
        self.state = state
        self.max_restarts = max_restarts
        self.healthy_after = healthy_after
        self.timeout = timeout  # s, for the message when the run limit ends the run
        self.hang_watch = hang_watch
        self.end_reason = None
        self.exit_code = 0

    def _start(self, child, now):
        """Starts a child; tells the hang watch of a watched one. False if it
        could not be executed."""
        if not child.start(self.env):
            return False
        if self.hang_watch is not None and child.spec.heartbeat:
            self.hang_watch.started(child.name, child.spec.heartbeat, child.proc.pid, now)
        return True

    def start_all(self):
        for child in self.services:
            if self.state.stop_signal is not None:
                return
            now = time.monotonic()
            if not self._start(child, now) and self._ends(self.handle_exit(child, now)):
                return

    def poll(self, now, deadline):
        """One look at the run: signals, the run limit, each child's exit or
        due restart. Returns True when the run has ended."""
        if self.state.stop_signal is not None:
            self.end_reason = "received %s; stopping" % signal.Signals(self.state.stop_signal).name
            self.exit_code = 128 + self.state.stop_signal
            return True
        if deadline is not None and now >= deadline:
            self.end_reason = "run limit of %s s reached; stopping (exit code %d)" % (
                format_number(self.timeout), EXIT_TIMEOUT)
            self.exit_code = EXIT_TIMEOUT
            return True
        for child in self.services:
            outcome = None
            if child.state == Child.RUNNING:
                self.reset_if_healthy(child, now)
            if child.state == Child.RUNNING and not child.alive():
                outcome = self.handle_exit(child, now)
            elif child.state == Child.RUNNING:
                self.end_if_hung(child, now)
            elif child.state == Child.WAITING and now >= child.restart_at:
                child.restart_at = None
                if not self._start(child, now):
                    outcome = self.handle_exit(child, now)
            if self._ends(outcome):
                return True
        return False

    def all_done(self):
        """True (and the run ended) when no service is left running or waiting."""
        if not all(c.state == Child.DONE for c in self.services):
            return False
        self.end_reason = "no service left running; stopping"
        failed = any((describe_exit(c.last_returncode)[0] or 0) != 0 or c.proc is None
                     for c in self.services)
        self.exit_code = 1 if failed else 0
        return True

    def _ends(self, outcome):
        if outcome is None:
            return False
        self.end_reason, self.exit_code = outcome
        return True

    def reset_if_healthy(self, child, now):
        """A service up --healthy-after seconds since its last restart gets
        its restart budget back."""
        if (child.restarts and self.healthy_after > 0 and child.started_at is not None
                and now - child.started_at >= self.healthy_after):
            self.say("%s has run %s s since its last restart; restart count reset (0/%d)"
                     % (child.name, format_number(self.healthy_after), self.max_restarts))
            child.restarts = 0

    def end_if_hung(self, child, now):
        """SIGTERM a live child the hang watch finds hung; SIGKILL it
        HANG_KILL_GRACE_S later if it is still there."""
        if self.hang_watch is None or not child.spec.heartbeat:
            return
        if child.hang_kill_at is not None:
            if now >= child.hang_kill_at:
                self.say("%s still there %g s after SIGTERM; sending SIGKILL"
                         % (child.name, HANG_KILL_GRACE_S))
                child.signal_group(signal.SIGKILL)
                child.hang_kill_at = float("inf")  # sent; its exit is handled as any other
            return
        why = self.hang_watch.verdict(child.name, now)
        if why is None:
            return
        child.hangs += 1
        child.killed_as_hung = True
        child.hang_kill_at = now + HANG_KILL_GRACE_S
        self.say("%s is HUNG (%s): SIGTERM, SIGKILL in %g s if it stays"
                 % (child.name, why, HANG_KILL_GRACE_S))
        child.signal_group(signal.SIGTERM)

    def handle_exit(self, child, now):
        """Decide what a child's exit means; returns (end_reason, exit_code) or None."""
        if child.proc is None:
            code, text = 127, "failed to start"
        else:
            child.finish_output()
            child.last_returncode = child.proc.returncode
            code, text = describe_exit(child.proc.returncode)
        if child.killed_as_hung:
            text += " after it hung"
            if child.spec.ends_run:
                # Whatever it returned on SIGTERM is not a verdict.
                child.state = Child.DONE
                return ("%s %s; it ends the run (exit code %d)"
                        % (child.name, text, EXIT_LAUNCHER_FAILURE)), EXIT_LAUNCHER_FAILURE
        if code == EXIT_SERVICE_CONFIG_ERROR:
            # Restarting cannot fix a configuration or usage error, and
            # the flight cannot go on without the service: stop now.
            child.state = Child.DONE
            return ("%s %s, a configuration or usage error (see its output above); "
                    "not restarted: ending the run (exit code %d)"
                    % (child.name, text, EXIT_BAD_INPUT)), EXIT_BAD_INPUT
        if child.spec.ends_run:
            child.state = Child.DONE
            return "%s %s; it ends the run" % (child.name, text), code
        if not child.spec.restart:
            child.state = Child.DONE
            self.say("%s %s; not restarted (restart: false)" % (child.name, text))
        elif child.restarts >= self.max_restarts:
            child.state = Child.DONE
            child.gave_up = True
            self.say("%s %s; GIVING UP after %d restart%s (--max-restarts %d)"
                     % (child.name, text, child.restarts, "" if child.restarts == 1 else "s",
                        self.max_restarts))
        else:
            child.restarts += 1
            child.total_restarts += 1
            delay = min(BACKOFF_START_S * 2 ** (child.restarts - 1), BACKOFF_CAP_S)
            child.state = Child.WAITING
            child.restart_at = now + delay
            self.say("%s %s; restarting in %g s (restart %d/%d)"
                     % (child.name, text, delay, child.restarts, self.max_restarts))
        return None


def check_inputs(args, table_path, scenario, values):
    """Everything checked once, before anything starts: the table, the
    selection, the scenario, each service's files, the keyring, lcm-logger
    and, when a selected process is watched for hangs, the heartbeat probe.
    Returns (specs, lcm-logger path or None, probe path or None); raises
    TableError."""
    table = load_table(table_path)
    specs = select_processes(table, args.only, args.host)
    check_yaml_file(scenario, "--scenario", allow_empty=False)
    check_files(table, specs, values)
    if values["bus_keys"]:
        check_keyring(values["bus_keys"], specs)
    logger_exe = None
    if not args.no_record:
        logger_exe = shutil.which("lcm-logger")
        if logger_exe is None:
            raise TableError("lcm-logger not found (apt-get install liblcm-bin), or pass --no-record")
    probe_exe = None
    if args.hang_timeout > 0 and any(s.heartbeat for s in specs):
        probe_exe = os.path.join(values["bin"], PROBE_PROGRAM)
        if not (os.path.isfile(probe_exe) and os.access(probe_exe, os.X_OK)):
            raise TableError("--hang-timeout: %s not found or not executable - build first: "
                             "make build (or --hang-timeout 0: no hang watch)" % probe_exe)
    return specs, logger_exe, probe_exe


def install_signal_handlers(state):
    def on_signal(signum, _frame):
        if state.stopping:
            # Second Ctrl-C during shutdown: do not wait out the grace period.
            state.force_kill = True
        elif state.stop_signal is None:
            state.stop_signal = signum

    # SIGHUP too: a dropped ssh session must stop the run cleanly (children
    # live in their own sessions and would not see the hangup).
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, on_signal)


def child_prefixes():
    """(orphan guard, line buffering) argv prefixes, each empty when its tool is missing."""
    # If the launcher itself is killed (SIGKILL, OOM) its children must not
    # fly on as orphans: have the kernel send them SIGTERM.
    setpriv = shutil.which("setpriv")
    orphan_guard = [setpriv, "--pdeathsig", "TERM"] if setpriv else []
    # Services write to a pipe, where C stdio would buffer whole blocks and
    # hold back crash context; stdbuf makes their output line-buffered.
    stdbuf = shutil.which("stdbuf")
    line_buffered = [stdbuf, "-oL", "-eL"] if stdbuf else []
    return orphan_guard, line_buffered


def logger_child(logger_exe, lcm_url, lcm_log, service_log_dir, orphan_guard, console):
    # lcm-logger prints a throughput summary every second; keep those in its
    # log file so they do not drown the services' output.
    return Child("lcm-logger", orphan_guard + [logger_exe, "--lcm-url=" + lcm_url, lcm_log],
                 os.path.join(service_log_dir, "lcm-logger.log"), console,
                 file_only=re.compile(rb"^Summary: "))


def start_logger(logger, lcm_log, log_dir, console, env):
    """True when lcm-logger started and is still alive after settling
    (latest_log then names its log); False, having said why, when not."""
    if not logger.start(env):
        return False
    time.sleep(LOGGER_SETTLE_S)
    if not logger.alive():
        logger.finish_output()
        console.say("lcm-logger %s; cannot record the flight (check the LCM URL and that "
                    "multicast is routed, or use --no-record)" % describe_exit(logger.proc.returncode)[1])
        return False
    console.say("recording LCM traffic to %s" % lcm_log)
    with open(os.path.join(log_dir, "latest_log"), "w") as f:
        f.write(lcm_log + "\n")
    return True


def probe_child(probe_exe, lcm_url, bus_keys, hang_watch, service_log_dir, orphan_guard,
                line_buffered, console):
    """The heartbeat probe: its heartbeat lines go to `hang_watch`, anything
    else to its log and the terminal."""
    argv = orphan_guard + line_buffered + [probe_exe, "--lcm-url", lcm_url]
    if bus_keys:
        argv += ["--bus-keys", bus_keys]
    return Child(PROBE_PROGRAM, argv, os.path.join(service_log_dir, PROBE_PROGRAM + ".log"),
                 console, line_sink=probe_line_sink(hang_watch))


def watch_run(supervisor, deadline, resources, logger, say, probe=None):
    """Polls until the supervisor ends the run: samples each service's
    memory and CPU, and warns once if lcm-logger or the heartbeat probe
    dies."""
    logger_warned = False
    probe_warned = False
    while supervisor.end_reason is None:
        now = time.monotonic()
        if supervisor.poll(now, deadline):
            return
        resources.sample(supervisor.services, now)
        if logger is not None and not logger_warned and not logger.alive():
            logger.finish_output()
            say("WARNING: lcm-logger %s; the rest of this flight is NOT being recorded"
                % describe_exit(logger.proc.returncode)[1])
            logger_warned = True
        if probe is not None and not probe_warned and not probe.alive():
            probe.finish_output()
            say("WARNING: %s %s; hung services are no longer found"
                % (PROBE_PROGRAM, describe_exit(probe.proc.returncode)[1]))
            probe_warned = True
        if supervisor.all_done():
            return
        time.sleep(POLL_INTERVAL_S)


def main(argv=None):
    args = parse_args(argv)

    table_path = os.path.abspath(args.table)
    scenario = os.path.abspath(os.path.expanduser(args.scenario))
    bin_dir = os.path.abspath(os.path.expanduser(args.bin))
    log_dir = os.path.abspath(os.path.expanduser(args.log_dir))
    # Named now, made once the checks pass: bad input creates nothing.
    stem = unique_log_stem(log_dir)
    service_log_dir = os.path.join(log_dir, stem)

    values = {
        "bin": bin_dir,
        "scenario": scenario,
        "rtf": format_number(args.rtf),
        "lcm_url": args.lcm_url,
        "timeout": format_number(args.timeout),
        "log_dir": log_dir,
        "flight_dir": service_log_dir,
        # Not a placeholder: expand_command adds --bus-keys/--bus-role.
        "bus_keys": os.path.abspath(os.path.expanduser(args.bus_keys)) if args.bus_keys else "",
    }

    try:
        specs, logger_exe, probe_exe = check_inputs(args, table_path, scenario, values)
    except TableError as e:
        sys.stderr.write("launch.py: error: %s\n" % e)
        return EXIT_BAD_INPUT

    try:
        os.makedirs(log_dir, exist_ok=True)
        os.makedirs(service_log_dir)
    except OSError as e:
        sys.stderr.write("launch.py: error: --out: cannot create %s: %s\n" % (log_dir, e.strerror))
        return EXIT_BAD_INPUT

    console = Console(max(len(name) for name in [s.name for s in specs] + ["lcm-logger"]))
    state = RunState()
    install_signal_handlers(state)

    env = dict(os.environ)
    env["LCM_DEFAULT_URL"] = args.lcm_url   # services that take no --lcm-url use the same bus
    env["PYTHONUNBUFFERED"] = "1"
    orphan_guard, line_buffered = child_prefixes()

    say, note = console.say, console.note
    say("table %s, %d process%s: %s" % (_display_path(table_path), len(specs),
                                      "" if len(specs) == 1 else "es",
                                      ", ".join("%s@%s" % (s.name, s.host) for s in specs)))
    say("scenario %s, rtf %s, LCM %s, bus %s" % (
        scenario, values["rtf"], args.lcm_url,
        "authenticated (keyring %s)" % values["bus_keys"] if values["bus_keys"] else "open"))
    pinning = Pinning(not args.no_pin, note)
    if not line_buffered:
        note("stdbuf not found; service output may arrive in blocks")

    services = []
    for spec in specs:
        argv_exe = expand_command(spec, values)
        argv_exe[0] = resolve_executable(argv_exe[0])
        full_argv = orphan_guard + pinning.prefix(spec) + line_buffered + argv_exe
        services.append(Child(spec.name, full_argv,
                              os.path.join(service_log_dir, spec.name + ".log"), console, spec))

    ends_run = [s for s in services if s.spec.ends_run]
    if args.timeout > 0:
        run_limit = args.timeout + (ENDS_RUN_TIMEOUT_GRACE_S if ends_run else 0.0)
        say("run limit %s s%s" % (format_number(args.timeout),
                                 " (+%g s for %s to report)" % (ENDS_RUN_TIMEOUT_GRACE_S,
                                                               ", ".join(c.name for c in ends_run))
                                 if ends_run else ""))
    else:
        run_limit = None
        say("no run limit (--timeout 0); stop with Ctrl-C")
    if not ends_run:
        note("no ends_run process selected; the run ends at the time limit or on Ctrl-C")

    logger = None
    lcm_log = os.path.join(log_dir, stem + ".lcm")
    resources = None
    hang_watch = None
    probe = None
    if probe_exe is not None:
        hang_watch = HangWatch(args.hang_timeout, args.rtf)
        probe = probe_child(probe_exe, args.lcm_url, values["bus_keys"], hang_watch,
                            service_log_dir, orphan_guard, line_buffered, console)
        say("hang watch: %s, %s s without a heartbeat (--hang-timeout)"
            % (", ".join("%s (%s)" % (s.name, s.heartbeat) for s in specs if s.heartbeat),
               format_number(args.hang_timeout)))
    elif args.hang_timeout == 0:
        note("no hang watch (--hang-timeout 0)")
    supervisor = Supervisor(services, env, console, state, args.max_restarts, args.healthy_after,
                            args.timeout, hang_watch)
    try:
        if logger_exe is not None:
            logger = logger_child(logger_exe, args.lcm_url, lcm_log, service_log_dir, orphan_guard,
                                  console)
            if not start_logger(logger, lcm_log, log_dir, console, env):
                return EXIT_LAUNCHER_FAILURE
        else:
            note("not recording LCM traffic (--no-record)")
        say("service logs in %s/" % service_log_dir)
        resources = ResourceWatch(os.path.join(service_log_dir, "resources.csv"))
        if probe is not None and not probe.start(env):
            say("WARNING: %s could not be started; hung services will not be found"
                % PROBE_PROGRAM)

        supervisor.start_all()
        deadline = time.monotonic() + run_limit if run_limit is not None else None
        watch_run(supervisor, deadline, resources, logger, say, probe)
        say(supervisor.end_reason)
    finally:
        # Services first (reverse start order, so consumers go before the
        # producers they depend on), then the probe, the logger last so it
        # captures their final messages.  Always runs, so no child outlives
        # the launcher.
        state.stopping = True
        stop_children(list(reversed(services)), console, state)
        if probe is not None:
            stop_children([probe], console, state)
        if logger is not None:
            stop_children([logger], console, state)
            try:
                size_mb = os.path.getsize(lcm_log) / 1e6
                say("flight recorded to %s (%.1f MB); replay with deploy/replay.sh %s"
                    % (lcm_log, size_mb, _display_path(lcm_log)))
            except OSError:
                say("WARNING: flight log %s was not written" % lcm_log)
        if resources is not None:
            resources.close()
        print_summary(services, console, args.max_restarts, resources)
    return supervisor.exit_code


def print_summary(services, console, max_restarts, resources=None):
    rows = []
    for child in services:
        if child.starts == 0:
            final = "not started"
        elif child.proc is None:
            final = "failed to start"
        else:
            code, text = describe_exit(child.proc.poll())
            final = text.replace("exited with ", "")
            if child.stopped_by_launcher:
                final += ", stopped by launcher"
            elif child.gave_up and child.spec.restart:
                final += ", gave up"
            elif code == EXIT_SERVICE_CONFIG_ERROR:
                final += ", configuration or usage error"
        restarts = "-"
        if child.spec.restart:
            restarts = "%d/%d" % (child.restarts, max_restarts)
            if child.total_restarts != child.restarts:
                restarts += " (%d in all)" % child.total_restarts
        if child.hangs:
            restarts += ", hung %d" % child.hangs
        usage = resources.describe(child.name) if resources is not None else ""
        rows.append((child.name, child.spec.host, restarts, final, usage))
    width = max(len(r[0]) for r in rows)
    host_width = max(len(r[1]) for r in rows)
    console.say("summary:")
    for name, host, restarts, final, usage in rows:
        console.say("  %s  %s  restarts %s  %s%s" % (name.ljust(width), host.ljust(host_width),
                                                    restarts, final,
                                                    ("; " + usage) if usage else ""))
    if resources is not None:
        console.say("memory and CPU of each service, once a second: %s" % resources.path)


if __name__ == "__main__":
    ofn_cli.run_main("launch.py", main)
