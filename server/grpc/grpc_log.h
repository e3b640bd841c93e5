// gRPC's own lines (its core writes them to stderr, in a format of its own) go to the server's
// log at their level.
#pragma once

namespace fluidcast::server {

// Once, before the gRPC server starts and after configure_log.
void route_grpc_log();

}  // namespace fluidcast::server
