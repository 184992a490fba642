// fahr::cli over CLI11 (see cli.h).
#include "fahr/cli/cli.h"

#include <CLI/CLI.hpp>

namespace fahr::cli {

Validator Range(double low, double high) {
  Validator v;
  v.kind = Validator::Kind::kRange;
  v.low = low;
  v.high = high;
  return v;
}

Validator Range(int low, int high) {
  Validator v = Range(static_cast<double>(low), static_cast<double>(high));
  v.integral = true;
  return v;
}

const Validator PositiveNumber{Validator::Kind::kPositive, 0.0, 0.0, false, {}};

Validator IsMember(std::vector<std::string> members) {
  Validator v;
  v.kind = Validator::Kind::kMember;
  v.members = std::move(members);
  return v;
}

Option* Option::required() {
  option_->required();
  return this;
}

Option* Option::check(const Validator& validator) {
  switch (validator.kind) {
    case Validator::Kind::kRange:
      if (validator.integral) {
        option_->check(CLI::Range(static_cast<long long>(validator.low),
                                  static_cast<long long>(validator.high)));
      } else {
        option_->check(CLI::Range(validator.low, validator.high));
      }
      break;
    case Validator::Kind::kPositive:
      option_->check(CLI::PositiveNumber);
      break;
    case Validator::Kind::kMember:
      option_->check(CLI::IsMember(validator.members));
      break;
  }
  return this;
}

Option* Option::type_name(const std::string& name) {
  option_->type_name(name);
  return this;
}

Option* Option::excludes(Option* other) {
  option_->excludes(other->option_);
  return this;
}

Option* Option::excludes(const std::string& other_name) {
  option_->excludes(other_name);
  return this;
}

App::App(const std::string& description, const std::string& name)
    : owned_(std::make_unique<CLI::App>(description, name)), app_(owned_.get()) {}

App::App(CLI::App* borrowed) : app_(borrowed) {}

App::~App() = default;

Option* App::keep(CLI::Option* option) {
  options_.push_back(std::make_unique<Option>(option));
  return options_.back().get();
}

Option* App::add_option(const std::string& names, std::string& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, double& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, int& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, unsigned& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, long& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, unsigned long& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, long long& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, unsigned long long& target,
                        const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, unsigned short& target, const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, std::vector<std::string>& target,
                        const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_option(const std::string& names, std::vector<double>& target,
                        const std::string& help) {
  return keep(app_->add_option(names, target, help));
}
Option* App::add_flag(const std::string& names, bool& target, const std::string& help) {
  return keep(app_->add_flag(names, target, help));
}

App* App::add_subcommand(const std::string& name, const std::string& description) {
  subcommands_.push_back(std::unique_ptr<App>(new App(app_->add_subcommand(name, description))));
  return subcommands_.back().get();
}

App* App::require_subcommand(int count) {
  app_->require_subcommand(count);
  return this;
}

App* App::footer(const std::string& text) {
  app_->footer(text);
  return this;
}

bool App::parsed() const {
  return app_->parsed();
}

std::size_t App::count(const std::string& name) const {
  return app_->count(name);
}

std::optional<int> App::parse(int argc, const char* const* argv) {
  try {
    app_->parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app_->exit(e);
  }
  return std::nullopt;
}

}  // namespace fahr::cli
