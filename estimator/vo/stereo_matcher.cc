#include "estimator/vo/stereo_matcher.h"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace rover::estimator::vo {
namespace {

// OpenCV's 128-bit universal intrinsics: SSE2 on the host, NEON on aarch64,
// OpenCV's scalar emulation on armhf builds without NEON. The sums are exact,
// so all give the same scores; wider vectors would not pay for ~120-pixel rows.
using VFloat = cv::v_float32x4;
constexpr int kLanes = VFloat::nlanes;
// Outputs per step of the row scan: four accumulators hide the add latency.
constexpr int kBlock = 4 * kLanes;
// Slack after every strip row for whole-vector loads past its last pixel.
constexpr int kRowPad = kBlock;
// Pixels are stored minus 128: products stay below 2^14, so correlation sums
// over windows of up to 1024 pixels are exact in float.
constexpr float kPixelOffset = -128.0f;
constexpr float kNotScored = std::numeric_limits<float>::quiet_NaN();

int RoundUp(int n, int multiple) { return (n + multiple - 1) / multiple * multiple; }

// The pixels one search reads, as float: converting only these (instead of
// both whole images per call) keeps them in L1 and touches no fresh memory.
// Every row has initialised slack after its pixels, so the kernels can load
// whole vectors past the last one (a row-scan block reads up to kBlock - 1
// beyond it); what they read there is finite and never used.
class Strip {
 public:
  Strip(int max_cols, int max_rows)
      : stride_(RoundUp(max_cols, kLanes) + kRowPad),
        data_(static_cast<size_t>(stride_) * static_cast<size_t>(max_rows), 0.0f) {}

  // Converts image columns [x0, x0 + cols) of rows [y0, y0 + rows), which must
  // lie inside the image and fit the strip.
  void Load(const cv::Mat& image, int x0, int y0, int cols, int rows) {
    x0_ = x0;
    y0_ = y0;
    const VFloat offset = cv::v_setall_f32(kPixelOffset);
    for (int y = 0; y < rows; ++y) {
      const uchar* src = image.ptr<uchar>(y0 + y) + x0;
      float* dst = data_.data() + static_cast<ptrdiff_t>(y) * stride_;
      int x = 0;
      // Eight pixels at a time (v_load_expand_q would read four as a
      // misaligned int, which UBSan rightly rejects).
      for (; x + 2 * kLanes <= cols; x += 2 * kLanes) {
        cv::v_uint32x4 lo, hi;
        cv::v_expand(cv::v_load_expand(src + x), lo, hi);
        cv::v_store(dst + x, cv::v_cvt_f32(cv::v_reinterpret_as_s32(lo)) + offset);
        cv::v_store(dst + x + kLanes, cv::v_cvt_f32(cv::v_reinterpret_as_s32(hi)) + offset);
      }
      for (; x < cols; ++x) dst[x] = static_cast<float>(src[x]) + kPixelOffset;
    }
  }
  // Pixel (x, y) of the image and the ones after it on its row.
  const float* At(int x, int y) const {
    return data_.data() + static_cast<ptrdiff_t>(y - y0_) * stride_ + (x - x0_);
  }

 private:
  int stride_;
  std::vector<float> data_;
  int x0_ = 0;
  int y0_ = 0;
};

// A square template, its rows zero-padded to whole vectors, and the sums its
// correlation needs.
struct Template {
  int half = 0;
  int side = 0;
  int padded = 0;           // row length in the buffers, a multiple of kLanes
  std::vector<float> w;     // side x padded pixel values
  std::vector<float> mask;  // padded: 1 on the template's columns, 0 after
  double count = 0.0;       // n = side^2
  double sum = 0.0;         // sum t
  double var_n2 = 0.0;      // n sum t^2 - (sum t)^2 = n^2 var(t)

