#!/usr/bin/python3
"""Fault soak for coupled runs (issue 17, docs/hardening.md; `make soak`).

Runs coupled scenarios (two_mass.yaml: the two-mass example participants, implicit coupling;
wheel.yaml: Simbody rig + DEM soil) again and again while injecting faults at random windows:

  kill     SIGKILL of a participant or of the coordinator: the run must fail, and be resumed
  stop     SIGSTOP ... SIGCONT of a participant or the coordinator, either short (under a quarter
           of coupling.peer_timeout_s: the run must carry on) or long (beyond it: the run must
           fail, naming the silent participant, and be resumed)
  garbage  a stranger's bytes at the coordinator's endpoint (random bytes, several frames, an
           Envelope without a body, Hellos it must refuse, messages a participant would send,
           a large frame, a raw TCP connection that does not speak ZeroMQ): the run must carry on
  slow     a peer stopped and continued many times in a row: the run must carry on

A third of the kills wait for a checkpoint being written; a third of the runs that fail are
killed again (a participant or the coordinator) within a fraction of a second of their restart,
while the resumed processes cut their files back to the checkpoint.

A run that fails is resumed (`grainlink run --resume`, or started afresh when no checkpoint is
complete yet) until it finishes. A run has
  recovered  when it finished, every kill and long stop ended its attempt with the cause named
             (the participant and "killed by signal 9", "disconnected" or "silent"; a killed
             coordinator exits by the signal), no short stop, slow peer or stranger ended one,
             no attempt hung, no participant outlived its coordinator by more than its timeouts,
             and the results were readable after every crash (CSV rows whole, snapshots
             well-formed XML);
  identical  when its results (coupling.csv without wall_s, each participant's CSVs, the
             snapshots) equal those of an uninterrupted run of the scenario, row for row and
             byte for byte (on a difference, a second uninterrupted run tells a resume that
             differs from a scenario that is not deterministic);
  lost records: the rows (and snapshots) there after a crash that are missing or changed once
             the run has finished, a row matched by its time (first cell).

Usage: soak.py GRAINLINK [--minutes M] [--work DIR] [--seed S] [--scenario two-mass|wheel]
Prints one summary line and a table per run; exits non-zero unless every run recovered, every
run's results are identical and no record was lost. Each run's logs stay in WORK/runs/, and the
outputs of those that failed. Replay a soak with the --seed it printed (the windows hit vary a
little with the machine's load). soak.py signals only processes it started: the coordinator
(its child) and the participants that coordinator started, checked by their command line.
"""
import argparse
import csv
import ctypes
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree

import yaml
import zmq

HERE = os.path.dirname(os.path.abspath(__file__))
REPOSITORY = os.path.dirname(os.path.dirname(HERE))
SCENARIOS = (("two-mass", "two_mass.yaml"), ("wheel", "wheel.yaml"))
KINDS = ("kill", "stop", "garbage", "slow")


# ---------------------------------------------------------------------------------------------
# Processes: only our own. The coordinator is our child (a Popen); the participants are its
# children, found by their parent's pid and checked by their command line (which holds the run's
# endpoint) before every signal. soak.py is a child subreaper, so participants orphaned by a
# killed coordinator become its children: it can wait for them and never loses track of them.

def become_subreaper():
    PR_SET_CHILD_SUBREAPER = 36
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
        sys.exit("soak: error: prctl(PR_SET_CHILD_SUBREAPER) failed")


