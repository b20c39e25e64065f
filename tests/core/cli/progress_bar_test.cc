#include "core/cli/progress_bar.h"

#include <gtest/gtest.h>

#include <cmath>

#include <sstream>
#include <string>

namespace rover::cli {
namespace {

int CountLines(const std::string& s) {
  int n = 0;
  for (const char c : s) n += c == '\n';
  return n;
}

TEST(ProgressBarTest, WithoutATerminalPrintsOneLinePerTenth) {
  std::ostringstream out;
  ProgressBar bar(out, "table", 200, "cells", false);
  for (uint64_t k = 1; k <= 200; ++k) bar.Update(k);
  bar.Finish();
  const std::string text = out.str();
  EXPECT_EQ(CountLines(text), 10) << text;  // 10 % .. 90 %, then the final line
  EXPECT_EQ(text.find('\r'), std::string::npos);
  EXPECT_NE(text.find("table:  10.0 % (20 of 200 cells)"), std::string::npos) << text;
  EXPECT_NE(text.find("100.0 % (200 of 200 cells)"), std::string::npos) << text;
  EXPECT_NE(text.find(", in "), std::string::npos) << text;
}

TEST(ProgressBarTest, OnATerminalRedrawsInPlace) {
  std::ostringstream out;
  ProgressBar bar(out, "table", 4, "cells", true);
  bar.Update(1);
  bar.Update(4);
  bar.Finish();
  const std::string text = out.str();
  EXPECT_EQ(text.front(), '\r');
  EXPECT_NE(text.find("[##############################] 100.0 %"), std::string::npos) << text;
  EXPECT_EQ(CountLines(text), 1);
}

TEST(ProgressBarTest, FormatsDurations) {
  EXPECT_EQ(ProgressBar::FormatDuration(5.2), "5s");
  EXPECT_EQ(ProgressBar::FormatDuration(65.0), "1m05s");
  EXPECT_EQ(ProgressBar::FormatDuration(7380.0), "2h03m");
  EXPECT_EQ(ProgressBar::FormatDuration(-1.0), "--");
  EXPECT_EQ(ProgressBar::FormatDuration(std::nan("")), "--");
}

}  // namespace
}  // namespace rover::cli