  explicit Template(int half_px)
      : half(half_px),
        side(2 * half_px + 1),
        padded(RoundUp(2 * half_px + 1, kLanes)),
        w(static_cast<size_t>(side * padded), 0.0f),
        mask(static_cast<size_t>(padded), 0.0f),
        count(static_cast<double>(side * side)) {
    std::fill(mask.begin(), mask.begin() + side, 1.0f);
  }

  // Copies the patch centred on (u, v), which must lie inside the image.
  void Load(const cv::Mat& image, int u, int v) {
    double s = 0.0, s2 = 0.0;
    for (int i = 0; i < side; ++i) {
      const uchar* src = image.ptr<uchar>(v - half + i) + (u - half);
      float* dst = w.data() + i * padded;
      for (int j = 0; j < side; ++j) {
        dst[j] = static_cast<float>(src[j]) + kPixelOffset;
        s += static_cast<double>(dst[j]);
        s2 += static_cast<double>(dst[j]) * static_cast<double>(dst[j]);
      }
    }
    sum = s;
    var_n2 = count * s2 - s * s;
  }
  // Population standard deviation, as cv::meanStdDev gives it.
  double StdDev() const { return std::sqrt(std::max(var_n2, 0.0)) / count; }
};

// TM_CCOEFF_NORMED from exact sums; a flat image window scores 0 (as in
// OpenCV), since it correlates with nothing.
float Ncc(const Template& t, double cross, double sum, double sum_sq) {
  const double var_n2 = t.count * sum_sq - sum * sum;
  if (!(var_n2 > 0.0)) return 0.0f;
  const double ncc = (t.count * cross - t.sum * sum) / std::sqrt(t.var_n2 * var_n2);
  return static_cast<float>(std::clamp(ncc, -1.0, 1.0));
}

// NCC of the template centred at (x, y) of `image`.
float ScoreAt(const Template& t, const Strip& image, int x, int y) {
  VFloat cross = cv::v_setzero_f32(), sum = cv::v_setzero_f32(), sum_sq = cv::v_setzero_f32();
  for (int i = 0; i < t.side; ++i) {
    const float* src = image.At(x - t.half, y - t.half + i);
    const float* w = t.w.data() + i * t.padded;
    for (int j = 0; j < t.padded; j += kLanes) {
      const VFloat p = cv::v_load(src + j);
      const VFloat pm = p * cv::v_load(t.mask.data() + j);  // drop the padding columns
      cross = cv::v_muladd(p, cv::v_load(w + j), cross);
      sum = sum + pm;
      sum_sq = cv::v_muladd(pm, p, sum_sq);
    }
  }
  return Ncc(t, static_cast<double>(cv::v_reduce_sum(cross)),
             static_cast<double>(cv::v_reduce_sum(sum)),
             static_cast<double>(cv::v_reduce_sum(sum_sq)));
}

// Buffers reused by every search of one Match() call.
struct Scratch {
  std::vector<float> cross;    // row scan numerators, whole blocks
  std::vector<float> col_sum;  // row scan column sums over the template height
  std::vector<float> col_sq;
  std::vector<float> band;  // scores of the row band, kNotScored until computed

