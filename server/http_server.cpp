// The only translation unit that includes Boost.Beast (its headers cost ~20 s of compile each): HTTP for the
// embedded page and the WebSocket at /ws, all on one io_context run by the calling thread. Render threads hand
// their messages over through an Outbox and wait on it for binary frames, so a frame is sent before the next
// one is rendered (back-pressure) and the send time is measured where it happens.
#include "server/http_server.h"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <string_view>

#include "core/errors.h"
#include "server/embedded_files.h"

namespace raysift::server {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

/// Messages from any thread to the network thread, in order; `wait_sent` blocks until one was written.
class Outbox {
 public:
  struct Message {
    bool is_binary = false;
    std::string data;
    std::uint64_t id = 0;
  };
  /// Queues the messages next to each other (no other thread's message between them); the last one's id, or 0
  /// once the connection is closed.
  std::uint64_t push(std::vector<Message> messages) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return 0;
    for (Message& m : messages) {
      m.id = ++pushed_;
      queue_.push_back(std::move(m));
    }
    return pushed_;
  }
  bool pop(Message& m) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.empty()) return false;
    m = std::move(queue_.front());
    queue_.pop_front();
    return true;
  }
  void mark_sent(std::uint64_t id) {
    const std::lock_guard<std::mutex> lock(mutex_);
    sent_ = id;
    cv_.notify_all();
  }
  bool wait_sent(std::uint64_t id) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return closed_ || sent_ >= id; });
    return sent_ >= id;
  }
  void close() {
    const std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    queue_.clear();
    cv_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Message> queue_;
  std::uint64_t pushed_ = 0, sent_ = 0;
  bool closed_ = false;
};

