// The station supervisor: one process per host and station that generates the
// vendor configuration into the run folder, starts the host's services as
// children, watches them and stops them (SIGINT, then SIGTERM, then SIGKILL)
// in reverse order. It writes its pid and a status file there, which `down`
// and `status` read.
#include "launcher.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "clock_check.h"
#include "fahr/lab_plan/profiles.h"

namespace fahr::lab {

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::atomic<bool> g_stop{false};

void on_stop_signal(int) {
  g_stop.store(true);
}

std::string now_text() {
  char text[32];
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &tm);
  return text;
}

// The folder fahr_lab runs from: services beside it (installed), or in the
// build tree's services/<name>/ (a build folder).
fs::path program_path(const std::string& program, const std::string& build_subdir) {
  const fs::path self = fs::read_symlink("/proc/self/exe").parent_path();
  if (fs::exists(self / program)) return self / program;
  const fs::path in_build = self.parent_path().parent_path() / build_subdir / program;
  if (fs::exists(in_build)) return in_build;
  return program;  // PATH
}

struct Child {
  std::string name;
  std::vector<std::string> argv;
  std::vector<std::string> env;  // NAME=value added to the supervisor's environment
  std::string ready_text;        // a log line that says it is ready; empty: none
  fs::path log;
  pid_t pid = -1;
  int restarts = 0;
  // Deaths in a row, each within kQuickDeath of its start: the back-off's
  // exponent, and after kMaxQuickDeaths the supervisor gives up.
  int quick_deaths = 0;
  bool restart_due = false;
  std::string state = "not started";
  std::chrono::steady_clock::time_point started;
  std::chrono::steady_clock::time_point restart_at;
};

// Restart back-off: a service that dies within a minute of its start is
// restarted after 0.5 s, then 1, 2, 4 and 8 s if it keeps dying that fast,
// and the station stops at the sixth such death; one that ran a minute
// starts the count again. A crash loop then neither spins the machine nor
// floods the logs, and a one-off death is back within half a second.
constexpr auto kQuickDeath = std::chrono::seconds(60);
constexpr int kMaxQuickDeaths = 5;
constexpr auto kFirstBackOff = std::chrono::milliseconds(500);

pid_t spawn(const Child& child) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed: " + std::string(std::strerror(errno)));
  if (pid > 0) return pid;
  // Child: its own process group (a terminal's Ctrl-C reaches the
  // supervisor, which stops the services in order), log as stdout/stderr.
  setpgid(0, 0);
  const int fd = open(child.log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd >= 0) {
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    close(fd);
  }
  const int null_fd = open("/dev/null", O_RDONLY);
  if (null_fd >= 0) {
    dup2(null_fd, STDIN_FILENO);
    close(null_fd);
  }
  for (const auto& e : child.env) putenv(const_cast<char*>(e.c_str()));
  std::vector<char*> argv;
  argv.reserve(child.argv.size() + 1);
  for (const auto& a : child.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execvp(argv[0], argv.data());
  std::fprintf(stderr, "fahr_lab: cannot start %s: %s\n", argv[0], std::strerror(errno));
  _exit(127);
}

std::string exit_text(int status) {
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  }
  return "status " + std::to_string(status);
}

bool log_has(const fs::path& log, const std::string& text) {
  std::ifstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

// SIGINT, then SIGTERM, then SIGKILL, `grace` apart. Returns the wait status.
int stop_child(Child& child, std::chrono::milliseconds grace) {
  if (child.pid <= 0) return 0;
  int status = 0;
  for (int sig : {SIGINT, SIGTERM, SIGKILL}) {
    kill(child.pid, sig);
    const auto until = std::chrono::steady_clock::now() + grace;
    while (std::chrono::steady_clock::now() < until) {
      if (waitpid(child.pid, &status, WNOHANG) == child.pid) {
        child.pid = -1;
        return status;
      }
      std::this_thread::sleep_for(20ms);
    }
    if (sig == SIGTERM) {
      std::printf("fahr_lab: %s ignored SIGINT and SIGTERM; killing it\n", child.name.c_str());
    }
  }
  waitpid(child.pid, &status, 0);
  child.pid = -1;
  return status;
}

struct RunFolder {
  fs::path dir;
  fs::path pid_file() const { return dir / "fahr_lab.pid"; }
  fs::path status_file() const { return dir / "status"; }
};

void write_status(const RunFolder& run, const Station& station, const std::string& host,
                  const std::string& state, const std::vector<Child>& children) {
  const fs::path tmp = run.status_file().string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << "station " << station.name << " host " << host << " supervisor " << getpid() << " state "
        << state << " since " << now_text() << "\n";
    for (const auto& c : children) {
      out << "service " << c.name << " pid " << c.pid << " state " << c.state << " restarts "
          << c.restarts << " log " << c.log.string() << "\n";
    }
  }
  fs::rename(tmp, run.status_file());
}

