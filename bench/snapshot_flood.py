#!/usr/bin/env python3
"""Many snapshot calls at once: a session of PARTICLES, then CONNECTIONS connections each calling
GetSnapshot on it in a loop for SECONDS (each its own HTTP/2 connection), acknowledging the
session's frames meanwhile. Prints how many were answered and the errors by status.

Usage: PYTHONPATH=MODULES snapshot_flood.py HOST:PORT PARTICLES CONNECTIONS SECONDS
(MODULES: the protocol's Python modules, generated as docs/examples/python_client.py says.)
"""
import queue
import sys
import threading
import time

import grpc
from fluidcast.v1 import fluidcast_pb2 as fc
from fluidcast.v1 import fluidcast_pb2_grpc as fc_grpc


def main():
    server, particles, connections, seconds = (sys.argv[1], int(sys.argv[2]), int(sys.argv[3]),
                                               float(sys.argv[4]))
    outgoing = queue.Queue()
    outgoing.put(fc.ClientMessage(hello=fc.Hello(viewport=fc.Viewport(width=64, height=48),
                                                 create=fc.NewSession(particles=particles))))

    def messages():
        while (message := outgoing.get()) is not None:
            yield message

    with grpc.insecure_channel(server) as channel:
        stream = fc_grpc.FluidcastStub(channel).Stream(messages())
        key = next(stream).welcome.access.view_key

        def acknowledge():
            try:
                for message in stream:
                    if message.HasField("frame"):
                        outgoing.put(fc.ClientMessage(ack=fc.FrameAck(sequence=message.frame.sequence)))
            except grpc.RpcError:
                pass

        threading.Thread(target=acknowledge, daemon=True).start()
        stop = threading.Event()
        answered = [0] * connections
        errors = {}

        def call(k):
            # A subchannel pool of its own: a connection of its own.
            with grpc.insecure_channel(server, options=[("grpc.use_local_subchannel_pool", 1)]) as own:
                stub = fc_grpc.FluidcastStub(own)
                while not stop.is_set():
                    try:
                        stub.GetSnapshot(fc.SnapshotRequest(key=key), timeout=30)
                        answered[k] += 1
                    except grpc.RpcError as error:
                        errors[error.code().name] = errors.get(error.code().name, 0) + 1
                        time.sleep(0.01)

        callers = [threading.Thread(target=call, args=(k,)) for k in range(connections)]
        for caller in callers:
            caller.start()
        time.sleep(seconds)
        stop.set()
        for caller in callers:
            caller.join()
        outgoing.put(None)
    print(f"snapshots answered: {sum(answered)} in {seconds:g} s over {connections} connections; "
          f"errors: {errors or 'none'}")


if __name__ == "__main__":
    main()
