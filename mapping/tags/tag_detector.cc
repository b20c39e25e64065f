#include "mapping/tags/tag_detector.h"

#include <apriltag/apriltag.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "mapping/loop/option_checks.h"
#include "mapping/tags/tag_border_fit.h"
#include "mapping/tags/tag_family.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

// The library puts the centre of the top-left pixel at (0.5, 0.5), OpenCV at (0, 0).
constexpr double kLibraryPixelCentreOffsetPx = 0.5;

// Twice the signed area of the quad (shoelace); positive for one winding.
double SignedArea2(const std::array<Eigen::Vector2d, 4>& c) {
  double a = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d& p = c[i];
    const Eigen::Vector2d& q = c[(i + 1) % 4];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return a;
}

// True if every turn of the quad has the same sign (convex, not self-crossing).
bool Convex(const std::array<Eigen::Vector2d, 4>& c) {
  int positive = 0;
  int negative = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d e1 = c[(i + 1) % 4] - c[i];
    const Eigen::Vector2d e2 = c[(i + 2) % 4] - c[(i + 1) % 4];
    const double cross = e1.x() * e2.y() - e1.y() * e2.x();
    (cross > 0.0 ? positive : negative)++;
  }
  return positive == 4 || negative == 4;
}

}  // namespace

void TagDetectorOptions::Validate() const {
  constexpr const char* kName = "TagDetectorOptions";
  if (families.empty()) {
    throw std::invalid_argument(std::string(kName) + ".families: expected at least one of " +
                                KnownTagFamilyList() + ", found none");
  }
  for (const std::string& f : families) {
    try {
      CreateTagFamily(f);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(kName) + ".families: " + e.what());
    }
  }
  CheckRange(kName, "max_bits_corrected", max_bits_corrected, 0, 3);
  CheckRange(kName, "max_hamming", max_hamming, 0, max_bits_corrected);
  CheckRange(kName, "min_decision_margin", min_decision_margin, 0.0, 255.0);
  CheckRange(kName, "quad_decimate", quad_decimate, 1.0, 8.0);
  CheckRange(kName, "quad_sigma_px", quad_sigma_px, 0.0, 10.0);
  CheckRange(kName, "decode_sharpening", decode_sharpening, 0.0, 10.0);
  CheckRange(kName, "border_margin_px", border_margin_px, 0.0, 100.0);
  CheckPositive(kName, "min_area_px2", min_area_px2);
  CheckRange(kName, "max_border_offset_px", max_border_offset_px, 0.0, 100.0);
  CheckRange(kName, "threads", threads, 1, 64);
}

class TagDetector::Impl {
 public:
  explicit Impl(const TagDetectorOptions& o) : detector_(apriltag_detector_create()) {
    if (detector_ == nullptr)
      throw std::runtime_error("TagDetector: the library could not create a detector");
    detector_->quad_decimate = static_cast<float>(o.quad_decimate);
    detector_->quad_sigma = static_cast<float>(o.quad_sigma_px);
    detector_->refine_edges = o.refine_edges;
    detector_->decode_sharpening = o.decode_sharpening;
    detector_->nthreads = o.threads;
    for (const std::string& name : o.families) {
      families_.push_back(CreateTagFamily(name));
      apriltag_detector_add_family_bits(detector_, families_.back().get(), o.max_bits_corrected);
    }
  }
  ~Impl() {
    apriltag_detector_destroy(detector_);  // before the families it refers to
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  apriltag_detector_t* detector() { return detector_; }

 private:
  apriltag_detector_t* detector_;
  std::vector<TagFamilyPtr> families_;
};

TagDetector::TagDetector(const TagDetectorOptions& options) : options_(options) {
  options_.Validate();
  impl_ = std::make_unique<Impl>(options_);
}

TagDetector::~TagDetector() = default;

std::vector<TagDetection> TagDetector::Detect(const cv::Mat& mono8,
                                              std::vector<TagRefusal>* refused) {
  if (mono8.empty() || mono8.type() != CV_8UC1) {
    std::ostringstream s;
    s << "TagDetector::Detect: expected a non-empty 8-bit single-channel image, found "
      << mono8.cols << "x" << mono8.rows << " of type " << mono8.type();
    throw std::invalid_argument(s.str());
  }
  // The library only reads the image struct, so it can wrap the Mat's rows
  // (Debian's build does not export image_u8_create).
  image_u8_t image = {mono8.cols, mono8.rows, static_cast<int32_t>(mono8.step[0]),
                      const_cast<uint8_t*>(mono8.ptr<uint8_t>(0))};
  zarray_t* found = apriltag_detector_detect(impl_->detector(), &image);
  std::vector<TagDetection> out;
  const double w = mono8.cols - 1.0;
  const double h = mono8.rows - 1.0;
  const double m = options_.border_margin_px;
  for (int i = 0; i < zarray_size(found); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(found, i, &det);
    TagDetection d;
    d.family = det->family->name;
    d.id = det->id;
    d.hamming = det->hamming;
    d.decision_margin = det->decision_margin;
    for (std::size_t c = 0; c < 4; ++c) {
      d.corners_px[c] = Eigen::Vector2d(det->p[c][0] - kLibraryPixelCentreOffsetPx,
                                        det->p[c][1] - kLibraryPixelCentreOffsetPx);
    }
    d.centre_px = Eigen::Vector2d(det->c[0] - kLibraryPixelCentreOffsetPx,
                                  det->c[1] - kLibraryPixelCentreOffsetPx);
    std::ostringstream why;
    bool inside = true;
    for (const Eigen::Vector2d& c : d.corners_px) {
      inside =
          inside && c.allFinite() && c.x() >= m && c.y() >= m && c.x() <= w - m && c.y() <= h - m;
    }
    const double area = 0.5 * std::abs(SignedArea2(d.corners_px));
    const bool convex = Convex(d.corners_px);
    if (d.hamming > options_.max_hamming) {
      why << d.hamming << " bits corrected (at most " << options_.max_hamming << ")";
    } else if (d.decision_margin < options_.min_decision_margin) {
      why << "decision margin " << d.decision_margin << " below " << options_.min_decision_margin;
    } else if (!inside) {
      why << "cut by the image border (a corner within " << m << " px of it)";
    } else if (!convex || !(area >= options_.min_area_px2)) {
      why << "degenerate quad (area " << area << " px^2, " << (convex ? "convex" : "not convex")
          << ")";
    }
    if (why.tellp() == 0 && options_.max_border_offset_px > 0.0) {
      const TagBorderFit border = FitTagBorder(
          mono8, d.corners_px, {det->family->width_at_border, det->family->reversed_border});
      if (!border.measured) {
        why << "its sides lie too close to the edge of the image to check them against the tag's "
               "border";
      } else if (!(border.worst_offset_px <= options_.max_border_offset_px)) {
        why << "corner " << border.worst_corner << " lies " << border.worst_offset_px
            << " px off the tag's border seen in the image (at most "
            << options_.max_border_offset_px << " px)";
      }
    }
    const std::string reason = why.str();
    if (reason.empty()) {
      out.push_back(std::move(d));
    } else if (refused != nullptr) {
      refused->push_back({d.family, d.id, reason, d.corners_px});
    }
  }
  apriltag_detections_destroy(found);
  return out;
}

}  // namespace rover::mapping
