#include "hil/sim/render/egl_context.h"

// Keep X11 out of Mesa's EGL headers.
#define EGL_NO_X11
#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace rover::sim {
namespace {

// EGL displays are per process and eglTerminate is not reference counted:
// terminate only when the last context of this process goes away.
std::mutex display_mutex;
int display_users = 0;

[[noreturn]] void Fail(const std::string& what) {
  throw std::runtime_error("EglContext: " + what + " (EGL error 0x" + [] {
    char buffer[16];
    std::snprintf(buffer, sizeof(buffer), "%x", static_cast<unsigned>(eglGetError()));
    return std::string(buffer);
  }() + ")");
}

bool HasExtension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::size_t length = std::strlen(name);
  for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + 1, name)) {
    if ((p == list || p[-1] == ' ') && (p[length] == ' ' || p[length] == '\0')) return true;
  }
  return false;
}

template <typename F>
F LoadEgl(const char* name) {
  // Casting from the generic function pointer is how EGL hands out extensions.
  return reinterpret_cast<F>(eglGetProcAddress(name));
}

EGLDisplay OpenSoftwareDisplay() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (HasExtension(client, "EGL_EXT_platform_device")) {
    const auto query_devices = LoadEgl<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
    const auto query_string = LoadEgl<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
    EGLint count = 0;
    if (query_devices != nullptr && query_string != nullptr &&
        query_devices(0, nullptr, &count) == EGL_TRUE && count > 0) {
      std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
      query_devices(count, devices.data(), &count);
      for (EGLDeviceEXT device : devices) {
        if (HasExtension(query_string(device, EGL_EXTENSIONS), "EGL_MESA_device_software")) {
          EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
          if (display != EGL_NO_DISPLAY) return display;
        }
      }
    }
  }
  if (HasExtension(client, "EGL_MESA_platform_surfaceless")) {
    return eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  }
  return EGL_NO_DISPLAY;
}

}  // namespace

EglContext::EglContext() {
  std::lock_guard<std::mutex> lock(display_mutex);
  EGLDisplay display = OpenSoftwareDisplay();
  if (display == EGL_NO_DISPLAY) Fail("no software EGL device and no surfaceless platform");
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) Fail("eglInitialize failed");
  ++display_users;
  display_ = display;
  try {
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) Fail("eglBindAPI(OpenGL) failed");
    // No config and no surface: all rendering goes to framebuffer objects.
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         4,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
    EGLContext context =
        eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attributes);
    if (context == EGL_NO_CONTEXT) Fail("no OpenGL 4.5 core context");
    context_ = context;
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
      Fail("eglMakeCurrent failed");
    }
    renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    version_ = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  } catch (...) {
    Release();
    throw;
  }
}

EglContext::~EglContext() {
  std::lock_guard<std::mutex> lock(display_mutex);
  Release();
}

void EglContext::Release() {
  EGLDisplay display = static_cast<EGLDisplay>(display_);
  if (context_ != nullptr) {
    if (eglGetCurrentContext() == static_cast<EGLContext>(context_)) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(display, static_cast<EGLContext>(context_));
    context_ = nullptr;
  }
  if (display_ != nullptr && --display_users == 0) eglTerminate(display);
  display_ = nullptr;
}

void EglContext::MakeCurrent() {
  if (eglGetCurrentContext() == static_cast<EGLContext>(context_)) return;
  if (eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE,
                     static_cast<EGLContext>(context_)) != EGL_TRUE) {
    Fail("eglMakeCurrent failed");
  }
}

void EglContext::ReleaseCurrent() {
  if (eglGetCurrentContext() != static_cast<EGLContext>(context_)) return;
  eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

}  // namespace rover::sim
