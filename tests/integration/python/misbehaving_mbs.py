#!/usr/bin/python3
"""The Python example participant made to break the protocol, for the coordinator's fault tests.

    misbehaving_mbs.py --fault wrong-version ...        speaks protocol major version 2
    misbehaving_mbs.py --fault garbage --at-window N    sends bytes that are no Envelope in place
                                                        of window N's WindowDone
    misbehaving_mbs.py --fault model-error --at-window N  the model raises in window N
                                                          (explicit coupling: one pass a window)

The other arguments go to examples/python/two_mass_multibody.py, which does all the rest.
"""
import argparse
import itertools
import os
import sys

from google.protobuf.message import DecodeError

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "..", "..", "examples", "python"))
import two_mass_multibody as example  # noqa: E402

# Starts with 0xff bytes: a field tag beyond the largest field number, so no protobuf parser
# reads it as an Envelope (checked in main, so the test cannot pass for another reason).
GARBAGE = b"\xff\xff\xff\xff\xff garbage, not a grainlink.v1.Envelope"


class WrongVersionLink(example.Link):
    PROTOCOL_MAJOR = 2


def garbage_link(at_window):
    class GarbageLink(example.Link):
        def send(self, window, **body):
            if "window_done" in body and window == at_window:
                self.main.send(GARBAGE)
            else:
                super().send(window, **body)

    return GarbageLink


def failing_model(at_window):
    advance = example.MassOne.advance
    window = itertools.count()

    def failing_advance(self, window_s, force_N):
        if next(window) == at_window:
            raise ValueError("simulated failure of the model")
        return advance(self, window_s, force_N)

    example.MassOne.advance = failing_advance


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--fault", choices=["wrong-version", "garbage", "model-error"], required=True)
    parser.add_argument("--at-window", type=int, default=5)
    parser.add_argument("--python-protocol-dir")
    args, rest = parser.parse_known_args()
    if args.python_protocol_dir:
        rest += ["--python-protocol-dir", args.python_protocol_dir]
    if args.fault == "wrong-version":
        return example.main(rest, WrongVersionLink)
    if args.fault == "model-error":
        failing_model(args.at_window)
        return example.main(rest)
    try:
        example.import_protocol(args.python_protocol_dir).Envelope().ParseFromString(GARBAGE)
        sys.exit("misbehaving_mbs: the garbage parses as an Envelope; choose other bytes")
    except DecodeError:
        pass
    return example.main(rest, garbage_link(args.at_window))


if __name__ == "__main__":
    sys.exit(main())