// The command line of one service.
Child make_child(const Plan& plan, const PlannedParticipant& p, const fs::path& config_dir,
                 const fs::path& run_dir) {
  const Station& station = *p.station;
  const ServiceSpec& s = *p.service;
  Child c;
  c.name = service_key(s.kind);
  c.log = run_dir / (c.name + ".log");
  const fs::path profile = config_dir / (c.name + ".xml");
  const std::string vendor(common::vendor_name(s.vendor));
  const std::string domain = std::to_string(station.domain);
  // Line-buffered output, so readiness lines reach the log as printed.
  c.argv = {"stdbuf", "-oL", "-eL"};
  auto add = [&](std::initializer_list<std::string> args) {
    for (const auto& a : args) c.argv.push_back(a);
  };
  const std::vector<std::string> dds = {"--dds", vendor,          "--domain",
                                        domain,  "--dds-profile", profile.string()};
  switch (s.kind) {
    case ServiceKind::kLogger:
      add({program_path("fahr_logger", "services/logger").string(), "-o",
           (run_dir / (station.name + ".mcap")).string(), "--scene", station.scene.string()});
      c.ready_text = "recording to";
      break;
    case ServiceKind::kFem:
      add({program_path("fahr_fem_service", "services/fem").string(), "--scene",
           station.scene.string(), "--duration-s", "0"});
      c.ready_text = "fahr_fem_service: ";
      break;
    case ServiceKind::kHaptic:
      add({program_path("fahr_haptic_service", "services/haptic").string(), "--scene",
           station.scene.string(), "--duration-s", "0"});
      c.ready_text = "ready";
      break;
    case ServiceKind::kDeviceGateway: {
      char duration[32];
      std::snprintf(duration, sizeof duration, "%g", station.duration_s);
      add({program_path("fahr_device_gateway", "services/device_gateway").string(), "--duration-s",
           duration});
      if (const ServiceSpec* haptic = station.service(ServiceKind::kHaptic);
          haptic != nullptr && haptic->host != s.host) {
        add({"--wait-haptic-s", std::to_string(kRemoteHapticWaitS)});
      }
      if (s.args.empty()) add({"--backend", "simulated", "--script", "intubation"});
      break;
    }
    case ServiceKind::kSummary:
      // Listens until the station stops it (it prints on SIGINT).
      add({program_path("fahr_run_summary", "tools/run_summary").string(), "--duration-s", "0"});
      break;
  }
  for (const auto& a : dds) c.argv.push_back(a);
  if (!s.cpus.empty() && s.kind != ServiceKind::kLogger && s.kind != ServiceKind::kSummary &&
      s.kind != ServiceKind::kDeviceGateway) {
    add({"--cpus", s.cpus});
  }
  if (s.rt_priority > 0 &&
      (s.kind == ServiceKind::kHaptic || s.kind == ServiceKind::kDeviceGateway)) {
    add({"--rt-priority", std::to_string(s.rt_priority)});
  }
  for (const auto& a : s.args) c.argv.push_back(a);
  c.env = {"FAHR_PARTITION=" + station.partition, "FAHR_STATION=" + station.name};
  (void)plan;
  return c;
}

