#pragma once
/// \file The seam between the transport (server/http_server.cpp, the only file that sees Boost.Beast) and what a
/// WebSocket connection does with its messages (server/viewer_session.h): plain functions and one interface.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace raysift::server {

/// How a connection's messages leave; callable from any thread, in order of the calls.
struct MessageSink {
  std::function<void(std::string)> text;                  ///< queued; returns at once
  /// A text header and its binary message, adjacent (another thread's text never comes between them); returns
  /// once both are written; false once the connection is gone.
  std::function<bool(std::string, std::vector<std::uint8_t>)> frame;
};

/// What one WebSocket connection runs. Destroyed on the transport's thread when the connection ends: the
/// destructor must stop its work promptly (the sink answers false from then on).
class ConnectionHandler {
 public:
  virtual ~ConnectionHandler() = default;
  /// One complete text message from the client (binary ones are answered with an error by the caller).
  virtual void on_text(const std::string& message) = 0;
};

using HandlerFactory = std::function<std::unique_ptr<ConnectionHandler>(MessageSink sink)>;

}  // namespace raysift::server
