#include "fahr/bench_support/results_file.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <link.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

extern char** environ;

namespace fahr::bench_support {

namespace {

#if defined(__clang__)
constexpr const char* kCompiler = "Clang " __clang_version__;
#else
constexpr const char* kCompiler = "GCC " __VERSION__;
#endif

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// What `command` prints on stdout, its trailing newline removed; ok false
// when it could not run or exited non-zero.
std::string run(const std::string& command, bool& ok) {
  std::string out;
  std::FILE* pipe = popen(command.c_str(), "r");
  ok = pipe != nullptr;
  if (!ok) return out;
  std::array<char, 256> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) {
    out += buffer.data();
  }
  ok = pclose(pipe) == 0;
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

std::string shell_quote(std::string_view word) {
  const bool plain = !word.empty() && word.find_first_not_of(
                                          "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                          "0123456789_-+=./:,@%") == std::string_view::npos;
  if (plain) return std::string(word);
  std::string quoted = "'";
  for (const char c : word) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

bool ends_with(std::string_view text, std::string_view tail) {
  return text.size() >= tail.size() && text.substr(text.size() - tail.size()) == tail;
}

// Both ends of the tee: the process's stdout and the results file.
ssize_t write_all(int fd, const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0) return -1;
    done += static_cast<std::size_t>(n);
  }
  return static_cast<ssize_t>(size);
}

ssize_t write_tee(void* cookie, const char* data, std::size_t size) {
  const int file = *static_cast<const int*>(cookie);
  if (write_all(STDOUT_FILENO, data, size) < 0) return -1;
  return write_all(file, data, size);
}

// OpenBLAS's description of itself through `handle` (RTLD_DEFAULT: the
// process's), or "" when it is not OpenBLAS.
std::string describe_openblas(void* handle) {
  void* config = dlsym(handle, "openblas_get_config");
  void* core = dlsym(handle, "openblas_get_corename");
  if (config == nullptr || core == nullptr) return "";
  using Text = char* (*)();
  Text get_config = nullptr;
  Text get_core = nullptr;
  static_assert(sizeof(get_config) == sizeof(config));
  std::memcpy(&get_config, &config, sizeof(config));
  std::memcpy(&get_core, &core, sizeof(core));
  const std::string described = get_config();
  const std::string kernels = get_core();
  return described.find(kernels) != std::string::npos ? described
                                                      : described + "; kernels " + kernels;
}

// The path of the first loaded object whose file name starts with `prefix`.
std::string loaded_object(const char* prefix) {
  struct Search {
    const char* prefix;
    std::string path;
  } search{prefix, {}};
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* data) {
        auto* s = static_cast<Search*>(data);
        const std::string_view name = info->dlpi_name != nullptr ? info->dlpi_name : "";
        const auto slash = name.rfind('/');
        const std::string_view file =
            slash == std::string_view::npos ? name : name.substr(slash + 1);
        if (!s->path.empty() || file.rfind(s->prefix, 0) != 0) return 0;
        s->path = std::string(name);
        return 1;
      },
      &search);
  return search.path;
}

std::string describe_loaded_blas() {
  for (const char* prefix : {"libopenblas", "libblas", "libmkl_rt", "libblis"}) {
    std::string path = loaded_object(prefix);
    if (path.empty()) continue;
    std::error_code error;
    const auto real = std::filesystem::canonical(path, error);
    if (!error) path = real.string();
    const std::string openblas = describe_openblas(RTLD_DEFAULT);
    return openblas.empty() ? path : openblas + " (" + path + ")";
  }
  return "";
}

void write_text(int fd, const std::string& text) {
  if (write_all(fd, text.data(), text.size()) < 0) {
    throw std::runtime_error(std::string("results file: ") + std::strerror(errno));
  }
}

}  // namespace

std::string machine_slug(std::string_view cpu_model, unsigned online_cpus) {
  std::string slug;
  bool gap = false;
  for (const char raw : cpu_model) {
    const auto c = static_cast<unsigned char>(raw);
    if (std::isalnum(c) != 0 && c < 128) {
      if (gap && !slug.empty()) slug += '-';
      slug += static_cast<char>(std::tolower(c));
      gap = false;
    } else {
      gap = true;
    }
  }
  if (slug.empty()) slug = "unknown-cpu";
  return slug + "-" + std::to_string(online_cpus) + "c";
}

Machine this_machine() {
  Machine m;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const auto first = line.find_first_not_of(" \t", colon + 1);
    m.cpu_model = first == std::string::npos ? "" : line.substr(first);
    break;
  }
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  m.online_cpus = cpus > 0 ? static_cast<unsigned>(cpus) : 1U;
  m.slug = machine_slug(m.cpu_model, m.online_cpus);
  if (m.cpu_model.empty()) m.cpu_model = "unknown";
  return m;
}

std::string source_commit() {
  const std::string git = "git -C " + shell_quote(FAHR_SOURCE_DIR) + " ";
  bool ok = false;
  const std::string head = run(git + "rev-parse --short=12 HEAD 2>/dev/null", ok);
  if (!ok || head.empty()) return "unknown";
  const std::string changes =
      run(git + "status --porcelain -- . ':(exclude)bench/results' 2>/dev/null", ok);
  return ok && changes.empty() ? head : head + "-dirty";
}

std::string utc_date() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text.data();
}

