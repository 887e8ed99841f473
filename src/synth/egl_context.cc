#include "liftoff/synth/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <string>

namespace liftoff::synth {
namespace {

// GL_VENDOR .. GL_VERSION, read through EGL so this file needs no GL headers
using GetStringFunction = const unsigned char* (*)(unsigned int);
constexpr unsigned int kGlRenderer = 0x1F01;
constexpr unsigned int kGlVersion = 0x1F02;

Status EglFailure(const char* step) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(eglGetError()));
  return UnsupportedError(std::string("headless OpenGL (EGL, Mesa surfaceless platform): ") + step +
                          " failed (EGL error " + code +
                          "); install libegl-mesa0 and libgl1-mesa-dri (scripts/install-deps)");
}

std::string GlString(unsigned int name) {
  const auto get_string = reinterpret_cast<GetStringFunction>(eglGetProcAddress("glGetString"));
  if (get_string == nullptr) return "?";
  const unsigned char* text = get_string(name);
  return text == nullptr ? "?" : reinterpret_cast<const char*>(text);
}

}  // namespace

Result<std::unique_ptr<EglContext>> EglContext::Create() {
  // the surfaceless platform: no window system, no device node required
  const auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) return EglFailure("eglGetPlatformDisplayEXT lookup");
  EGLDisplay display =
      get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) return EglFailure("eglGetPlatformDisplayEXT");
  EGLint major = 0, minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) return EglFailure("eglInitialize");

  std::unique_ptr<EglContext> result(new EglContext());
  result->display_ = display;

  // any desktop-GL config: MuJoCo renders into its own framebuffer object
  // (the surfaceless platform's configs are pbuffer ones: asking for a window fails)
  const EGLint config_attributes[] = {EGL_RED_SIZE,        8,
                                      EGL_GREEN_SIZE,      8,
                                      EGL_BLUE_SIZE,       8,
                                      EGL_DEPTH_SIZE,      24,
                                      EGL_SURFACE_TYPE,    EGL_PBUFFER_BIT,
                                      EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                      EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (eglChooseConfig(display, config_attributes, &config, 1, &count) != EGL_TRUE || count < 1) {
    return EglFailure("eglChooseConfig (8-bit RGB, 24-bit depth, OpenGL)");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) return EglFailure("eglBindAPI(EGL_OPENGL_API)");
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, nullptr);
  if (context == EGL_NO_CONTEXT) return EglFailure("eglCreateContext");
  result->context_ = context;
  LIFTOFF_RETURN_IF_ERROR(result->MakeCurrent());

  result->description_ = "EGL " + std::to_string(major) + "." + std::to_string(minor) + ", " +
                         eglQueryString(display, EGL_VENDOR) + ", OpenGL " +
                         GlString(kGlVersion) + ", " + GlString(kGlRenderer);
  return result;
}

Status EglContext::MakeCurrent() const {
  if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
    return EglFailure("eglMakeCurrent (no surface)");
  }
  return Status::Ok();
}

EglContext::~EglContext() {
  if (display_ == nullptr) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_ != nullptr) eglDestroyContext(display_, context_);
  // no eglTerminate: every EglContext of the process shares the one surfaceless display

}

}  // namespace liftoff::synth