  Scratch(int max_span, int half, int band_rows)
      : cross(static_cast<size_t>(RoundUp(max_span, kBlock))),
        col_sum(static_cast<size_t>(RoundUp(max_span + 2 * half, kLanes))),
        col_sq(col_sum.size()),
        band(static_cast<size_t>(max_span * band_rows)) {}
};

// NCC of the template centred at (x, y) of `image` for x in [x0, x1], into
// out[0 .. x1 - x0]. Register-blocked over kBlock consecutive centres: each
// template pixel is broadcast once and multiplied into four vectors.
void ScoreRow(const Template& t, const Strip& image, int y, int x0, int x1, Scratch* s,
              float* out) {
  const int n = x1 - x0 + 1;
  const int top = y - t.half;
  for (int b = 0; b < n; b += kBlock) {
    VFloat a0 = cv::v_setzero_f32(), a1 = a0, a2 = a0, a3 = a0;
    for (int i = 0; i < t.side; ++i) {
      const float* src = image.At(x0 + b - t.half, top + i);
      const float* w = t.w.data() + i * t.padded;
      for (int j = 0; j < t.side; ++j) {
        const VFloat wj = cv::v_setall_f32(w[j]);
        a0 = cv::v_muladd(cv::v_load(src + j), wj, a0);
        a1 = cv::v_muladd(cv::v_load(src + j + kLanes), wj, a1);
        a2 = cv::v_muladd(cv::v_load(src + j + 2 * kLanes), wj, a2);
        a3 = cv::v_muladd(cv::v_load(src + j + 3 * kLanes), wj, a3);
      }
    }
    float* c = s->cross.data() + b;
    cv::v_store(c, a0);
    cv::v_store(c + kLanes, a1);
    cv::v_store(c + 2 * kLanes, a2);
    cv::v_store(c + 3 * kLanes, a3);
  }
  // Window sums by columns: the column sums over the template height first,
  // then a running sum along the row (integers, so exact).
  const int cols = n + 2 * t.half;
  for (int c = 0; c < cols; c += kLanes) {
    VFloat sum = cv::v_setzero_f32(), sum_sq = cv::v_setzero_f32();
    for (int i = 0; i < t.side; ++i) {
      const VFloat p = cv::v_load(image.At(x0 - t.half + c, top + i));
      sum = sum + p;
      sum_sq = cv::v_muladd(p, p, sum_sq);
    }
    cv::v_store(s->col_sum.data() + c, sum);
    cv::v_store(s->col_sq.data() + c, sum_sq);
  }
  double sum = 0.0, sum_sq = 0.0;
  for (int c = 0; c < t.side; ++c) {
    sum += static_cast<double>(s->col_sum[static_cast<size_t>(c)]);
    sum_sq += static_cast<double>(s->col_sq[static_cast<size_t>(c)]);
  }
  for (int k = 0; k < n; ++k) {
    if (k > 0) {
      const auto add = static_cast<size_t>(k + t.side - 1);
      const auto drop = static_cast<size_t>(k - 1);
      sum += static_cast<double>(s->col_sum[add]) - static_cast<double>(s->col_sum[drop]);
      sum_sq += static_cast<double>(s->col_sq[add]) - static_cast<double>(s->col_sq[drop]);
    }
    out[k] = Ncc(t, static_cast<double>(s->cross[static_cast<size_t>(k)]), sum, sum_sq);
  }
}

// Where a template is searched: centres on rows [row_lo, row_hi] (the band
// around the template's row), at columns [lo, hi]; [scan_lo, scan_hi] adds the
// guard columns next to a prior's window, which are scored but may not hold
// the peak.
struct SearchRange {
  int row = 0;
  int row_lo = 0;
  int row_hi = 0;
  int lo = 0;
  int hi = 0;
  int scan_lo = 0;
  int scan_hi = 0;
};

struct Peak {
  int x = 0;
  int y = 0;
  float score = -std::numeric_limits<float>::infinity();
};

// The band's scores, computed on demand.
class BandScores {
 public:
  BandScores(const Template& t, const Strip& image, const SearchRange& r, Scratch* s)
      : t_(t), image_(image), r_(r), width_(r.scan_hi - r.scan_lo + 1), scores_(s->band.data()) {
    std::fill_n(scores_, width_ * (r.row_hi - r.row_lo + 1), kNotScored);
  }

  bool Inside(int x, int y) const {
    return x >= r_.scan_lo && x <= r_.scan_hi && y >= r_.row_lo && y <= r_.row_hi;
  }
  float* Row(int y) { return scores_ + (y - r_.row_lo) * width_; }
  float At(int x, int y) {
    float& s = Row(y)[x - r_.scan_lo];
    if (std::isnan(s)) s = ScoreAt(t_, image_, x, y);
    return s;
  }

