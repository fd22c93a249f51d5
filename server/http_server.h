#pragma once
/// \file `raysift serve`'s transport: HTTP (the embedded page, server/embedded_files.h) and the WebSocket at /ws
/// on one port, one network thread. [choice] Boost.Beast (docs/serve.md): it is the one Debian library that does
/// both on one port in one event loop; Beast stays inside http_server.cpp.
#include <functional>
#include <string>

#include "server/connection.h"

namespace raysift::server {

struct HttpServerOptions {
  std::string host = "127.0.0.1";
  int port = 8080;                              ///< 0 = a free port, chosen by the system
  std::size_t max_message_bytes = 1 << 20;      ///< a longer client message closes its connection (1008)
  std::function<void(int port)> on_listening;   ///< called once the socket listens, with the actual port
};

/// Serves until SIGINT or SIGTERM, then closes every connection and returns the signal's number. [choice] The
/// server takes the signals itself (an asio signal_set) rather than through core/signals.h's process-wide cancel
/// flag: for a server a signal is the normal way to stop, not a failure, so --stats must still be written
/// (write_atomically refuses once that flag is set). A second signal, during the shutdown, has the default action.
/// Every WebSocket connection gets its own handler from `factory`.
/// \throw IoError when the address cannot be bound (the message names host and port).
int run_http_server(const HttpServerOptions& options, const HandlerFactory& factory);

}  // namespace raysift::server
