// make_mcap_seed_corpus DIR: writes small valid MCAP files into DIR as the
// seed corpus of fuzz_mcap_reader: every compression, several chunks,
// schemas, channels, metadata and an attachment; plus an empty log and a
// truncated one. Small files keep the fuzzer's inputs short and fast.

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/log/mcap/mcap_writer.h"

namespace {

using rover::log::Compression;
using rover::log::McapWriter;
using rover::log::McapWriterOptions;

void WriteLog(const std::string& path, Compression compression, uint64_t chunk_size, int messages,
              bool extras, uint32_t seed) {
  McapWriterOptions options;
  options.compression = compression;
  options.chunk_size_bytes = chunk_size;
  McapWriter writer(options);
  writer.Open(path);
  const std::string text = "float64 x\nuint8[] data\n";
  const uint16_t schema =
      writer.AddSchema("rover_msgs/msg/Sample", "ros2msg", std::as_bytes(std::span(text)));
  const uint16_t a = writer.AddChannel(schema, "/a", "cdr", {{"qos", "reliable"}});
  const uint16_t b = writer.AddChannel(0, "/b", "raw");
  if (extras) {
    writer.WriteMetadata("rover", {{"board", "sim"}});
    const std::vector<std::byte> calib(24, std::byte{0x42});
    writer.WriteAttachment("calib.bin", "application/octet-stream", 5, 4, calib);
  }
  std::mt19937 rng(seed);
  for (int i = 0; i < messages; ++i) {
    std::vector<std::byte> data(rng() % 24);
    for (auto& byte : data) byte = static_cast<std::byte>(rng() % 4);      // Compressible.
    const uint64_t t = 1000 + static_cast<uint64_t>(i) * 10 + rng() % 15;  // Slightly unordered.
    writer.WriteMessage(i % 3 == 0 ? b : a, static_cast<uint32_t>(i), t, t - 1, data);
  }
  writer.Close();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  std::filesystem::create_directories(dir);
  try {
    uint32_t seed = 1;
    for (const auto& [compression, name] :
         {std::pair{Compression::kNone, "none"}, std::pair{Compression::kZstd, "zstd"},
          std::pair{Compression::kLz4, "lz4"}}) {
      WriteLog(dir + "/seed_" + name + "_chunks.mcap", compression, 120, 24, true, seed++);
      WriteLog(dir + "/seed_" + name + "_one_chunk.mcap", compression, 1 << 20, 6, false, seed++);
    }
    WriteLog(dir + "/seed_empty.mcap", Compression::kNone, 1 << 20, 0, false, seed++);
    // A log cut in its last chunk, as power loss leaves it.
    const std::string whole = dir + "/seed_truncated.mcap";
    WriteLog(whole, Compression::kZstd, 100, 20, true, seed++);
    std::filesystem::resize_file(whole, std::filesystem::file_size(whole) * 2 / 3);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_mcap_seed_corpus: %s\n", e.what());
    return 1;
  }
  return 0;
}
