#ifndef ROVER_TESTS_SUPPORT_TEMP_DIR_H_
#define ROVER_TESTS_SUPPORT_TEMP_DIR_H_

// A fresh, empty directory per test, removed again when the test ends.
//
// Tests run in parallel under ctest (and several engineers' builds share one
// machine), so a fixed path like /tmp/rover_test would collide. The directory
// name carries the running gtest suite and test name so a leftover directory
// (kept with ROVER_KEEP_TEST_TMP=1) can be traced back to its test.

#include <filesystem>
#include <string>
#include <string_view>

namespace rover::testing {

class TempDir {
 public:
  /// Creates a unique directory under $TEST_TMPDIR, or under the system
  /// temporary directory if that is unset. The name is
  /// "rover_<suite>_<test>_XXXXXX" while a gtest test is running, otherwise
  /// "rover_<label>_XXXXXX". Aborts the test program if the directory cannot
  /// be created, since no test can meaningfully continue without it.
  explicit TempDir(std::string_view label = "tmp");
  /// Removes the directory and everything in it, unless the environment
  /// variable ROVER_KEEP_TEST_TMP is set to a non-empty value other than "0"
  /// (then the path is printed instead, for post-mortem inspection).
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  /// Absolute path of the directory.
  const std::filesystem::path& path() const { return path_; }
  /// Convenience: path() / relative.
  std::filesystem::path File(std::string_view relative) const { return path_ / relative; }

 private:
  std::filesystem::path path_;
};

/// The whole of the file at `path` ("" if it cannot be read): output files
/// of child processes, written logs.
std::string ReadTextFile(const std::filesystem::path& path);

}  // namespace rover::testing

#endif  // ROVER_TESTS_SUPPORT_TEMP_DIR_H_
