// The visualizer's HTTP + WebSocket server (Boost.Beast on one asio thread):
//   GET /, /app.js, ...  the page, from --web-root (built by esbuild)
//   GET /stats           counters as JSON
//   WebSocket /ws        the page's stream (page_model.h frames) and its
//                        requests (replay control, the mouse device's poses)
//   WebSocket with subprotocol foxglove.websocket.v1 (any path): Foxglove
//                        WebSocket protocol v1, fahr's topics as `cdr` with
//                        their `omgidl` schemas, the bytes as they arrived.
// Every client is sent the newest frame of each stream at most at its
// display rate; its send queue is capped (bytes and frames) and a full queue
// drops its oldest frame (never one being written, never a scene), counted.
// Client messages are bounded in size and rate; a malformed, oversized,
// flooding or forbidden one is refused with a reason and counted, never
// trusted.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "fahr/visualizer_service/live_state.h"
#include "fahr/visualizer_service/page_model.h"

namespace fahr::visualizer_service {

struct ServerOptions {
  std::string address = "127.0.0.1";  // loopback unless asked otherwise
  unsigned short port = 8765;         // 0: any free port (tests)
  std::string web_root;               // the built page; empty: no page
  std::string mode = "live";          // "live" or "replay"
  double rate_hz = 60;                // the most any client is sent per second
  std::size_t client_buffer_bytes = 8u << 20;
  std::size_t client_buffer_frames = 128;
  std::size_t max_message_bytes = 16u << 10;  // a client message, larger: refused
  double message_rate_hz = 100;               // client messages per second, sustained
  double message_burst = 200;
  int max_clients = 32;
  // Remote input (the page's mouse device, a Foxglove client's publishing):
  // refused unless the station allows it.
  bool allow_remote_input = false;
};

// A pose from the page's mouse device, in the device's frame (m).
struct RemotePose {
  double p[3] = {0, 0, 0};
  double q[4] = {1, 0, 0, 0};  // w x y z
  std::uint32_t buttons = 0;
};

struct ServerHooks {
  // Replay control ("pause", "play", "seek" with t_s, "speed" with speed);
  // returns an empty string or why it was refused. Empty hook: live.
  std::function<std::string(const std::string& action, double value)> replay_control;
  // {"op":"replay", ...} position text for the page; empty hook: live.
  std::function<std::string()> replay_position;
  // A pose of the mouse device (already screened: finite, bounded).
  std::function<void(const RemotePose&)> remote_pose;
  // A Foxglove client's sample on fahr/RemoteInput: CDR bytes of DevicePose.
  std::function<bool(std::span<const std::uint8_t> cdr)> remote_cdr;
};

struct ServerStats {
  std::uint64_t connections = 0, page_clients = 0, foxglove_clients = 0;
  std::uint64_t frames_sent = 0, frames_dropped = 0, bytes_sent = 0;
  std::uint64_t refused_malformed = 0, refused_oversized = 0, refused_flood = 0;
  std::uint64_t refused_publish = 0, refused_http = 0, refused_clients = 0;
  std::uint64_t remote_poses = 0;
  std::uint64_t ticks = 0;
};

class Server {
 public:
  Server(ServerOptions options, LiveState& live, std::shared_ptr<const scene::Scene> scene,
         ServerHooks hooks = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and starts the server's thread. Throws std::runtime_error if the
  // address cannot be bound.
  void start();
  void stop();
  unsigned short port() const;
  ServerStats stats() const;
  std::string stats_json() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace fahr::visualizer_service
