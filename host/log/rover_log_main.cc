// rover-log: list and download logs from the board, inspect, export, verify and repair rover
// flight logs (MCAP), extract the global map from mapd's logs.

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <map>

#include "host/log/commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rover-log: list and download, inspect, export, verify and repair rover flight logs,\n"
      "and extract the global map from mapd's logs.\n"
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

  // The board's log service: list and download.
  const auto add_access_options = [](CLI::App* command, rover::host::LogServiceAccess& access) {
    command->add_option("--url", access.url, "the board's log service, http://HOST:PORT")
        ->required();
    command->add_option("--token-file", access.token_file,
                        "file holding the service's bearer token (the default source; else "
                        "--token, else the environment variable ROVER_LOG_TOKEN)");
    command->add_option("--token", access.token,
                        "the bearer token itself (visible to other users in `ps`; prefer "
                        "--token-file or ROVER_LOG_TOKEN)");
    command
        ->add_option("--connect-timeout-s", access.connect_timeout_s,
                     "give up connecting after this long")
        ->check(CLI::Range(1, 600))
        ->capture_default_str();
    command
        ->add_option("--read-timeout-s", access.read_timeout_s,
                     "give up on a connection silent for this long")
        ->check(CLI::Range(1, 3600))
        ->capture_default_str();
  };

  rover::host::ListOptions list_options;
  auto* list = app.add_subcommand(
      "list",
      "List the logs on the board: name, size, duration and first log time, complete or\n"
      "in-progress, SHA-256 prefix. A log still being written is listed (and served) up to its\n"
      "last complete record. Times are log times on the rover's monotonic clock, not wall clock.\n"
      "Exit 0 ok, 1 network or service failure, 2 bad URL or missing/refused token.");
  add_access_options(list, list_options.access);
  list->add_flag("--json", list_options.json, "print the service's JSON listing as received");

  rover::host::DownloadOptions download_options;
  auto* download = app.add_subcommand(
      "download",
      "Download one log from the board into DIR/NAME.part, resuming with Range requests after a\n"
      "cut connection (and from an existing NAME.part), with a progress bar (rate, ETA) on\n"
      "stderr. The SHA-256 is checked against the listing before the file is renamed to\n"
      "DIR/NAME; on a mismatch nothing is kept. Exit 0 ok, 1 network failure after the retries\n"
      "or hash mismatch, 2 bad input (name, URL, token, folder, or a log the board does not "
      "list).");
  download->add_option("NAME", download_options.name, "log name as listed, e.g. flight_0001.mcap")
      ->required();
  add_access_options(download, download_options.access);
  download
      ->add_option("--out", download_options.out_dir, "folder to write into (created if missing)")
      ->capture_default_str();
  download
      ->add_option("--retries", download_options.retries,
                   "attempts in a row that may fail without receiving a byte before giving "
                   "up (any progress resets the count)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  download
      ->add_option("--backoff-s", download_options.initial_backoff_s,
                   "wait before the first retry; doubles per failed retry, at most "
                   "--max-backoff-s")
      ->check(CLI::Range(0.0, 600.0))
      ->capture_default_str();
  download
      ->add_option("--max-backoff-s", download_options.max_backoff_s,
                   "longest wait between attempts (also caps the service's Retry-After)")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();

  rover::host::MapOptions map_options;
  std::vector<std::string> map_formats;
  bool map_no_cloud = false;
  bool map_chain = false;
  auto* map_command = app.add_subcommand(
      "map",
      "Extract the global map from mapd's logs into STEM.bt, STEM.ot, STEM.ply (view with\n"
      "`octovis STEM.bt` and any PLY viewer)");
  map_command->footer(
      "Reads every submap mapd logged (/mapd/submap/info, /mapd/submap/octomap and\n"
      "/mapd/submap/cloud in mapd-<time>-<pid>.mcap; give all logs of a restarted mapd, in\n"
      "order) and places each at its frame's origin: with --roverd-log, chained from the\n"
      "frame switches (/estimator/frame_switch_record) in roverd's flight log, frame 0 of\n"
      "the mission being the map frame; without it (one mapd log only), chained by the\n"
      "origins the submaps record, the first submap's frame being the map frame. Submaps\n"
      "are merged into one octree (log-odds summed, clamped) and one point cloud.\n"
      "A team's map: give the mapd logs of several rovers (each holds its own graph\n"
      "factors and those the team sent it); the team's graph is rebuilt from all of them\n"
      "and solved, the lowest robot id's first origin being the map frame, and each\n"
      "rover's submaps go at its origins there (a rover no detection or match links to\n"
      "that one is left out, and said so).\n"
      "Writes STEM.bt (occupied/free octree), STEM.ot (octree with probabilities) and\n"
      "STEM.ply (point cloud, obstacles red); view them with `octovis STEM.bt` (or .ot)\n"
      "and any PLY viewer (MeshLab, CloudCompare, Open3D). Prints each log's submaps,\n"
      "damage found (reading goes on past it), submaps that could not be placed and the\n"
      "composed map's size, memory and compose time.\n"
      "Exit 0 ok, 1 map written but input damaged or submaps left out, 2 bad usage, an\n"
      "unreadable or non-MCAP file, no submaps at all, or an output that cannot be written.");
  map_command->add_option("MAPD_LOG", map_options.mapd_logs, "mapd log(s) (mapd-<time>-<pid>.mcap)")
      ->required()
      ->check(CLI::ExistingFile);
  map_command
      ->add_option("--roverd-log", map_options.roverd_log,
                   "roverd's flight log of the same mission, for the frame switches (required "
                   "with several mapd logs)")
      ->check(CLI::ExistingFile);
  map_command
      ->add_option("--out", map_options.out_stem,
                   "output path without extension: writes STEM.bt, STEM.ot, STEM.ply")
      ->required();
  map_command->add_flag("--no-cloud", map_no_cloud,
                        "do not compose the point cloud (faster, less memory; no .ply)");
  map_command->add_flag("--chain", map_chain,
                        "place submaps by the filter's frame switches only, not at the pose "
                        "graph's optimised origins that mapd logged");
  map_command
      ->add_option("--format", map_formats, "files to write, comma-separated (default: bt,ot,ply)")
      ->delimiter(',')
      ->check(CLI::IsMember({"bt", "ot", "ply"}));

  // Usage errors exit with 2, as the subcommands do for bad input.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  if (*info) return rover::host::RunInfo(path, std::cout, std::cerr);
  if (*exp) return rover::host::RunExport(export_options, std::cout, std::cerr);
  if (*verify) return rover::host::RunVerify(path, std::cout, std::cerr);
  if (*list) return rover::host::RunList(list_options, std::cout, std::cerr);
  if (*map_command) {
    map_options.compose_cloud = !map_no_cloud;
    map_options.use_graph = !map_chain;
    if (!map_formats.empty()) {
      const auto has = [&](const char* f) {
        return std::find(map_formats.begin(), map_formats.end(), f) != map_formats.end();
      };
      map_options.write_bt = has("bt");
      map_options.write_ot = has("ot");
      map_options.write_ply = has("ply");
    } else if (map_no_cloud) {
      map_options.write_ply = false;
    }
    return rover::host::RunMap(map_options, std::cout, std::cerr);
  }
  if (*download) {
    download_options.progress_tty = ::isatty(STDERR_FILENO) == 1;
    return rover::host::RunDownload(download_options, std::cout, std::cerr);
  }
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
