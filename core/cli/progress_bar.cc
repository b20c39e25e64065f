#include "core/cli/progress_bar.h"

#include <cmath>
#include <cstdio>

namespace rover::cli {
namespace {
constexpr int kBarWidth = 30;
constexpr auto kRedrawPeriod = std::chrono::milliseconds(250);
}  // namespace

ProgressBar::ProgressBar(std::ostream& out, std::string name, uint64_t total, std::string unit,
                         bool tty)
    : out_(out),
      name_(std::move(name)),
      total_(total),
      unit_(std::move(unit)),
      tty_(tty),
      start_(Clock::now()),
      last_draw_(start_ - kRedrawPeriod) {}

std::string ProgressBar::FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--";
  const auto s = static_cast<long long>(std::llround(seconds));
  char text[32];
  if (s < 60) {
    std::snprintf(text, sizeof text, "%llds", s);
  } else if (s < 3600) {
    std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  }
  return text;
}

void ProgressBar::Update(uint64_t done) {
  done_ = done;
  if (tty_) {
    if (Clock::now() - last_draw_ >= kRedrawPeriod) Draw(false);
    return;
  }
  const int tenth = total_ == 0 ? 10 : static_cast<int>(done_ * 10 / total_);
  if (tenth >= next_tenth_ && tenth < 10) {
    next_tenth_ = tenth + 1;
    Draw(false);
  }
}

void ProgressBar::Finish() {
  Draw(true);
  if (tty_) out_ << "\n";
  out_ << std::flush;
}

void ProgressBar::Draw(bool final) {
  last_draw_ = Clock::now();
  const double elapsed_s = std::chrono::duration<double>(last_draw_ - start_).count();
  const double fraction =
      total_ == 0 ? 1.0 : static_cast<double>(done_) / static_cast<double>(total_);
  const double rate = elapsed_s > 0.0 ? static_cast<double>(done_) / elapsed_s : 0.0;
  const double left_s = rate > 0.0 ? static_cast<double>(total_ - done_) / rate : std::nan("");
  char head[64];
  std::snprintf(head, sizeof head, "%5.1f %%", 100.0 * fraction);
  const std::string counts = std::to_string(done_) + " of " + std::to_string(total_) + " " + unit_;
  char rate_text[48];
  std::snprintf(rate_text, sizeof rate_text, "%.1f %s/s", rate, unit_.c_str());
  const std::string when =
      final ? "in " + FormatDuration(elapsed_s) : "ETA " + FormatDuration(left_s);
  if (tty_) {
    const int filled = static_cast<int>(fraction * kBarWidth);
    out_ << "\r" << name_ << " [" << std::string(static_cast<std::size_t>(filled), '#')
         << std::string(static_cast<std::size_t>(kBarWidth - filled), '-') << "] " << head << "  "
         << counts << "  " << rate_text << "  " << when << "   " << std::flush;
  } else {
    out_ << name_ << ": " << head << " (" << counts << ") at " << rate_text << ", " << when << "\n";
  }
}

}  // namespace rover::cli
