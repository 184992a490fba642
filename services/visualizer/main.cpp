// fahr_visualizer: the browser view of a run, live or replayed, and a
// Foxglove WebSocket server on the same port.
//
//   fahr_visualizer [--dds V] [--domain N] [--dds-profile F]
//                   [--address A] [--port P] [--rate-hz R] [--scene FILE]
//                   [--replay FILE.mcap [--speed X]] [--allow-remote-input]
//                   [--client-buffer-kib N] [--duration-s S] [--web-root DIR]
//
// Live: a DDS participant with raw subscriptions to the shown topics. Replay:
// no DDS; the recording is streamed with indexed seeks. The server listens on
// 127.0.0.1 unless --address says otherwise. --allow-remote-input lets the
// page's mouse device (and Foxglove clients) publish DevicePose on
// fahr/RemoteInput, which the gateway reads with --backend remote. With the
// scene's glottic_view section it scores the glottic view (POGO) and
// publishes fahr/GlotticView.
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <thread>

#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/stop_signal.h"
#include "fahr/scene/load_scene.h"
#include "fahr/visualizer_service/glottic_view_service.h"
#include "fahr/visualizer_service/server.h"
#include "fahr/visualizer_service/sources.h"

namespace fahr::visualizer_service {
namespace {

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_visualizer: the run in a browser, live or replayed; Foxglove WebSocket"};
  ServerOptions options;
  options.web_root = FAHR_VISUALIZER_WEB_ROOT;
  std::string dds, domain, profile, replay_path;
  std::string scene_path = FAHR_DEFAULT_SCENE;
  double speed = 1.0, duration_s = 0;
  std::size_t buffer_kib = options.client_buffer_bytes >> 10;
  app.add_option("--dds", dds,
                 "DDS vendor: fastdds or cyclonedds (default $FAHR_DDS, else fastdds)");
  app.add_option("--domain", domain, "DDS domain 0-230 (default $FAHR_DOMAIN_ID, else 0)");
  app.add_option("--dds-profile", profile, "vendor XML profile (default $FAHR_DDS_PROFILE)");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  app.add_option("--address", options.address, "address to listen on (default 127.0.0.1)");
  app.add_option("--port", options.port, "port (default 8765; 0: any free port)");
  app.add_option("--rate-hz", options.rate_hz, "most frames per second per client")
      ->check(fahr::cli::Range(1.0, 240.0));
  app.add_option("--client-buffer-kib", buffer_kib,
                 "a client's send queue; beyond it its oldest frame is dropped")
      ->check(fahr::cli::Range(16, 1 << 20));
  app.add_option("--scene", scene_path, "scene file: the rigid bodies' meshes");
  app.add_option("--replay", replay_path, "replay this MCAP recording instead of a live run");
  app.add_option("--speed", speed, "replay speed (0.05-4)")->check(fahr::cli::Range(0.05, 4.0));
  app.add_flag("--allow-remote-input", options.allow_remote_input,
               "accept the page's mouse device and Foxglove publishing on fahr/RemoteInput");
  app.add_option("--duration-s", duration_s, "stop after this long (0: at SIGINT/SIGTERM)");
  app.add_option("--web-root", options.web_root, "the built page's folder");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  options.client_buffer_bytes = buffer_kib << 10;

  std::shared_ptr<const scene::Scene> scene;
  if (!scene_path.empty()) {
    try {
      scene = scene::load_scene(scene_path);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fahr_visualizer: the scene's rigid meshes are not shown: %s\n",
                   e.what());
    }
  }

  common::install_stop_handlers();
  LiveState live;
  ServerHooks hooks;
  std::unique_ptr<common::Participant> participant;
  std::unique_ptr<DdsSource> dds_source;
  std::unique_ptr<RemoteInput> remote;
  std::unique_ptr<ReplaySource> replay;
  if (!replay_path.empty()) {
    options.mode = "replay";
    if (options.allow_remote_input) {
      std::fprintf(stderr, "fahr_visualizer: --allow-remote-input has no meaning in a replay\n");
      options.allow_remote_input = false;
    }
    replay = std::make_unique<ReplaySource>(replay_path, live, speed);
    hooks.replay_control = [&](const std::string& a, double v) { return replay->control(a, v); };
    hooks.replay_position = [&] { return replay->position_json(); };
  } else {
    participant = std::make_unique<common::Participant>(
        common::transport_config_from(dds, domain, profile, "visualizer", security));
    dds_source = std::make_unique<DdsSource>(*participant, live);
    if (options.allow_remote_input) {
      remote = std::make_unique<RemoteInput>(*participant);
      hooks.remote_pose = [&](const RemotePose& p) { remote->publish(p); };
      hooks.remote_cdr = [&](std::span<const std::uint8_t> cdr) {
        return remote->publish_cdr(cdr);
      };
    }
  }
  // The glottic view: scored from the scene's eye on the blade, published
  // (live) and shown; a scene without the section, or whose meshes cannot
  // be read, runs without it.
  std::unique_ptr<GlotticViewService> glottic;
  if (scene && scene->glottic_view) {
    try {
      glottic = std::make_unique<GlotticViewService>(*scene, live, participant.get());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fahr_visualizer: no glottic view: %s\n", e.what());
    }
  }
  Server server(options, live, scene, hooks);
  server.start();
  if (replay) replay->start();
  if (glottic) glottic->start();
  std::printf(
      "fahr_visualizer: %s on http://%s:%u/ (Foxglove WebSocket: ws://%s:%u), %.0f Hz%s%s\n",
      options.mode.c_str(), options.address.c_str(), server.port(), options.address.c_str(),
      server.port(), options.rate_hz, options.allow_remote_input ? ", remote input allowed" : "",
      replay ? (", " + replay_path).c_str() : "");
  std::fflush(stdout);

  const std::int64_t start = common::monotonic_now_ns();
  while (!common::stop_requested()) {
    if (duration_s > 0 &&
        static_cast<double>(common::monotonic_now_ns() - start) * 1e-9 >= duration_s)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (glottic) glottic->stop();
  if (replay) replay->stop();
  server.stop();
  if (glottic) {
    const auto g = glottic->stats();
    std::printf(
        "fahr_visualizer: glottic view %llu scored, %llu refused, last %.1f %%, peak tool force "
        "%.2f N\n",
        static_cast<unsigned long long>(g.scored), static_cast<unsigned long long>(g.refused),
        g.last_percent, g.peak_force_n);
  }
  std::printf("fahr_visualizer: %s\n", server.stats_json().c_str());
  return 0;
}

}  // namespace
}  // namespace fahr::visualizer_service

int main(int argc, char** argv) {
  try {
    return fahr::visualizer_service::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_visualizer: %s\n", e.what());
    return 1;
  }
}
