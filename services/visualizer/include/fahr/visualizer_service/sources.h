// Where the visualizer's samples come from, and where the mouse device's
// poses go.
//   DdsSource:    raw CDR subscriptions to the shown topics on a participant;
//                 each callback copies the bytes into LiveState and returns.
//   ReplaySource: an MCAP recording streamed through mcap::IndexedReader
//                 (only the chunks around the play position are read) at
//                 real or scaled speed, with pause and seek.
//   RemoteInput:  DevicePose on fahr/RemoteInput, which the device gateway's
//                 remote back-end (--backend remote) screens, clamps to the
//                 workspace and turns into the device's poses.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/participant.h"
#include "fahr/common/raw_subscriber.h"
#include "fahr/mcap/indexed_reader.h"
#include "fahr/visualizer_service/live_state.h"
#include "fahr/visualizer_service/server.h"

namespace fahr::msg {
class DevicePose;
}  // namespace fahr::msg

namespace fahr::visualizer_service {

class DdsSource {
 public:
  DdsSource(common::Participant& participant, LiveState& live);
  ~DdsSource();
  DdsSource(const DdsSource&) = delete;
  DdsSource& operator=(const DdsSource&) = delete;
  int matched_writers() const;

 private:
  std::vector<std::unique_ptr<common::RawSubscriber>> subscribers_;
};

class ReplaySource {
 public:
  // Throws std::runtime_error if the file cannot be read with its index.
  ReplaySource(const std::string& path, LiveState& live, double speed);
  ~ReplaySource();
  ReplaySource(const ReplaySource&) = delete;
  ReplaySource& operator=(const ReplaySource&) = delete;

  void start();
  void stop();
  // "pause", "play", "seek" (value: seconds from the start), "speed"
  // (value: 0.05-4). Returns "" or why it was refused. Any thread.
  std::string control(const std::string& action, double value);
  // {"op":"replay","t":..,"duration":..,"paused":..,"speed":..}
  std::string position_json() const;
  double duration_s() const;
  std::uint64_t chunks_read() const { return chunks_read_.load(); }
  bool finished() const { return finished_.load(); }

 private:
  void run();
  void fill(std::uint64_t begin, std::uint64_t end);
  void refill(std::uint64_t cursor);

  mcap::IndexedReader reader_;
  LiveState& live_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, finished_{false};
  mutable std::mutex mutex_;
  std::uint64_t cursor_ = 0;  // log time, ns
  bool paused_ = false;
  double speed_ = 1.0;
  std::uint64_t seek_to_ = 0;
  bool seek_pending_ = false;
  std::atomic<std::uint64_t> chunks_read_{0};
};

class RemoteInput {
 public:
  explicit RemoteInput(common::Participant& participant);
  ~RemoteInput();
  RemoteInput(const RemoteInput&) = delete;
  RemoteInput& operator=(const RemoteInput&) = delete;
  void publish(const RemotePose& pose);
  // A Foxglove client's DevicePose in CDR; false if it does not decode.
  bool publish_cdr(std::span<const std::uint8_t> cdr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fahr::visualizer_service
