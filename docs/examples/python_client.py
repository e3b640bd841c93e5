#!/usr/bin/env python3
"""A fluidcast client in Python: the steps of docs/protocol.md, in one file.

It asks the server what it offers, opens a session, acknowledges every frame, drags a finger
across the fluid and measures touch-to-photon latency, saves the last frame as a JPEG, and says
goodbye. The protocol's modules are generated from the .proto first; on Debian 12 (packages
python3-grpcio, python3-protobuf, protobuf-compiler-grpc), from the repository's root:

  protoc -I proto --python_out=OUT --grpc_python_out=OUT \\
    --plugin=protoc-gen-grpc_python=/usr/bin/grpc_python_plugin proto/fluidcast/v1/fluidcast.proto
  PYTHONPATH=OUT docs/examples/python_client.py --server 127.0.0.1:50051 --jpeg last.jpg

Exit status: 0 after a goodbye the server answered with OK; 1 when the stream ended otherwise
(the status and the server's sentence are printed); 2 for a bad argument.
"""
import argparse
import itertools
import queue
import sys
import time

import grpc
from fluidcast.v1 import fluidcast_pb2 as fc
from fluidcast.v1 import fluidcast_pb2_grpc as fc_grpc

# The drag: a finger down at this frame, moving across the frame until the last, then lifted.
DRAG_FIRST, DRAG_LAST = 10, 50


def finger(frame_count):
    """The pointer event for this frame of the drag, or None: x goes 0.2 to 0.8, y stays 0.6."""
    if not DRAG_FIRST <= frame_count <= DRAG_LAST:
        return None
    phase = {DRAG_FIRST: fc.PointerEvent.DOWN, DRAG_LAST: fc.PointerEvent.UP}.get(
        frame_count, fc.PointerEvent.MOVE)
    x = 0.2 + 0.6 * (frame_count - DRAG_FIRST) / (DRAG_LAST - DRAG_FIRST)
    return fc.PointerEvent(pointer_id=0, phase=phase, x=x, y=0.6)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of its gRPC")
    parser.add_argument("--token", default="", help="the server's token, when it asks for one")
    parser.add_argument("--particles", type=int, default=0, help="0: the server's default")
    parser.add_argument("--frames", type=int, default=90, help="frames to watch before goodbye")
    parser.add_argument("--jpeg", help="where to save the last frame")
    args = parser.parse_args()
    if args.frames <= DRAG_LAST:
        parser.error(f"--frames must be more than {DRAG_LAST}, the drag's last frame")

    with grpc.insecure_channel(args.server) as channel:
        try:
            return run(fc_grpc.FluidcastStub(channel), args)
        except grpc.RpcError as error:  # the server's status, and its sentence saying why
            print(f"{args.server}: {error.code().name}: {error.details()}", file=sys.stderr)
            return 1


def run(stub, args):
    """One session, as docs/protocol.md walks through it; returns the exit status."""
    info = stub.GetServerInfo(fc.GetServerInfoRequest(), timeout=10)
    print(f"fluidcast-server {info.version} on {info.device}: scenes {', '.join(info.rules.scenes)};"
          f" at most {info.limits.max_particles} particles and "
          f"{info.limits.max_width}x{info.limits.max_height} pixels")

    # What goes to the server, in order; None closes our side (the goodbye).
    outgoing = queue.Queue()
    event_ids = itertools.count(1)
    sent_at = {}  # input event id -> when it was sent

    def send_input(**kind):
        event_id = next(event_ids)
        sent_at[event_id] = time.monotonic()
        outgoing.put(fc.ClientMessage(event_id=event_id, **kind))

    def messages():
        while (message := outgoing.get()) is not None:
            yield message

    outgoing.put(fc.ClientMessage(hello=fc.Hello(
        token=args.token, viewport=fc.Viewport(width=320, height=240),
        create=fc.NewSession(particles=args.particles))))
    frames, last, latencies_ms = 0, None, []
    try:
        for message in stub.Stream(messages()):
            kind = message.WhichOneof("kind")
            if kind == "welcome":
                state, access = message.welcome.state, message.welcome.access
                print(f"session {message.welcome.session_id}: {state.particles} particles, "
                      f"{state.scene}, {state.solver}; others may watch with {access.view_key}")
            elif kind == "session":
                print(f"the session changed: {message.session.scene}, "
                      f"{message.session.particles} particles, paused {message.session.paused}")
            elif kind == "frame":
                frame, last = message.frame, message.frame
                frames += 1
                outgoing.put(fc.ClientMessage(ack=fc.FrameAck(sequence=frame.sequence)))
                now = time.monotonic()
                for event_id in [e for e in sent_at if e <= frame.input_event_id]:
                    latencies_ms.append(1000 * (now - sent_at.pop(event_id)))
                if (pointer := finger(frames)) is not None:
                    send_input(pointer=pointer)
                if frames == args.frames:
                    outgoing.put(None)
    finally:
        outgoing.put(None)  # ends messages() however the stream ended
    if frames < args.frames:
        print(f"the server ended the stream after {frames} frames, before the goodbye",
              file=sys.stderr)
        return 1

    latencies_ms.sort()
    median = latencies_ms[len(latencies_ms) // 2] if latencies_ms else float("nan")
    print(f"{frames} frames, the last {last.width}x{last.height} at t = {last.sim_time:.2f} s "
          f"({last.renderer}); touch-to-photon median {median:.1f} ms over {len(latencies_ms)} "
          f"touches; goodbye answered with OK")
    if args.jpeg:
        with open(args.jpeg, "wb") as out:
            out.write(last.jpeg)
    return 0


if __name__ == "__main__":
    sys.exit(main())