 private:
  const Template& t_;
  const Strip& image_;
  const SearchRange& r_;
  int width_;
  float* scores_;
};

// Parabola through the scores at -1, 0, +1: the peak's offset, or 0 when the
// three do not bend down.
float ParabolaOffset(float a, float c, float b) {
  const float den = a - 2.0f * c + b;
  return den < 0.0f ? std::clamp(0.5f * (a - b) / den, -0.5f, 0.5f) : 0.0f;
}

// Best NCC of the template in `image` over `r`, refined to sub-pixel; false
// when no peak inside [lo, hi] reaches min_ncc.
bool Search(const Template& t, const Strip& image, const SearchRange& r,
            const StereoMatcherOptions& o, Scratch* s, cv::Point2f* best_at) {
  BandScores band(t, image, r, s);
  float* row = band.Row(r.row);
  ScoreRow(t, image, r.row, r.scan_lo, r.scan_hi, s, row);

  // The strongest peaks of the template's own row, best first (ties: left first).
  constexpr int kMaxPeaks = 8;
  std::array<Peak, kMaxPeaks> peaks;
  const int max_peaks = std::clamp(o.max_row_peaks, 1, kMaxPeaks);
  int n_peaks = 0;
  const auto floor_ncc = static_cast<float>(o.min_ncc - std::max(o.row_peak_ncc_slack, 0.0));
  for (int x = r.lo; x <= r.hi; ++x) {
    const float c = row[x - r.scan_lo];
    if (!(c >= floor_ncc)) continue;
    if (x > r.scan_lo && !(c > row[x - 1 - r.scan_lo])) continue;  // a plateau counts once
    if (x < r.scan_hi && !(c >= row[x + 1 - r.scan_lo])) continue;
    int at = std::min(n_peaks, max_peaks - 1);
    if (n_peaks == max_peaks && !(c > peaks[static_cast<size_t>(at)].score)) continue;
    while (at > 0 && c > peaks[static_cast<size_t>(at - 1)].score) {
      peaks[static_cast<size_t>(at)] = peaks[static_cast<size_t>(at - 1)];
      --at;
    }
    peaks[static_cast<size_t>(at)] = Peak{x, r.row, c};
    n_peaks = std::min(n_peaks + 1, max_peaks);
  }

  // Climb each over the band, strictly uphill (so it stops) and with the
  // diagonals: edges make the NCC surface a ridge slanted across the rows,
  // along which a 4-neighbour climb stalls. A climb that ends on a guard
  // column has left the prior's window.
  Peak best;
  for (int k = 0; k < n_peaks; ++k) {
    Peak p = peaks[static_cast<size_t>(k)];
    for (;;) {
      Peak next = p;
      for (int y = p.y - 1; y <= p.y + 1; ++y) {
        for (int x = p.x - 1; x <= p.x + 1; ++x) {
          if (!band.Inside(x, y)) continue;
          const float c = band.At(x, y);
          if (c > next.score) next = Peak{x, y, c};
        }
      }
      if (next.x == p.x && next.y == p.y) break;
      p = next;
    }
    if (p.x < r.lo || p.x > r.hi) continue;
    // Ties as a row-major scan of the band finds them (top row, then left).
    if (p.score > best.score ||
        (p.score == best.score && (p.y < best.y || (p.y == best.y && p.x < best.x)))) {
      best = p;
    }
  }
  if (!(best.score >= static_cast<float>(o.min_ncc))) return false;

  float dx = 0.0f, dy = 0.0f;
  if (band.Inside(best.x - 1, best.y) && band.Inside(best.x + 1, best.y)) {
    dx = ParabolaOffset(band.At(best.x - 1, best.y), best.score, band.At(best.x + 1, best.y));
  }
  if (band.Inside(best.x, best.y - 1) && band.Inside(best.x, best.y + 1)) {
    dy = ParabolaOffset(band.At(best.x, best.y - 1), best.score, band.At(best.x, best.y + 1));
  }
  *best_at = cv::Point2f(static_cast<float>(best.x) + dx, static_cast<float>(best.y) + dy);
  return true;
}

}  // namespace

