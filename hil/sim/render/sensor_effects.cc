#include "hil/sim/render/sensor_effects.h"

#include <cmath>

namespace rover::sim {

uint64_t MixSeed(uint64_t a, uint64_t b) {
  uint64_t z = a + 0x9e3779b97f4a7c15ULL * (b + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

SensorEffects::SensorEffects(const StereoCameraOptions& camera)
    : camera_(camera),
      dn_per_radiance_(camera.exposure_time_s * camera.gain * camera.sensitivity_dn_per_s) {
  vignetted_gain_.create(camera.height_px, camera.width_px, CV_32FC1);
  for (int v = 0; v < camera.height_px; ++v) {
    float* row = vignetted_gain_.ptr<float>(v);
    for (int u = 0; u < camera.width_px; ++u) {
      // cos^4 of the angle between the pixel's ray and the optical axis.
      Eigen::Vector3d ray;
      double cos4 = 1.0;
      if (PixelToRay(camera, Eigen::Vector2d(u, v), &ray)) cos4 = std::pow(ray.z(), 4.0);
      const double vignetting = 1.0 - camera.vignetting_strength * (1.0 - cos4);
      row[u] = static_cast<float>(dn_per_radiance_ * vignetting);
    }
  }
}

void SensorEffects::Apply(const cv::Mat& radiance, bool with_effects, uint64_t seed,
                          cv::Mat* out_u8) {
  CV_Assert(radiance.type() == CV_32FC1 && radiance.rows == camera_.height_px &&
            radiance.cols == camera_.width_px);
  if (!with_effects) {
    // convertTo rounds to nearest and saturates.
    radiance.convertTo(*out_u8, CV_8U, dn_per_radiance_);
    return;
  }
  cv::multiply(radiance, vignetted_gain_, signal_);
  // Variance in DN^2: read noise plus shot noise, which grows with the signal
  // and, in DN, with the gain.
  const double read_variance = camera_.read_noise_dn * camera_.read_noise_dn;
  const double shot_scale = camera_.gain * camera_.dn_per_electron;
  cv::Mat sigma;
  cv::max(signal_, 0.0, sigma);
  sigma.convertTo(sigma, CV_32F, shot_scale, read_variance);
  cv::sqrt(sigma, sigma);
  noise_.create(signal_.size(), CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise_, cv::RNG::NORMAL, 0.0, 1.0);
  cv::multiply(noise_, sigma, noise_);
  signal_ += noise_;
  signal_.convertTo(*out_u8, CV_8U);
}

}  // namespace rover::sim
