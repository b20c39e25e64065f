#include "hil/sim/render/stereo_renderer.h"

#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "hil/sim/render/egl_context.h"
#include "hil/sim/render/sensor_effects.h"
#include "hil/sim/render/terrain_lod.h"
#include "mapping/tags/tag_pattern.h"

namespace rover::sim {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// ---------------------------------------------------------------- shaders --

// Terrain: the vertex position comes from gl_VertexID within a patch and the
// height from the heightfield texture, so no vertex buffer holds the 6.5 M
// samples of a full-size site. Positions are relative to an eye origin so
// single precision keeps sub-millimetre accuracy anywhere on the site.
constexpr const char* kTerrainVertexShader = R"(#version 450 core
uniform sampler2D u_height;
uniform ivec2 u_grid_size;
uniform vec2 u_origin_rel;
uniform float u_eye_z;
uniform float u_resolution_m;
// Per patch (instanced): first cell, sample stride; edge strides -x, +x, -y, +y.
layout(location = 0) in ivec4 a_patch;
layout(location = 1) in ivec4 a_edge_stride;
uniform mat4 u_clip_from_rel;
uniform vec2 u_albedo_offset;
uniform vec2 u_albedo_scale;
uniform float u_detail_scale;
out vec2 v_albedo_uv;
out vec2 v_detail_cells;  // world position in fine detail cells
out vec3 v_normal;

const int kQuads = KQUADS;

float H(ivec2 c) { return texelFetch(u_height, clamp(c, ivec2(0), u_grid_size - 1), 0).r; }

void main() {
  ivec2 local = ivec2(gl_VertexID % (kQuads + 1), gl_VertexID / (kQuads + 1));
  int stride = a_patch.z;
  ivec2 cell = min(a_patch.xy + local * stride, u_grid_size - 1);
  float h = H(cell);
  // On an edge shared with a coarser patch, lie on that patch's straight edge.
  int snap = 0;
  bool along_y = false;
  if (local.x == 0 && a_edge_stride.x > stride) {
    snap = a_edge_stride.x;
    along_y = true;
  } else if (local.x == kQuads && a_edge_stride.y > stride) {
    snap = a_edge_stride.y;
    along_y = true;
  } else if (local.y == 0 && a_edge_stride.z > stride) {
    snap = a_edge_stride.z;
  } else if (local.y == kQuads && a_edge_stride.w > stride) {
    snap = a_edge_stride.w;
  }
  if (snap > 0) {
    int t = along_y ? cell.y : cell.x;
    int t0 = (t / snap) * snap;
    if (t0 != t) {
      ivec2 a = along_y ? ivec2(cell.x, t0) : ivec2(t0, cell.y);
      ivec2 b = along_y ? ivec2(cell.x, t0 + snap) : ivec2(t0 + snap, cell.y);
      h = mix(H(a), H(b), float(t - t0) / float(snap));
    }
  }
  int s = stride;
  float inv = 1.0 / (2.0 * float(s) * u_resolution_m);
  v_normal = vec3((H(cell - ivec2(s, 0)) - H(cell + ivec2(s, 0))) * inv,
                  (H(cell - ivec2(0, s)) - H(cell + ivec2(0, s))) * inv, 1.0);
  vec2 c = vec2(cell);
  v_albedo_uv = u_albedo_offset + c * u_albedo_scale;
  v_detail_cells = c * u_detail_scale;
  vec3 p_rel = vec3(u_origin_rel + c * u_resolution_m, h - u_eye_z);
  gl_Position = u_clip_from_rel * vec4(p_rel, 1.0);
}
)";

// The albedo map has texels of a few centimetres; close to the camera that is
// a blur, so a fine detail modulation is added: two octaves of seeded value
// noise (detail_texel_m = 5 mm cells and 4.7x coarser ones, rotated so the two
// lattices never line up), fixed to the ground so both cameras see the same. It is computed, not
// sampled: in llvmpipe one filtered texture fetch costs about as much as the rest of the frame's
// shading, while the noise is a few dozen SIMD integer operations. Each octave fades out as its
// cells shrink below the pixel footprint, so distant ground does not alias.
constexpr const char* kTerrainFragmentShader = R"(#version 450 core
in vec2 v_albedo_uv;
in vec2 v_detail_cells;
in vec3 v_normal;
uniform sampler2D u_albedo;
uniform vec3 u_sun;
uniform float u_ambient;
uniform float u_sun_irradiance;
uniform float u_detail_strength;
uniform uint u_detail_seed;
layout(location = 0) out float o_radiance;

float Hash(ivec2 p) {
  uint h = (uint(p.x) * 0x8da6b343u) ^ (uint(p.y) * 0xd8163841u) ^ u_detail_seed;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return float(h & 0xffffu) * (1.0 / 65535.0);
}

// Smooth value noise in [0, 1] on a unit lattice.
float ValueNoise(vec2 x) {
  vec2 i = floor(x);
  vec2 f = x - i;
  vec2 w = f * f * (3.0 - 2.0 * f);
  ivec2 c = ivec2(i);
  return mix(mix(Hash(c), Hash(c + ivec2(1, 0)), w.x),
             mix(Hash(c + ivec2(0, 1)), Hash(c + ivec2(1, 1)), w.x), w.y);
}

void main() {
  float albedo = texture(u_albedo, v_albedo_uv).r;
  float cells_per_pixel = sqrt(length(dFdx(v_detail_cells)) * length(dFdy(v_detail_cells)));
  float fine = (ValueNoise(v_detail_cells) - 0.5) * clamp(1.5 - cells_per_pixel, 0.0, 1.0);
  vec2 x2 = mat2(0.8, 0.6, -0.6, 0.8) * v_detail_cells * 0.2137 + vec2(37.0, 61.0);
  float coarse =
      (ValueNoise(x2) - 0.5) * clamp(1.5 - 0.2137 * cells_per_pixel, 0.0, 1.0);
  float detail = max(1.0 + u_detail_strength * (fine + 0.8 * coarse), 0.0);
  float shade = u_ambient + u_sun_irradiance * max(dot(normalize(v_normal), u_sun), 0.0);
  o_radiance = albedo * detail * shade;
}
)";

