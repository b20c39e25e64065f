#include "drivers/imu/xbus_parser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "drivers/imu/xbus_protocol.h"

namespace rover::drivers {
namespace {

using Bytes = std::vector<uint8_t>;

struct Frame {
  uint8_t mid = 0;
  Bytes payload;
  bool operator==(const Frame&) const = default;
};

Bytes Encode(const Frame& f) {
  Bytes out(xbus::FrameBytes(f.payload.size()));
  EXPECT_EQ(xbus::EncodeMessage(f.mid, f.payload, out), out.size());
  return out;
}

void Append(Bytes* stream, const Bytes& bytes) {
  stream->insert(stream->end(), bytes.begin(), bytes.end());
}

// Drains every frame the parser has.
void Drain(XbusParser* parser, std::vector<Frame>* out) {
  xbus::Message m;
  while (parser->Next(&m)) out->push_back({m.mid, Bytes(m.payload.begin(), m.payload.end())});
}

// Feeds `stream` in the given chunk sizes (cycled), draining after each.
std::vector<Frame> ParseInChunks(XbusParser* parser, const Bytes& stream,
                                 const std::vector<std::size_t>& chunks) {
  std::vector<Frame> frames;
  std::size_t i = 0;
  for (std::size_t c = 0; i < stream.size(); ++c) {
    const std::size_t n = std::min(chunks[c % chunks.size()], stream.size() - i);
    std::size_t fed = 0;
    while (fed < n) {
      fed += parser->Feed({stream.data() + i + fed, n - fed});
      Drain(parser, &frames);
    }
    i += n;
  }
  Drain(parser, &frames);
  return frames;
}

std::vector<Frame> ParseAll(const Bytes& stream, XbusParserStats* stats = nullptr) {
  XbusParser parser;
  std::vector<Frame> frames = ParseInChunks(&parser, stream, {stream.size() + 1});
  if (stats != nullptr) *stats = parser.stats();
  return frames;
}

Frame Payload(uint8_t mid, std::size_t size, uint8_t seed) {
  Frame f{mid, Bytes(size)};
  for (std::size_t i = 0; i < size; ++i) f.payload[i] = static_cast<uint8_t>(seed + 13 * i);
  return f;
}

TEST(XbusParserTest, RoundTripsFramesOfEverySizeClass) {
  const std::vector<Frame> frames = {Payload(0x31, 0, 1),   Payload(0x36, 1, 2),
                                     Payload(0x36, 254, 3), Payload(0x36, 255, 4),
                                     Payload(0x36, 300, 5), Payload(0x36, 2048, 6)};
  Bytes stream;
  for (const Frame& f : frames) Append(&stream, Encode(f));
  XbusParserStats stats;
  EXPECT_EQ(ParseAll(stream, &stats), frames);
  EXPECT_EQ(stats.frames, frames.size());
  EXPECT_EQ(stats.garbage_bytes, 0u);
  EXPECT_EQ(stats.checksum_errors, 0u);
  EXPECT_EQ(stats.resyncs, 0u);
}

// Garbage that holds lone preambles and bus ids but never the pair 0xFA
// 0xFF, so the exact garbage count is known.
const Bytes kGarbage = {0x00, 0xFA, 0x12, 0xFF, 0xFA, 0xFA, 0x36, 0x10, 0xFF, 0xFF, 0xFA};

TEST(XbusParserTest, ResyncsAfterGarbageAtEverySplitPoint) {
  const std::vector<Frame> frames = {Payload(0x36, 40, 1), Payload(0x31, 0, 2),
                                     Payload(0x36, 300, 3), Payload(0x01, 4, 4)};
  Bytes stream = kGarbage;
  for (const Frame& f : frames) {
    Append(&stream, Encode(f));
    Append(&stream, kGarbage);
  }
  XbusParserStats whole;
  ASSERT_EQ(ParseAll(stream, &whole), frames);
  // The trailing lone 0xFA stays buffered as a possible frame start, so the
  // last run counts one byte short until more bytes come.
  EXPECT_EQ(whole.garbage_bytes, kGarbage.size() * (frames.size() + 1) - 1);
  // Each garbage run is one loss of sync (the parser starts in sync).
  EXPECT_EQ(whole.resyncs, frames.size() + 1);

  for (std::size_t split = 0; split <= stream.size(); ++split) {
    XbusParser parser;
    std::vector<Frame> got;
    parser.Feed({stream.data(), split});
    Drain(&parser, &got);
    parser.Feed({stream.data() + split, stream.size() - split});
    Drain(&parser, &got);
    ASSERT_EQ(got, frames) << "split at " << split;
    ASSERT_EQ(parser.stats().garbage_bytes, whole.garbage_bytes) << "split at " << split;
    ASSERT_EQ(parser.stats().resyncs, whole.resyncs) << "split at " << split;
  }
  // And byte by byte.
  XbusParser parser;
  EXPECT_EQ(ParseInChunks(&parser, stream, {1}), frames);
  EXPECT_EQ(parser.stats().garbage_bytes, whole.garbage_bytes);
}

TEST(XbusParserTest, RejectsABadChecksumAndFindsTheNextFrame) {
  const Frame a = Payload(0x36, 40, 1), b = Payload(0x36, 40, 2);
  Bytes bad = Encode(a);
  bad[10] ^= 0x01;
  Bytes stream = bad;
  Append(&stream, Encode(b));
  XbusParserStats stats;
  EXPECT_EQ(ParseAll(stream, &stats), std::vector<Frame>{b});
  EXPECT_EQ(stats.checksum_errors, 1u);
  EXPECT_EQ(stats.garbage_bytes, bad.size());
  EXPECT_EQ(stats.resyncs, 1u);
}

TEST(XbusParserTest, RejectsImpossibleLengths) {
  // Extended length 4096 > 2048.
  Bytes stream = {0xFA, 0xFF, 0x36, 0xFF, 0x10, 0x00, 0x01, 0x02};
  const Frame b = Payload(0x36, 10, 2);
  Append(&stream, Encode(b));
  XbusParserStats stats;
  EXPECT_EQ(ParseAll(stream, &stats), std::vector<Frame>{b});
  EXPECT_EQ(stats.oversize_frames, 1u);
  EXPECT_EQ(stats.garbage_bytes, 8u);

  // A smaller maximum makes shorter lengths impossible too.
  XbusParser small(100);
  Bytes big = Encode(Payload(0x36, 101, 3));
  small.Feed(big);
  xbus::Message m;
  EXPECT_FALSE(small.Next(&m));
  EXPECT_EQ(small.stats().oversize_frames, 1u);
}

TEST(XbusParserTest, FindsAFrameThatStartsInsideATruncatedOne) {
  const Frame a = Payload(0x36, 60, 1), b = Payload(0x36, 20, 2), c = Payload(0x36, 20, 3);
  const Bytes full_a = Encode(a);
  Bytes stream(full_a.begin(), full_a.begin() + 30);  // a lost its tail
  Append(&stream, Encode(b));
  Append(&stream, Encode(c));
  XbusParserStats stats;
  EXPECT_EQ(ParseAll(stream, &stats), (std::vector<Frame>{b, c}));
  EXPECT_GE(stats.checksum_errors, 1u);
}

TEST(XbusParserTest, ZeroCopyReadsGoStraightIntoTheBuffer) {
  const Frame a = Payload(0x36, 100, 1);
  const Bytes bytes = Encode(a);
  XbusParser parser;
  std::vector<Frame> got;
  for (int round = 0; round < 200; ++round) {  // enough to wrap the buffer many times
    std::size_t i = 0;
    while (i < bytes.size()) {
      std::span<uint8_t> space = parser.WritableSpace();
      ASSERT_GT(space.size(), 0u);
      const std::size_t n = std::min<std::size_t>({space.size(), bytes.size() - i, 37});
      std::copy_n(bytes.begin() + static_cast<std::ptrdiff_t>(i), n, space.begin());
      parser.Commit(n);
      i += n;
      Drain(&parser, &got);
    }
  }
  ASSERT_EQ(got.size(), 200u);
  EXPECT_EQ(got.back(), a);
}

// Seeded random corruption: frames flipped, truncated, split by garbage,
// fed in random chunks. The parser must never crash, never hand out a frame
// that is not verbatim in the stream with a valid checksum, lose almost no
// intact frame (an 8-bit checksum lets about 1 in 256 false candidates
// through, and such a candidate may swallow the frame after it), and
// parse the same whatever the chunking.
TEST(XbusParserTest, SurvivesSeededRandomCorruption) {
  uint64_t intact_total = 0, intact_found = 0;
  for (uint32_t seed = 1; seed <= 25; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> byte(0, 255), percent(0, 99);
    Bytes stream;
    std::vector<Frame> intact;
    for (int k = 0; k < 200; ++k) {
      const auto size = static_cast<std::size_t>(
          percent(rng) < 5 ? 255 + byte(rng) : std::uniform_int_distribution<int>(0, 80)(rng));
      Frame f{static_cast<uint8_t>(percent(rng) < 80 ? 0x36 : byte(rng)), Bytes(size)};
      for (uint8_t& b : f.payload) b = static_cast<uint8_t>(byte(rng));
      Bytes bytes = Encode(f);
      const int op = percent(rng);
      if (op < 10) {  // garbage before the frame (keeps it intact)
        const int n = 1 + percent(rng) % 40;
        for (int i = 0; i < n; ++i) stream.push_back(static_cast<uint8_t>(byte(rng)));
      }
      if (op >= 10 && op < 20) {  // flip a byte
        bytes[static_cast<std::size_t>(rng() % bytes.size())] ^=
            static_cast<uint8_t>(1 + byte(rng) % 255);
      } else if (op >= 20 && op < 28) {  // truncate
        bytes.resize(static_cast<std::size_t>(rng() % bytes.size()));
      } else if (op >= 28 && op < 34) {  // lose a byte in the middle
        bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(rng() % bytes.size()));
      } else {
        intact.push_back(f);
      }
      Append(&stream, bytes);
    }
    // A live stream keeps flowing: idle bytes complete any candidate still
    // waiting for its announced length, so the frames behind it come out.
    stream.resize(stream.size() + xbus::kMaxFrameBytes, 0x00);

    XbusParserStats whole_stats;
    const std::vector<Frame> whole = ParseAll(stream, &whole_stats);
    std::vector<std::size_t> chunks;
    for (int i = 0; i < 16; ++i) chunks.push_back(1 + rng() % 97);
    XbusParser chunked;
    ASSERT_EQ(ParseInChunks(&chunked, stream, chunks), whole) << "seed " << seed;
    EXPECT_EQ(chunked.stats().garbage_bytes, whole_stats.garbage_bytes);
    EXPECT_EQ(chunked.stats().checksum_errors, whole_stats.checksum_errors);

    for (const Frame& f : whole) {
      ASSERT_LE(f.payload.size(), xbus::kMaxPayloadBytes);
      const Bytes encoded = Encode(f);
      ASSERT_NE(std::search(stream.begin(), stream.end(), encoded.begin(), encoded.end()),
                stream.end())
          << "seed " << seed << ": delivered a frame that is not in the stream";
    }
    // Intact frames come out in order; count those that do.
    std::size_t next = 0, found = 0;
    for (const Frame& f : whole) {
      const auto it =
          std::find(intact.begin() + static_cast<std::ptrdiff_t>(next), intact.end(), f);
      if (it == intact.end()) continue;
      next = static_cast<std::size_t>(it - intact.begin()) + 1;
      ++found;
    }
    intact_total += intact.size();
    intact_found += found;
    EXPECT_GE(found + 2, intact.size()) << "seed " << seed;
  }
  EXPECT_GE(static_cast<double>(intact_found), 0.99 * static_cast<double>(intact_total));
}

}  // namespace
}  // namespace rover::drivers
