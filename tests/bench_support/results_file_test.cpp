#include "fahr/bench_support/results_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fahr::bench_support {
namespace {

TEST(MachineSlug, LowercasesAndJoinsWordsWithDashes) {
  EXPECT_EQ(machine_slug("AMD EPYC", 2), "amd-epyc-2c");
  EXPECT_EQ(machine_slug("Intel(R) Core(TM) i7-8650U CPU @ 1.90GHz", 8),
            "intel-r-core-tm-i7-8650u-cpu-1-90ghz-8c");
  EXPECT_EQ(machine_slug("  --  ", 1), "unknown-cpu-1c");
}

TEST(MachineSlug, ThisMachineHasOne) {
  const Machine m = this_machine();
  EXPECT_GE(m.online_cpus, 1U);
  EXPECT_EQ(m.slug, machine_slug(m.cpu_model == "unknown" ? "" : m.cpu_model, m.online_cpus));
}

// argv as a bench gets it, kept alive for MarkdownResults to edit.
struct Args {
  explicit Args(std::vector<std::string> words) : storage(std::move(words)) {
    for (auto& w : storage) pointers.push_back(w.data());
    pointers.push_back(nullptr);
    argc = static_cast<int>(storage.size());
  }
  std::vector<std::string> rest() const { return {pointers.begin(), pointers.begin() + argc}; }
  std::vector<std::string> storage;
  std::vector<char*> pointers;
  int argc = 0;
};

TEST(MarkdownResults, TakesItsFlagOutOfTheArguments) {
  Args plain({"bench", "detection", "--ticks", "20"});
  const MarkdownResults none(plain.argc, plain.pointers.data());
  EXPECT_FALSE(none.requested());
  EXPECT_EQ(plain.rest(), (std::vector<std::string>{"bench", "detection", "--ticks", "20"}));

  Args bare({"bench", "--markdown", "detection"});
  const MarkdownResults default_path(bare.argc, bare.pointers.data());
  EXPECT_TRUE(default_path.requested());
  EXPECT_EQ(bare.rest(), (std::vector<std::string>{"bench", "detection"}));

  Args file({"bench", "all", "--markdown", "out/x.md", "--quick"});
  const MarkdownResults named(file.argc, file.pointers.data());
  EXPECT_TRUE(named.requested());
  EXPECT_EQ(file.rest(), (std::vector<std::string>{"bench", "all", "--quick"}));
  EXPECT_EQ(file.pointers[static_cast<std::size_t>(file.argc)], nullptr);

  Args script({"tool", "name", "--markdown", "--", "run.sh", "--markdown", "a.md"});
  const MarkdownResults before_dashes(script.argc, script.pointers.data());
  EXPECT_TRUE(before_dashes.requested());
  EXPECT_EQ(script.rest(),
            (std::vector<std::string>{"tool", "name", "--", "run.sh", "--markdown", "a.md"}));

  Args equals({"bench", "--markdown=y", "punch"});
  const MarkdownResults with_equals(equals.argc, equals.pointers.data());
  EXPECT_TRUE(with_equals.requested());
  EXPECT_EQ(equals.rest(), (std::vector<std::string>{"bench", "punch"}));
}

TEST(MarkdownResults, FileHoldsTheHeaderAndWhatWasPrinted) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("fahr-bench-support-" + std::to_string(::getpid()));
  const std::string path = (dir / "nested" / "result.md").string();
  Args args({"bench", "--ticks", "5", "--markdown", path});
  {
    MarkdownResults results(args.argc, args.pointers.data());
    std::printf("before begin\n");
    results.begin("ignored-name");
    std::printf("| a | b |\n|---|---|\n| %d | %.1f |\n", 1, 2.5);
    results.finish();
    std::printf("after finish\n");
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string file = text.str();
  EXPECT_NE(file.find("| command | `bench --ticks 5 --markdown " + path + "` |"), std::string::npos)
      << file;
  EXPECT_NE(file.find("| commit | "), std::string::npos);
  EXPECT_NE(file.find("| machine | "), std::string::npos);
  EXPECT_NE(file.find("| date | "), std::string::npos);
  EXPECT_NE(file.find("| a | b |\n|---|---|\n| 1 | 2.5 |\n"), std::string::npos) << file;
  EXPECT_EQ(file.find("before begin"), std::string::npos);
  EXPECT_EQ(file.find("after finish"), std::string::npos);
  EXPECT_NE(file.find("Wall time"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(MarkdownResults, FencesPlainTextOutput) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("fahr-bench-support-text-" + std::to_string(::getpid()) + ".md");
  Args args({"bench", "--markdown=" + path.string()});
  {
    MarkdownResults results(args.argc, args.pointers.data());
    results.begin("text", MarkdownResults::Output::kText);
    std::printf("  runs  froze\n    10      2\n");
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("```text\n  runs  froze\n    10      2\n```\n"), std::string::npos)
      << text.str();
  std::filesystem::remove(path);
}

TEST(MarkdownResults, WithoutTheFlagWritesNothing) {
  Args args({"bench"});
  MarkdownResults results(args.argc, args.pointers.data());
  results.begin("never-written");
  results.finish();
  EXPECT_FALSE(std::filesystem::exists(default_results_path("never-written")));
}

}  // namespace
}  // namespace fahr::bench_support