constexpr const char* kBoxVertexShader = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_clip_from_model;
uniform mat3 u_world_from_model_rotation;
out vec3 v_normal;
void main() {
  v_normal = u_world_from_model_rotation * a_normal;
  gl_Position = u_clip_from_model * vec4(a_position, 1.0);
}
)";

constexpr const char* kBoxFragmentShader = R"(#version 450 core
in vec3 v_normal;
uniform vec3 u_sun;
uniform float u_ambient;
uniform float u_sun_irradiance;
uniform float u_albedo;
layout(location = 0) out float o_radiance;
void main() {
  float shade = u_ambient + u_sun_irradiance * max(dot(normalize(v_normal), u_sun), 0.0);
  o_radiance = u_albedo * shade;
}
)";

constexpr const char* kTagVertexShader = R"(#version 450 core
layout(location = 0) in vec2 a_xy;  // tag frame, -0.5 .. 0.5 of the printed square
uniform mat4 u_clip_from_model;
uniform float u_cells;
out vec2 v_cells;
void main() {
  v_cells = (a_xy + 0.5) * u_cells;  // x right, y down: row 0 is the top of the tag
  gl_Position = u_clip_from_model * vec4(a_xy, 0.0, 1.0);
}
)";

// The tag cells are sharp-edged squares. Sampling them at the pixel centre
// would put every edge on a pixel boundary (up to 0.5 px off); instead the
// cell pattern is box-filtered over the pixel's footprint, so edge pixels
// carry their area coverage and the detector can find the edges to sub-pixel
// accuracy.
constexpr const char* kTagFragmentShader = R"(#version 450 core
in vec2 v_cells;
uniform sampler2DArray u_tags;
uniform int u_layer;
uniform int u_cell_count;
uniform float u_black;
uniform float u_white;
uniform float u_shade;
layout(location = 0) out float o_radiance;
float Cell(ivec2 c) {
  c = clamp(c, ivec2(0), ivec2(u_cell_count - 1));
  return texelFetch(u_tags, ivec3(c, u_layer), 0).r;
}
void main() {
  vec2 w = clamp(fwidth(v_cells), vec2(1e-4), vec2(1.0));
  vec2 boundary = floor(v_cells + 0.5);
  vec2 f = clamp((boundary - (v_cells - 0.5 * w)) / w, 0.0, 1.0);  // share below the boundary
  ivec2 hi = ivec2(boundary);
  ivec2 lo = hi - 1;
  float value = f.x * f.y * Cell(lo) + (1.0 - f.x) * f.y * Cell(ivec2(hi.x, lo.y)) +
                f.x * (1.0 - f.y) * Cell(ivec2(lo.x, hi.y)) + (1.0 - f.x) * (1.0 - f.y) * Cell(hi);
  o_radiance = mix(u_black, u_white, value) * u_shade;
}
)";

GLuint CompileShader(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[4096] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error(std::string("StereoRenderer: shader compile failed: ") + log);
  }
  return shader;
}

GLuint LinkProgram(const char* vertex_source, const char* fragment_source) {
  const GLuint vs = CompileShader(GL_VERTEX_SHADER, vertex_source);
  const GLuint fs = CompileShader(GL_FRAGMENT_SHADER, fragment_source);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[4096] = {};
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    glDeleteProgram(program);
    throw std::runtime_error(std::string("StereoRenderer: program link failed: ") + log);
  }
  return program;
}

// Uniform locations are looked up once; a name the compiler optimised away
// gives -1, which GL ignores on upload.
struct Uniforms {
  GLuint program = 0;
  std::map<std::string, GLint> locations;
  GLint operator[](const char* name) {
    auto it = locations.find(name);
    if (it == locations.end()) {
      it = locations.emplace(name, glGetUniformLocation(program, name)).first;
    }
    return it->second;
  }
};

void SetMatrix4(GLint location, const Eigen::Matrix4d& m) {
  const Eigen::Matrix4f f = m.cast<float>();
  glUniformMatrix4fv(location, 1, GL_FALSE, f.data());  // Eigen is column-major, as GL
}

void SetMatrix3(GLint location, const Eigen::Matrix3d& m) {
  const Eigen::Matrix3f f = m.cast<float>();
  glUniformMatrix3fv(location, 1, GL_FALSE, f.data());
}

// Pinhole intrinsics of the undistorted image that is actually rasterised.
struct RenderIntrinsics {
  int width_px = 0;
  int height_px = 0;
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;
};

// Clip coordinates straight from OpenCV camera coordinates (x right, y down,
// z forward), reversed-Z with an infinite far plane: depth = near / z. The
// pixel centre convention differs by half a pixel: OpenCV's pixel u spans
// [u - 0.5, u + 0.5], GL's window pixel i spans [i, i + 1]. Image row v is
// window row v (y_ndc grows with v), so glReadPixels rows come out top-down.
Eigen::Matrix4d ClipFromCamera(const RenderIntrinsics& k, double near_m) {
  const double w = k.width_px;
  const double h = k.height_px;
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 2.0 * k.fx_px / w;
  P(0, 2) = 2.0 * (k.cx_px + 0.5) / w - 1.0;
  P(1, 1) = 2.0 * k.fy_px / h;
  P(1, 2) = 2.0 * (k.cy_px + 0.5) / h - 1.0;
  P(2, 3) = near_m;
  P(3, 2) = 1.0;
  return P;
}

Eigen::Matrix4d ToMatrix(const Eigen::Isometry3d& T) { return T.matrix(); }

}  // namespace

// ------------------------------------------------------------------ Impl --

struct StereoRenderer::Impl {
  Impl(const World& world, const StereoCameraOptions& camera, const RenderOptions& options);
  ~Impl();
  void Render(const Eigen::Isometry3d& T_world_body,
              const std::vector<Eigen::Isometry3d>& T_world_carriers, uint64_t frame_index,
              RenderedStereoFrame* out);

