// Boost.Beast server: static page, stats, the page's WebSocket stream and
// Foxglove WebSocket protocol v1, one asio thread for all of it.
#include "fahr/visualizer_service/server.h"

#include <algorithm>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "fahr/common/clock.h"
#include "fahr/idl/schemas.h"

namespace fahr::visualizer_service {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;

namespace {

constexpr std::string_view kFoxgloveSubprotocol = "foxglove.websocket.v1";
constexpr std::uint8_t kFoxgloveMessageData = 1;  // binary opcode, both directions
constexpr std::string_view kRemoteInputTopic = "fahr/RemoteInput";
constexpr std::size_t kMaxHttpHeader = 8 * 1024;
constexpr std::size_t kMaxHttpBody = 1024;

struct Counters {
  std::atomic<std::uint64_t> connections{0}, page_clients{0}, foxglove_clients{0};
  std::atomic<std::uint64_t> frames_sent{0}, frames_dropped{0}, bytes_sent{0};
  std::atomic<std::uint64_t> refused_malformed{0}, refused_oversized{0}, refused_flood{0};
  std::atomic<std::uint64_t> refused_publish{0}, refused_http{0}, refused_clients{0};
  std::atomic<std::uint64_t> remote_poses{0}, ticks{0};
  std::atomic<int> open_sessions{0};
};

std::string_view mime_type(const std::filesystem::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

// A request path the server may map to a file under the web root: plain
// names only (no "..", no hidden files, no odd bytes).
bool safe_path(std::string_view target) {
  if (target.empty() || target[0] != '/' || target.size() > 200) return false;
  if (target.find("..") != std::string_view::npos || target.find("/.") != std::string_view::npos)
    return false;
  return std::all_of(target.begin(), target.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '/' || c == '.' || c == '-' ||
           c == '_';
  });
}

bool finite_array(const json& j, std::size_t n, double* out, double bound) {
  if (!j.is_array() || j.size() != n) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!j[i].is_number()) return false;
    const double v = j[i].get<double>();
    if (!std::isfinite(v) || std::abs(v) > bound) return false;
    out[i] = v;
  }
  return true;
}

}  // namespace

class WsSession;

struct Server::Impl {
  Impl(ServerOptions o, LiveState& l, std::shared_ptr<const scene::Scene> scene, ServerHooks h)
      : options(std::move(o)), live(l), hooks(std::move(h)), model(std::move(scene)) {}

  ServerOptions options;
  LiveState& live;
  ServerHooks hooks;
  PageModel model;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  net::steady_timer timer{ioc};
  std::thread thread;
  unsigned short bound_port = 0;
  Counters counters;
  std::set<std::shared_ptr<WsSession>> sessions;
  std::vector<Slot> slots;  // the newest copy of the live state
  bool running = false;

  void accept();
  void tick();
  std::string stats_json() const;
};

