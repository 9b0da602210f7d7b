#!/usr/bin/python3
"""Mass 1 of the two-mass example as a grainlink participant, in plain Python.

This is the multibody side of examples/two_mass (MassOneSide in TwoMassModel.hpp): mass 1 hangs
on spring k1 and damper c1 to ground and is pushed by the coupling force the coordinator sends
each window. It speaks the grainlink.v1 protocol (proto/grainlink/v1/coupling.proto) directly,
with only ZeroMQ and protobuf, to show what any third-party code (a Python multibody code, a
Julia or Matlab bridge) has to do to take part in a coupled run:

    Hello  ->            join: name, role, the bodies we integrate, their initial states
           <- Welcome    the run: tick length, windows, scheme, heartbeat settings, restore point
           <- AdvanceTo  integrate one window under the given wrench (maybe save or roll back)
    WindowDone ->        the bodies' states at the window end, and the work the wrench did
           <- Checkpoint write our state into a folder
    CheckpointDone ->
           <- Shutdown   the run is over (failure = false) or was stopped (failure = true)

Heartbeats travel on a second connection from a thread, so a long window never looks like a
dead process. See README.md beside this file for how to run it and what each field means.

Requires: Debian's python3-zmq and python3-protobuf, and the classes CMake generates from the
.proto into <build>/python (give that folder with --python-protocol-dir or in PYTHONPATH).
Exit status: 0 when the coordinator ends the run normally, 1 with one line on stderr otherwise.
"""

import argparse
import math
import os
import sys
import threading
import time

import zmq
from google.protobuf.message import DecodeError


# --------------------------------------------------------------------------------------------
# The physics: replace this class with your own multibody code.


class MassOne:
    """Mass 1 on a spring and a damper to ground, under a force held constant over a window.

    The same numbers and the same RK4 sub-stepping as MassOneSide in
    examples/two_mass/TwoMassModel.hpp, written in the same arithmetic order, so a run with this
    script gives the C++ node's results to the last bit.
    """

    name = "mass1"
    mass_kg = 1.0
    spring_N_m = 40.0  # k1
    damper_N_s_m = 0.1  # c1
    max_substep_s = 1e-4  # RK4 sub-steps inside a window are at most this long

    def __init__(self, x_m=0.1):
        self.x_m = x_m
        self.v_m_s = 0.0
        self.saved = (self.x_m, self.v_m_s)

    def advance(self, window_s, force_N):
        """Integrates over window_s under force_N; returns the work that force did [J]."""
        x0 = self.x_m
        n = math.ceil(window_s / self.max_substep_s - 1e-9)
        h = window_s / n
        x, v = self.x_m, self.v_m_s

        def accel(x, v):
            return (force_N - self.spring_N_m * x - self.damper_N_s_m * v) / self.mass_kg

        for _ in range(n):  # classic RK4 on (x, v)
            k1x, k1v = v, accel(x, v)
            k2x = v + 0.5 * h * k1v
            k2v = accel(x + 0.5 * h * k1x, k2x)
            k3x = v + 0.5 * h * k2v
            k3v = accel(x + 0.5 * h * k2x, k3x)
            k4x = v + h * k3v
            k4v = accel(x + h * k3x, k4x)
            x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
            v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        self.x_m, self.v_m_s = x, v
        return force_N * (self.x_m - x0)  # the force is constant over the window

    # Implicit coupling repeats a window until it converges: save at its start, roll back.
    def save(self):
        self.saved = (self.x_m, self.v_m_s)

    def restore(self):
        self.x_m, self.v_m_s = self.saved

    # Checkpoints: the same text file the C++ node writes ("x v", 17 digits: exact round trip).
    def write(self, path):
        with open(path, "w") as f:
            f.write(f"{self.x_m:.17g} {self.v_m_s:.17g}\n")

    def read(self, path):
        with open(path) as f:
            self.x_m, self.v_m_s = (float(word) for word in f.read().split())