  void ChooseRenderIntrinsics();
  void BuildMaps();
  void UploadTerrain(const World& world);
  void UploadAlbedo(const World& world);
  void UploadObjects(const World& world);
  void CreateFramebuffer();
  void DrawView(int view, const Eigen::Isometry3d& T_world_cam,
                const std::vector<TerrainPatch>& patches,
                const std::vector<Eigen::Isometry3d>& T_world_carriers);
  bool PatchVisible(const TerrainPatch& patch, const Eigen::Isometry3d& T_cam_world) const;
  void RemapDepth(const cv::Mat& depth_buffer, cv::Mat* depth_m) const;

  StereoCameraOptions camera;
  RenderOptions options;
  EglContext context;
  RenderIntrinsics render;
  Eigen::Matrix4d clip_from_cam = Eigen::Matrix4d::Identity();
  std::array<double, 4> frustum_slopes = {};  // x/z and y/z bounds of the render image

  // Distorted output pixel -> undistorted render pixel, CV_32FC1 each.
  cv::Mat map_x;
  cv::Mat map_y;
  // The same mapping for the depth resampling: sample offset and weights.
  struct DepthTap {
    std::ptrdiff_t offset = 0;
    float fx = 0.0f;
    float fy = 0.0f;
  };
  std::vector<DepthTap> depth_taps;
  std::array<SensorEffects, 2> view_effects;  // one per view: they keep scratch images

  // World data kept on the CPU side.
  TerrainQuadtree quadtree;
  int grid_cols = 0;
  int grid_rows = 0;
  double resolution_m = 0.0;
  Eigen::Vector2d grid_origin_xy = Eigen::Vector2d::Zero();
  Eigen::Vector2d albedo_offset = Eigen::Vector2d::Zero();
  Eigen::Vector2d albedo_scale = Eigen::Vector2d::Zero();
  struct Carrier {
    bool is_static = true;
    Eigen::Isometry3d T_world_carrier = Eigen::Isometry3d::Identity();
    std::vector<Box> boxes;
    struct Tag {
      int layer = 0;
      double printed_size_m = 0.0;  // including the white margin
      Eigen::Isometry3d T_carrier_tag = Eigen::Isometry3d::Identity();
    };
    std::vector<Tag> tags;
  };
  std::vector<Carrier> carriers;
  int dynamic_carrier_count = 0;
  int tag_cells = 10;
  Eigen::Vector3d sun_world = Eigen::Vector3d::UnitZ();

  // GL objects.
  GLuint terrain_program = 0;
  GLuint box_program = 0;
  GLuint tag_program = 0;
  Uniforms terrain_uniforms;
  Uniforms box_uniforms;
  Uniforms tag_uniforms;
  GLuint height_texture = 0;
  GLuint albedo_texture = 0;
  GLuint tag_texture = 0;
  GLuint terrain_vao = 0;
  GLuint terrain_indices = 0;
  std::array<GLuint, 2> patch_buffers = {0, 0};  // per view: instanced patch parameters
  std::vector<GLint> instances;
  GLsizei terrain_index_count = 0;
  GLuint box_vao = 0;
  GLuint box_vertices = 0;
  GLuint tag_vao = 0;
  GLuint tag_vertices = 0;
  GLuint framebuffer = 0;
  GLuint color_texture = 0;
  GLuint depth_renderbuffer = 0;

  // Per-frame scratch.
  cv::Mat radiance_both;                   // CV_32FC1, render_height x 2 * render_width
  cv::Mat depth_buffer;                    // CV_32FC1, render_height x render_width (cam0)
  std::array<cv::Mat, 2> distorted_views;  // CV_32FC1 output size
  Eigen::Vector3d eye_origin = Eigen::Vector3d::Zero();
  int patch_count = 0;
  int64_t triangle_count = 0;
  RenderTimings timings;
};

StereoRenderer::Impl::Impl(const World& world, const StereoCameraOptions& camera_options,
                           const RenderOptions& render_options)
    : camera((camera_options.Validate(), camera_options)),
      options(render_options),
      view_effects{SensorEffects(camera_options), SensorEffects(camera_options)},
      quadtree(world.terrain) {
  if (!(options.supersample >= 0.25 && options.supersample <= 4.0)) {
    throw std::invalid_argument("RenderOptions: supersample must be in [0.25, 4]");
  }
  if (!(options.full_resolution_distance_m >= 0.0) || !(options.max_terrain_error_px > 0.0)) {
    throw std::invalid_argument(
        "RenderOptions: need full_resolution_distance_m >= 0 and max_terrain_error_px > 0");
  }
  if (!(options.max_anisotropy >= 1.0)) {
    throw std::invalid_argument("RenderOptions: max_anisotropy must be >= 1");
  }
  const double azimuth = options.sun_azimuth_deg * M_PI / 180.0;
  const double elevation = options.sun_elevation_deg * M_PI / 180.0;
  sun_world = Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));

  ChooseRenderIntrinsics();
  BuildMaps();

  std::string terrain_vertex_shader = kTerrainVertexShader;
  terrain_vertex_shader.replace(terrain_vertex_shader.find("KQUADS"), 6,
                                std::to_string(TerrainQuadtree::kPatchQuads));
  terrain_program = LinkProgram(terrain_vertex_shader.c_str(), kTerrainFragmentShader);
  box_program = LinkProgram(kBoxVertexShader, kBoxFragmentShader);
  tag_program = LinkProgram(kTagVertexShader, kTagFragmentShader);
  terrain_uniforms.program = terrain_program;
  box_uniforms.program = box_program;
  tag_uniforms.program = tag_program;

  UploadTerrain(world);
  UploadAlbedo(world);
  UploadObjects(world);
  CreateFramebuffer();

  // Reversed-Z: depth = near / z in [0, 1], so the float depth buffer keeps
  // ~24 bits of relative precision at every range.
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("StereoRenderer: GL setup failed");
}

