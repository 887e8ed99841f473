// A headless OpenGL context for MuJoCo's offscreen renderer: EGL on Mesa's surfaceless
// platform (eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)), desktop OpenGL
// (EGL_OPENGL_API), no surface and no window system. MuJoCo renders into its own
// offscreen framebuffer (mjFB_OFFSCREEN), so the context needs no drawable.
//
// Needs libEGL with Mesa's EGL (libegl-mesa0) and a Mesa driver (libgl1-mesa-dri; with no
// GPU, llvmpipe renders on the CPU). scripts/install-deps installs them.
#pragma once

#include <memory>
#include <string>

#include "liftoff/core/status.h"

namespace liftoff::synth {

/// One EGL display + OpenGL context, current on the thread that created it. A context is
/// current on one thread at a time: use one EglContext per rendering thread.
class EglContext {
 public:
  /// Initialises EGL on the surfaceless platform and makes a new context current on this
  /// thread. kUnsupported (with EGL's error code and the step that failed) when the
  /// platform, a config or a context is unavailable: no Mesa EGL, no driver.
  static Result<std::unique_ptr<EglContext>> Create();

  /// Makes the context current on the calling thread again. kUnsupported on failure.
  Status MakeCurrent() const;

  /// "EGL 1.5, Mesa Project, OpenGL 4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256
  /// bits)".
  const std::string& description() const { return description_; }

  /// Releases the context and the display.
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

 private:
  EglContext() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string description_;
};

}  // namespace liftoff::synth
