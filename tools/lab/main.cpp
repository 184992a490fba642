// fahr_lab: a lab file's plan, its generated vendor configuration, and a
// station's services on this host.
//
//   fahr_lab check LAB                          the plan, or the file's problems
//   fahr_lab config LAB STATION HOST OUTDIR     vendor files and env files for a host
//   fahr_lab up LAB STATION [--host H] [--run-root DIR] [--detach]
//   fahr_lab down STATION [--run-root DIR]
//   fahr_lab status STATION [--run-root DIR]
//
// Exit status: 0 done; 1 failed (a service died, not running); 2 a bad lab
// file or command line; 3 (status) running with a service down.
#include <cstdio>
#include <exception>

#include "fahr/cli/cli.h"
#include "fahr/lab_plan/lab.h"
#include "fahr/lab_plan/plan.h"
#include "fahr/lab_plan/profiles.h"
#include "src/launcher.h"

int main(int argc, char** argv) try {
  using namespace fahr::lab;
  fahr::cli::App app{"fahr_lab: a lab file's plan, configuration and station launcher"};
  app.require_subcommand(1);
  std::string lab_file, station, host, out_dir, run_root;
  bool detach = false;

  auto* check = app.add_subcommand("check", "print the plan (what runs where, ports, peers)");
  check->add_option("LAB", lab_file, "lab file")->required();
  auto* config = app.add_subcommand("config", "generate a host's vendor files for a station");
  config->add_option("LAB", lab_file, "lab file")->required();
  config->add_option("STATION", station, "station name")->required();
  config->add_option("HOST", host, "host name")->required();
  config->add_option("OUTDIR", out_dir, "folder for the files")->required();
  auto* up = app.add_subcommand("up", "start and supervise this host's services of a station");
  up->add_option("LAB", lab_file, "lab file")->required();
  up->add_option("STATION", station, "station name")->required();
  up->add_option("--host", host, "this machine's host name in the lab (default: by address)");
  up->add_option("--run-root", run_root, "run folders' parent (default $FAHR_RUN_ROOT)");
  up->add_flag("--detach", detach, "supervise in the background");
  auto* down = app.add_subcommand("down", "stop a station's services on this host");
  down->add_option("STATION", station, "station name")->required();
  down->add_option("--run-root", run_root, "run folders' parent (default $FAHR_RUN_ROOT)");
  auto* status = app.add_subcommand("status", "report a station's services on this host");
  status->add_option("STATION", station, "station name")->required();
  status->add_option("--run-root", run_root, "run folders' parent (default $FAHR_RUN_ROOT)");
  if (const auto exit = app.parse(argc, argv)) return *exit;

  const std::filesystem::path root =
      run_root.empty() ? default_run_root() : std::filesystem::path(run_root);
  if (down->parsed()) return station_down(station, root);
  if (status->parsed()) return station_status(station, root);

  Lab lab;
  Plan plan;
  try {
    lab = load_lab(lab_file);
    plan = make_plan(lab);
  } catch (const fahr::scene::SceneError& e) {
    for (const auto& issue : e.issues()) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
    std::fprintf(stderr, "fahr_lab: %s: %zu problem(s)\n", lab_file.c_str(), e.issues().size());
    return 2;
  }
  if (check->parsed()) {
    std::printf("%s", describe_plan(plan).c_str());
    return 0;
  }
  const Station* s = lab.station(station);
  if (s == nullptr) {
    std::fprintf(stderr, "fahr_lab: no station '%s' in %s\n", station.c_str(), lab_file.c_str());
    return 2;
  }
  if (config->parsed()) {
    const Host* h = lab.host(host);
    if (h == nullptr) {
      std::fprintf(stderr, "fahr_lab: no host '%s' in %s\n", host.c_str(), lab_file.c_str());
      return 2;
    }
    const auto files = station_files(plan, *s, *h, out_dir);
    write_files(files);
    for (const auto& f : files) std::printf("%s\n", f.path.c_str());
    return 0;
  }
  UpOptions options;
  options.host = host;
  options.run_root = root;
  options.detach = detach;
  return station_up(plan, *s, options);
} catch (const std::exception& e) {
  std::fprintf(stderr, "fahr_lab: %s\n", e.what());
  return 1;
}