StereoRenderer::Impl::~Impl() {
  // The objects die with the context anyway; deleting them first only
  // matters for a long-lived process, so a failure here is not worth a throw.
  try {
    context.MakeCurrent();
  } catch (const std::runtime_error&) {
    return;
  }
  const GLuint textures[] = {height_texture, albedo_texture, tag_texture, color_texture};
  glDeleteTextures(4, textures);
  const GLuint buffers[] = {terrain_indices, box_vertices, tag_vertices, patch_buffers[0],
                            patch_buffers[1]};
  glDeleteBuffers(5, buffers);
  const GLuint arrays[] = {terrain_vao, box_vao, tag_vao};
  glDeleteVertexArrays(3, arrays);
  glDeleteRenderbuffers(1, &depth_renderbuffer);
  glDeleteFramebuffers(1, &framebuffer);
  glDeleteProgram(terrain_program);
  glDeleteProgram(box_program);
  glDeleteProgram(tag_program);
}

void StereoRenderer::Impl::ChooseRenderIntrinsics() {
  // Undistort the border of the output image to find the pinhole field of
  // view the rasteriser must cover; barrel distortion pushes the corners far
  // out, so the render image is larger than the output one.
  double x_min = 0.0;
  double x_max = 0.0;
  double y_min = 0.0;
  double y_max = 0.0;
  const int w = camera.width_px;
  const int h = camera.height_px;
  auto visit = [&](double u, double v) {
    Eigen::Vector3d ray;
    if (!PixelToRay(camera, Eigen::Vector2d(u, v), &ray)) {
      throw std::invalid_argument("StereoCameraOptions: distortion not invertible in the image");
    }
    x_min = std::min(x_min, ray.x() / ray.z());
    x_max = std::max(x_max, ray.x() / ray.z());
    y_min = std::min(y_min, ray.y() / ray.z());
    y_max = std::max(y_max, ray.y() / ray.z());
  };
  // Half a pixel beyond the outermost pixel centres.
  for (int u = 0; u <= 4 * w; ++u) {
    visit(u / 4.0 - 0.5, -0.5);
    visit(u / 4.0 - 0.5, h - 0.5);
  }
  for (int v = 0; v <= 4 * h; ++v) {
    visit(-0.5, v / 4.0 - 0.5);
    visit(w - 0.5, v / 4.0 - 0.5);
  }
  render.fx_px = camera.fx_px * options.supersample;
  render.fy_px = camera.fy_px * options.supersample;
  // Two pixels of margin for the bilinear resampling footprint.
  constexpr double kMarginPx = 2.0;
  const double left_px = -x_min * render.fx_px + kMarginPx;
  const double right_px = x_max * render.fx_px + kMarginPx;
  const double top_px = -y_min * render.fy_px + kMarginPx;
  const double bottom_px = y_max * render.fy_px + kMarginPx;
  render.width_px = static_cast<int>(std::ceil(left_px + right_px));
  render.height_px = static_cast<int>(std::ceil(top_px + bottom_px));
  render.cx_px = left_px - 0.5;
  render.cy_px = top_px - 0.5;
  clip_from_cam = ClipFromCamera(render, camera.near_m);
  frustum_slopes = {
      (-0.5 - render.cx_px) / render.fx_px, (render.width_px - 0.5 - render.cx_px) / render.fx_px,
      (-0.5 - render.cy_px) / render.fy_px, (render.height_px - 0.5 - render.cy_px) / render.fy_px};
}

void StereoRenderer::Impl::BuildMaps() {
  map_x.create(camera.height_px, camera.width_px, CV_32FC1);
  map_y.create(camera.height_px, camera.width_px, CV_32FC1);
  depth_taps.resize(static_cast<std::size_t>(camera.width_px) *
                    static_cast<std::size_t>(camera.height_px));
  for (int v = 0; v < camera.height_px; ++v) {
    for (int u = 0; u < camera.width_px; ++u) {
      Eigen::Vector3d ray;
      PixelToRay(camera, Eigen::Vector2d(u, v), &ray);  // checked in ChooseRenderIntrinsics
      const double x = render.fx_px * ray.x() / ray.z() + render.cx_px;
      const double y = render.fy_px * ray.y() / ray.z() + render.cy_px;
      map_x.at<float>(v, u) = static_cast<float>(x);
      map_y.at<float>(v, u) = static_cast<float>(y);
      // The depth resampling reads a 4 x 4 neighbourhood around (x0, y0);
      // the render margin keeps it inside the image, the clamp makes sure.
      const int x0 = std::clamp(static_cast<int>(std::floor(x)), 1, render.width_px - 3);
      const int y0 = std::clamp(static_cast<int>(std::floor(y)), 1, render.height_px - 3);
      DepthTap& tap = depth_taps[static_cast<std::size_t>(v * camera.width_px + u)];
      tap.offset = static_cast<std::ptrdiff_t>(y0) * render.width_px + x0;
      tap.fx = static_cast<float>(std::clamp(x - x0, 0.0, 1.0));
      tap.fy = static_cast<float>(std::clamp(y - y0, 0.0, 1.0));
    }
  }
}

void StereoRenderer::Impl::UploadTerrain(const World& world) {
  const Heightfield& terrain = world.terrain;
  grid_cols = terrain.cols();
  grid_rows = terrain.rows();
  resolution_m = terrain.resolution_m();
  grid_origin_xy = terrain.origin_xy();
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (grid_cols > max_size || grid_rows > max_size) {
    throw std::runtime_error("StereoRenderer: heightfield larger than GL_MAX_TEXTURE_SIZE");
  }
  glGenTextures(1, &height_texture);
  glBindTexture(GL_TEXTURE_2D, height_texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, grid_cols, grid_rows, 0, GL_RED, GL_FLOAT,
               terrain.heights_m().data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);

  // One index pattern for every patch: 64 x 64 quads over a 65 x 65 vertex
  // grid whose vertex index is gl_VertexID.
  constexpr int kQuads = TerrainQuadtree::kPatchQuads;
  std::vector<uint16_t> indices;
  indices.reserve(static_cast<std::size_t>(kQuads * kQuads * 6));
  for (int y = 0; y < kQuads; ++y) {
    for (int x = 0; x < kQuads; ++x) {
      const auto i00 = static_cast<uint16_t>(y * (kQuads + 1) + x);
      const auto i10 = static_cast<uint16_t>(i00 + 1);
      const auto i01 = static_cast<uint16_t>(i00 + kQuads + 1);
      const auto i11 = static_cast<uint16_t>(i01 + 1);
      indices.insert(indices.end(), {i00, i10, i11, i00, i11, i01});
    }
  }
  terrain_index_count = static_cast<GLsizei>(indices.size());
  glGenVertexArrays(1, &terrain_vao);
  glBindVertexArray(terrain_vao);
  glGenBuffers(1, &terrain_indices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, terrain_indices);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint16_t)),
               indices.data(), GL_STATIC_DRAW);
  glGenBuffers(2, patch_buffers.data());
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  glVertexAttribDivisor(0, 1);
  glVertexAttribDivisor(1, 1);
  glBindVertexArray(0);
}