Child discovery_server_child(const Plan& plan, const Station& station, const fs::path& run_dir) {
  Child c;
  c.name = "discovery_server";
  c.log = run_dir / "discovery_server.log";
  const Locator server = plan.discovery_server(station);
  c.argv = {"stdbuf",
            "-oL",
            "fast-discovery-server",
            "-i",
            std::to_string(discovery_server_id(plan, station)),
            "-l",
            server.address,
            "-p",
            std::to_string(server.port)};
  c.ready_text = "Server is running";
  return c;
}

bool wait_ready(Child& c, std::chrono::seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until && !g_stop.load()) {
    if (c.ready_text.empty() || log_has(c.log, c.ready_text)) return true;
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) == c.pid) {
      c.pid = -1;
      c.state = "died during start-up (" + exit_text(status) + ")";
      return false;
    }
    std::this_thread::sleep_for(100ms);
  }
  if (!g_stop.load()) c.state = "not ready after " + std::to_string(timeout.count()) + " s";
  return false;
}

std::vector<std::string> read_lines(const fs::path& file) {
  std::vector<std::string> lines;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

bool process_alive(pid_t pid) {
  if (pid <= 0 || kill(pid, 0) != 0) return false;
  // A zombie is not running.
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  std::getline(stat, text);
  const auto close = text.rfind(')');
  return close == std::string::npos || close + 2 >= text.size() || text[close + 2] != 'Z';
}

pid_t read_pid(const fs::path& file) {
  std::ifstream in(file);
  long pid = -1;
  in >> pid;
  return static_cast<pid_t>(pid);
}

}  // namespace

fs::path default_run_root() {
  if (const char* env = std::getenv("FAHR_RUN_ROOT"); env != nullptr && *env != '\0') return env;
  return geteuid() == 0 ? fs::path("/var/lib/fahr/runs") : fs::path("/tmp/fahr-lab");
}

const Host& this_host(const Lab& lab, const std::string& wanted) {
  std::string name = wanted;
  if (name.empty()) {
    if (const char* env = std::getenv("FAHR_HOST"); env != nullptr) name = env;
  }
  if (!name.empty()) {
    if (const Host* h = lab.host(name)) return *h;
    throw std::runtime_error("no host '" + name + "' in " + lab.file.string());
  }
  ifaddrs* addrs = nullptr;
  if (getifaddrs(&addrs) == 0) {
    for (ifaddrs* a = addrs; a != nullptr; a = a->ifa_next) {
      if (a->ifa_addr == nullptr || a->ifa_addr->sa_family != AF_INET) continue;
      char text[INET_ADDRSTRLEN];
      const auto* in = reinterpret_cast<const sockaddr_in*>(a->ifa_addr);
      inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
      for (const auto& h : lab.hosts) {
        if (h.address == text) {
          freeifaddrs(addrs);
          return h;
        }
      }
    }
    freeifaddrs(addrs);
  }
  char hostname[256] = {};
  gethostname(hostname, sizeof hostname - 1);
  if (const Host* h = lab.host(hostname)) return *h;
  throw std::runtime_error(
      "this machine is none of the lab's hosts (no address of it and not its name '" +
      std::string(hostname) + "'): give --host NAME or FAHR_HOST");
}

