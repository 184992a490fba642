// Samples of every topic type with every field set to a seeded,
// non-default value, and a byte-exact comparison through CDR, so interop
// tests prove that all fields cross a vendor boundary intact.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fahr/common/topics.h"

namespace fahr::test {

// Fills every field, sequences at `sequence_length` elements (clamped to
// their bounds). The same seed gives the same sample.
void fill(msg::DevicePose& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::ForceCommand& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::ContactSet& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::DeformationState& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::SceneDescription& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::ServiceStatus& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::ServiceEvents& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::SimClock& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::StepAck& s, std::uint64_t seed, std::size_t sequence_length);
void fill(msg::GlotticView& s, std::uint64_t seed, std::size_t sequence_length);

// The CDR bytes of a sample (fastddsgen serialisation, with encapsulation).
template <class T>
std::vector<std::uint8_t> cdr_bytes(const T& sample);

}  // namespace fahr::test