void StereoRenderer::Impl::UploadAlbedo(const World& world) {
  const AlbedoMap& albedo = world.albedo;
  cv::Mat image;
  double texel_m = albedo.resolution_m;
  Eigen::Vector2d origin = albedo.origin_xy;
  if (albedo.cols > 0 && albedo.rows > 0 &&
      albedo.values.size() ==
          static_cast<std::size_t>(albedo.cols) * static_cast<std::size_t>(albedo.rows)) {
    image = cv::Mat(albedo.rows, albedo.cols, CV_8UC1, const_cast<uint8_t*>(albedo.values.data()))
                .clone();
  } else {
    // No albedo map: uniform mid grey over the terrain.
    image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(128));
    texel_m = resolution_m * (grid_cols - 1);
    origin = grid_origin_xy;
  }
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (image.cols > max_size || image.rows > max_size) {
    // Keep the covered area; the texel grows. Samples stay at texel centres
    // of the coarser grid, so the origin moves by half the growth.
    const double factor = std::max(static_cast<double>(image.cols) / max_size,
                                   static_cast<double>(image.rows) / max_size);
    cv::Mat smaller;
    cv::resize(
        image, smaller,
        cv::Size(static_cast<int>(image.cols / factor), static_cast<int>(image.rows / factor)), 0,
        0, cv::INTER_AREA);
    const double new_texel = texel_m * image.cols / smaller.cols;
    origin += Eigen::Vector2d::Constant(0.5 * (new_texel - texel_m));
    texel_m = new_texel;
    image = smaller;
  }
  // Texture coordinate of world point p: ((p - origin) / texel + 0.5) / size;
  // expressed per heightfield cell so the vertex shader needs no world xy.
  const Eigen::Vector2d size(image.cols, image.rows);
  albedo_offset =
      ((grid_origin_xy - origin) / texel_m + Eigen::Vector2d::Constant(0.5)).cwiseQuotient(size);
  albedo_scale = (Eigen::Vector2d::Constant(resolution_m / texel_m)).cwiseQuotient(size);

  glGenTextures(1, &albedo_texture);
  glBindTexture(GL_TEXTURE_2D, albedo_texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, image.cols, image.rows, 0, GL_RED, GL_UNSIGNED_BYTE,
               image.data);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY,
                  static_cast<float>(options.max_anisotropy));
}

void StereoRenderer::Impl::UploadObjects(const World& world) {
  // Tag patterns: one texture layer per distinct id.
  std::map<int, int> layer_of_id;
  for (const TagCarrier& carrier : world.carriers) {
    for (const TagMarker& tag : carrier.tags) layer_of_id.emplace(tag.id, 0);
  }
  std::vector<uint8_t> layers;
  int border_cells = 8;
  for (auto& [id, layer] : layer_of_id) {
    const mapping::TagPattern pattern = mapping::MakeTagPattern("tag36h11", id);
    tag_cells = pattern.cells_per_side;
    border_cells = pattern.border_cells;
    layer = static_cast<int>(layers.size() / pattern.cells.size());
    layers.insert(layers.end(), pattern.cells.begin(), pattern.cells.end());
  }
  for (const TagCarrier& carrier : world.carriers) {
    Carrier c;
    c.is_static = carrier.is_static;
    c.T_world_carrier = carrier.T_world_carrier;
    c.boxes = carrier.boxes;
    for (const TagMarker& tag : carrier.tags) {
      Carrier::Tag t;
      t.layer = layer_of_id.at(tag.id);
      t.printed_size_m = tag.size_m * tag_cells / border_cells;
      t.T_carrier_tag = tag.T_carrier_tag;
      c.tags.push_back(t);
    }
    if (!carrier.is_static) ++dynamic_carrier_count;
    carriers.push_back(std::move(c));
  }
  glGenTextures(1, &tag_texture);
  glBindTexture(GL_TEXTURE_2D_ARRAY, tag_texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const int layer_count = std::max<int>(1, static_cast<int>(layer_of_id.size()));
  if (layers.empty()) layers.assign(static_cast<std::size_t>(tag_cells * tag_cells), 255);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R8, tag_cells, tag_cells, layer_count, 0, GL_RED,
               GL_UNSIGNED_BYTE, layers.data());
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, 0);

  // Unit cube centred at the origin, outward normals, 36 vertices.
  std::vector<float> cube;
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = sign;
      const Eigen::Vector3f a = Eigen::Vector3f::Unit((axis + 1) % 3) * 0.5f;
      const Eigen::Vector3f b = Eigen::Vector3f::Unit((axis + 2) % 3) * 0.5f;
      const Eigen::Vector3f c = n * 0.5f;
      const Eigen::Vector3f corners[4] = {c - a - b, c + a - b, c + a + b, c - a + b};
      for (const int i : {0, 1, 2, 0, 2, 3}) {
        cube.insert(cube.end(),
                    {corners[i].x(), corners[i].y(), corners[i].z(), n.x(), n.y(), n.z()});
      }
    }
  }
  glGenVertexArrays(1, &box_vao);
  glBindVertexArray(box_vao);
  glGenBuffers(1, &box_vertices);
  glBindBuffer(GL_ARRAY_BUFFER, box_vertices);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(cube.size() * sizeof(float)), cube.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));

  const float quad[] = {-0.5f, -0.5f, 0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f};
  glGenVertexArrays(1, &tag_vao);
  glBindVertexArray(tag_vao);
  glGenBuffers(1, &tag_vertices);
  glBindBuffer(GL_ARRAY_BUFFER, tag_vertices);
  glBufferData(GL_ARRAY_BUFFER, sizeof(quad), quad, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  glBindVertexArray(0);
}

