// rover-log: inspect, export, verify and repair rover flight logs (MCAP).

#include <CLI/CLI.hpp>

#include <iostream>
#include <map>

#include "host/log/commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rover-log: inspect, export, verify and repair rover flight logs.\n"
      "Flight logs are MCAP files with ROS 2 CDR messages (they open in Foxglove Studio and play\n"
      "with `ros2 bag`). A log cut short by power loss stays readable up to its last complete\n"
      "chunk; `verify` says what is damaged and where, `recover` saves the rest."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rover-log 0.1.0");

  std::string path;
  auto* info = app.add_subcommand("info",
                                  "Summarise a log: channels, message counts, rates, "
                                  "time range, compression");
  info->add_option("FILE", path, "flight log (.mcap)")->required()->check(CLI::ExistingFile);

  rover::host::ExportOptions export_options;
  auto* exp = app.add_subcommand(
      "export", "Write one topic as CSV: log_time_ns, sequence, then every field of the message");
  exp->add_option("FILE", export_options.path, "flight log (.mcap)")
      ->required()
      ->check(CLI::ExistingFile);
  exp->add_option("--csv", export_options.topic, "topic to export, e.g. /imu")->required();
  exp->add_option("-o,--output", export_options.output, "CSV file to write (default: stdout)");

  auto* verify = app.add_subcommand(
      "verify", "Check every CRC and index; list damage with file offsets (exit 1 if damaged)");
  verify->add_option("FILE", path, "flight log (.mcap)")->required()->check(CLI::ExistingFile);

  std::string recover_out;
  std::string compression = "zstd";
  rover::log::McapWriterOptions writer_options;
  auto* recover = app.add_subcommand(
      "recover", "Rewrite the readable part of a damaged or truncated log into a new valid file");
  recover->add_option("IN", path, "damaged flight log")->required()->check(CLI::ExistingFile);
  recover->add_option("OUT", recover_out, "new file to write")->required();
  recover->add_option("--compression", compression, "chunk compression of OUT")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->capture_default_str();
  recover->add_option("--zstd-level", writer_options.zstd_level, "zstd level of OUT (1-19)")
      ->check(CLI::Range(1, 19))
      ->capture_default_str();

  CLI11_PARSE(app, argc, argv);

  if (*info) return rover::host::RunInfo(path, std::cout, std::cerr);
  if (*exp) return rover::host::RunExport(export_options, std::cout, std::cerr);
  if (*verify) return rover::host::RunVerify(path, std::cout, std::cerr);
  if (*recover) {
    static const std::map<std::string, rover::log::Compression> kCodecs = {
        {"zstd", rover::log::Compression::kZstd},
        {"lz4", rover::log::Compression::kLz4},
        {"none", rover::log::Compression::kNone}};
    writer_options.compression = kCodecs.at(compression);
    return rover::host::RunRecover(path, recover_out, writer_options, std::cout, std::cerr);
  }
  return 2;
}
