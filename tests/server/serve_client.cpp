#include "tests/server/serve_client.h"

#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <thread>

#include "tests/support/test_support.h"

namespace raysift::test {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

constexpr int kTimeoutS = 60;  // a hang guard only: generous for a sanitizer build next to other tests

/// Connected socket whose blocking reads fail after kTimeoutS instead of hanging.
tcp::socket connect_socket(net::io_context& io, int port) {
  tcp::socket socket(io);
  socket.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  timeval tv{kTimeoutS, 0};
  setsockopt(socket.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return socket;
}

}  // namespace

ServeProcess::ServeProcess(const std::string& dir, const std::string& args) : dir_(dir) {
  const std::string command = "exec '" RAYSIFT_EXE "' serve " + args + " --port 0 > serve_out.txt 2> serve_err.txt";
  std::filesystem::remove(dir + "/serve_out.txt");  // an earlier server's URL must not be read as this one's
  pid_ = fork();
  if (pid_ == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const std::regex url(R"(http://[^ ]+:(\d+)/)");
  for (int i = 0; i < kTimeoutS * 100; ++i) {
    std::smatch m;
    const std::string out = read_text(dir + "/serve_out.txt");
    if (std::regex_search(out, m, url)) {
      port_ = std::stoi(m[1]);
      return;
    }
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      throw std::runtime_error("raysift serve exited before listening: " + stderr_text());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  throw std::runtime_error("raysift serve printed no URL within " + std::to_string(kTimeoutS) + " s: " + stderr_text());
}

ServeProcess::~ServeProcess() {
  if (pid_ > 0) stop(SIGKILL);
}

int ServeProcess::stop(int signo) {
  if (pid_ <= 0) return -1;
  kill(pid_, signo);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string ServeProcess::stderr_text() const { return read_text(dir_ + "/serve_err.txt"); }

HttpReply http_get(int port, const std::string& target) {
  net::io_context io;
  beast::tcp_stream stream(connect_socket(io, port));
  http::request<http::empty_body> request(http::verb::get, target, 11);
  request.set(http::field::host, "127.0.0.1");
  http::write(stream, request);
  beast::flat_buffer buffer;
  http::response<http::string_body> response;
  http::read(stream, buffer, response);
  return {int(response.result_int()), std::string(response[http::field::content_type]), response.body()};
}

struct WsClient::Impl {
  net::io_context io;
  websocket::stream<beast::tcp_stream> ws;
  beast::flat_buffer buffer;
  explicit Impl(int port) : ws(connect_socket(io, port)) { ws.handshake("127.0.0.1", "/ws"); }
};

WsClient::WsClient(int port) : impl_(std::make_unique<Impl>(port)) {
  const WsMessage m = read();
  hello_ = Json::parse(m.data);
}

WsClient::~WsClient() {
  beast::error_code ignored;
  if (impl_->ws.is_open()) impl_->ws.close(websocket::close_code::normal, ignored);
}

void WsClient::send(const std::string& text) {
  impl_->ws.text(true);
  impl_->ws.write(net::buffer(text));
}

WsMessage WsClient::read() {
  impl_->buffer.consume(impl_->buffer.size());
  beast::error_code ec;
  impl_->ws.read(impl_->buffer, ec);
  if (ec) throw std::runtime_error("WebSocket read failed: " + ec.message());
  return {impl_->ws.got_text(), beast::buffers_to_string(impl_->buffer.data())};
}

Json WsClient::read_type(const std::string& type) {
  for (;;) {
    const WsMessage m = read();
    if (!m.is_text) continue;
    Json j = Json::parse(m.data);
    if (j.value("type", "") == type) return j;
  }
}

ServeFrame WsClient::read_frame() {
  ServeFrame f;
  f.header = read_type("frame");
  const WsMessage image = read();
  if (image.is_text) throw std::runtime_error("expected the frame's image, got text: " + image.data);
  f.image = image.data;
  return f;
}

ServeFrame WsClient::read_converged(int camera_seq) {
  for (;;) {
    ServeFrame f = read_frame();
    if (f.header["converged"] == true && f.header["camera_seq"] == camera_seq) return f;
  }
}

int WsClient::read_close_code() {
  for (;;) {
    beast::error_code ec;
    impl_->ws.read(impl_->buffer, ec);
    impl_->buffer.consume(impl_->buffer.size());
    if (ec == websocket::error::closed) return int(impl_->ws.reason().code);
    if (ec) return -1;
  }
}

std::pair<int, int> png_size(const std::string& png) {
  if (png.size() < 24 || png.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return {0, 0};
  const auto be32 = [&](std::size_t at) {
    int v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(png[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

}  // namespace raysift::test