void StereoRenderer::Impl::CreateFramebuffer() {
  // Both views side by side: one clear, one read-back.
  glGenTextures(1, &color_texture);
  glBindTexture(GL_TEXTURE_2D, color_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, 2 * render.width_px, render.height_px, 0, GL_RED,
               GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glGenRenderbuffers(1, &depth_renderbuffer);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_renderbuffer);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, 2 * render.width_px,
                        render.height_px);
  glGenFramebuffers(1, &framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_texture, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                            depth_renderbuffer);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("StereoRenderer: framebuffer incomplete");
  }
  radiance_both.create(render.height_px, 2 * render.width_px, CV_32FC1);
  depth_buffer.create(render.height_px, render.width_px, CV_32FC1);
}

bool StereoRenderer::Impl::PatchVisible(const TerrainPatch& patch,
                                        const Eigen::Isometry3d& T_cam_world) const {
  // Reject a patch whose bounding box lies wholly outside one side plane of
  // the frustum (the planes pass through the camera centre) or behind it.
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p((i & 1) ? patch.max_world.x() : patch.min_world.x(),
                            (i & 2) ? patch.max_world.y() : patch.min_world.y(),
                            (i & 4) ? patch.max_world.z() : patch.min_world.z());
    corners[static_cast<std::size_t>(i)] = T_cam_world * p;
  }
  auto all = [&](auto outside) { return std::all_of(corners.begin(), corners.end(), outside); };
  const auto& s = frustum_slopes;
  if (all([&](const Eigen::Vector3d& p) { return p.z() < camera.near_m; })) return false;
  if (all([&](const Eigen::Vector3d& p) { return p.x() < s[0] * p.z(); })) return false;
  if (all([&](const Eigen::Vector3d& p) { return p.x() > s[1] * p.z(); })) return false;
  if (all([&](const Eigen::Vector3d& p) { return p.y() < s[2] * p.z(); })) return false;
  if (all([&](const Eigen::Vector3d& p) { return p.y() > s[3] * p.z(); })) return false;
  return true;
}

