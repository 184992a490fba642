// Whatever text arrives, the loader either returns a scene or throws
// SceneError: never another exception from yaml-cpp or the standard library.
// Deterministic mutations of the example scene stand in for a fuzzer.
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "fahr/scene/scene_error.h"
#include "test_support.h"

namespace fahr::scene::test {
namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += line + '\n';
  return out;
}

// One of: drop a line, duplicate a line, cut the text short, put a YAML
// indicator somewhere, replace a value with a troublesome scalar or structure.
std::string mutate(const std::string& text, std::mt19937& rng) {
  static constexpr const char* kValues[] = {
      "",    "~",    "[]", "{}",  "[1, 2]", "{a: 1}",   "\"7\"",       "-1",   "1e400",
      "nan", ".inf", "x",  "- a", "&a 1",   "*missing", "[[a, b], c]", "0x10", "true"};
  std::vector<std::string> lines = lines_of(text);
  if (lines.empty()) return "name: x\n";  // cut to nothing earlier: start again
  std::uniform_int_distribution<std::size_t> pick_line(0, lines.size() - 1);
  const std::size_t at = pick_line(rng);
  switch (rng() % 5) {
    case 0:
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(at));
      break;
    case 1:
      lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(at), lines[at]);
      break;
    case 2:
      return text.substr(0, rng() % text.size());
    case 3: {
      // A YAML indicator character where it does not belong.
      static constexpr std::string_view kIndicators = "[]{}:-&*!|>#'\"\t\n ,?%@`";
      std::string out = text;
      out[rng() % out.size()] = kIndicators[rng() % kIndicators.size()];
      return out;
    }
    default: {
      const std::size_t colon = lines[at].find(':');
      const char* value = kValues[rng() % std::size(kValues)];
      if (colon != std::string::npos) lines[at] = lines[at].substr(0, colon + 1) + " " + value;
      break;
    }
  }
  return joined(lines);
}

TEST(SceneRobustness, MutatedScenesOnlyEverThrowSceneError) {
  const std::string original = read_text(scenes_dir() / "neonatal_intubation.yaml");
  std::mt19937 rng(20240611);  // fixed seed: the same 2,000 cases every run
  int rejected = 0;
  for (int i = 0; i < 2000; ++i) {
    std::string text = original;
    const int mutations = 1 + static_cast<int>(rng() % 3);
    for (int m = 0; m < mutations; ++m) text = mutate(text, rng);
    try {
      parse_scene(text, "fuzz.yaml", "/scene", LoadOptions{false});
    } catch (const SceneError& error) {
      ++rejected;
      EXPECT_NE(std::string(error.what()).find("fuzz.yaml"), std::string::npos);
    } catch (const std::exception& error) {
      ADD_FAILURE() << "case " << i << " threw " << error.what() << " for:\n" << text;
      return;
    }
  }
  // Most mutations break something; if none did, the mutator is broken.
  EXPECT_GT(rejected, 500);
}

}  // namespace
}  // namespace fahr::scene::test