# --------------------------------------------------------------------------------------------
# The protocol: this part stays the same for any multibody code.


class CouplingError(Exception):
    """The run cannot go on; the message says why."""


class StoppedByCoordinator(CouplingError):
    """The coordinator stopped the run or refused us: it knows already, so we tell it nothing."""


def import_protocol(directory):
    """The classes protoc generated from grainlink/v1/coupling.proto (module coupling_pb2)."""
    if directory:
        sys.path.insert(0, os.path.abspath(directory))
    try:
        from grainlink.v1 import coupling_pb2
    except ImportError as error:
        raise CouplingError(
            f"cannot import grainlink.v1.coupling_pb2 ({error}): build the project, then pass "
            "--python-protocol-dir <build>/python or put that folder in PYTHONPATH"
        ) from None
    return coupling_pb2


class Link:
    """Our two connections to the coordinator, and the envelope rules of grainlink.v1.

    Every message is one Envelope: our protocol major version, our name, a sequence number
    (1 for the Hello, then +1 per message; heartbeats carry 0 and are not counted), the window
    index it belongs to, and exactly one body.
    """

    PROTOCOL_MAJOR = 1  # must equal the coordinator's; a different major is refused
    PROTOCOL_MINOR = 0

    def __init__(self, pb, endpoint, name):
        self.pb, self.endpoint, self.name = pb, endpoint, name
        self.context = zmq.Context()
        self.main = self.context.socket(zmq.DEALER)  # commands and replies
        self.main.setsockopt(zmq.LINGER, 2000)  # a last message still leaves on exit
        self.main.connect(endpoint)
        self.sent = 0  # sequence of our last message
        self.received = 0  # sequence of the coordinator's last message
        self.heartbeat_interval_s = 0.2  # until the Welcome gives the run's values
        self.peer_timeout_s = 5.0
        self.last_heard = None  # time.monotonic() of the last sign of life from the coordinator
        self.joined = False  # True once the Welcome came
        self.stop_heartbeats = threading.Event()
        self.heartbeat_thread = None
        self.shutdown_reason = None  # set by the heartbeat thread

    def envelope(self, window, **body):
        return self.pb.Envelope(
            version=self.PROTOCOL_MAJOR, sender=self.name, window=window, **body
        )

    def send(self, window, **body):
        """Sends one message, e.g. send(3, window_done=pb.WindowDone(...))."""
        self.sent += 1
        message = self.envelope(window, **body)
        message.sequence = self.sent
        self.main.send(message.SerializeToString())

    def receive(self, waiting_for, timeout_s=math.inf):
        """The coordinator's next message, checked: well formed, our version, in order."""
        start = time.monotonic()
        while not self.main.poll(50):
            now = time.monotonic()
            if self.shutdown_reason is not None:
                raise CouplingError(f"the coordinator stopped the run: {self.shutdown_reason}")
            # Silence counts once the coordinator has answered (it may start after us).
            if self.last_heard is not None and now - self.last_heard > self.peer_timeout_s:
                raise CouplingError(
                    f"the coordinator has been silent for {now - self.last_heard:.3g} s while "
                    f"waiting for {waiting_for} (it stopped, or the connection is down)"
                )
            if now - start > timeout_s:
                raise CouplingError(
                    f"no {waiting_for} from the coordinator at {self.endpoint} within "
                    f"{timeout_s:g} s"
                )
        data = self.main.recv()
        self.last_heard = time.monotonic()
        message = self.pb.Envelope()
        try:
            message.ParseFromString(data)
        except DecodeError:
            raise CouplingError(
                f"malformed message from the coordinator ({len(data)} bytes that are not a "
                "grainlink.v1.Envelope)"
            ) from None
        if message.version != self.PROTOCOL_MAJOR:
            raise CouplingError(
                f"the coordinator speaks protocol major version {message.version}, "
                f"this side speaks {self.PROTOCOL_MAJOR}"
            )
        if message.WhichOneof("body") is None:
            raise CouplingError("message from the coordinator has no body")
        if message.sequence != self.received + 1:
            raise CouplingError(
                f"message {message.sequence} from the coordinator arrived after "
                f"{self.received} (out of order)"
            )
        self.received = message.sequence
        return message

    def start_heartbeats(self):
        """A thread that sends a Heartbeat every interval on its own connection. The coordinator
        answers each with its own Heartbeat: that is how we notice a coordinator that has gone
        away."""

        def beat():
            socket = self.context.socket(zmq.DEALER)
            socket.setsockopt(zmq.LINGER, 0)
            socket.connect(self.endpoint)
            heartbeat = self.envelope(0, heartbeat=self.pb.Heartbeat()).SerializeToString()
            while not self.stop_heartbeats.is_set():
                try:
                    socket.send(heartbeat, zmq.NOBLOCK)
                except zmq.Again:
                    pass  # not connected yet
                sent = time.monotonic()
                # The interval is read each turn: the Welcome may shorten it meanwhile.
                while (not self.stop_heartbeats.is_set()
                       and time.monotonic() - sent < self.heartbeat_interval_s):
                    if socket.poll(min(50, int(self.heartbeat_interval_s * 1000) + 1)):
                        reply = self.pb.Envelope()
                        reply.ParseFromString(socket.recv())
                        self.last_heard = time.monotonic()
                        # A run that fails before we joined is announced on this connection.
                        if reply.WhichOneof("body") == "shutdown":
                            self.shutdown_reason = reply.shutdown.reason
            socket.close()

        self.heartbeat_thread = threading.Thread(target=beat, daemon=True)
        self.heartbeat_thread.start()

    def fail(self, reason):
        """Tells the coordinator we cannot go on (it then stops the run everywhere)."""
        if not self.joined:
            return  # it would not listen; a run without us fails at its handshake timeout
        error = self.pb.Error(code=self.pb.Error.CODE_PARTICIPANT_FAILED, message=reason)
        try:
            self.send(0, error=error)
        except zmq.ZMQError:
            pass  # best effort: the coordinator also notices our missing heartbeats

    def close(self):
        self.stop_heartbeats.set()
        if self.heartbeat_thread:
            self.heartbeat_thread.join()
        self.main.close()
        self.context.term()


