// gRPC's own lines (its core writes them to stderr, in a format of its own) go to the server's
// log at their level, and one of them is a health fact: gRPC's own acceptor (with --tls-cert,
// grpc_listener.h) says "Failed accept4" when it stops accepting for good.
#pragma once

namespace fluidcast::server {

// Once, before the gRPC server starts and after configure_log.
void route_grpc_log();

// Whether gRPC's own acceptor has stopped accepting connections, for good (then only a restart
// serves new gRPC clients).
bool grpc_acceptor_failed();

}  // namespace fluidcast::server
