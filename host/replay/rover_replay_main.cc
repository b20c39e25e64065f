// rover-replay LOG.mcap: feeds the estimator inputs logged by roverd back
// through the local reference filter (with the logged options) and checks
// that every logged output is bit-identical to the replayed one. Exit 0 only
// when the replay is bit-exact; 1 when it is not (the first difference is
// printed); 2 when the file cannot be read.

#include <CLI/CLI.hpp>

#include <unistd.h>
#include <cstdio>
#include <exception>
#include <string>

#include "estimator/io/log_replay.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rover-replay: replays a flight log's estimator inputs through the local reference\n"
      "filter and checks that every logged output (state at IMU rate, frame-switch\n"
      "records) is bit-identical. Exit 0: bit-exact; 1: a difference (the first is\n"
      "printed, with the field and both values); 2: the log cannot be read.\n"};
  std::string path;
  app.add_option("LOG", path, "flight log written by roverd (MCAP)")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    const bool tty = isatty(STDERR_FILENO) != 0;
    const auto progress = [&](double fraction) {
      if (tty) std::fprintf(stderr, "\rrover-replay: %3.0f %%", 100.0 * fraction);
    };
    const rover::estimator::io::ReplayResult r = rover::estimator::io::ReplayLog(path, progress);
    if (tty) std::fprintf(stderr, "\r%*s\r", 24, "");
    std::printf("rover-replay: %s\n", path.c_str());
    std::printf("  inputs replayed        %llu\n", static_cast<unsigned long long>(r.inputs));
    std::printf("  states compared        %llu\n",
                static_cast<unsigned long long>(r.states_compared));
    std::printf("  frame switches compared %llu\n",
                static_cast<unsigned long long>(r.switches_compared));
    for (const std::string& note : r.notes) std::printf("  note: %s\n", note.c_str());
    if (!r.bit_exact) std::printf("  first difference: %s\n", r.first_difference.c_str());
    std::printf("RESULT bit_exact=%d inputs=%llu states=%llu switches=%llu\n", r.bit_exact ? 1 : 0,
                static_cast<unsigned long long>(r.inputs),
                static_cast<unsigned long long>(r.states_compared),
                static_cast<unsigned long long>(r.switches_compared));
    return r.bit_exact ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rover-replay: %s: %s\n", path.c_str(), e.what());
    return 2;
  }
}