void StereoRenderer::Impl::DrawView(int view, const Eigen::Isometry3d& T_world_cam,
                                    const std::vector<TerrainPatch>& patches,
                                    const std::vector<Eigen::Isometry3d>& T_world_carriers) {
  glViewport(view * render.width_px, 0, render.width_px, render.height_px);
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  // Clip from eye-origin-relative world coordinates.
  Eigen::Isometry3d T_world_rel = Eigen::Isometry3d::Identity();
  T_world_rel.translation() = eye_origin;
  const Eigen::Matrix4d clip_from_rel = clip_from_cam * ToMatrix(T_cam_world * T_world_rel);

  // Terrain.
  glUseProgram(terrain_program);
  Uniforms& tu = terrain_uniforms;
  glUniformMatrix4fv(tu["u_clip_from_rel"], 1, GL_FALSE,
                     Eigen::Matrix4f(clip_from_rel.cast<float>()).data());
  glUniform2i(tu["u_grid_size"], grid_cols, grid_rows);
  glUniform2f(tu["u_origin_rel"], static_cast<float>(grid_origin_xy.x() - eye_origin.x()),
              static_cast<float>(grid_origin_xy.y() - eye_origin.y()));
  glUniform1f(tu["u_eye_z"], static_cast<float>(eye_origin.z()));
  glUniform1f(tu["u_resolution_m"], static_cast<float>(resolution_m));
  glUniform2f(tu["u_albedo_offset"], static_cast<float>(albedo_offset.x()),
              static_cast<float>(albedo_offset.y()));
  glUniform2f(tu["u_albedo_scale"], static_cast<float>(albedo_scale.x()),
              static_cast<float>(albedo_scale.y()));
  // Detail cells counted from the grid origin, so they stay positive and
  // below ~3e4 (single precision keeps 1e-3 of a cell).
  glUniform1f(tu["u_detail_scale"], static_cast<float>(resolution_m / options.detail_texel_m));
  glUniform1ui(tu["u_detail_seed"], static_cast<GLuint>(options.detail_seed & 0xffffffffu));
  glUniform3f(tu["u_sun"], static_cast<float>(sun_world.x()), static_cast<float>(sun_world.y()),
              static_cast<float>(sun_world.z()));
  glUniform1f(tu["u_ambient"], static_cast<float>(options.ambient));
  glUniform1f(tu["u_sun_irradiance"], static_cast<float>(options.sun_irradiance));
  glUniform1f(tu["u_detail_strength"], static_cast<float>(options.detail_strength));
  glUniform1i(tu["u_height"], 0);
  glUniform1i(tu["u_albedo"], 1);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, height_texture);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, albedo_texture);
  glBindVertexArray(terrain_vao);
  // The ground is only ever seen from above; its back faces are hidden by
  // front faces, so drop them before rasterisation. Triangles wind counter-
  // clockwise seen from above, which is clockwise in this flipped window.
  glEnable(GL_CULL_FACE);
  glFrontFace(GL_CW);
  glCullFace(GL_BACK);
  // All visible patches in one instanced draw: llvmpipe's cost per draw call
  // is far above its cost per small patch.
  instances.clear();
  for (const TerrainPatch& patch : patches) {
    if (!PatchVisible(patch, T_cam_world)) continue;
    instances.insert(instances.end(), {patch.ix0, patch.iy0, patch.stride_cells, 0,
                                       patch.edge_stride_cells[0], patch.edge_stride_cells[1],
                                       patch.edge_stride_cells[2], patch.edge_stride_cells[3]});
  }
  const auto instance_count = static_cast<GLsizei>(instances.size() / 8);
  glBindBuffer(GL_ARRAY_BUFFER, patch_buffers[static_cast<std::size_t>(view)]);
  // Orphan and refill: the previous contents may still be in use.
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(instances.size() * sizeof(GLint)),
               instances.data(), GL_STREAM_DRAW);
  glVertexAttribIPointer(0, 4, GL_INT, 8 * sizeof(GLint), nullptr);
  glVertexAttribIPointer(1, 4, GL_INT, 8 * sizeof(GLint),
                         reinterpret_cast<const void*>(4 * sizeof(GLint)));
  if (instance_count > 0) {
    glDrawElementsInstanced(GL_TRIANGLES, terrain_index_count, GL_UNSIGNED_SHORT, nullptr,
                            instance_count);
  }
  patch_count += instance_count;
  triangle_count += static_cast<int64_t>(instance_count) * (terrain_index_count / 3);
  glDisable(GL_CULL_FACE);

  // Carriers: boxes, then tags drawn just in front of the faces they sit on.
  std::size_t dynamic_index = 0;
  for (const Carrier& carrier : carriers) {
    Eigen::Isometry3d T_world_carrier = carrier.T_world_carrier;
    if (!carrier.is_static) T_world_carrier = T_world_carriers[dynamic_index++];
    const Eigen::Matrix4d clip_from_carrier =
        clip_from_cam * ToMatrix(T_cam_world * T_world_carrier);

    glUseProgram(box_program);
    Uniforms& bu = box_uniforms;
    glUniform3f(bu["u_sun"], static_cast<float>(sun_world.x()), static_cast<float>(sun_world.y()),
                static_cast<float>(sun_world.z()));
    glUniform1f(bu["u_ambient"], static_cast<float>(options.ambient));
    glUniform1f(bu["u_sun_irradiance"], static_cast<float>(options.sun_irradiance));
    SetMatrix3(bu["u_world_from_model_rotation"], T_world_carrier.linear());
    glBindVertexArray(box_vao);
    for (const Box& box : carrier.boxes) {
      Eigen::Matrix4d carrier_from_model = Eigen::Matrix4d::Identity();
      carrier_from_model.block<3, 3>(0, 0) = box.size_m.asDiagonal();
      carrier_from_model.block<3, 1>(0, 3) = box.center_carrier;
      SetMatrix4(bu["u_clip_from_model"], clip_from_carrier * carrier_from_model);
      glUniform1f(bu["u_albedo"], static_cast<float>(box.albedo));
      glDrawArrays(GL_TRIANGLES, 0, 36);
      triangle_count += 12;
    }

    if (carrier.tags.empty()) continue;
    glUseProgram(tag_program);
    Uniforms& gu = tag_uniforms;
    glUniform1i(gu["u_tags"], 3);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tag_texture);
    glUniform1f(gu["u_cells"], static_cast<float>(tag_cells));
    glUniform1i(gu["u_cell_count"], tag_cells);
    glUniform1f(gu["u_black"], static_cast<float>(options.tag_black_albedo));
    glUniform1f(gu["u_white"], static_cast<float>(options.tag_white_albedo));
    glBindVertexArray(tag_vao);
    // Coplanar with the carrier's face: pull the tag towards the viewer in
    // depth only (reversed-Z: larger is nearer), not in geometry.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 4.0f);
    for (const Carrier::Tag& tag : carrier.tags) {
      const Eigen::Isometry3d T_world_tag = T_world_carrier * tag.T_carrier_tag;
      // The printed side faces -z of the tag frame.
      const Eigen::Vector3d normal_world = -T_world_tag.linear().col(2);
      const double shade =
          options.ambient + options.sun_irradiance * std::max(0.0, normal_world.dot(sun_world));
      Eigen::Matrix4d tag_from_model = Eigen::Matrix4d::Identity();
      tag_from_model(0, 0) = tag.printed_size_m;
      tag_from_model(1, 1) = tag.printed_size_m;
      SetMatrix4(gu["u_clip_from_model"],
                 clip_from_carrier * ToMatrix(tag.T_carrier_tag) * tag_from_model);
      glUniform1i(gu["u_layer"], tag.layer);
      glUniform1f(gu["u_shade"], static_cast<float>(shade));
      glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
      triangle_count += 2;
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
  }
  glBindVertexArray(0);
}

void StereoRenderer::Impl::RemapDepth(const cv::Mat& depth, cv::Mat* depth_m) const {
  // depth holds near / z (0 where nothing was drawn). Inverse depth is linear
  // in image coordinates on a plane, so bilinear interpolation of it is
  // exact there and very nearly so on smooth terrain. Where the 2 x 2 samples
  // straddle an occlusion boundary the nearest sample is taken instead of
  // inventing a surface in between. A boundary shows as a step between two
  // neighbouring samples that is much larger than the steps just outside
  // them (on a smooth surface consecutive steps are nearly equal, however
  // steep the surface is in the image).
  const float near = static_cast<float>(camera.near_m);
  const float min_inverse = static_cast<float>(camera.near_m / camera.max_depth_m);
  const auto stride = static_cast<std::ptrdiff_t>(depth.step1());
  // Is the step a -> b continuous with the steps before a and after b?
  auto continuous = [](float before, float a, float b, float after) {
    const float inner = std::abs(b - a);
    const float outer = std::max(std::abs(a - before), std::abs(after - b));
    return inner <= 2.0f * outer + 1e-4f * std::max(a, b);
  };
  depth_m->create(camera.height_px, camera.width_px, CV_32FC1);
  cv::parallel_for_(cv::Range(0, camera.height_px), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const DepthTap* taps = depth_taps.data() + static_cast<std::size_t>(v) *
                                                     static_cast<std::size_t>(camera.width_px);
      float* out = depth_m->ptr<float>(v);
      for (int u = 0; u < camera.width_px; ++u) {
        const DepthTap& t = taps[u];
        const float* p = depth.ptr<float>(0) + t.offset;  // sample (x0, y0)
        const float d00 = p[0];
        const float d10 = p[1];
        const float d01 = p[stride];
        const float d11 = p[stride + 1];
        const bool smooth = std::min({d00, d10, d01, d11}) > 0.0f &&
                            continuous(p[-1], d00, d10, p[2]) &&
                            continuous(p[stride - 1], d01, d11, p[stride + 2]) &&
                            continuous(p[-stride], d00, d01, p[2 * stride]) &&
                            continuous(p[1 - stride], d10, d11, p[2 * stride + 1]);
        float inverse;
        if (smooth) {
          inverse = (1.0f - t.fy) * ((1.0f - t.fx) * d00 + t.fx * d10) +
                    t.fy * ((1.0f - t.fx) * d01 + t.fx * d11);
        } else {
          inverse = t.fy < 0.5f ? (t.fx < 0.5f ? d00 : d10) : (t.fx < 0.5f ? d01 : d11);
        }
        out[u] = inverse > min_inverse ? near / inverse : 0.0f;
      }
    }
  });
}

