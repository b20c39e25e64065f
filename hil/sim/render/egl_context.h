#ifndef ROVER_HIL_SIM_RENDER_EGL_CONTEXT_H_
#define ROVER_HIL_SIM_RENDER_EGL_CONTEXT_H_

// A headless OpenGL 4.5 core context through EGL, on Mesa's software
// rasteriser (llvmpipe): no display server, no GPU. EGL types are kept out of
// this header because Mesa's eglplatform.h can pull in X11 macros.

#include <string>

namespace rover::sim {

class EglContext {
 public:
  /// Opens the display and creates a context with no surface (rendering goes
  /// to framebuffer objects). Prefers the EGL device that Mesa marks as
  /// software (EGL_MESA_device_software), so llvmpipe is used even on a
  /// machine with a GPU; falls back to the surfaceless platform. Makes the
  /// context current on the calling thread. Throws std::runtime_error.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Binds the context to the calling thread (a no-op if already bound).
  void MakeCurrent();
  /// Unbinds it from the calling thread if bound there, so that another
  /// thread may bind it (EGL allows a context to be current in one thread).
  void ReleaseCurrent();

  /// GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& renderer() const { return renderer_; }
  /// GL_VERSION.
  const std::string& version() const { return version_; }

 private:
  void Release();  // caller holds the display lock

  void* display_ = nullptr;
  void* context_ = nullptr;
  std::string renderer_;
  std::string version_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_RENDER_EGL_CONTEXT_H_