int station_up(const Plan& plan, const Station& station, const UpOptions& options) {
  const Host& host = this_host(*plan.lab, options.host);
  RunFolder run{options.run_root / station.name};
  fs::create_directories(run.dir);
  if (const pid_t old = read_pid(run.pid_file()); process_alive(old)) {
    std::fprintf(stderr,
                 "fahr_lab: station %s already runs here (supervisor %d); fahr_lab down %s\n",
                 station.name.c_str(), old, station.name.c_str());
    return 1;
  }
  const fs::path config_dir = run.dir / "config";
  write_files(station_files(plan, station, host, config_dir));

  std::vector<Child> children;
  if (station.discovery == Discovery::kServer && station.discovery_server_host == host.name) {
    children.push_back(discovery_server_child(plan, station, run.dir));
  }
  for (const auto& p : plan.participants) {
    if (p.station == &station && p.host == &host) {
      children.push_back(make_child(plan, p, config_dir, run.dir));
    }
  }
  if (children.empty()) {
    std::printf("fahr_lab: station %s runs nothing on host %s\n", station.name.c_str(),
                host.name.c_str());
    return 0;
  }

  if (options.detach) {
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid > 0) {
      // Wait until the supervisor has started every service (or gave up).
      for (int i = 0; i < 1800; ++i) {
        const auto lines = read_lines(run.status_file());
        if (!lines.empty() && read_pid(run.pid_file()) == pid &&
            lines[0].find(" state starting ") == std::string::npos) {
          break;
        }
        if (!process_alive(pid)) break;
        std::this_thread::sleep_for(100ms);
      }
      return station_status(station.name, options.run_root) == 0 ? 0 : 1;
    }
    setsid();
    const int fd = open((run.dir / "fahr_lab.log").c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
  }
  setvbuf(stdout, nullptr, _IOLBF, 0);
  {
    std::ofstream pid_out(run.pid_file());
    pid_out << getpid() << "\n";
  }
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGHUP, &action, nullptr);

  // The clocks of the station's hosts against this one's, in clock.txt.
  ClockCheck clock_check(plan, station, host, run.dir / "clock.txt");
  std::printf("fahr_lab: %s station %s on host %s (%s): %zu services, logs in %s\n",
              now_text().c_str(), station.name.c_str(), host.name.c_str(), host.address.c_str(),
              children.size(), run.dir.c_str());
  write_status(run, station, host.name, "starting", children);
  int result = 0;
  std::string why_stopped;
  for (auto& c : children) {
    if (g_stop.load()) break;
    // Each service starts when the ones before it are ready: the recorder
    // first, the gateway (whose script starts at its first tick) last.
    c.pid = spawn(c);
    c.started = std::chrono::steady_clock::now();
    c.state = "starting";
    write_status(run, station, host.name, "starting", children);
    if (!wait_ready(c, 120s)) {
      if (g_stop.load()) break;
      why_stopped = c.name + " " + c.state;
      std::printf("fahr_lab: station %s: %s; stopping the station\n", station.name.c_str(),
                  why_stopped.c_str());
      result = 1;
      break;
    }
    c.state = "running";
    std::printf("fahr_lab: %s running (pid %d)\n", c.name.c_str(), c.pid);
  }
  if (result == 0 && !g_stop.load()) {
    write_status(run, station, host.name, "running", children);
    std::printf("fahr_lab: station %s running\n", station.name.c_str());
  }
  // Supervise.
  while (result == 0 && !g_stop.load()) {
    for (auto& c : children) {
      int status = 0;
      if (c.pid <= 0 || waitpid(c.pid, &status, WNOHANG) != c.pid) continue;
      c.pid = -1;
      const bool gateway_done = c.name == "device_gateway" && station.duration_s > 0 &&
                                WIFEXITED(status) && WEXITSTATUS(status) == 0;
      if (gateway_done) {
        c.state = "finished";
        char text[64];
        std::snprintf(text, sizeof text, "the gateway's run of %g s ended", station.duration_s);
        why_stopped = text;
        g_stop.store(true);
        break;
      }
      c.state = "died (" + exit_text(status) + ")";
      std::printf("fahr_lab: %s station %s: service %s died: %s\n", now_text().c_str(),
                  station.name.c_str(), c.name.c_str(), exit_text(status).c_str());
      const auto died = std::chrono::steady_clock::now();
      c.quick_deaths = died - c.started < kQuickDeath ? c.quick_deaths + 1 : 1;
      if (station.restart && c.quick_deaths <= kMaxQuickDeaths) {
        const auto delay = kFirstBackOff * (1 << (c.quick_deaths - 1));
        c.restart_at = died + delay;
        c.restart_due = true;
        char text[96];
        std::snprintf(text, sizeof text, "restarting in %.1f s",
                      std::chrono::duration<double>(delay).count());
        c.state += ", " + std::string(text);
        std::printf("fahr_lab: %s %s (death %d in a row within a minute of its start)\n",
                    c.name.c_str(), text, c.quick_deaths);
      } else {
        if (station.restart) {
          why_stopped = "service " + c.name + " died " + std::to_string(c.quick_deaths) +
                        " times in a row within a minute of its start";
        } else {
          why_stopped = "service " + c.name + " died";
        }
        result = 1;
      }
      write_status(run, station, host.name, result == 0 ? "running" : "stopping", children);
      if (result != 0) break;
    }
    // Restarts whose back-off has passed (the loop goes on supervising the
    // others meanwhile).
    for (auto& c : children) {
      if (result != 0 || g_stop.load() || !c.restart_due ||
          std::chrono::steady_clock::now() < c.restart_at)
        continue;
      c.restart_due = false;
      ++c.restarts;
      c.pid = spawn(c);
      c.started = std::chrono::steady_clock::now();
      c.state = "running";
      std::printf("fahr_lab: %s restarted (pid %d, restart %d)\n", c.name.c_str(), c.pid,
                  c.restarts);
      write_status(run, station, host.name, "running", children);
    }
    std::this_thread::sleep_for(50ms);
  }
  if (why_stopped.empty()) why_stopped = "asked to stop";
  std::printf("fahr_lab: %s station %s stopping: %s\n", now_text().c_str(), station.name.c_str(),
              why_stopped.c_str());
  write_status(run, station, host.name, "stopping", children);
  // The gateway first, then the services that answer it, then the
  // listeners (the summary, the recorder), which keep the others' final
  // reports, then the discovery server.
  for (const char* name :
       {"device_gateway", "haptic", "fem", "summary", "logger", "discovery_server"}) {
    for (auto& c : children) {
      if (c.name != name || c.pid <= 0) continue;
      const int status = stop_child(c, 5s);
      if (c.state == "running" || c.state == "starting") {
        c.state = "stopped (" + exit_text(status) + ")";
      }
      std::printf("fahr_lab: %s %s\n", c.name.c_str(), c.state.c_str());
      write_status(run, station, host.name, "stopping", children);
    }
  }
  write_status(run, station, host.name, result == 0 ? "stopped" : "failed", children);
  fs::remove(run.pid_file());
  std::printf("fahr_lab: station %s %s (%s)\n", station.name.c_str(),
              result == 0 ? "stopped" : "failed", why_stopped.c_str());
  return result;
}

