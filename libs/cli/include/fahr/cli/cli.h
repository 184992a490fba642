// Command lines for fahr's executables: options, flags, checks and
// subcommands, parsed with CLI11 behind a small compiled interface.
// CLI11 is header-only and costs tens of seconds of compile time in every
// file that includes it; this header includes none of it, so a main pays
// once, in this library.
//
//   fahr::cli::App app("what it does");
//   app.add_option("--rate-hz", rate, "frames per second")->check(fahr::cli::Range(1, 500));
//   if (const auto exit = app.parse(argc, argv)) return *exit;
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace fahr::cli {

// A check on an option's value (Range, PositiveNumber, IsMember).
struct Validator {
  enum class Kind { kRange, kPositive, kMember };
  Kind kind = Kind::kRange;
  double low = 0.0;
  double high = 0.0;
  bool integral = false;
  std::vector<std::string> members;
};

// CLI11's own names for its validators, kept so that call sites read as
// CLI11's documentation does.
// NOLINTBEGIN(readability-identifier-naming)
// The value must lie in [low, high] (the help names an INT range for
// integer bounds, a FLOAT range for floating-point ones).
Validator Range(double low, double high);
Validator Range(int low, int high);
// The value must be > 0.
extern const Validator PositiveNumber;
// The value must be one of these words.
Validator IsMember(std::vector<std::string> members);
// NOLINTEND(readability-identifier-naming)

// One option or flag of an App; chained as option->required()->check(...).
class Option {
 public:
  explicit Option(CLI::Option* option) : option_(option) {}
  Option* required();
  Option* check(const Validator& validator);
  Option* type_name(const std::string& name);
  Option* excludes(Option* other);
  Option* excludes(const std::string& other_name);

 private:
  CLI::Option* option_;
};

class App {
 public:
  explicit App(const std::string& description, const std::string& name = "");
  ~App();
  App(const App&) = delete;
  App& operator=(const App&) = delete;

  Option* add_option(const std::string& names, std::string& target, const std::string& help);
  Option* add_option(const std::string& names, double& target, const std::string& help);
  Option* add_option(const std::string& names, int& target, const std::string& help);
  Option* add_option(const std::string& names, unsigned& target, const std::string& help);
  Option* add_option(const std::string& names, long& target, const std::string& help);
  Option* add_option(const std::string& names, unsigned long& target, const std::string& help);
  Option* add_option(const std::string& names, long long& target, const std::string& help);
  Option* add_option(const std::string& names, unsigned long long& target, const std::string& help);
  Option* add_option(const std::string& names, unsigned short& target, const std::string& help);
  Option* add_option(const std::string& names, std::vector<std::string>& target,
                     const std::string& help);
  Option* add_option(const std::string& names, std::vector<double>& target,
                     const std::string& help);
  Option* add_flag(const std::string& names, bool& target, const std::string& help);

  // A subcommand; parsed() says whether the command line named it.
  App* add_subcommand(const std::string& name, const std::string& description);
  App* require_subcommand(int count);
  App* footer(const std::string& text);
  bool parsed() const;
  // How often the option or flag was given (0: not at all).
  std::size_t count(const std::string& name) const;

  // Parses the command line. Returns nothing to go on, or the exit code to
  // return from main: 0 after --help, non-zero after an error (printed).
  std::optional<int> parse(int argc, const char* const* argv);

 private:
  explicit App(CLI::App* borrowed);
  Option* keep(CLI::Option* option);

  std::unique_ptr<CLI::App> owned_;
  CLI::App* app_;
  std::vector<std::unique_ptr<Option>> options_;
  std::vector<std::unique_ptr<App>> subcommands_;
};

}  // namespace fahr::cli