// --- WebSocket sessions ------------------------------------------------

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(Server::Impl& server, tcp::socket socket, bool foxglove)
      : server_(server), ws_(std::move(socket)), foxglove_(foxglove) {
    tokens_ = server_.options.message_burst;
    last_refill_ns_ = common::monotonic_now_ns();
    period_ns_ = static_cast<std::int64_t>(1e9 / server_.options.rate_hz);
  }

  void start(http::request<http::string_body> req) {
    ws_.read_message_max(server_.options.max_message_bytes);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    const bool fox = foxglove_;
    ws_.set_option(websocket::stream_base::decorator([fox](websocket::response_type& res) {
      res.set(http::field::server, "fahr_visualizer");
      if (fox) res.set(http::field::sec_websocket_protocol, std::string(kFoxgloveSubprotocol));
    }));
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
      self->on_open();
    });
  }

  // Called every display tick on the server thread.
  void on_tick(std::int64_t now_ns) {
    if (closed_ || !open_) return;
    if (now_ns < next_send_ns_) return;
    // The next send a period on, never earlier than half a period from now:
    // a client that was skipped does not get a burst to catch up.
    next_send_ns_ = std::max(next_send_ns_ + period_ns_, now_ns + period_ns_ / 2);
    if (foxglove_) {
      send_foxglove_messages();
    } else {
      for (const auto& [stream, frame] : server_.model.frames()) {
        auto& sent = sent_[stream];
        if (frame->version <= sent) continue;
        sent = frame->version;
        enqueue(frame);
      }
      if (server_.hooks.replay_position) enqueue(text(server_.hooks.replay_position(), false));
    }
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    server_.counters.open_sessions.fetch_sub(1);
    server_.sessions.erase(shared_from_this());
  }

  void shutdown() {
    if (closed_) return;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  static FramePtr text(std::string s, bool sticky) {
    auto f = std::make_shared<Frame>();
    f->binary = false;
    f->sticky = sticky;
    f->data = std::move(s);
    return f;
  }

  void on_open() {
    open_ = true;
    if (foxglove_) {
      server_.counters.foxglove_clients.fetch_add(1);
      json caps = json::array();
      if (server_.options.allow_remote_input) caps.push_back("clientPublish");
      json info = {{"op", "serverInfo"},
                   {"name", "fahr_visualizer"},
                   {"capabilities", caps},
                   {"metadata", {{"mode", server_.options.mode}}}};
      if (server_.options.allow_remote_input) info["supportedEncodings"] = {"cdr"};
      enqueue(text(info.dump(), true));
      json channels = json::array();
      const auto& table = topic_table();
      for (std::size_t i = 0; i < table.size(); ++i) {
        channels.push_back({{"id", i + 1},
                            {"topic", table[i].name},
                            {"encoding", "cdr"},
                            {"schemaName", table[i].type_name},
                            {"schema", std::string(idl::schema_of(table[i].type_name))},
                            {"schemaEncoding", "omgidl"}});
      }
      enqueue(text(json{{"op", "advertise"}, {"channels", channels}}.dump(), true));
    } else {
      server_.counters.page_clients.fetch_add(1);
      json hello = {{"op", "hello"},
                    {"mode", server_.options.mode},
                    {"rate_hz", server_.options.rate_hz},
                    {"remote_input", server_.options.allow_remote_input}};
      enqueue(text(hello.dump(), true));
    }
    read();
  }

  void read() {
    ws_.async_read(
        in_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(beast::error_code ec) {
    if (ec) {
      // Beast answers an oversized message with close code 1009 itself.
      if (ec == websocket::error::message_too_big) server_.counters.refused_oversized.fetch_add(1);
      return close();
    }
    const bool binary = ws_.got_binary();
    const auto data = in_.cdata();
    std::string_view bytes(static_cast<const char*>(data.data()), data.size());
    if (take_token()) {
      if (binary) {
        on_binary(bytes);
      } else {
        on_text(bytes);
      }
    }
    in_.consume(in_.size());
    if (closed_) return;
    if (static_cast<double>(flood_refusals_) > 20 * server_.options.message_burst) {
      // A client that keeps flooding is cut off with "policy violation".
      ws_.async_close(websocket::close_code::policy_error,
                      [self = shared_from_this()](beast::error_code) { self->close(); });
      return;
    }
    read();
  }

  bool take_token() {
    const std::int64_t now = common::monotonic_now_ns();
    tokens_ = std::min(server_.options.message_burst,
                       tokens_ + static_cast<double>(now - last_refill_ns_) * 1e-9 *
                                     server_.options.message_rate_hz);
    last_refill_ns_ = now;
    if (tokens_ >= 1.0) {
      tokens_ -= 1.0;
      return true;
    }
    server_.counters.refused_flood.fetch_add(1);
    ++flood_refusals_;
    if (now - last_flood_notice_ns_ > 1'000'000'000) {
      last_flood_notice_ns_ = now;
      refuse("flood", "more than " + std::to_string(server_.options.message_rate_hz) +
                          " messages per second: refused");
    }
    return false;
  }

  void refuse(const std::string& what, const std::string& why) {
    if (foxglove_) {
      enqueue(text(json{{"op", "status"}, {"level", 2}, {"message", why}}.dump(), false));
    } else {
      enqueue(text(json{{"op", "refused"}, {"what", what}, {"reason", why}}.dump(), false));
    }
  }

  void malformed(const std::string& why) {
    server_.counters.refused_malformed.fetch_add(1);
    refuse("malformed", why);
  }

  void on_text(std::string_view bytes) {
    json j = json::parse(bytes, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("op") || !j["op"].is_string()) {
      return malformed("not a JSON object with a string \"op\"");
    }
    const std::string op = j["op"].get<std::string>();
    if (foxglove_) return on_foxglove(op, j);
    if (op == "rate") {
      if (!j.contains("hz") || !j["hz"].is_number()) return malformed("rate wants a number hz");
      const double hz = std::clamp(j["hz"].get<double>(), 1.0, server_.options.rate_hz);
      if (!std::isfinite(hz)) return malformed("rate wants a finite hz");
      period_ns_ = static_cast<std::int64_t>(1e9 / hz);
    } else if (op == "replay") {
      if (!server_.hooks.replay_control)
        return refuse("replay", "not a replay: nothing to control");
      if (!j.contains("action") || !j["action"].is_string())
        return malformed("replay wants a string action");
      double value = 0;
      if (j.contains("value")) {
        if (!j["value"].is_number()) return malformed("replay value must be a number");
        value = j["value"].get<double>();
        if (!std::isfinite(value)) return malformed("replay value must be finite");
      }
      const std::string refusal =
          server_.hooks.replay_control(j["action"].get<std::string>(), value);
      if (!refusal.empty()) refuse("replay", refusal);
    } else if (op == "pose") {
      if (!server_.options.allow_remote_input || !server_.hooks.remote_pose) {
        server_.counters.refused_publish.fetch_add(1);
        return refuse("pose", "remote input is not allowed on this station");
      }
      RemotePose pose;
      // Positions within a metre, a quaternion of finite parts: the gateway's
      // remote back-end clamps to the workspace and normalises.
      if (!j.contains("p") || !finite_array(j["p"], 3, pose.p, 1.0) || !j.contains("q") ||
          !finite_array(j["q"], 4, pose.q, 2.0)) {
        return malformed("pose wants p [x,y,z] (|.| <= 1 m) and q [w,x,y,z]");
      }
      if (j.contains("buttons")) {
        if (!j["buttons"].is_number_unsigned()) return malformed("buttons must be unsigned");
        pose.buttons = static_cast<std::uint32_t>(j["buttons"].get<std::uint64_t>() & 0xffffffffu);
      }
      server_.counters.remote_poses.fetch_add(1);
      server_.hooks.remote_pose(pose);
    } else {
      malformed("unknown op '" + op.substr(0, 32) + "'");
    }
  }

  void on_foxglove(const std::string& op, const json& j) {
    const std::size_t channels = topic_table().size();
    if (op == "subscribe") {
      if (!j.contains("subscriptions") || !j["subscriptions"].is_array())
        return malformed("subscribe wants an array subscriptions");
      for (const auto& s : j["subscriptions"]) {
        if (!s.is_object() || !s.contains("id") || !s["id"].is_number_unsigned() ||
            !s.contains("channelId") || !s["channelId"].is_number_unsigned()) {
          return malformed("a subscription wants unsigned id and channelId");
        }
        const std::uint64_t id = s["id"].get<std::uint64_t>();
        const std::uint64_t channel = s["channelId"].get<std::uint64_t>();
        if (channel < 1 || channel > channels || id > 0xffffffffu) {
          malformed("no channel " + std::to_string(channel));
          continue;
        }
        if (subscriptions_.count(static_cast<std::uint32_t>(id)) != 0) {
          malformed("subscription id " + std::to_string(id) + " is in use");
          continue;
        }
        subscriptions_[static_cast<std::uint32_t>(id)] = static_cast<std::size_t>(channel - 1);
      }
    } else if (op == "unsubscribe") {
      if (!j.contains("subscriptionIds") || !j["subscriptionIds"].is_array())
        return malformed("unsubscribe wants an array subscriptionIds");
      for (const auto& id : j["subscriptionIds"]) {
        if (!id.is_number_unsigned()) return malformed("subscription ids are unsigned");
        subscriptions_.erase(static_cast<std::uint32_t>(id.get<std::uint64_t>()));
      }
    } else if (op == "advertise") {
      if (!server_.options.allow_remote_input) {
        server_.counters.refused_publish.fetch_add(1);
        return refuse("advertise",
                      "client publishing is refused: this station does not allow remote input");
      }
      if (!j.contains("channels") || !j["channels"].is_array())
        return malformed("advertise wants an array channels");
      for (const auto& c : j["channels"]) {
        if (!c.is_object() || !c.contains("id") || !c["id"].is_number_unsigned() ||
            !c.contains("topic") || !c["topic"].is_string() || !c.contains("encoding") ||
            !c["encoding"].is_string()) {
          return malformed("a client channel wants id, topic and encoding");
        }
        if (c["topic"].get<std::string>() != kRemoteInputTopic ||
            c["encoding"].get<std::string>() != "cdr") {
          server_.counters.refused_publish.fetch_add(1);
          refuse("advertise", "clients may publish only fahr/RemoteInput (DevicePose, cdr)");
          continue;
        }
        if (client_channels_.size() < 8)
          client_channels_.insert(static_cast<std::uint32_t>(c["id"].get<std::uint64_t>()));
      }
    } else if (op == "unadvertise") {
      if (!j.contains("channelIds") || !j["channelIds"].is_array())
        return malformed("unadvertise wants an array channelIds");
      for (const auto& id : j["channelIds"]) {
        if (id.is_number_unsigned())
          client_channels_.erase(static_cast<std::uint32_t>(id.get<std::uint64_t>()));
      }
    } else {
      malformed("unsupported op '" + op.substr(0, 32) + "'");
    }
  }

  void on_binary(std::string_view bytes) {
    if (!foxglove_) return malformed("the page protocol takes no binary messages");
    if (bytes.size() < 5 || static_cast<std::uint8_t>(bytes[0]) != kFoxgloveMessageData)
      return malformed("unknown binary opcode");
    std::uint32_t channel = 0;
    std::memcpy(&channel, bytes.data() + 1, 4);
    if (!server_.options.allow_remote_input || client_channels_.count(channel) == 0 ||
        !server_.hooks.remote_cdr) {
      server_.counters.refused_publish.fetch_add(1);
      return refuse("publish", "no advertised client channel " + std::to_string(channel) +
                                   " (remote input allowed: " +
                                   (server_.options.allow_remote_input ? "yes" : "no") + ")");
    }
    const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data() + 5);
    if (!server_.hooks.remote_cdr(std::span<const std::uint8_t>(p, bytes.size() - 5)))
      return malformed("fahr/RemoteInput sample does not decode as DevicePose CDR");
    server_.counters.remote_poses.fetch_add(1);
  }

  void send_foxglove_messages() {
    if (subscriptions_.empty()) return;
    const auto& slots = server_.slots;
    if (sent_slot_.size() < slots.size()) sent_slot_.resize(slots.size(), 0);
    for (std::size_t i = 0; i < slots.size(); ++i) {
      const Slot& slot = slots[i];
      if (slot.version == sent_slot_[i] || slot.bytes.empty()) continue;
      bool any = false;
      for (const auto& [sub, topic] : subscriptions_) {
        if (topic != slot.topic) continue;
        any = true;
        auto f = std::make_shared<Frame>();
        f->binary = true;
        // A latched scene must reach the client even when it is slow.
        f->sticky = slot.topic == kSceneDescription;
        f->data.resize(1 + 4 + 8 + slot.bytes.size());
        char* out = f->data.data();
        out[0] = static_cast<char>(kFoxgloveMessageData);
        std::memcpy(out + 1, &sub, 4);
        const std::uint64_t t = static_cast<std::uint64_t>(slot.receive_ns);
        std::memcpy(out + 5, &t, 8);
        std::memcpy(out + 13, slot.bytes.data(), slot.bytes.size());
        enqueue(f);
      }
      if (any) sent_slot_[i] = slot.version;
    }
  }

  void enqueue(FramePtr frame) {
    if (closed_) return;
    const std::size_t cap_bytes = server_.options.client_buffer_bytes;
    const std::size_t cap_frames = server_.options.client_buffer_frames;
    // Drop the oldest droppable frames until this one fits: never the one
    // being written (the front while writing), never a sticky one.
    while (!queue_.empty() &&
           (queued_bytes_ + frame->data.size() > cap_bytes || queue_.size() + 1 > cap_frames)) {
      auto it = queue_.begin();
      if (writing_) ++it;
      while (it != queue_.end() && (*it)->sticky) ++it;
      if (it == queue_.end()) break;
      queued_bytes_ -= (*it)->data.size();
      queue_.erase(it);
      server_.counters.frames_dropped.fetch_add(1);
      ++dropped_;
    }
    queued_bytes_ += frame->data.size();
    queue_.push_back(std::move(frame));
    if (!writing_) write_next();
  }

  void write_next() {
    if (queue_.empty() || closed_) {
      writing_ = false;
      return;
    }
    writing_ = true;
    const FramePtr& f = queue_.front();
    ws_.binary(f->binary);
    ws_.async_write(net::buffer(f->data),
                    [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                      if (ec) return self->close();
                      self->server_.counters.frames_sent.fetch_add(1);
                      self->server_.counters.bytes_sent.fetch_add(n);
                      self->queued_bytes_ -= self->queue_.front()->data.size();
                      self->queue_.pop_front();
                      self->write_next();
                    });
  }

  Server::Impl& server_;
  websocket::stream<beast::tcp_stream> ws_;
  bool foxglove_;
  bool open_ = false, closed_ = false, writing_ = false;
  beast::flat_buffer in_;
  std::deque<FramePtr> queue_;
  std::size_t queued_bytes_ = 0;
  std::uint64_t dropped_ = 0;
  std::int64_t period_ns_ = 0, next_send_ns_ = 0;
  double tokens_ = 0;
  std::int64_t last_refill_ns_ = 0, last_flood_notice_ns_ = 0;
  std::uint64_t flood_refusals_ = 0;
  std::map<int, std::uint64_t> sent_;                   // page: stream -> version sent
  std::map<std::uint32_t, std::size_t> subscriptions_;  // foxglove: id -> topic
  std::vector<std::uint64_t> sent_slot_;                // foxglove: slot -> version sent
  std::set<std::uint32_t> client_channels_;
};

// --- HTTP ----------------------------------------------------------------

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Server::Impl& server, tcp::socket socket)
      : server_(server), stream_(std::move(socket)) {}

  void start() {
    parser_.emplace();
    parser_->header_limit(kMaxHttpHeader);
    parser_->body_limit(kMaxHttpBody);
    stream_.expires_after(std::chrono::seconds(10));
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec) {
      if (ec != http::error::end_of_stream && ec != beast::error::timeout)
        server_.counters.refused_http.fetch_add(1);
      return;
    }
    auto req = parser_->release();
    if (websocket::is_upgrade(req)) {
      const std::string protocols(req[http::field::sec_websocket_protocol]);
      const bool foxglove = protocols.find(kFoxgloveSubprotocol) != std::string::npos;
      if (!foxglove && req.target() != "/ws")
        return respond(req, http::status::not_found, "no such stream\n", "text/plain");
      if (server_.counters.open_sessions.load() >= server_.options.max_clients) {
        server_.counters.refused_clients.fetch_add(1);
        return respond(req, http::status::service_unavailable, "too many clients\n", "text/plain");
      }
      server_.counters.connections.fetch_add(1);
      server_.counters.open_sessions.fetch_add(1);
      stream_.expires_never();
      auto session = std::make_shared<WsSession>(server_, stream_.release_socket(), foxglove);
      server_.sessions.insert(session);
      session->start(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      server_.counters.refused_http.fetch_add(1);
      return respond(req, http::status::method_not_allowed, "GET only\n", "text/plain");
    }
    std::string target(req.target());
    if (const auto q = target.find('?'); q != std::string::npos) target.resize(q);
    if (target == "/stats")
      return respond(req, http::status::ok, server_.stats_json(), "application/json");
    if (target == "/") target = "/index.html";
    if (server_.options.web_root.empty() || !safe_path(target)) {
      server_.counters.refused_http.fetch_add(1);
      return respond(req, http::status::not_found, "not found\n", "text/plain");
    }
    const std::filesystem::path path =
        std::filesystem::path(server_.options.web_root) / target.substr(1);
    std::ifstream f(path, std::ios::binary);
    if (!f) return respond(req, http::status::not_found, "not found\n", "text/plain");
    std::stringstream body;
    body << f.rdbuf();
    respond(req, http::status::ok, body.str(), mime_type(path));
  }

  void respond(const http::request<http::string_body>& req, http::status status, std::string body,
               std::string_view type) {
    auto res = std::make_shared<http::response<http::string_body>>(status, req.version());
    res->set(http::field::server, "fahr_visualizer");
    res->set(http::field::content_type, std::string(type));
    res->set(http::field::cache_control, "no-store");
    res->keep_alive(false);
    res->body() = req.method() == http::verb::head ? std::string() : std::move(body);
    res->prepare_payload();
    http::async_write(stream_, *res,
                      [self = shared_from_this(), res](beast::error_code, std::size_t) {
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                      });
  }

  Server::Impl& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