void StereoRenderer::Impl::Render(const Eigen::Isometry3d& T_world_body,
                                  const std::vector<Eigen::Isometry3d>& T_world_carriers,
                                  uint64_t frame_index, RenderedStereoFrame* out) {
  if (static_cast<int>(T_world_carriers.size()) != dynamic_carrier_count) {
    throw std::invalid_argument(
        "StereoRenderer::Render: expected " + std::to_string(dynamic_carrier_count) +
        " poses of non-static carriers, got " + std::to_string(T_world_carriers.size()));
  }
  const Clock::time_point start = Clock::now();
  context.MakeCurrent();
  const Eigen::Isometry3d T_world_cam0 = T_world_body * camera.T_body_cam0;
  const Eigen::Isometry3d T_world_cam1 = T_world_body * camera.T_body_cam1();
  eye_origin = T_world_cam0.translation();
  // One level-of-detail choice for both views, so both see the same mesh.
  TerrainLodParams lod;
  lod.full_resolution_distance_m = options.full_resolution_distance_m;
  lod.max_error_px = options.max_terrain_error_px;
  lod.focal_px = std::max(render.fx_px, render.fy_px);
  const std::vector<TerrainPatch> patches =
      quadtree.Select(0.5 * (T_world_cam0.translation() + T_world_cam1.translation()), lod);

  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, 2 * render.width_px, render.height_px);
  glClearColor(static_cast<float>(options.sky_radiance), 0.0f, 0.0f, 0.0f);
  glClearDepth(0.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  patch_count = 0;
  triangle_count = 0;
  DrawView(0, T_world_cam0, patches, T_world_carriers);
  // Let llvmpipe's threads rasterise cam0 while this thread prepares cam1.
  glFlush();
  DrawView(1, T_world_cam1, patches, T_world_carriers);
  glFinish();
  const Clock::time_point drawn = Clock::now();
  timings.gl_s = SecondsSince(start);

  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, 2 * render.width_px, render.height_px, GL_RED, GL_FLOAT, radiance_both.data);
  glReadPixels(0, 0, render.width_px, render.height_px, GL_DEPTH_COMPONENT, GL_FLOAT,
               depth_buffer.data);
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("StereoRenderer: GL error in Render");
  const Clock::time_point read = Clock::now();
  timings.readback_s = SecondsSince(drawn);

  out->frame_index = frame_index;
  const bool with_effects = options.apply_effects;
  // The three outputs are independent: resample and expose both images and
  // resample the depth side by side (the llvmpipe threads are idle now).
  cv::parallel_for_(cv::Range(0, 3), [&](const cv::Range& tasks) {
    for (int task = tasks.start; task < tasks.end; ++task) {
      if (task == 2) {
        RemapDepth(depth_buffer, &out->depth0_m);
        continue;
      }
      const cv::Mat radiance =
          radiance_both(cv::Rect(task * render.width_px, 0, render.width_px, render.height_px));
      cv::Mat& distorted = distorted_views[static_cast<std::size_t>(task)];
      cv::remap(radiance, distorted, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      const uint64_t seed =
          MixSeed(MixSeed(options.noise_seed, frame_index), static_cast<uint64_t>(task));
      view_effects[static_cast<std::size_t>(task)].Apply(distorted, with_effects, seed,
                                                         task == 0 ? &out->cam0 : &out->cam1);
    }
  });
  timings.post_s = SecondsSince(read);
}

// ------------------------------------------------------------ interface --

StereoRenderer::StereoRenderer(const World& world, const StereoCameraOptions& camera,
                               const RenderOptions& options)
    : impl_(std::make_unique<Impl>(world, camera, options)) {}

StereoRenderer::~StereoRenderer() = default;

void StereoRenderer::Render(const Eigen::Isometry3d& T_world_body,
                            const std::vector<Eigen::Isometry3d>& T_world_carriers,
                            uint64_t frame_index, RenderedStereoFrame* out) {
  impl_->Render(T_world_body, T_world_carriers, frame_index, out);
}

const std::string& StereoRenderer::gl_renderer() const { return impl_->context.renderer(); }
const StereoCameraOptions& StereoRenderer::camera() const { return impl_->camera; }
const RenderOptions& StereoRenderer::options() const { return impl_->options; }
void StereoRenderer::set_apply_effects(bool apply) { impl_->options.apply_effects = apply; }
void StereoRenderer::ReleaseThread() { impl_->context.ReleaseCurrent(); }
int StereoRenderer::render_width_px() const { return impl_->render.width_px; }
int StereoRenderer::render_height_px() const { return impl_->render.height_px; }
int StereoRenderer::last_patch_count() const { return impl_->patch_count; }
int64_t StereoRenderer::last_triangle_count() const { return impl_->triangle_count; }
const RenderTimings& StereoRenderer::last_timings() const { return impl_->timings; }

}  // namespace rover::sim