std::string load_average() {
  std::ifstream file("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(file >> one >> five >> fifteen)) return "unknown";
  return one + " " + five + " " + fifteen;
}

std::string command_line(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    if (i > 0) line += ' ';
    line += shell_quote(argv[i]);
  }
  return line;
}

std::string relevant_environment() {
  std::vector<std::string> found;
  for (char** entry = environ; entry != nullptr && *entry != nullptr; ++entry) {
    const std::string_view text = *entry;
    for (const char* prefix :
         {"OPENBLAS_", "OMP_", "FAHR_", "CYCLONEDDS_", "FASTDDS_", "FASTRTPS_"}) {
      if (text.rfind(prefix, 0) == 0) {
        found.emplace_back(text);
        break;
      }
    }
  }
  std::sort(found.begin(), found.end());
  std::string out;
  for (const auto& entry : found) {
    if (!out.empty()) out += ' ';
    out += shell_quote(entry);
  }
  return out;
}

std::string blas_in_use(bool load_if_absent) {
  std::string loaded = describe_loaded_blas();
  if (!loaded.empty() || !load_if_absent) return loaded;
  void* handle = dlopen("libblas.so.3", RTLD_LAZY | RTLD_LOCAL);
  if (handle == nullptr) return "";
  std::string path;
  if (link_map* map = nullptr; dlinfo(handle, RTLD_DI_LINKMAP, &map) == 0 && map != nullptr) {
    std::error_code error;
    const auto real = std::filesystem::canonical(map->l_name, error);
    path = error ? map->l_name : real.string();
  }
  const std::string openblas = describe_openblas(handle);
  dlclose(handle);
  return "libblas.so.3 resolves to " + (openblas.empty() ? path : openblas + " (" + path + ")");
}

std::string default_results_path(std::string_view name) {
  return std::string(FAHR_SOURCE_DIR) + "/bench/results/" + this_machine().slug + "/" +
         std::string(name) + ".md";
}

MarkdownResults::MarkdownResults(int& argc, char** argv) : command_(command_line(argc, argv)) {
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") {
      while (i < argc) argv[kept++] = argv[i++];
      break;
    }
    if (arg == "--markdown") {
      requested_ = true;
      if (i + 1 < argc && ends_with(argv[i + 1], ".md")) path_ = argv[++i];
    } else if (arg.rfind("--markdown=", 0) == 0) {
      requested_ = true;
      path_ = std::string(arg.substr(std::strlen("--markdown=")));
    } else {
      argv[kept++] = argv[i];
    }
  }
  argv[kept] = nullptr;
  argc = kept;
}

MarkdownResults::~MarkdownResults() {
  try {
    finish();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "results file: %s\n", e.what());
  }
}

void MarkdownResults::begin(std::string_view name, Output output) {
  if (!requested_ || fd_ >= 0) return;
  output_ = output;
  if (path_.empty()) path_ = default_results_path(name);
  const std::filesystem::path path(path_);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(errno));
  start_s_ = now_s();
  const Machine machine = this_machine();
  const std::string environment = relevant_environment();
  const std::string blas = blas_in_use(script_);
  std::string header = "# Results: " + std::string(name) +
                       "\n\n<!-- Written by the bench itself (--markdown); rerun the command to "
                       "refresh it. -->\n\n| run | |\n|---|---|\n";
  header += "| command | `" + command_ + "` |\n";
  if (!environment.empty()) header += "| environment | `" + environment + "` |\n";
  header += "| commit | " + source_commit() + " |\n";
  header += "| machine | " + machine.cpu_model + ", " + std::to_string(machine.online_cpus) +
            " online CPUs (" + machine.slug + ") |\n";
  if (!blas.empty()) header += "| BLAS | " + blas + " |\n";
  header += std::string("| build | ") + FAHR_BUILD_TYPE + ", " + kCompiler + " |\n";
  header += "| date | " + utc_date() + " |\n";
  header += "| load average at start (1, 5, 15 min) | " +
            (load_at_start_.empty() ? load_average() : load_at_start_) + " |\n\n";
  if (output_ == Output::kText) header += "```text\n";
  write_text(fd_, header);
  std::fflush(stdout);
  static constexpr cookie_io_functions_t kTee{nullptr, write_tee, nullptr, nullptr};
  tee_ = fopencookie(&fd_, "w", kTee);
  if (tee_ == nullptr) throw std::runtime_error("cannot copy stdout to " + path_);
  std::setvbuf(tee_, nullptr, _IOLBF, BUFSIZ);
  original_stdout_ = stdout;
  stdout = tee_;
}

void MarkdownResults::finish() {
  if (fd_ < 0) return;
  if (tee_ != nullptr) {
    std::fflush(tee_);
    stdout = original_stdout_;
    std::fclose(tee_);
    tee_ = nullptr;
  }
  std::array<char, 160> footer{};
  std::snprintf(footer.data(), footer.size(), "\n_Wall time %.0f s; load average at the end %s._\n",
                now_s() - start_s_ + elapsed_before_s_, load_average().c_str());
  const int fd = fd_;
  fd_ = -1;
  if (output_ == Output::kText) write_text(fd, "```\n");
  write_text(fd, footer.data());
  ::close(fd);
  std::fprintf(stderr, "results: wrote %s\n", path_.c_str());
}

}  // namespace fahr::bench_support
