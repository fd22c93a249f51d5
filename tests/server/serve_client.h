#pragma once
/// \file Test side of `raysift serve`: the server as a child process on a free port (--port 0), and a small
/// HTTP/WebSocket client (Boost.Beast, in serve_client.cpp only). Every read times out after 20 s, so a hang
/// fails the test instead of blocking ctest.
#include <memory>
#include <string>
#include <vector>

#include "core/json_io.h"

namespace raysift::test {

/// `raysift serve ARGS --port 0` started in `dir`; its stdout and stderr go to serve_out.txt / serve_err.txt there.
class ServeProcess {
 public:
  /// Waits for the printed URL. \throw std::runtime_error if the server exits or prints none within 20 s.
  ServeProcess(const std::string& dir, const std::string& args);
  ~ServeProcess();  ///< SIGKILL if still running
  ServeProcess(const ServeProcess&) = delete;
  ServeProcess& operator=(const ServeProcess&) = delete;

  int port() const { return port_; }
  /// Sends `signo`, waits; the exit code, or -1 if the process did not exit normally.
  int stop(int signo);
  std::string stderr_text() const;

 private:
  std::string dir_;
  int pid_ = -1;
  int port_ = 0;
};

struct HttpReply {
  int status = 0;
  std::string content_type, body;
};

/// One GET of `target` exactly as given (no normalisation of "..", no encoding).
HttpReply http_get(int port, const std::string& target);

struct WsMessage {
  bool is_text = true;
  std::string data;
};

/// A frame: its JSON header and the image that followed it.
struct ServeFrame {
  Json header;
  std::string image;
};

class WsClient {
 public:
  /// Connects to ws://127.0.0.1:port/ws and reads the hello. \throw std::runtime_error.
  explicit WsClient(int port);
  ~WsClient();

  const Json& hello() const { return hello_; }
  void send(const std::string& text);
  void send(const Json& message) { send(message.dump()); }
  /// The next message. \throw std::runtime_error on timeout or close.
  WsMessage read();
  /// The next text message whose "type" is `type` (others skipped; a frame's image is skipped with it).
  Json read_type(const std::string& type);
  /// The next frame (other messages skipped).
  ServeFrame read_frame();
  /// Frames until a converged one reflecting the camera message with this seq.
  ServeFrame read_converged(int camera_seq);
  /// Reads until the server closes; its close code (-1 if the connection ended without one).
  int read_close_code();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Json hello_;
};

/// Width and height from a PNG's IHDR (0,0 if `png` is not a PNG).
std::pair<int, int> png_size(const std::string& png);

}  // namespace raysift::test
