#ifndef ROVER_HIL_SIM_RENDER_SENSOR_EFFECTS_H_
#define ROVER_HIL_SIM_RENDER_SENSOR_EFFECTS_H_

// The camera's sensor model, applied to the distorted radiance image:
// exposure and gain, vignetting, shot noise (Poisson, as a Gaussian with
// signal-dependent variance) and read noise, then rounding and clipping to
// 8 bit. The noise is drawn from a generator seeded per image, so a frame is
// reproducible from its seed alone.

#include <cstdint>
#include <opencv2/core.hpp>

#include "hil/sim/render/stereo_camera.h"

namespace rover::sim {

class SensorEffects {
 public:
  /// Precomputes the per-pixel signal gain (exposure * gain * sensitivity *
  /// vignetting) for the camera's image size.
  explicit SensorEffects(const StereoCameraOptions& camera);

  /// radiance: CV_32FC1 (height_px x width_px). With effects, adds noise
  /// seeded by `seed`; without, only exposure, gain and quantisation.
  void Apply(const cv::Mat& radiance, bool with_effects, uint64_t seed, cv::Mat* out_u8);

  /// Signal gain per pixel, DN per unit radiance, vignetting included.
  const cv::Mat& vignetted_gain() const { return vignetted_gain_; }

 private:
  StereoCameraOptions camera_;
  double dn_per_radiance_ = 0.0;
  cv::Mat vignetted_gain_;  ///< CV_32FC1
  cv::Mat signal_;          ///< scratch, CV_32FC1
  cv::Mat noise_;           ///< scratch, CV_32FC1
};

/// Mixes a 64-bit seed (splitmix64 finaliser) so that nearby frame indices
/// give unrelated noise.
uint64_t MixSeed(uint64_t a, uint64_t b);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_RENDER_SENSOR_EFFECTS_H_