int station_down(const std::string& station, const fs::path& run_root) {
  RunFolder run{run_root / station};
  const pid_t pid = read_pid(run.pid_file());
  if (!process_alive(pid)) {
    std::printf("fahr_lab: station %s is not running here\n", station.c_str());
    return station_status(station, run_root) == 1 ? 0 : 1;
  }
  kill(pid, SIGTERM);
  for (int i = 0; i < 600 && process_alive(pid); ++i) std::this_thread::sleep_for(100ms);
  if (process_alive(pid)) {
    std::fprintf(stderr, "fahr_lab: the supervisor of %s (pid %d) did not stop within 60 s\n",
                 station.c_str(), pid);
    return 1;
  }
  station_status(station, run_root);
  return 0;
}

int station_status(const std::string& station, const fs::path& run_root) {
  RunFolder run{run_root / station};
  const auto lines = read_lines(run.status_file());
  if (lines.empty()) {
    std::printf("station %s: never started here (no %s)\n", station.c_str(),
                run.status_file().c_str());
    return 1;
  }
  const pid_t supervisor = read_pid(run.pid_file());
  const bool running = process_alive(supervisor);
  std::printf("%s%s\n", lines[0].c_str(), running ? "" : " (supervisor not running)");
  bool all_up = true;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::istringstream in(lines[i]);
    std::string word, name, state;
    long pid = -1;
    in >> word >> name >> word >> pid >> word >> state;
    const bool alive = process_alive(static_cast<pid_t>(pid));
    if (!alive) all_up = false;
    std::printf("  %-17s %s\n", name.c_str(),
                alive ? ("running, pid " + std::to_string(pid)).c_str()
                      : lines[i].substr(lines[i].find(" state ") + 7).c_str());
  }
  if (!running) return 1;
  return all_up ? 0 : 3;
}

}  // namespace fahr::lab
