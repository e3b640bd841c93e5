#!/usr/bin/env node
// Holds gRPC messages half-sent on many HTTP/2 streams to a fluidcast-server: each PutSnapshot
// says its message is DECLARED bytes long, then sends all but its last byte as fast as the
// server's flow control lets it, and waits. Prints what it has sent each second; runs until
// killed. tests/cli/grpc_memory_test.sh runs it; bench/results/grpc-partial-messages-cpu-2026-12-01.md
// has what servers held.
// Usage: tests/cli/grpc_partial_messages.js GRPC_PORT CONNECTIONS STREAMS_EACH DECLARED_BYTES
"use strict";
const http2 = require("node:http2");
const [port, connections, streams, declared] = process.argv.slice(2).map(Number);
let sent = 0, closed = 0, opened = 0;
const chunk = Buffer.alloc(1 << 16, 0x55);
for (let c = 0; c < connections; ++c) {
  const session = http2.connect(`http://127.0.0.1:${port}`);
  session.on("error", () => {});
  for (let s = 0; s < streams; ++s) {
    const request = session.request({
      ":method": "POST", ":path": "/fluidcast.v1.Fluidcast/PutSnapshot",
      "content-type": "application/grpc", te: "trailers",
    });
    ++opened;
    request.on("error", () => {});
    request.on("close", () => ++closed);
    const prefix = Buffer.alloc(5);
    prefix.writeUInt32BE(declared, 1);
    request.write(prefix);
    let left = declared - 1;
    const pump = () => {
      while (left > 0) {
        const n = Math.min(left, chunk.length);
        left -= n;
        sent += n;
        if (!request.write(chunk.subarray(0, n))) return request.once("drain", pump);
      }
    };
    pump();
  }
}
setInterval(() => console.log(JSON.stringify({ opened, closed, sent_mb: Math.round(sent / 1048576) })), 1000);