// --- the server ------------------------------------------------------------

void Server::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (!running) return;
    if (!ec) std::make_shared<HttpSession>(*this, std::move(socket))->start();
    accept();
  });
}

void Server::Impl::tick() {
  if (!running) return;
  counters.ticks.fetch_add(1);
  if (live.collect(slots) > 0) model.update(slots, options.mode);
  const std::int64_t now = common::monotonic_now_ns();
  // A copy: a session may close (and leave the set) during its tick.
  std::vector<std::shared_ptr<WsSession>> all(sessions.begin(), sessions.end());
  for (auto& s : all) s->on_tick(now);
  timer.expires_after(std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / options.rate_hz)));
  timer.async_wait([this](beast::error_code ec) {
    if (!ec) tick();
  });
}

std::string Server::Impl::stats_json() const {
  const auto& c = counters;
  const auto l = live.stats();
  json j = {{"mode", options.mode},
            {"clients", c.open_sessions.load()},
            {"connections", c.connections.load()},
            {"page_clients", c.page_clients.load()},
            {"foxglove_clients", c.foxglove_clients.load()},
            {"frames_sent", c.frames_sent.load()},
            {"frames_dropped", c.frames_dropped.load()},
            {"bytes_sent", c.bytes_sent.load()},
            {"refused_malformed", c.refused_malformed.load()},
            {"refused_oversized", c.refused_oversized.load()},
            {"refused_flood", c.refused_flood.load()},
            {"refused_publish", c.refused_publish.load()},
            {"refused_http", c.refused_http.load()},
            {"refused_clients", c.refused_clients.load()},
            {"remote_poses", c.remote_poses.load()},
            {"ticks", c.ticks.load()},
            {"samples_received", l.received},
            {"samples_malformed", l.malformed},
            {"slots_full", l.slots_full}};
  return j.dump();
}