Eigen::Vector3d StereoMatcher::Triangulate(const cv::Point2f& left,
                                           const cv::Point2f& right) const {
  const double d = static_cast<double>(left.x) - static_cast<double>(right.x);
  const double z = intrinsics_.fx * baseline_m_ / d;
  const double v = 0.5 * (static_cast<double>(left.y) + static_cast<double>(right.y));
  return {(static_cast<double>(left.x) - intrinsics_.cx) * z / intrinsics_.fx,
          (v - intrinsics_.cy) * z / intrinsics_.fy, z};
}

double StereoMatcher::DepthSigma(double depth_m) const {
  return depth_m * depth_m / (intrinsics_.fx * baseline_m_) * options_.disparity_sigma_px;
}

std::vector<StereoPoint> StereoMatcher::Match(const cv::Mat& left, const cv::Mat& right,
                                              const std::vector<cv::Point2f>& left_points,
                                              StereoMatchStats* stats,
                                              const std::vector<float>* disparity_prior_px,
                                              double prior_radius_px) const {
  StereoMatchStats s;
  std::vector<StereoPoint> out;
  s.candidates = static_cast<int>(left_points.size());
  if (left.empty() || right.empty() || left.size() != right.size() || left.type() != CV_8UC1 ||
      right.type() != CV_8UC1 || left_points.empty() ||
      (disparity_prior_px != nullptr && disparity_prior_px->size() != left_points.size())) {
    if (stats != nullptr) *stats = s;
    return out;
  }
  const int half = std::max(options_.search_window_px, 3) / 2;
  const int margin = std::max(options_.search_row_margin_px, 0);
  // No disparity beyond the image width can match; this also bounds the buffers.
  const auto width = static_cast<double>(left.cols);
  const int d_max = static_cast<int>(std::ceil(std::clamp(options_.max_disparity_px, -1.0, width)));
  const int d_min = static_cast<int>(std::floor(std::clamp(options_.min_disparity_px, 0.0, width)));
  // A negative or non-finite radius is taken as 0; beyond the image width it
  // changes nothing (and bounding it keeps the window's ends ints).
  const double radius =
      std::isfinite(prior_radius_px) ? std::clamp(prior_radius_px, 0.0, width) : 0.0;
  if (d_max < d_min) {
    s.search_rejected = s.candidates;
    if (stats != nullptr) *stats = s;
    return out;
  }

  Template templ(half);
  const int max_span = d_max - d_min + 1;  // centre columns of one search
  Scratch scratch(max_span, half, 2 * margin + 1);
  Strip strip(max_span + 2 * half, 2 * (margin + half) + 1);
  const int x_min = half, x_max = left.cols - 1 - half;  // centres with the patch inside
  const int y_min = half, y_max = left.rows - 1 - half;

  // Searches the patch of `from` at (u, v) in `to` over the centre columns
  // u + sign * [d_min, d_max], or only around the disparity `prior` (>= 0).
  const auto search = [&](const cv::Mat& from, const cv::Mat& to, int u, int v, int sign,
                          double prior, cv::Point2f* best_at) {
    if (u < x_min || u > x_max || v < y_min || v > y_max) return false;
    templ.Load(from, u, v);
    // A flat template correlates with nothing (and would divide by zero).
    if (!(templ.var_n2 > 0.0) || templ.StdDev() < options_.min_template_stddev) return false;
    SearchRange r;
    r.row = v;
    r.row_lo = std::max(v - margin, y_min);
    r.row_hi = std::min(v + margin, y_max);
    int legal_lo = sign > 0 ? u + d_min : u - d_max;
    int legal_hi = sign > 0 ? u + d_max : u - d_min;
    legal_lo = std::max(legal_lo, x_min);
    legal_hi = std::min(legal_hi, x_max);
    r.lo = legal_lo;
    r.hi = legal_hi;
    if (prior >= 0.0) {
      if (prior - radius > d_max || prior + radius < d_min) return false;
      const double centre = u + sign * prior;
      int lo = static_cast<int>(std::ceil(centre - radius));
      int hi = static_cast<int>(std::floor(centre + radius));
      if (lo > hi) lo = hi = static_cast<int>(std::lround(centre));
      r.lo = std::max(lo, legal_lo);
      r.hi = std::min(hi, legal_hi);
    }
    if (r.lo > r.hi) return false;
    // One guard column on each side, where legal, tells a peak from a slope.
    r.scan_lo = std::max(r.lo - 1, legal_lo);
    r.scan_hi = std::min(r.hi + 1, legal_hi);
    strip.Load(to, r.scan_lo - half, r.row_lo - half, r.scan_hi - r.scan_lo + 1 + 2 * half,
               r.row_hi - r.row_lo + 1 + 2 * half);
    return Search(templ, strip, r, options_, &scratch, best_at);
  };

  for (size_t i = 0; i < left_points.size(); ++i) {
    const cv::Point2f& l = left_points[i];
    double prior = -1.0;
    if (disparity_prior_px != nullptr) {
      const float p = (*disparity_prior_px)[i];
      if (std::isfinite(p) && p >= 0.0f) {
        prior = static_cast<double>(p);
        ++s.prior_searches;
      }
    }
    if (!std::isfinite(l.x) || !std::isfinite(l.y)) {
      ++s.search_rejected;
      continue;
    }
    const auto u = static_cast<int>(std::lround(l.x));
    const auto v = static_cast<int>(std::lround(l.y));
    cv::Point2f r;
    if (!search(left, right, u, v, -1, prior, &r)) {
      ++s.search_rejected;
      continue;
    }
    r += cv::Point2f(l.x - static_cast<float>(u), l.y - static_cast<float>(v));
    // Left-right consistency: the right patch must find its way back.
    const auto ur = static_cast<int>(std::lround(r.x));
    const auto vr = static_cast<int>(std::lround(r.y));
    cv::Point2f back;
    // Over the whole disparity range even with a prior: the window may hold a
    // wrong patch that correlates well enough, and only the right patch's
    // best partner along the whole row tells (it is its own true match).
    if (!search(right, left, ur, vr, +1, -1.0, &back)) {
      ++s.consistency_rejected;
      continue;
    }
    back += cv::Point2f(r.x - static_cast<float>(ur), r.y - static_cast<float>(vr));
    const cv::Point2f fb = back - l;
    if (std::sqrt(static_cast<double>(fb.dot(fb))) > options_.max_fb_error_px) {
      ++s.consistency_rejected;
      continue;
    }
    if (std::abs(static_cast<double>(l.y - r.y)) > options_.max_row_error_px) {
      ++s.row_rejected;
      continue;
    }
    const double d = static_cast<double>(l.x - r.x);
    if (d < options_.min_disparity_px) {
      ++s.disparity_rejected;
      continue;
    }
    const Eigen::Vector3d p = Triangulate(l, r);
    const double sigma = DepthSigma(p.z());
    if (sigma > options_.max_depth_sigma_m || sigma > options_.max_relative_depth_sigma * p.z()) {
      ++s.depth_sigma_rejected;
      continue;
    }
    StereoPoint sp;
    sp.feature_index = static_cast<int>(i);
    sp.left = l;
    sp.right = r;
    sp.p_cam0rect = p;
    sp.depth_sigma_m = sigma;
    out.push_back(sp);
  }
  s.accepted = static_cast<int>(out.size());
  if (stats != nullptr) *stats = s;
  return out;
}

}  // namespace rover::estimator::vo