def proc_stat(pid):
    """(state, parent pid) of a process, or None when it is gone."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return fields[0], int(fields[1])
    except (OSError, IndexError, ValueError):
        return None


def proc_argv(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return [a.decode(errors="replace") for a in f.read().split(b"\0") if a]
    except OSError:
        return []


def alive(pid):
    """Whether pid runs; reaps it when it is our (adopted) zombie."""
    stat = proc_stat(pid)
    if stat is None:
        return False
    if stat[0] == "Z":
        if stat[1] == os.getpid():
            try:
                os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                pass
        return False
    return True


def children_of(parent):
    found = []
    for name in os.listdir("/proc"):
        if name.isdigit():
            stat = proc_stat(int(name))
            if stat is not None and stat[1] == parent and stat[0] != "Z":
                found.append(int(name))
    return found


# ---------------------------------------------------------------------------------------------
# Results: the files of an output folder, without its checkpoints.

class Results:
    """What a run has written: CSV rows (coupling.csv without wall_s), the DataSet entries of
    ParaView collections (.pvd), the bytes of every other file; and what could not be read."""

    def __init__(self, out):
        self.rows = {}      # CSV path -> list of rows (each a tuple of cells)
        self.entries = {}   # .pvd path -> list of DataSet entries
        self.blobs = {}     # other path -> bytes
        self.unreadable = []
        self.torn = set()   # files that could not be read whole
        for folder, dirs, files in os.walk(out):
            dirs[:] = [d for d in dirs if os.path.relpath(os.path.join(folder, d), out)
                       != "checkpoints"]
            for name in files:
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, out)
                with open(path, "rb") as f:
                    data = f.read()
                if name.endswith(".csv"):
                    self.rows[rel] = self.read_csv(rel, data)
                elif name.endswith(".pvd") or name.endswith(".vtu"):
                    try:
                        root = ElementTree.fromstring(data)
                    except ElementTree.ParseError as e:
                        self.unreadable.append(f"{rel}: not well-formed XML ({e})")
                        self.torn.add(rel)
                        root = None
                    if name.endswith(".pvd"):
                        self.entries[rel] = [] if root is None else [
                            tuple(sorted(d.attrib.items())) for d in root.iter("DataSet")]
                    else:
                        self.blobs[rel] = data
                else:
                    self.blobs[rel] = data
        self.records = sum(map(len, self.rows.values())) + sum(
            map(len, self.entries.values())) + len(self.blobs)

    def read_csv(self, rel, data):
        text = data.decode(errors="replace")
        if text and not text.endswith("\n"):
            self.unreadable.append(f"{rel}: last line cut off ({text.rsplit(chr(10), 1)[-1]!r})")
            text = text[:text.rfind("\n") + 1]
        table = list(csv.reader(text.splitlines()))
        if not table:
            return []
        header, rows = table[0], table[1:]
        for i, row in enumerate(rows, start=2):
            if len(row) != len(header) or not all(cell.strip() for cell in row):
                self.unreadable.append(f"{rel}:{i}: {len(row)} cells, the header has "
                                       f"{len(header)}: {','.join(row)[:80]}")
        drop = {i for i, name in enumerate(header) if rel == "coupling.csv" and name == "wall_s"}
        return [tuple(c for i, c in enumerate(r) if i not in drop) for r in table]


def differences(reference, results):
    """Where results differ from the reference: a list of sentences (empty: identical)."""
    found = []
    for kind in ("rows", "entries", "blobs"):
        a, b = getattr(reference, kind), getattr(results, kind)
        for name in sorted(set(a) | set(b)):
            if name not in b:
                found.append(f"{name} missing")
            elif name not in a:
                found.append(f"{name} written, not by the uninterrupted run")
            elif a[name] != b[name]:
                if kind == "blobs":
                    found.append(f"{name} differs")
                    continue
                if len(a[name]) != len(b[name]):
                    found.append(f"{name}: {len(b[name]) - 1} rows, uninterrupted "
                                 f"{len(a[name]) - 1}")
                first = next((i for i, (x, y) in enumerate(zip(a[name], b[name])) if x != y),
                             None)
                if first is not None:
                    found.append(f"{name} line {first + 1}: {','.join(b[name][first])[:120]} "
                                 f"(uninterrupted {','.join(a[name][first])[:120]})")
    return found


def lost_records(before, after):
    """Records present after a crash that are missing or changed once the run has finished:
    (file, 'missing' or 'changed', line) triples. A CSV row is kept when the finished file has
    it among the rows of the same time (first cell), so one row lost does not shift the rest."""
    lost = []
    for name, rows in before.rows.items():
        final = after.rows.get(name, [])
        if rows and final[:1] != rows[:1]:
            lost.append((name, "changed", 1))
        by_time = {}
        for row in final[1:]:
            by_time.setdefault(row[0], []).append(row)
        for line, row in enumerate(rows[1:], start=2):
            if row not in by_time.get(row[0], []):
                lost.append((name, "changed" if row[0] in by_time else "missing", line))
    for name, entries in before.entries.items():
        final = set(after.entries.get(name, []))
        lost += [(name, "missing", i + 1) for i, e in enumerate(entries) if e not in final]
    for name, data in before.blobs.items():
        if name in before.torn:
            continue  # unreadable then (reported as such), not a record yet
        if after.blobs.get(name) != data:
            lost.append((name, "changed" if name in after.blobs else "missing", 0))
    return lost


def describe_lost(lost):
    """'rig.csv: 28 missing (from line 124), 31 changed (from line 152); ...'"""
    parts = []
    for name in sorted({n for n, _, _ in lost}):
        kinds = []
        for kind in ("missing", "changed"):
            lines = [line for n, k, line in lost if n == name and k == kind]
            if lines:
                kinds.append(f"{len(lines)} {kind}" + (f" (from line {min(lines)})"
                                                       if min(lines) else ""))
        parts.append(f"{name}: {', '.join(kinds)}")
    return "; ".join(parts)


# ---------------------------------------------------------------------------------------------
# Faults

class Fault:
    def __init__(self, kind, target, window, **detail):
        self.kind, self.target, self.window, self.detail = kind, target, window, detail
        self.injected_at = None     # coupling.csv rows when injected
        self.note = ""              # what happened

    @property
    def fatal(self):
        return self.kind == "kill" or (self.kind == "stop" and self.detail["long"])

    @property
    def name(self):
        if self.kind == "stop":
            return f"stop-{'long' if self.detail['long'] else 'short'}"
        return self.kind

    def __str__(self):
        where = self.injected_at if self.injected_at is not None else f"({self.window})"
        if "after_resume" in self.detail:
            where = f"resume+{self.detail['after_resume']:.2f}s"
        text = f"{self.name} {self.target}@{where}"
        if self.detail.get("at_checkpoint"):
            text += " in checkpoint"
        if "seconds" in self.detail:
            text += f" {self.detail['seconds']:.2f}s"
        if "cycles" in self.detail:
            text += f" x{self.detail['cycles']}"
        return text + (f" [{self.note}]" if self.note else "")


def plan_faults(rng, scenario):
    """One to three faults at increasing random windows, well inside the run."""
    count = rng.randint(1, 3)
    lo, hi = int(0.05 * scenario.windows), int(0.9 * scenario.windows)
    gap = max(scenario.checkpoint_every, scenario.windows // 10)
    windows = []
    for _ in range(50):
        windows = sorted(rng.sample(range(lo, hi), count))
        if all(b - a >= gap for a, b in zip(windows, windows[1:])):
            break
    else:
        windows = windows[:1]
    faults = []
    if rng.random() < 0.2:  # strangers while the participants join
        faults.append(Fault("garbage", "coordinator", 0, seed=rng.getrandbits(32)))
    for window in windows:
        kind = rng.choices(KINDS, weights=(3, 3, 2, 2))[0]
        peers = [name for name, _ in scenario.participants]
        if kind in ("kill", "stop") and rng.random() < 0.25:
            target = "coordinator"
        else:
            target = rng.choice(peers)
        if kind == "stop":
            long_stop = rng.random() < 0.5
            seconds = (scenario.peer_timeout * rng.uniform(1.5, 2.0) if long_stop
                       else scenario.peer_timeout * rng.uniform(0.05, 0.25))
            faults.append(Fault(kind, target, window, long=long_stop, seconds=seconds))
        elif kind == "slow":
            faults.append(Fault(kind, target, window, cycles=rng.randint(5, 15),
                                seed=rng.getrandbits(32)))
        elif kind == "garbage":
            faults.append(Fault(kind, "coordinator", window, seed=rng.getrandbits(32)))
        else:  # a third of the kills while a checkpoint is being written
            faults.append(Fault(kind, target, window, at_checkpoint=rng.random() < 0.33))
        if faults[-1].fatal and rng.random() < 0.35:
            # A crash again soon after the restart: what the resumed processes do first (cut
            # their files back to the checkpoint) must survive it.
            target = "coordinator" if rng.random() < 0.25 else rng.choice(peers)
            faults.append(Fault("kill", target, window, after_resume=rng.uniform(0.05, 0.6)))
    return faults


def noise_bytes(rng, n):
    return rng.getrandbits(8 * n).to_bytes(n, "little")


class Stranger:
    """Sends a batch of bytes a participant would never send (or must not be believed) to the
    coordinator's endpoint, from a connection that never joined, and counts the answers."""

    def __init__(self, pb, participants):
        self.pb, self.participants = pb, participants

    def envelope(self, sender, sequence=1, version=1, **body):
        e = self.pb.Envelope(version=version, sender=sender, sequence=sequence)
        for field, value in body.items():
            getattr(e, field).CopyFrom(value)
        return e.SerializeToString()

    def hello(self, name, role, major=1, sender=None):
        h = self.pb.Hello(protocol_major=major, protocol_minor=1, participant=name, role=role)
        return self.envelope(sender or name, hello=h)

    def batch(self, rng, handshake):
        """Messages to send: (what, frames()) pairs. In the handshake, no valid Hello for an
        expected name: the first one takes the name (docs/protocol.md, without CURVE)."""
        pb, (name, role) = self.pb, rng.choice(self.participants)
        noise = lambda n: noise_bytes(rng, n)
        menu = [
            ("random bytes", lambda: [noise(rng.randint(1, 300))]),
            ("empty frame", lambda: [b""]),
            ("two frames", lambda: [noise(20), noise(20)]),
            ("three frames", lambda: [self.hello(name, role), b"", noise(5)]),
            ("no body", lambda: [self.envelope(name)]),
            ("Hello of major 2", lambda: [self.hello(name, role, major=2)]),
            ("Hello for a joined name", lambda: [self.hello(name, role)]),
            ("Hello in another role", lambda: [self.hello(name, 3 - role)]),
            ("Hello for an unknown name", lambda: [self.hello("stranger", role)]),
            ("Hello naming another", lambda: [self.hello(name, role, sender="stranger")]),
            ("Hello with control bytes", lambda: [self.hello(name + "\n\x00", role)]),
            ("cut Envelope", lambda: [self.hello(name, role)[:7]]),
            ("WindowDone", lambda: [self.envelope(name, sequence=rng.randint(2, 9999),
                                                  window_done=pb.WindowDone(end_tick=10**9))]),
            ("Error", lambda: [self.envelope(name, sequence=rng.randint(2, 9999), error=pb.Error(
                code=pb.Error.CODE_PARTICIPANT_FAILED, message="soak: a stranger's error"))]),
            ("Shutdown", lambda: [self.envelope("coordinator", shutdown=pb.Shutdown(
                failure=True, reason="soak: a stranger's shutdown"))]),
            ("Heartbeat", lambda: [self.envelope(name, sequence=0, heartbeat=pb.Heartbeat())]),
            ("large frame", lambda: [noise(rng.randint(1 << 20, 3 << 20))]),
        ]
        if handshake:
            menu = [m for m in menu if m[0] != "Hello for a joined name"]
        return [rng.choice(menu) for _ in range(rng.randint(6, 14))]

    def send(self, endpoint, seed, context, handshake=False):
        """Sends a batch from one connection, sometimes a flood (more than the coordinator's
        limits.max_stranger_messages_per_s) or a frame over limits.max_message_bytes from
        another, and bytes that are not ZeroMQ from a plain TCP connection. Returns the count
        of messages sent, of answers, and the answers' error codes."""
        rng = random.Random(seed)
        sent = self.batch(rng, handshake)
        if rng.random() < 0.3:
            sent += [("flood", lambda: [noise_bytes(rng, 8)])] * 150
        if rng.random() < 0.2:
            self.once(context, endpoint, [noise_bytes(rng, (16 << 20) + 1)])
        socket_ = context.socket(zmq.DEALER)
        socket_.setsockopt(zmq.LINGER, 0)
        socket_.connect(endpoint)
        try:
            for _, frames in sent:
                socket_.send_multipart(frames())
            answers, codes = 0, set()
            deadline = time.monotonic() + 0.5
            while time.monotonic() < deadline:
                if socket_.poll(50):
                    frames = socket_.recv_multipart()
                    answers += 1
                    try:
                        e = self.pb.Envelope.FromString(frames[-1])
                        if e.HasField("error"):
                            codes.add(self.pb.Error.Code.Name(e.error.code)[5:].lower())
                    except Exception:
                        codes.add("undecodable")
        finally:
            socket_.close(0)
        # And a connection that does not speak ZeroMQ at all.
        host, port = endpoint[len("tcp://"):].rsplit(":", 1)
        try:
            with socket.create_connection((host, int(port)), timeout=1) as raw:
                raw.sendall(rng.choice([b"GET / HTTP/1.0\r\n\r\n",
                                        b"\xff" * 64 + noise_bytes(rng, 200)]))
        except OSError:
            pass
        return len(sent) + 1, answers, codes

    @staticmethod
    def once(context, endpoint, frames):
        socket_ = context.socket(zmq.DEALER)
        socket_.setsockopt(zmq.LINGER, 2000)
        socket_.connect(endpoint)
        socket_.send_multipart(frames)
        socket_.close()  # lingers until the frame has gone (or 2 s)


