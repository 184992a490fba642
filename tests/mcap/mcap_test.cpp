// The MCAP writer and reader against each other, and recovery after SIGKILL.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fahr/mcap/indexed_reader.h"
#include "fahr/mcap/reader.h"
#include "fahr/mcap/writer.h"

namespace fahr::mcap {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  return fs::temp_directory_path() / ("fahr_mcap_test_" + std::to_string(getpid()));
}

std::string temp_path(const std::string& name) {
  fs::create_directories(temp_dir());
  return (temp_dir() / name).string();
}

// Removes the test's files when the binary ends.
class TempFiles : public ::testing::Environment {
 public:
  void TearDown() override { fs::remove_all(temp_dir()); }
};
const auto* const kTempFiles = ::testing::AddGlobalTestEnvironment(new TempFiles);

// Payload of message i: its size varies so chunks hold uneven counts.
std::vector<std::uint8_t> payload(std::uint32_t i) {
  std::vector<std::uint8_t> p(20 + (std::size_t{i} * 37) % 300);
  for (std::size_t k = 0; k < p.size(); ++k)
    p[k] = static_cast<std::uint8_t>(std::size_t{i} * 7 + k);
  return p;
}

struct Written {
  std::uint16_t a = 0, b = 0;
};

Written write_sample(Writer& w, std::uint32_t messages) {
  const auto schema = w.add_schema({0, "fahr::msg::Test", "omgidl", "module fahr { };"});
  Written ids;
  ids.a = w.add_channel({0, schema, "fahr/A", "cdr", {{"key", "body_id=0"}}});
  ids.b = w.add_channel({0, schema, "fahr/B", "cdr", {}});
  w.write_metadata({"fahr_run", {{"scene", "text"}, {"vendor", "fast"}}});
  for (std::uint32_t i = 0; i < messages; ++i) {
    const auto p = payload(i);
    const std::uint64_t t = 1'000'000'000ULL + i * 1'000'000ULL;
    w.write_message(i % 3 == 0 ? ids.b : ids.a, i, t, t - 500, p.data(), p.size());
  }
  return ids;
}

class RoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(RoundTrip, EveryMessageComesBackWithItsTimesAndCrcsHold) {
  WriterOptions options;
  options.compression = GetParam();
  options.chunk_size = 16 * 1024ULL;  // many chunks
  options.sync_chunks = false;
  const std::string path =
      temp_path("roundtrip_" + (GetParam().empty() ? "none" : GetParam()) + ".mcap");
  constexpr std::uint32_t kMessages = 5000;
  {
    Writer w(options);
    w.open(path);
    EXPECT_TRUE(fs::exists(path + ".part"));
    write_sample(w, kMessages);
    w.close();
  }
  EXPECT_FALSE(fs::exists(path + ".part"));
  std::uint32_t next = 0;
  bool in_order = true;
  const auto r = read_file(path, [&](const Channel& c, const MessageView& m) {
    const auto p = payload(m.sequence);
    in_order = in_order && m.sequence == next;
    ++next;
    EXPECT_EQ(c.topic, m.sequence % 3 == 0 ? "fahr/B" : "fahr/A");
    EXPECT_EQ(m.log_time, 1'000'000'000ULL + m.sequence * 1'000'000ULL);
    EXPECT_EQ(m.publish_time, m.log_time - 500);
    ASSERT_EQ(m.data.size(), p.size());
    EXPECT_TRUE(std::equal(p.begin(), p.end(), m.data.begin()));
  });
  EXPECT_TRUE(r.valid()) << r.error;
  EXPECT_TRUE(in_order);
  EXPECT_EQ(r.messages, kMessages);
  EXPECT_GT(r.chunks, 10U);
  // One chunk CRC per chunk, the data section's and the summary's: none 0.
  EXPECT_EQ(r.crcs_checked, r.chunks + 2);
  EXPECT_EQ(r.crcs_absent, 0U);
  ASSERT_TRUE(r.statistics.has_value());
  EXPECT_EQ(r.statistics->message_count, kMessages);
  EXPECT_EQ(r.statistics->chunk_count, r.chunks);
  EXPECT_EQ(r.statistics->channel_count, 2U);
  EXPECT_EQ(r.statistics->schema_count, 1U);
  EXPECT_EQ(r.statistics->metadata_count, 1U);
  EXPECT_EQ(r.chunk_indexes.size(), r.chunks);
  EXPECT_EQ(r.compressions.count(GetParam()), 1U);
  ASSERT_EQ(r.metadata.size(), 1U);
  EXPECT_EQ(r.metadata[0].values.at("vendor"), "fast");
  EXPECT_EQ(r.channels.at(1).metadata.at("key"), "body_id=0");
}

INSTANTIATE_TEST_SUITE_P(Compression, RoundTrip, ::testing::Values("", "zstd", "lz4"),
                         [](const auto& test) {
                           return test.param.empty() ? std::string("none") : test.param;
                         });

TEST(Mcap, AFlippedByteFailsItsCrc) {
  WriterOptions options;
  options.compression = "";
  options.sync_chunks = false;
  const std::string path = temp_path("flipped.mcap");
  {
    Writer w(options);
    w.open(path);
    write_sample(w, 100);
  }
  ASSERT_TRUE(read_file(path).valid());
  // Byte 600 lies inside the first (uncompressed) chunk's messages.
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(600);
  char c = 0;
  f.read(&c, 1);
  c = static_cast<char>(c ^ 0x5a);
  f.seekp(600);
  f.write(&c, 1);
  f.close();
  const auto r = read_file(path);
  EXPECT_FALSE(r.valid());
  EXPECT_GE(r.crc_failures, 1U);
}

TEST(Mcap, SplitsBySizeAndEveryPartStandsAlone) {
  WriterOptions options;
  options.chunk_size = 8 * 1024ULL;
  options.split_bytes = 64 * 1024ULL;
  options.sync_chunks = false;
  const std::string path = temp_path("split.mcap");
  std::vector<std::string> files;
  {
    Writer w(options);
    w.open(path);
    write_sample(w, 3000);
    w.close();
    files = w.files();
  }
  ASSERT_GT(files.size(), 2U);
  EXPECT_EQ(files[1], split_file_name(path, 1));
  std::uint64_t total = 0;
  for (const auto& f : files) {
    const auto r = read_file(f, [](const Channel&, const MessageView&) {});
    EXPECT_TRUE(r.valid()) << f << ": " << r.error;
    EXPECT_EQ(r.schemas.size(), 1U);
    EXPECT_EQ(r.channels.size(), 2U);
    EXPECT_EQ(r.metadata.size(), 1U);
    total += r.messages;
  }
  EXPECT_EQ(total, 3000U);
}

// A recorder killed with SIGKILL keeps every chunk it had written out.
TEST(Mcap, RecoverAfterSigkillKeepsEveryCompleteChunk) {
  const std::string path = temp_path("killed.mcap");
  constexpr std::uint32_t kFlushed = 1200;  // written, then flushed as chunks
  constexpr std::uint32_t kOpen = 150;      // in the open chunk at the kill
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(ready[0]);
    WriterOptions options;
    options.chunk_size = 32 * 1024ULL;
    options.compression = "zstd";
    Writer w(options);
    w.open(path);
    write_sample(w, kFlushed);
    w.flush();
    const auto p = payload(0);
    for (std::uint32_t i = 0; i < kOpen; ++i) {
      w.write_message(1, kFlushed + i, 5'000'000'000ULL + i, 0, p.data(), p.size());
    }
    const char byte = 1;
    if (write(ready[1], &byte, 1) != 1) _exit(3);
    pause();  // killed here, never closes
    _exit(0);
  }
  close(ready[1]);
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  close(ready[0]);
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  ASSERT_TRUE(fs::exists(path + ".part"));
  ASSERT_FALSE(fs::exists(path));
  EXPECT_FALSE(read_file(path + ".part").valid());

  const auto result = recover(path + ".part");
  EXPECT_EQ(result.output, path);
  EXPECT_EQ(result.messages, kFlushed);
  const auto r = read_file(path);
  EXPECT_TRUE(r.valid()) << r.error;
  EXPECT_EQ(r.messages, kFlushed);
  EXPECT_EQ(r.metadata.size(), 1U);
  EXPECT_EQ(r.channels.size(), 2U);
}

// A file cut at any byte recovers to a valid file holding a prefix.
TEST(Mcap, RecoverFromAnyTruncation) {
  WriterOptions options;
  options.chunk_size = 4 * 1024ULL;
  options.sync_chunks = false;
  const std::string path = temp_path("cut.mcap");
  {
    Writer w(options);
    w.open(path);
    write_sample(w, 400);
  }
  std::string bytes(fs::file_size(path), '\0');
  std::ifstream(path, std::ios::binary)
      .read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::uint64_t previous = 0;
  for (std::size_t cut = 2000; cut < bytes.size(); cut += 1777) {
    const std::string part = temp_path("cut_piece.mcap.part");
    std::ofstream(part, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(cut));
    const auto result = recover(part);
    const auto r = read_file(result.output);
    EXPECT_TRUE(r.valid()) << "cut at " << cut << ": " << r.error;
    EXPECT_GE(r.messages, previous);
    previous = r.messages;
  }
  EXPECT_GT(previous, 300U);
}

TEST(Mcap, IndexedReaderSeeksByReadingOnlyTheChunksOfTheSpan) {
  WriterOptions options;
  options.compression = "zstd";
  options.chunk_size = 16 * 1024ULL;
  options.sync_chunks = false;
  const std::string path = temp_path("indexed.mcap");
  constexpr std::uint32_t kMessages = 5000;
  {
    Writer w(options);
    w.open(path);
    write_sample(w, kMessages);
    w.close();
  }
  IndexedReader r(path);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r.message_count(), kMessages);
  EXPECT_EQ(r.start_time(), 1'000'000'000ULL);
  EXPECT_EQ(r.end_time(), 1'000'000'000ULL + (kMessages - 1) * 1'000'000ULL);
  EXPECT_EQ(r.channels().size(), 2U);
  EXPECT_EQ(r.schemas().size(), 1U);
  ASSERT_GT(r.chunks().size(), 10U);
  // 100 ms in the middle: messages 3000..3099, from one or two chunks.
  const std::uint64_t begin = 1'000'000'000ULL + 3000ULL * 1'000'000ULL;
  std::vector<std::uint32_t> seen;
  ASSERT_TRUE(r.read(begin, begin + 100'000'000ULL, [&](const Channel& c, const MessageView& m) {
    const auto p = payload(m.sequence);
    ASSERT_EQ(m.data.size(), p.size());
    EXPECT_TRUE(std::equal(p.begin(), p.end(), m.data.begin()));
    EXPECT_EQ(c.topic, m.sequence % 3 == 0 ? "fahr/B" : "fahr/A");
    seen.push_back(m.sequence);
  }));
  ASSERT_EQ(seen.size(), 100U);
  for (std::uint32_t i = 0; i < 100; ++i) EXPECT_EQ(seen[i], 3000 + i);
  EXPECT_LE(r.chunks_read(), 3U);
  // The torn .part of a killed writer has no summary: refused, not guessed.
  {
    Writer w(options);
    w.open(temp_path("torn.mcap"));
    write_sample(w, 100);
    w.flush();
    IndexedReader torn(temp_path("torn.mcap") + ".part");
    EXPECT_FALSE(torn.ok());
  }
}

// A stream that falls silent (a recorder that received nothing of it for a
// while): the state at a moment long after still holds its last message,
// and only the chunks that can hold it are read.
TEST(Mcap, IndexedReaderFindsEachChannelsNewestMessageHoweverOld) {
  WriterOptions options;
  options.compression = "zstd";
  options.chunk_size = 16 * 1024ULL;
  options.sync_chunks = false;
  const std::string path = temp_path("newest.mcap");
  Written ids;
  {
    Writer w(options);
    w.open(path);
    const auto schema = w.add_schema({0, "fahr::msg::Test", "omgidl", "module fahr { };"});
    ids.a = w.add_channel({0, schema, "fahr/A", "cdr", {}});
    ids.b = w.add_channel({0, schema, "fahr/B", "cdr", {}});
    // B for the first 200 ms only, A throughout (5 s at 1 kHz).
    for (std::uint32_t i = 0; i < 5000; ++i) {
      const auto p = payload(i);
      const std::uint64_t t = 1'000'000'000ULL + i * 1'000'000ULL;
      w.write_message(i < 200 && i % 2 == 0 ? ids.b : ids.a, i, t, t, p.data(), p.size());
    }
    w.close();
  }
  IndexedReader r(path);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_GT(r.chunks().size(), 20U);
  std::vector<std::pair<std::string, std::uint32_t>> seen;
  const auto collect = [&](const Channel& c, const MessageView& m) {
    const auto p = payload(m.sequence);
    EXPECT_TRUE(std::equal(p.begin(), p.end(), m.data.begin(), m.data.end()));
    seen.emplace_back(c.topic, m.sequence);
  };
  // At 4 s: A's message 2999, B's 198 (its last), oldest first.
  const auto all = [](const Channel&) { return true; };
  ASSERT_TRUE(r.read_newest(1'000'000'000ULL + 3000ULL * 1'000'000ULL, all, collect));
  const std::vector<std::pair<std::string, std::uint32_t>> expected{{"fahr/B", 198},
                                                                    {"fahr/A", 2999}};
  EXPECT_EQ(seen, expected);
  // The chunk before the moment and B's last: not every chunk between.
  EXPECT_LE(r.chunks_read(), 3U);
  // Before the first message nothing; 1 ms later B's first alone; a filter
  // that takes only B.
  seen.clear();
  ASSERT_TRUE(r.read_newest(1'000'000'000ULL, all, collect));
  EXPECT_TRUE(seen.empty());
  ASSERT_TRUE(r.read_newest(1'000'000'000ULL + 1'000'000ULL, all, collect));
  ASSERT_EQ(seen.size(), 1U);
  EXPECT_EQ(seen[0], std::make_pair(std::string("fahr/B"), 0U));
  seen.clear();
  ASSERT_TRUE(r.read_newest(
      1'000'000'000ULL + 4000ULL * 1'000'000ULL,
      [](const Channel& c) { return c.topic == "fahr/B"; }, collect));
  ASSERT_EQ(seen.size(), 1U);
  EXPECT_EQ(seen[0].second, 198U);
}

TEST(Mcap, IndexedReaderRefusesGarbage) {
  const std::string path = temp_path("garbage.mcap");
  {
    std::ofstream f(path, std::ios::binary);
    for (int i = 0; i < 1000; ++i) f.put(static_cast<char>(i * 31));
  }
  IndexedReader r(path);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.read(0, ~0ULL, [](const Channel&, const MessageView&) {}));
  IndexedReader missing(temp_path("missing.mcap"));
  EXPECT_FALSE(missing.ok());
}

}  // namespace
}  // namespace fahr::mcap
