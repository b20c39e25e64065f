#ifndef ROVER_HIL_SIM_RENDER_STEREO_RENDERER_H_
#define ROVER_HIL_SIM_RENDER_STEREO_RENDERER_H_

// Renders the stereo pair and cam0 ground-truth depth of a World with OpenGL
// (EGL, headless, Mesa llvmpipe).
//
// Pipeline per frame: both cameras are rasterised as ideal pinhole cameras
// with a field of view wide enough to cover the distorted image, into one
// float radiance + float depth framebuffer; the radiance is then resampled
// through the radial-tangential model (cv::remap with maps built once), and
// the sensor model (exposure, gain, vignetting, shot and read noise,
// quantisation) turns it into 8-bit pixels. Depth is read from the depth
// buffer (reversed-Z, so its precision is ~1e-7 relative at any range).
//
// Terrain is drawn as a level-of-detail quadtree of patches (see
// terrain_lod.h) sampling the heightfield in the vertex shader; the albedo
// map is one mipmapped texture, modulated by seeded procedural fine detail
// (value noise, 5 mm cells) so that there is texture at 1 m range. Posts
// and rovers are boxes; tags are quads textured with the apriltag library's
// own tag36h11 bit pattern, box-filtered over the pixel footprint so that
// their edges are sub-pixel accurate. Shading is Lambertian with a fixed sun
// plus ambient light; there are no shadows.
//
// Determinism: the same world, options, pose and frame index give
// byte-identical images and depth on the same machine, across runs, renderer
// instances and llvmpipe thread counts (checked with LP_NUM_THREADS = 1, 2,
// 4: each pixel is computed the same way whichever thread owns its tile). The
// noise is seeded from noise_seed and the frame index. Another CPU (SIMD
// width) or Mesa version may differ in the last bit.
//
// Cost: llvmpipe pays per triangle and per texture fetch, far more than a
// GPU; the level of detail and the procedural detail exist for that reason.
// bench_render prints the figures (about 20 stereo pairs/s at 752 x 480 on
// two cores).
//
// Not thread-safe. Each Render binds the renderer's GL context to the calling
// thread, so a renderer may move between threads, but never call it from two
// threads at once.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/world/world.h"

namespace rover::sim {

/// Scene and quality settings (the camera itself is StereoCameraOptions).
struct RenderOptions {
  /// Direction to the sun: azimuth from +x (east) towards +y (north).
  double sun_azimuth_deg = 135.0;
  double sun_elevation_deg = 35.0;
  /// radiance = albedo * (ambient + sun_irradiance * max(0, n . sun)).
  double sun_irradiance = 0.8;
  double ambient = 0.2;
  double sky_radiance = 0.12;
  /// Terrain level of detail (see terrain_lod.h): full heightfield
  /// resolution within this distance of the camera; beyond it the mesh
  /// coarsens as long as its height error stays below max_terrain_error_px
  /// in the image. Ground-truth depth is the depth of this mesh.
  double full_resolution_distance_m = 6.0;
  double max_terrain_error_px = 2.0;
  /// Relative amplitude of the fine albedo detail (0 disables it).
  double detail_strength = 0.6;
  double detail_texel_m = 0.005;  ///< cell of the finer detail octave
  uint64_t detail_seed = 1;       ///< its low 32 bits seed the detail noise
  /// Maximum anisotropic filtering of the terrain textures. 1 = off: in
  /// llvmpipe anisotropic sampling costs 5-50x the whole frame.
  double max_anisotropy = 1.0;
  /// Render focal length relative to the output one: > 1 supersamples.
  double supersample = 1.0;
  double tag_white_albedo = 0.85;
  double tag_black_albedo = 0.04;
  /// False: no vignetting or noise, DN = radiance * exposure * gain * sensitivity
  /// rounded (for checks that want the clean image).
  bool apply_effects = true;
  uint64_t noise_seed = 1;
};

/// One hardware-triggered stereo exposure: both images and the depth belong
/// to the same instant (the pose passed to Render).
struct RenderedStereoFrame {
  uint64_t frame_index = 0;
  cv::Mat cam0;  ///< CV_8UC1, height_px x width_px, distorted (as the lens delivers it)
  cv::Mat cam1;  ///< CV_8UC1, as cam0
  /// CV_32FC1 z-depth (along cam0's optical axis, metres) of the surface seen
  /// by each distorted cam0 pixel; 0 where there is none within max_depth_m
  /// (sky, or too far). Interpolated in inverse depth, which is exact on
  /// planes; at occlusion boundaries the nearest rendered sample is used.
  cv::Mat depth0_m;
};

/// Wall-clock split of the last Render call, seconds.
struct RenderTimings {
  double gl_s = 0.0;        ///< draw calls and rasterisation (until the read-back returns)
  double readback_s = 0.0;  ///< glReadPixels
  double post_s = 0.0;      ///< distortion remap, depth, sensor effects
};

class StereoRenderer {
 public:
  /// Uploads the world (heightfield, albedo, carriers, tags) to a new
  /// headless GL context. Throws std::invalid_argument for bad options and
  /// std::runtime_error if EGL/OpenGL 4.5 is unavailable.
  StereoRenderer(const World& world, const StereoCameraOptions& camera,
                 const RenderOptions& options = RenderOptions());
  ~StereoRenderer();
  StereoRenderer(const StereoRenderer&) = delete;
  StereoRenderer& operator=(const StereoRenderer&) = delete;

  /// Renders the pair for body pose T_world_body. T_world_carriers holds one
  /// pose per non-static carrier of the world (is_static == false), in the
  /// order they appear in World::carriers; static carriers use their own
  /// pose. frame_index seeds the sensor noise. Output Mats are reallocated
  /// only when their size changes.
  void Render(const Eigen::Isometry3d& T_world_body,
              const std::vector<Eigen::Isometry3d>& T_world_carriers, uint64_t frame_index,
              RenderedStereoFrame* out);

  /// GL_RENDERER of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& gl_renderer() const;
  const StereoCameraOptions& camera() const;
  const RenderOptions& options() const;
  void set_apply_effects(bool apply);
  /// Unbinds the GL context from the calling thread, so that the next
  /// Render() may run on another thread (the constructor leaves it bound to
  /// the constructing thread, each Render() to the rendering one).
  void ReleaseThread();
  /// Size of the undistorted pinhole image rasterised per camera.
  int render_width_px() const;
  int render_height_px() const;
  /// Terrain patches and triangles drawn for both cameras in the last frame.
  int last_patch_count() const;
  int64_t last_triangle_count() const;
  const RenderTimings& last_timings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_RENDER_STEREO_RENDERER_H_