# ---------------------------------------------------------------------------------------------
# Runs

class Scenario:
    def __init__(self, name, file):
        self.name, self.path = name, os.path.join(HERE, file)
        with open(self.path) as f:
            self.text = f.read()
        config = yaml.safe_load(self.text)
        coupling = config["coupling"]
        self.windows = round(coupling["end_time_s"] / coupling["macro_step_s"])
        self.checkpoint_every = coupling["checkpoint_every_windows"]
        self.peer_timeout = coupling["peer_timeout_s"]
        # How long a participant may outlive its coordinator: until its peer timeout, or before
        # the Welcome (which tells it the timeout) until its handshake timeout.
        self.orphan_s = max(self.peer_timeout, coupling["handshake_timeout_s"]) + 10
        roles = {"multibody": 1, "soil": 2}  # grainlink.v1.Role
        self.participants = [(p["name"], roles[p["role"]]) for p in config["participants"]]
        self.reference = None       # Results of an uninterrupted run
        self.reference_s = None     # its wall time

    def copy_to(self, folder, port):
        """The scenario with coupling.endpoint on a fixed port (the strangers need it)."""
        text, n = re.subn(r"(?m)^(  endpoint: )tcp://127\.0\.0\.1:\*$",
                          rf"\g<1>tcp://127.0.0.1:{port}", self.text)
        if n != 1:
            sys.exit(f"soak: error: {self.path}: expected one 'endpoint: tcp://127.0.0.1:*' line")
        path = os.path.join(folder, "scenario.yaml")
        with open(path, "w") as f:
            f.write(text)
        return path


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Attempt:
    """One `grainlink run` (or `--resume`) of a run, injecting the faults due in it."""

    def __init__(self, soak, run, resume, start_rows):
        self.soak, self.run = soak, run
        self.log = os.path.join(run.folder, f"attempt_{len(run.attempts) + 1}.log")
        argv = [soak.grainlink, "run", run.config, "--out", run.out, "--progress-interval", "0"]
        if resume:
            argv.append("--resume")
        env = dict(os.environ, OMP_WAIT_POLICY="PASSIVE")
        with open(self.log, "w") as log:
            self.coordinator = subprocess.Popen(argv, cwd=soak.work, stdout=log,
                                                stderr=subprocess.STDOUT, env=env)
        self.pids = {}              # participant name -> pid
        self.discovered_at = None   # when all were found
        self.start_rows = start_rows
        self.ready = False          # coupling.csv cut back to where this attempt starts
        self.csv = os.path.join(run.out, "coupling.csv")
        self.size, self.lines, self.tail = -1, 0, b""
        self.injected = []
        self.rc = None
        self.error = ""

    def rows(self):
        """Windows in coupling.csv (read incrementally)."""
        try:
            size = os.path.getsize(self.csv)
        except OSError:
            return 0
        if size != self.size:
            with open(self.csv, "rb") as f:
                # Count only what was added, unless the file was cut back (a resume does that)
                # and written again: then the bytes before the old end have changed.
                grown = 0 <= self.size < size
                if grown:
                    f.seek(self.size - len(self.tail))
                    grown = f.read(len(self.tail)) == self.tail
                if not grown:
                    f.seek(0)
                    self.lines, self.tail = 0, b""
                data = f.read(size - f.tell())
            self.lines += data.count(b"\n")
            self.tail = (self.tail + data)[-64:]
            self.size = size
        return max(self.lines - 1, 0)

    def writing_checkpoint(self):
        """Whether a checkpoint folder newer than checkpoints/latest exists: one being written."""
        folder = os.path.join(self.run.out, "checkpoints")
        try:
            names = os.listdir(folder)
        except OSError:
            return False
        try:
            with open(os.path.join(folder, "latest")) as f:
                latest = f.read().strip()
        except OSError:
            latest = ""
        return any(n.startswith("window_") and n > latest for n in names)

    def ours(self, pid):
        return self.run.endpoint in proc_argv(pid)

    def discover(self):
        for pid in children_of(self.coordinator.pid):
            argv = proc_argv(pid)
            if self.run.endpoint in argv and "--name" in argv[:-1]:
                self.pids.setdefault(argv[argv.index("--name") + 1], pid)

    def pid_of(self, target):
        if target == "coordinator":
            return self.coordinator.pid if self.coordinator.poll() is None else None
        pid = self.pids.get(target)
        return pid if pid is not None and alive(pid) and self.ours(pid) else None

    def signal(self, target, number):
        pid = self.pid_of(target)
        if pid is not None:
            os.kill(pid, number)
        return pid is not None

    def pause(self, seconds, until_exit=False):
        end = time.monotonic() + seconds
        while time.monotonic() < end and not (until_exit and self.coordinator.poll() is not None):
            time.sleep(min(0.02, max(end - time.monotonic(), 0)))

    def inject(self, fault):
        """Injects the fault; one whose target has already ended is dropped (not counted)."""
        rows = self.rows()
        if fault.kind == "kill":
            if not self.signal(fault.target, signal.SIGKILL):
                return
        elif fault.kind == "stop":
            if not self.signal(fault.target, signal.SIGSTOP):
                return
            try:
                self.pause(fault.detail["seconds"], until_exit=fault.target != "coordinator")
            finally:
                self.signal(fault.target, signal.SIGCONT)
        elif fault.kind == "slow":
            rng = random.Random(fault.detail["seed"])
            for cycle in range(fault.detail["cycles"]):
                if not self.signal(fault.target, signal.SIGSTOP):
                    if cycle == 0:
                        return
                    break
                try:
                    self.pause(rng.uniform(0.05, 0.2))
                finally:
                    self.signal(fault.target, signal.SIGCONT)
                self.pause(rng.uniform(0.02, 0.1))
        elif fault.kind == "garbage":
            sent, answers, codes = self.soak.stranger.send(self.run.endpoint,
                                                           fault.detail["seed"],
                                                           self.soak.context,
                                                           handshake=fault.window == 0)
            fault.note = f"{sent} sent, {answers} answered"
            if codes:
                fault.note += ": " + " ".join(sorted(codes))
            if answers == 0 and self.coordinator.poll() is not None:
                fault.note = ""
                return  # the run ended first: nothing reached it
            if answers == 0:
                self.run.problem(f"{fault.name}: the coordinator answered none of the "
                                 f"stranger's {sent} messages")
        fault.injected_at = rows
        self.injected.append(fault)

    def execute(self, pending, limit_s):
        deadline = time.monotonic() + limit_s
        while self.coordinator.poll() is None:
            if time.monotonic() > deadline:
                self.run.problem(f"attempt {len(self.run.attempts)} still running after "
                                 f"{limit_s:.0f} s (hung): stopped by soak")
                self.soak.stop_all(self)
                break
            rows = self.rows()
            if not self.ready:
                self.ready = rows <= self.start_rows
            if len(self.pids) < len(self.run.scenario.participants):
                self.discover()
                if len(self.pids) == len(self.run.scenario.participants):
                    self.discovered_at = time.monotonic()
            # After a fault that ends the run, nothing more until the next attempt.
            due = bool(pending) and not any(f.fatal for f in self.injected)
            if due and pending[0].window == 0:  # strangers while the participants join
                pass
            elif due and "after_resume" in pending[0].detail:
                due = len(self.run.attempts) > 1 and self.discovered_at is not None and \
                    time.monotonic() - self.discovered_at >= pending[0].detail["after_resume"]
            elif due:
                due = self.ready and rows >= pending[0].window and self.discovered_at is not None
                if due and pending[0].detail.get("at_checkpoint"):
                    due = self.writing_checkpoint()
            if due:
                self.inject(pending.pop(0))
            else:
                time.sleep(0.01)
        self.rc = self.coordinator.wait()
        with open(self.log, errors="replace") as f:
            # grainlink's one error line, or (a participant that ended badly after the last
            # window) "run: participant soil was killed by signal 9 (Killed)"
            lines = [line.strip() for line in f if "error:" in line
                     or line.startswith("run: participant ")]
        self.error = lines[-1] if lines else ""


