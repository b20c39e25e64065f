#include "tests/support/temp_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace rover::testing {
namespace {

// Keeps directory names portable and shell-friendly: typed and parameterised
// test names contain '/' and '<'.
std::string Sanitize(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    out.push_back(std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' ? c : '_');
  }
  // Leaves room for the prefix and the mkdtemp suffix within NAME_MAX.
  constexpr std::size_t kMaxLabelChars = 160;
  if (out.size() > kMaxLabelChars) {
    out.resize(kMaxLabelChars);
  }
  return out;
}

std::filesystem::path BaseDirectory() {
  const char* test_tmpdir = std::getenv("TEST_TMPDIR");
  if (test_tmpdir != nullptr && test_tmpdir[0] != '\0') {
    return test_tmpdir;
  }
  std::error_code ec;
  std::filesystem::path system_tmp = std::filesystem::temp_directory_path(ec);
  return ec ? std::filesystem::path("/tmp") : system_tmp;
}

bool KeepRequested() {
  const char* keep = std::getenv("ROVER_KEEP_TEST_TMP");
  return keep != nullptr && keep[0] != '\0' && std::string_view(keep) != "0";
}

}  // namespace

TempDir::TempDir(std::string_view label) {
  std::string name = "rover_";
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  if (info != nullptr) {
    name += Sanitize(std::string(info->test_suite_name()) + "_" + info->name());
  } else {
    name += Sanitize(label);
  }
  name += "_XXXXXX";
  std::string templ = (BaseDirectory() / name).string();
  std::vector<char> buffer(templ.begin(), templ.end());
  buffer.push_back('\0');
  if (mkdtemp(buffer.data()) == nullptr) {
    std::perror(("TempDir: mkdtemp(" + templ + ")").c_str());
    std::abort();
  }
  path_ = buffer.data();
}

TempDir::~TempDir() {
  if (KeepRequested()) {
    std::fprintf(stderr, "TempDir: keeping %s (ROVER_KEEP_TEST_TMP set)\n", path_.c_str());
    return;
  }
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
  if (ec) {
    std::fprintf(stderr, "TempDir: could not remove %s: %s\n", path_.c_str(), ec.message().c_str());
  }
}

std::string ReadTextFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace rover::testing