class WsSession;
using Registry = std::vector<std::weak_ptr<WsSession>>;  ///< live WebSocket sessions (network thread only)

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, std::size_t max_message_bytes)
      : ws_(std::move(socket)), max_bytes_(max_message_bytes), outbox_(std::make_shared<Outbox>()) {}

  void start(http::request<http::string_body> request, const HandlerFactory& factory) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(0);  // read() enforces the limit itself, to close with 1008 rather than Beast's 1009
    ws_.async_accept(request, [self = shared_from_this(), &factory](beast::error_code ec) {
      if (ec) return self->shut_down();
      self->handler_ = factory(self->make_sink());
      self->read();
    });
  }

  /// Ends the session: pending and future sends fail, then the handler (and its threads) go.
  void shut_down() {
    outbox_->close();
    handler_.reset();
    if (ws_.is_open()) ws_.async_close(websocket::close_code::going_away, [self = shared_from_this()](beast::error_code) {});
  }

 private:
  MessageSink make_sink() {
    const auto kick = [weak = weak_from_this(), executor = ws_.get_executor()] {
      net::post(executor, [weak] {
        if (auto self = weak.lock()) self->flush();
      });
    };
    MessageSink sink;
    sink.text = [outbox = outbox_, kick](std::string s) {
      std::vector<Outbox::Message> messages(1);
      messages[0].data = std::move(s);
      if (outbox->push(std::move(messages)) != 0) kick();
    };
    sink.frame = [outbox = outbox_, kick](std::string header, std::vector<std::uint8_t> bytes) {
      std::vector<Outbox::Message> messages(2);
      messages[0].data = std::move(header);
      messages[1].is_binary = true;
      messages[1].data.assign(bytes.begin(), bytes.end());
      const std::uint64_t id = outbox->push(std::move(messages));
      if (id == 0) return false;
      kick();
      return outbox->wait_sent(id);
    };
    return sink;
  }

  void read() {
    ws_.async_read_some(buffer_, 64 * 1024, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

  void on_read(beast::error_code ec) {
    if (ec) return shut_down();
    if (buffer_.size() > max_bytes_) {  // the policy: drop the connection, tell the client why
      outbox_->close();
      handler_.reset();
      ws_.async_close(websocket::close_code::policy_error, [self = shared_from_this()](beast::error_code) {});
      return;
    }
    if (ws_.is_message_done()) {
      if (!handler_) return;
      if (ws_.got_text())
        handler_->on_text(beast::buffers_to_string(buffer_.data()));
      else
        make_sink().text(R"({"type":"error","message":"binary messages are not accepted; send JSON text"})");
      buffer_.consume(buffer_.size());
    }
    read();
  }

  void flush() {
    if (writing_ || !ws_.is_open()) return;
    Outbox::Message m;
    if (!outbox_->pop(m)) return;
    writing_ = true;
    current_ = std::move(m);
    ws_.binary(current_.is_binary);
    ws_.async_write(net::buffer(current_.data), [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      if (ec) return self->shut_down();
      self->outbox_->mark_sent(self->current_.id);
      self->flush();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  std::size_t max_bytes_;
  beast::flat_buffer buffer_;
  std::shared_ptr<Outbox> outbox_;
  std::unique_ptr<ConnectionHandler> handler_;
  Outbox::Message current_;
  bool writing_ = false;
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Registry& registry, const HttpServerOptions& options, const HandlerFactory& factory)
      : stream_(std::move(socket)), registry_(registry), options_(options), factory_(factory) {}

  void read() {
    parser_.emplace();
    parser_->body_limit(64 * 1024);  // the page sends no bodies
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec) return close();
    http::request<http::string_body> request = parser_->release();
    const std::string target(request.target());
    if (websocket::is_upgrade(request) && target.substr(0, target.find('?')) == "/ws") {
      stream_.expires_never();
      auto ws = std::make_shared<WsSession>(stream_.release_socket(), options_.max_message_bytes);
      registry_.erase(std::remove_if(registry_.begin(), registry_.end(), [](const auto& w) { return w.expired(); }),
                      registry_.end());
      registry_.push_back(ws);
      ws->start(std::move(request), factory_);
      return;
    }
    respond(request);
  }

  void respond(const http::request<http::string_body>& request) {
    const EmbeddedFile* file = nullptr;
    http::status status = http::status::method_not_allowed;
    if (request.method() == http::verb::get || request.method() == http::verb::head) {
      file = find_embedded_file(std::string_view(request.target().data(), request.target().size()));
      status = file ? http::status::ok : http::status::not_found;
    }
    auto response = std::make_shared<http::response<http::string_body>>(status, request.version());
    response->set(http::field::server, "raysift");
    response->set(http::field::content_type, file ? content_type(file->path) : "text/plain; charset=utf-8");
    response->set(http::field::cache_control, "no-store");
    response->body() = file ? std::string(file->data) : std::string(http::obsolete_reason(status)) + "\n";
    response->keep_alive(request.keep_alive());
    response->prepare_payload();
    if (request.method() == http::verb::head) response->body().clear();
    http::async_write(stream_, *response, [self = shared_from_this(), response](beast::error_code ec, std::size_t) {
      if (ec || response->need_eof()) return self->close();
      self->read();
    });
  }

  void close() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  Registry& registry_;
  const HttpServerOptions& options_;
  const HandlerFactory& factory_;
};

class Listener {
 public:
  Listener(net::io_context& io, const HttpServerOptions& options, const HandlerFactory& factory)
      : io_(io), acceptor_(io), signals_(io, SIGINT, SIGTERM), linger_(io), options_(options), factory_(factory) {
    beast::error_code ec;
    const auto address = net::ip::make_address(options.host, ec);
    if (ec) throw InvalidInput("--host must be an IP address, got '" + options.host + "'");
    const tcp::endpoint endpoint(address, static_cast<unsigned short>(options.port));
    acceptor_.open(endpoint.protocol(), ec);
    if (!ec) acceptor_.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) acceptor_.bind(endpoint, ec);
    if (!ec) acceptor_.listen(net::socket_base::max_listen_connections, ec);
    if (ec)
      throw IoError("cannot listen on " + options.host + ":" + std::to_string(options.port) + ": " + ec.message());
    if (options.on_listening) options.on_listening(acceptor_.local_endpoint().port());
    accept();
    signals_.async_wait([this](beast::error_code ec, int signo) {
      if (ec) return;
      signal_ = signo;
      signals_.clear();  // back to the default action: a second Ctrl-C ends a shutdown that hangs
      stop();
    });
  }

  int signal() const { return signal_; }

 private:
  void accept() {
    acceptor_.async_accept(net::make_strand(io_), [this](beast::error_code ec, tcp::socket socket) {
      if (ec) return;  // the acceptor was closed
      std::make_shared<HttpSession>(std::move(socket), registry_, options_, factory_)->read();
      accept();
    });
  }

  void stop() {
    acceptor_.close();
    for (const std::weak_ptr<WsSession>& w : registry_)
      if (auto ws = w.lock()) ws->shut_down();
    registry_.clear();
    // A moment for the close frames to go out; idle keep-alive HTTP reads would keep run() going for ever.
    linger_.expires_after(std::chrono::milliseconds(200));
    linger_.async_wait([this](beast::error_code) { io_.stop(); });
  }

  net::io_context& io_;
  tcp::acceptor acceptor_;
  net::signal_set signals_;
  net::steady_timer linger_;
  int signal_ = 0;
  const HttpServerOptions& options_;
  const HandlerFactory& factory_;
  Registry registry_;
};

}  // namespace

int run_http_server(const HttpServerOptions& options, const HandlerFactory& factory) {
  net::io_context io(1);
  Listener listener(io, options, factory);
  io.run();
  return listener.signal();
}

}  // namespace raysift::server