class Run:
    def __init__(self, soak, index, scenario, faults):
        self.soak, self.index, self.scenario, self.faults = soak, index, scenario, faults
        self.folder = os.path.join(soak.work, "runs", f"{index:03d}-{scenario.name}")
        shutil.rmtree(self.folder, ignore_errors=True)
        os.makedirs(self.folder)
        self.out = os.path.join(self.folder, "out")
        self.endpoint = f"tcp://127.0.0.1:{free_port()}"
        self.config = scenario.copy_to(self.folder, self.endpoint.rsplit(":", 1)[1])
        self.attempts, self.problems, self.kept, self.unreadable = [], [], [], []
        self.recovery_problems = 0
        self.finished = self.identical = False
        self.lost = []
        self.wall_s = 0.0

    def problem(self, text, recovery=True):
        """Notes what went wrong; recovery: it means the run did not recover (a fault not
        detected as it must be, a hang, a process left over, unreadable results)."""
        self.problems.append(text)
        self.recovery_problems += recovery

    def checkpoint(self):
        """Windows before the last complete checkpoint (None: there is none)."""
        latest = os.path.join(self.out, "checkpoints", "latest")
        try:
            with open(latest) as f:
                name = f.read().strip()
        except OSError:
            return None
        if not os.path.isdir(os.path.join(self.out, "checkpoints", name)):
            self.problem(f"checkpoints/latest names {name!r}, which does not exist")
            return None
        return int(name.rsplit("_", 1)[1])

    def judge_failure(self, attempt):
        """An attempt failed: was it a fault that must end the run, reported as such?"""
        fatal = [f for f in attempt.injected if f.fatal]
        if not fatal:
            self.problem(f"attempt {len(self.attempts)} failed after "
                         f"{', '.join(map(str, attempt.injected)) or 'no fault'}: "
                         f"{attempt.error or f'exit status {attempt.rc}'}")
            return
        fault = fatal[0]
        window = re.search(r"failed in window (\d+)", attempt.error)
        fault.note = f"failed in window {window.group(1)}" if window else f"exit {attempt.rc}"
        # How the coordinator noticed: a killed participant by waitpid ("killed by signal 9") or,
        # when a send to it fails first, by its vanished connection ("disconnected"); a stopped
        # one by its missing heartbeats ("silent").
        causes = {"killed by signal 9": "signal 9", "disconnected": "disconnected",
                  "silent for": "silent"}
        cause = next((short for text, short in causes.items() if text in attempt.error), None)
        if cause:
            fault.note += f": {cause}"
        if fault.target == "coordinator":
            expected = attempt.rc != 0
        elif attempt.error.startswith(f"run: participant {fault.target} "):
            fault.note = "after its last window: " + attempt.error[5:]
            expected = fault.kind == "kill" and cause == "signal 9"
        else:
            named = f"participant '{fault.target}'" in attempt.error
            expected = named and cause in (("signal 9", "disconnected") if fault.kind == "kill"
                                           else ("silent",))
        if not expected:
            self.problem(f"{fault}: the run failed with another reason: "
                         f"{attempt.error or f'exit status {attempt.rc}'}")

    def leftovers(self, attempt):
        """Waits for the attempt's participants to end; stops and reports any that stay. Once
        welcomed, a participant must notice a vanished coordinator within its peer timeout.
        Before, one that never heard the coordinator waits for its Welcome as long as its
        handshake timeout (the two-mass node's is the library's 120 s): noted, not a failure."""
        with open(attempt.log, errors="replace") as f:
            welcomed = "coordinator: run " in f.read()
        wait_s = self.scenario.peer_timeout + 10 if welcomed else self.scenario.orphan_s
        limit = time.monotonic() + wait_s
        while time.monotonic() < limit:
            if not any(alive(pid) for pid in attempt.pids.values()):
                return
            time.sleep(0.05)
        names = [n for n, pid in attempt.pids.items() if alive(pid)]
        self.problem(f"participant(s) {', '.join(names)} still running {wait_s:.0f} s after the "
                     f"run ended {'' if welcomed else 'during the handshake '}(killed by soak)",
                     recovery=welcomed)
        self.soak.stop_all(attempt)

    def execute(self):
        began = time.monotonic()
        pending = list(self.faults)
        start_rows, resume = 0, False
        limit_s = 20 * self.scenario.reference_s + 4 * self.scenario.peer_timeout + 60
        for _ in range(len(self.faults) + 3):
            attempt = Attempt(self.soak, self, resume, start_rows)
            self.attempts.append(attempt)
            attempt.execute(pending, limit_s)
            self.leftovers(attempt)
            if attempt.rc == 0:
                self.finished = True
                for fault in attempt.injected:
                    # coupling.csv is written at least at every checkpoint: a fault this early
                    # came before the participants' last window.
                    early = fault.injected_at < self.scenario.windows - 2 * \
                        self.scenario.checkpoint_every
                    if fault.fatal and early:
                        self.problem(f"{fault}: the run finished as if nothing had happened")
                    elif fault.fatal:
                        fault.note = "came after the last window: the run finished"
                break
            self.judge_failure(attempt)
            kept = Results(self.out)
            self.unreadable += [f"after attempt {len(self.attempts)}: {u}"
                                for u in kept.unreadable]
            self.kept.append(kept)
            start_rows = self.checkpoint()
            resume = start_rows is not None
            start_rows = start_rows or 0
        else:
            self.problem(f"not finished after {len(self.attempts)} attempts")
        final = Results(self.out)
        self.unreadable += [f"at the end: {u}" for u in final.unreadable]
        for text in self.unreadable:
            self.problem(f"unreadable {text}")
        if self.finished:
            diff = differences(self.scenario.reference, final)
            self.identical = not diff
            if diff:
                self.problem("results differ from the uninterrupted run: " + "; ".join(diff[:4]),
                             recovery=False)
                self.soak.check_determinism(self.scenario, self)
        for kept in self.kept:
            self.lost += lost_records(kept, final)
        if self.lost:
            self.problem(f"lost records: {describe_lost(self.lost)}", recovery=False)
        self.wall_s = time.monotonic() - began
        if self.recovered and self.identical and not self.lost:
            shutil.rmtree(self.out, ignore_errors=True)  # keep the logs, not the results

    @property
    def recovered(self):
        return self.finished and not self.recovery_problems