def body_state(pb, body):
    """A BodyState in the world frame. The coordinator requires a unit orientation."""
    return pb.BodyState(
        body=body.name,
        position_m=pb.Vec3(x=body.x_m),
        orientation=pb.Quaternion(w=1.0),
        linear_velocity_m_s=pb.Vec3(x=body.v_m_s),
        angular_velocity_rad_s=pb.Vec3(),
        frame=pb.FRAME_WORLD,
    )


def stopped(message):
    """The error for a message that ends the run from the coordinator's side."""
    kind = message.WhichOneof("body")
    if kind == "shutdown":
        return StoppedByCoordinator("the coordinator stopped the run: " + message.shutdown.reason)
    if kind == "error":
        return StoppedByCoordinator("the coordinator refused: " + message.error.message)
    return CouplingError(f"unexpected {kind} from the coordinator")


def run(link, body):
    """The participant's life: join, then obey the coordinator until it says Shutdown."""
    pb = link.pb

    # 1. Join. The coordinator checks the name against the run's participants, the role against
    #    its configuration, and needs an initial state for every body we provide.
    hello = pb.Hello(
        protocol_major=link.PROTOCOL_MAJOR,
        protocol_minor=link.PROTOCOL_MINOR,
        participant=link.name,
        role=pb.ROLE_MULTIBODY,
        provides=[pb.BodyDescription(name=body.name, mass=pb.MassProperties(mass_kg=body.mass_kg))],
        capabilities=pb.Capabilities(rollback=True, checkpoint=True),
        initial_states=pb.BodyStates(tick=0, states=[body_state(pb, body)]),
    )
    link.send(0, hello=hello)
    link.start_heartbeats()
    message = link.receive("Welcome", timeout_s=120.0)
    if message.WhichOneof("body") != "welcome":
        raise stopped(message)
    welcome = message.welcome
    link.joined = True
    link.heartbeat_interval_s = welcome.heartbeat_interval_ms / 1000.0
    link.peer_timeout_s = welcome.peer_timeout_ms / 1000.0
    state_file = link.name + ".state"
    expected_window = 0
    if welcome.HasField("restore"):  # the run continues from a checkpoint
        body.read(os.path.join(welcome.restore.checkpoint_directory, state_file))
        expected_window = welcome.restore.window

    # 2. Obey.
    while True:
        message = link.receive("the next command")
        kind = message.WhichOneof("body")

        if kind == "advance_to":
            advance = message.advance_to
            # Windows come in order; implicit coupling repeats the previous one (iteration > 0).
            repeat = advance.iteration > 0 and message.window + 1 == expected_window
            if message.window != expected_window and not repeat:
                raise CouplingError(
                    f"AdvanceTo for window {message.window} while window {expected_window} "
                    "was expected"
                )
            expected_window = message.window + 1
            if advance.restore_state:
                body.restore()
            if advance.save_state:
                body.save()
            # Times are integer ticks; the window length is exact as ticks x tick_s.
            window_s = (advance.end_tick - advance.start_tick) * welcome.tick_s
            wrench = next((w for w in advance.wrenches.wrenches if w.body == body.name), None)
            if wrench is None:
                raise CouplingError(f"AdvanceTo has no wrench for body '{body.name}'")
            work_J = body.advance(window_s, wrench.force_N.x)  # this 1-D body moves along x
            done = pb.WindowDone(
                end_tick=advance.end_tick,
                iteration=advance.iteration,
                states=pb.BodyStates(tick=advance.end_tick, states=[body_state(pb, body)]),
                work=[pb.BodyWork(body=body.name, work_J=work_J)],
            )
            link.send(message.window, window_done=done)

        elif kind == "checkpoint":
            directory = message.checkpoint.checkpoint_directory
            os.makedirs(directory, exist_ok=True)
            body.write(os.path.join(directory, state_file))
            window = message.checkpoint.window
            link.send(window, checkpoint_done=pb.CheckpointDone(window=window))

        elif kind == "shutdown" and not message.shutdown.failure:
            return  # the run reached its end

        else:
            raise stopped(message)


def main(argv=None, link_class=Link):
    """Command line entry; the tests pass a misbehaving link_class."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--endpoint", default="tcp://127.0.0.1:5555",
                        help="the coordinator's endpoint (default: %(default)s)")
    parser.add_argument("--name", default="mbs",
                        help="participant name, as in the run's YAML (default: %(default)s)")
    parser.add_argument("--python-protocol-dir",
                        help="folder holding grainlink/v1/coupling_pb2.py (<build>/python); "
                             "default: found through PYTHONPATH")
    args = parser.parse_args(argv)

    body = MassOne()
    link = None
    try:
        pb = import_protocol(args.python_protocol_dir)
        link = link_class(pb, args.endpoint, args.name)
        run(link, body)
    except Exception as error:  # our own failures and the model's: one line, exit status 1
        reason = str(error)
        if not isinstance(error, CouplingError):
            reason = f"{type(error).__name__}: {reason}"  # e.g. "ValueError: math domain error"
        if link and not isinstance(error, StoppedByCoordinator):
            link.fail(reason)
        print(f"{args.name}: error: participant '{args.name}': {reason}", file=sys.stderr)
        return 1
    finally:
        if link:
            link.close()
    print(f"{args.name}: done, x = {body.x_m:.9f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