Server::Server(ServerOptions options, LiveState& live, std::shared_ptr<const scene::Scene> scene,
               ServerHooks hooks)
    : impl_(std::make_unique<Impl>(std::move(options), live, std::move(scene), std::move(hooks))) {
  if (!(impl_->options.rate_hz >= 1 && impl_->options.rate_hz <= 240))
    throw std::runtime_error("the display rate must be 1-240 Hz");
}

Server::~Server() {
  stop();
}

void Server::start() {
  auto& s = *impl_;
  beast::error_code ec;
  const auto address = net::ip::make_address(s.options.address, ec);
  if (ec) throw std::runtime_error("not an IP address: '" + s.options.address + "'");
  const tcp::endpoint endpoint(address, s.options.port);
  s.acceptor.open(endpoint.protocol(), ec);
  if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(endpoint, ec);
  if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    throw std::runtime_error("cannot listen on " + s.options.address + ":" +
                             std::to_string(s.options.port) + ": " + ec.message());
  }
  s.bound_port = s.acceptor.local_endpoint().port();
  s.running = true;
  s.accept();
  net::post(s.ioc, [&s] { s.tick(); });
  s.thread = std::thread([&s] { s.ioc.run(); });
}

void Server::stop() {
  auto& s = *impl_;
  if (!s.thread.joinable()) return;
  net::post(s.ioc, [&s] {
    s.running = false;
    beast::error_code ec;
    s.acceptor.close(ec);
    s.timer.cancel();
    std::vector<std::shared_ptr<WsSession>> all(s.sessions.begin(), s.sessions.end());
    for (auto& session : all) session->shutdown();
  });
  // Sessions end as their sockets close; a bounded wait, then stop the loop.
  for (int i = 0; i < 50 && s.counters.open_sessions.load() > 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  s.ioc.stop();
  s.thread.join();
  s.sessions.clear();
}

unsigned short Server::port() const {
  return impl_->bound_port;
}

ServerStats Server::stats() const {
  const auto& c = impl_->counters;
  ServerStats s;
  s.connections = c.connections.load();
  s.page_clients = c.page_clients.load();
  s.foxglove_clients = c.foxglove_clients.load();
  s.frames_sent = c.frames_sent.load();
  s.frames_dropped = c.frames_dropped.load();
  s.bytes_sent = c.bytes_sent.load();
  s.refused_malformed = c.refused_malformed.load();
  s.refused_oversized = c.refused_oversized.load();
  s.refused_flood = c.refused_flood.load();
  s.refused_publish = c.refused_publish.load();
  s.refused_http = c.refused_http.load();
  s.refused_clients = c.refused_clients.load();
  s.remote_poses = c.remote_poses.load();
  s.ticks = c.ticks.load();
  return s;
}

std::string Server::stats_json() const {
  return impl_->stats_json();
}

}  // namespace fahr::visualizer_service