class Soak:
    def __init__(self, args):
        self.work = os.path.abspath(args.work)
        self.deadline = time.monotonic() + 60 * args.minutes
        for sub in ("runs", "reference", "proto", "bin"):  # packings/ is kept: a cache
            shutil.rmtree(os.path.join(self.work, sub), ignore_errors=True)
        os.makedirs(os.path.join(self.work, "proto"))
        self.grainlink = self.install(os.path.abspath(args.grainlink))
        self.rng = random.Random(args.seed)
        self.context = zmq.Context()
        self.stranger = Stranger(self.protobuf(), None)
        self.scenarios = [Scenario(name, file) for name, file in SCENARIOS
                          if name in args.scenario]

    def install(self, grainlink):
        """A copy of grainlink and the programs built beside it (the participants it starts)
        in the work folder, so that a rebuild during the soak changes nothing under test."""
        folder = os.path.join(self.work, "bin")
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
        source = os.path.dirname(grainlink)
        for name in os.listdir(source):
            path = os.path.join(source, name)
            if (name == os.path.basename(grainlink) or name.startswith("grainlink-")) and \
                    os.path.isfile(path) and os.access(path, os.X_OK):
                shutil.copy2(path, folder)
        copy = os.path.join(folder, os.path.basename(grainlink))
        done = subprocess.run([copy, "--version"], capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f"soak: error: {grainlink} --version failed (being rebuilt?): "
                     f"{done.stderr.strip()}")
        print(f"soak: testing a copy of {grainlink} ({done.stdout.strip()}) and "
              f"{', '.join(sorted(n for n in os.listdir(folder) if n.startswith('grainlink-')))}",
              flush=True)
        return copy

    def protobuf(self):
        """grainlink.v1's Python classes, generated into the work folder."""
        out = os.path.join(self.work, "proto")
        done = subprocess.run(["protoc", "-I", os.path.join(REPOSITORY, "proto"),
                               "--python_out", out, "grainlink/v1/coupling.proto"],
                              capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f"soak: error: protoc failed: {done.stderr.strip()}")
        sys.path.insert(0, out)
        from grainlink.v1 import coupling_pb2
        return coupling_pb2

    def stop_all(self, attempt):
        """Kills the attempt's processes (ours: the coordinator and the participants found)."""
        for name in ["coordinator", *attempt.pids]:
            pid = attempt.pid_of(name)
            if pid is not None:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        for pid in attempt.pids.values():
            alive(pid)

    def straight(self, scenario, folder):
        """An uninterrupted run of the scenario: its results and wall time."""
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
        config = scenario.copy_to(folder, free_port())
        began = time.monotonic()
        done = subprocess.run([self.grainlink, "run", config, "--out", os.path.join(folder, "out"),
                               "--progress-interval", "0"], cwd=self.work, capture_output=True,
                              text=True, env=dict(os.environ, OMP_WAIT_POLICY="PASSIVE"),
                              timeout=900)
        if done.returncode != 0:
            sys.exit(f"soak: error: the uninterrupted {scenario.name} run failed:\n"
                     + (done.stdout + done.stderr)[-2000:])
        return Results(os.path.join(folder, "out")), time.monotonic() - began

    def check_determinism(self, scenario, run):
        """After a difference: does a second uninterrupted run agree with the first?"""
        again, _ = self.straight(scenario, os.path.join(self.work, "reference",
                                                        scenario.name + "-again"))
        diff = differences(scenario.reference, again)
        run.problem("a second uninterrupted run " + ("differs too (the scenario is not "
                                                     "deterministic)" if diff else
                                                     "is identical to the first"), recovery=False)

    def execute(self):
        for scenario in self.scenarios:
            scenario.reference, scenario.reference_s = self.straight(
                scenario, os.path.join(self.work, "reference", scenario.name))
            scenario.reference_s = max(scenario.reference_s, 0.5)
            print(f"soak: uninterrupted {scenario.name} run: {scenario.windows} windows in "
                  f"{scenario.reference_s:.1f} s, {scenario.reference.records} records",
                  flush=True)
        runs = []
        while True:
            scenario = self.scenarios[len(runs) % len(self.scenarios)]
            faults = plan_faults(self.rng, scenario)
            if time.monotonic() + expected_s(scenario, faults) > self.deadline:
                break
            self.stranger.participants = scenario.participants
            run = Run(self, len(runs) + 1, scenario, faults)
            runs.append(run)
            try:
                run.execute()
            finally:
                for attempt in run.attempts:
                    if attempt.coordinator.poll() is None:
                        self.stop_all(attempt)
            print(f"soak: run {run.index} ({scenario.name}): "
                  f"{'recovered' if run.recovered else 'NOT RECOVERED'}, "
                  f"{len(run.attempts)} attempt(s), {run.wall_s:.1f} s", flush=True)
            for text in run.problems:
                print(f"  {text}", flush=True)
        return runs


def expected_s(scenario, faults):
    """About how long a run with these faults takes: the run, a share of it again per restart,
    the stops, and a peer timeout per failure (participants that outlive a killed coordinator)."""
    fatal = sum(f.fatal for f in faults)
    return (scenario.reference_s * (1 + 0.5 * fatal) + fatal * (scenario.peer_timeout + 1) + 2
            + sum(f.detail.get("seconds", 0) + 0.2 * f.detail.get("cycles", 0) for f in faults))


def report(runs):
    injected = [f for run in runs for f in run.faults if f.injected_at is not None]
    count = {kind: sum(f.kind == kind for f in injected) for kind in KINDS}
    recovered = sum(run.recovered for run in runs)
    identical = sum(run.identical for run in runs)
    lost = sum(len(run.lost) for run in runs)
    print(f"soak: runs {len(runs)}, faults injected {len(injected)} (kill {count['kill']}, "
          f"stop {count['stop']}, garbage {count['garbage']}, slow {count['slow']}), "
          f"recovered {recovered}, results identical {identical}/{len(runs)}, "
          f"lost records {lost}")
    print(f"{'run':>3}  {'scenario':<8}  {'attempts':>8}  {'recovered':<9}  {'readable':<8}  "
          f"{'identical':<9}  {'lost':>4}  {'wall_s':>6}  faults (kind target@window [outcome])")
    for run in runs:
        faults = "; ".join(str(f) for f in run.faults if f.injected_at is not None) or "none"
        print(f"{run.index:>3}  {run.scenario.name:<8}  {len(run.attempts):>8}  "
              f"{'yes' if run.recovered else 'NO':<9}  {'NO' if run.unreadable else 'yes':<8}  "
              f"{'yes' if run.identical else 'NO':<9}  "
              f"{len(run.lost):>4}  {run.wall_s:>6.1f}  {faults}")
    for run in runs:
        for text in run.problems:
            print(f"run {run.index}: {text}")
    return bool(runs) and recovered == len(runs) and identical == len(runs) and lost == 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("grainlink", help="the grainlink executable (BUILD/apps/grainlink)")
    parser.add_argument("--minutes", type=float, default=5.0, help="bound on the whole soak")
    parser.add_argument("--work", default="soak", help="work folder (its runs/ are replaced)")
    parser.add_argument("--scenario", action="append", choices=[n for n, _ in SCENARIOS],
                        help="only this scenario (repeatable; default: all, in turn)")
    parser.add_argument("--seed", type=int, default=None,
                        help="seed of the random choices (default: from the clock, printed)")
    args = parser.parse_args()
    args.scenario = args.scenario or [n for n, _ in SCENARIOS]
    if args.seed is None:
        args.seed = int(time.time()) % 100000
    if not os.access(args.grainlink, os.X_OK):
        sys.exit(f"soak: error: {args.grainlink} is not an executable")
    os.makedirs(args.work, exist_ok=True)
    become_subreaper()
    print(f"soak: seed {args.seed}, {args.minutes:g} minutes, work folder {args.work}", flush=True)
    soak = Soak(args)
    runs = soak.execute()
    sys.exit(0 if report(runs) else 1)


if __name__ == "__main__":
    main()
