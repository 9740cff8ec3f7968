#include "senses/gl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include "core/error.h"

namespace cradle::senses {
namespace {

// A platform library, opened with global symbols so that MuJoCo's loader finds its
// GetProcAddress, and never unloaded: MuJoCo keeps the entry points it took from it.
class Library {
 public:
  explicit Library(std::initializer_list<const char*> names) {
    for (const char* name : names) {
      handle_ = dlopen(name, RTLD_NOW | RTLD_GLOBAL | RTLD_NODELETE);
      if (handle_) return;
    }
  }
  ~Library() {
    if (handle_) dlclose(handle_);
  }
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;

  bool loaded() const { return handle_ != nullptr; }
  // Typed symbol lookup; nullptr when absent.
  template <typename Fn>
  Fn get(const char* name) const {
    return reinterpret_cast<Fn>(dlsym(handle_, name));
  }

 private:
  void* handle_ = nullptr;
};

// MuJoCo's loader takes every GL entry point, once per process, from the first visible of
// eglGetProcAddress, OSMesaGetProcAddress and glXGetProcAddressARB. A backend is refused when the
// other one is already visible, i.e. was used earlier in this process.
void require_platform(GlBackend wanted) {
  const char* other = wanted == GlBackend::kOsmesa ? "eglGetProcAddress" : "OSMesaGetProcAddress";
  if (dlsym(RTLD_DEFAULT, other)) {
    throw UserError("CRADLE_GL=" + std::string(gl_backend_name(wanted)) +
                    ": this process already renders through the other GL backend (one backend "
                    "per process)");
  }
}

// Checks that the current context can run MuJoCo's renderer (GL >= 1.5 with framebuffer
// objects), before mjr_makeContext would abort the process instead. Returns "renderer, GL version".
std::string require_usable_gl(GlBackend backend, void* (*proc)(const char*)) {
  using GetString = const GLubyte* (*)(GLenum);
  const auto get_string = reinterpret_cast<GetString>(proc("glGetString"));
  const char* version =
      get_string ? reinterpret_cast<const char*>(get_string(GL_VERSION)) : nullptr;
  const std::string name(gl_backend_name(backend));
  if (!version) throw UserError("CRADLE_GL=" + name + ": the GL context answers no version");
  int major = 0, minor = 0;
  std::sscanf(version, "%d.%d", &major, &minor);
  const char* ext = reinterpret_cast<const char*>(get_string(GL_EXTENSIONS));
  const bool fbo = major >= 3 || (ext && std::strstr(ext, "GL_ARB_framebuffer_object"));
  if (major * 10 + minor < 15 || !fbo) {
    throw UserError("CRADLE_GL=" + name + ": GL " + version +
                    " lacks what MuJoCo's renderer needs (1.5 with framebuffer objects)");
  }
  const char* renderer = reinterpret_cast<const char*>(get_string(GL_RENDERER));
  return name + ": " + (renderer ? renderer : "unknown renderer") + ", GL " + version;
}

// OSMesa: Mesa's software rasteriser drawing into memory we own.
class OsmesaContext final : public GlContext {
 public:
  OsmesaContext(int width, int height)
      : lib_({"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}),
        width_(width),
        height_(height),
        buffer_(static_cast<size_t>(width) * height * 4) {
    if (!lib_.loaded()) {
      throw UserError("CRADLE_GL=osmesa: libOSMesa is not installed (libosmesa6)");
    }
    create_ = lib_.get<decltype(&OSMesaCreateContextAttribs)>("OSMesaCreateContextAttribs");
    make_current_ = lib_.get<decltype(&OSMesaMakeCurrent)>("OSMesaMakeCurrent");
    get_current_ = lib_.get<decltype(&OSMesaGetCurrentContext)>("OSMesaGetCurrentContext");
    destroy_ = lib_.get<decltype(&OSMesaDestroyContext)>("OSMesaDestroyContext");
    proc_ = lib_.get<void* (*)(const char*)>("OSMesaGetProcAddress");
    if (!create_ || !make_current_ || !get_current_ || !destroy_ || !proc_) {
      throw UserError("CRADLE_GL=osmesa: libOSMesa lacks OSMesaCreateContextAttribs (too old)");
    }
    // Compatibility profile (fixed-function GL) with depth and stencil; pairs, zero-terminated.
    // clang-format off
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_PROFILE, OSMESA_COMPAT_PROFILE,
                           OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8, 0};
    // clang-format on
    ctx_ = create_(attribs, nullptr);
    if (!ctx_) throw UserError("CRADLE_GL=osmesa: OSMesaCreateContextAttribs failed");
    try {
      make_current();
      set_description(require_usable_gl(GlBackend::kOsmesa, proc_));
    } catch (const UserError&) {
      release();
      destroy_(ctx_);
      throw;
    }
  }

  ~OsmesaContext() override {
    const std::lock_guard lock(gl_mutex());
    if (is_current()) release();
    destroy_(ctx_);
  }

  void make_current() override {
    if (get_current_() == ctx_) return;
    if (!make_current_(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
      throw UserError("CRADLE_GL=osmesa: OSMesaMakeCurrent failed");
    }
  }
  void release() override { make_current_(nullptr, nullptr, 0, 0, 0); }
  bool is_current() const override { return get_current_() == ctx_; }
  GlBackend backend() const override { return GlBackend::kOsmesa; }

 private:
  Library lib_;
  int width_, height_;
  std::vector<unsigned char> buffer_;  // default framebuffer (MuJoCo draws into its own FBO)
  decltype(&OSMesaCreateContextAttribs) create_ = nullptr;
  decltype(&OSMesaMakeCurrent) make_current_ = nullptr;
  decltype(&OSMesaGetCurrentContext) get_current_ = nullptr;
  decltype(&OSMesaDestroyContext) destroy_ = nullptr;
  void* (*proc_)(const char*) = nullptr;
  OSMesaContext ctx_ = nullptr;
};

// EGL without a surface: the first device that initialises (a GPU first), else Mesa's
// surfaceless platform, else the default display.
class EglContext final : public GlContext {
 public:
  EglContext() : lib_({"libEGL.so.1", "libEGL.so"}) {
    if (!lib_.loaded()) throw UserError("CRADLE_GL=egl: libEGL is not installed (libegl1)");
    proc_ = lib_.get<decltype(&eglGetProcAddress)>("eglGetProcAddress");
    if (!proc_) throw UserError("CRADLE_GL=egl: libEGL lacks eglGetProcAddress");
    load(get_error_, "eglGetError");
    load(initialize_, "eglInitialize");
    load(query_string_, "eglQueryString");
    load(bind_api_, "eglBindAPI");
    load(choose_config_, "eglChooseConfig");
    load(create_context_, "eglCreateContext");
    load(destroy_context_, "eglDestroyContext");
    load(make_current_, "eglMakeCurrent");
    load(get_current_, "eglGetCurrentContext");
    display_ = open_display();
    if (display_ == EGL_NO_DISPLAY) {
      throw UserError(
          "CRADLE_GL=egl: no EGL display initialises (no GPU, and no Mesa software driver: "
          "install libegl-mesa0 and libgl1-mesa-dri)");
    }
    const char* ext = query_string_(display_, EGL_EXTENSIONS);
    if (!ext || !std::strstr(ext, "EGL_KHR_surfaceless_context")) {
      throw UserError("CRADLE_GL=egl: the EGL display lacks EGL_KHR_surfaceless_context");
    }
    if (!bind_api_(EGL_OPENGL_API)) throw UserError("CRADLE_GL=egl: no desktop OpenGL API");
    // Desktop GL, 8-bit colour, 24-bit depth; pairs, EGL_NONE-terminated.
    // clang-format off
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                     EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
                                     EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                                     EGL_DEPTH_SIZE, 24, EGL_NONE};
    // clang-format on
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!choose_config_(display_, config_attribs, &config, 1, &count) || count < 1) {
      throw UserError("CRADLE_GL=egl: no EGL config for desktop OpenGL");
    }
    ctx_ = create_context_(display_, config, EGL_NO_CONTEXT, nullptr);
    if (ctx_ == EGL_NO_CONTEXT) {
      throw UserError("CRADLE_GL=egl: eglCreateContext failed (error " + hex(get_error_()) + ")");
    }
    try {
      make_current();
      set_description(
          require_usable_gl(GlBackend::kEgl, reinterpret_cast<void* (*)(const char*)>(proc_)));
    } catch (const UserError&) {
      release();
      destroy_context_(display_, ctx_);
      throw;
    }
  }

  // The display stays initialised: EGL displays are per-process and shared with other contexts,
  // and eglTerminate would invalidate theirs.
  ~EglContext() override {
    const std::lock_guard lock(gl_mutex());
    if (is_current()) release();
    destroy_context_(display_, ctx_);
  }

  void make_current() override {
    if (get_current_() == ctx_) return;
    bind_api_(EGL_OPENGL_API);  // per-thread state
    if (!make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_)) {
      throw UserError("CRADLE_GL=egl: eglMakeCurrent failed (error " + hex(get_error_()) +
                      "; is the context current on another thread?)");
    }
  }
  void release() override {
    make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  bool is_current() const override { return get_current_() == ctx_; }
  GlBackend backend() const override { return GlBackend::kEgl; }

 private:
  // Core entry points come from the library, extensions from eglGetProcAddress.
  template <typename Fn>
  void load(Fn& fn, const char* name) {
    fn = lib_.get<Fn>(name);
    if (!fn) fn = reinterpret_cast<Fn>(proc_(name));
    if (!fn) throw UserError(std::string("CRADLE_GL=egl: libEGL lacks ") + name);
  }

  static std::string hex(EGLint code) {
    char text[16];
    std::snprintf(text, sizeof text, "0x%04x", static_cast<unsigned>(code));
    return text;
  }

  bool try_initialize(EGLDisplay display) {
    EGLint major = 0, minor = 0;
    return display != EGL_NO_DISPLAY && initialize_(display, &major, &minor);
  }

  EGLDisplay open_display() {
    const char* client = query_string_(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    const std::string_view exts = client ? client : "";
    PFNEGLGETPLATFORMDISPLAYEXTPROC platform_display = nullptr;
    if (exts.find("EGL_EXT_platform_base") != std::string_view::npos) {
      load(platform_display, "eglGetPlatformDisplayEXT");
    }
    if (platform_display && exts.find("EGL_EXT_platform_device") != std::string_view::npos) {
      PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;
      load(query_devices, "eglQueryDevicesEXT");
      EGLDeviceEXT devices[16];
      EGLint n = 0;
      if (query_devices(16, devices, &n)) {
        for (EGLint i = 0; i < n; ++i) {
          EGLDisplay d = platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
          if (try_initialize(d)) return d;
        }
      }
    }
    if (platform_display && exts.find("EGL_MESA_platform_surfaceless") != std::string_view::npos) {
      EGLDisplay d = platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (try_initialize(d)) return d;
    }
    PFNEGLGETDISPLAYPROC get_display = nullptr;
    load(get_display, "eglGetDisplay");
    EGLDisplay d = get_display(EGL_DEFAULT_DISPLAY);
    return try_initialize(d) ? d : EGL_NO_DISPLAY;
  }

  Library lib_;
  decltype(&eglGetProcAddress) proc_ = nullptr;
  PFNEGLGETERRORPROC get_error_ = nullptr;
  PFNEGLINITIALIZEPROC initialize_ = nullptr;
  PFNEGLQUERYSTRINGPROC query_string_ = nullptr;
  PFNEGLBINDAPIPROC bind_api_ = nullptr;
  PFNEGLCHOOSECONFIGPROC choose_config_ = nullptr;
  PFNEGLCREATECONTEXTPROC create_context_ = nullptr;
  PFNEGLDESTROYCONTEXTPROC destroy_context_ = nullptr;
  PFNEGLMAKECURRENTPROC make_current_ = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC get_current_ = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext ctx_ = EGL_NO_CONTEXT;
};

}  // namespace

std::mutex& gl_mutex() {
  // The one process-wide object here: it stands for the process-wide state inside Mesa.
  static std::mutex mutex;
  return mutex;
}

std::string_view gl_backend_name(GlBackend backend) {
  return backend == GlBackend::kEgl ? "egl" : "osmesa";
}

std::optional<GlBackend> gl_backend_from_name(std::string_view name) {
  if (name == "osmesa") return GlBackend::kOsmesa;
  if (name == "egl") return GlBackend::kEgl;
  return std::nullopt;
}

std::optional<GlBackend> gl_backend_from_env() {
  const char* value = std::getenv("CRADLE_GL");
  if (!value || !*value) return std::nullopt;
  if (auto backend = gl_backend_from_name(value)) return *backend;
  throw UserError(std::string("CRADLE_GL=") + value +
                  ": unknown GL backend (expected egl or osmesa)");
}

std::unique_ptr<GlContext> GlContext::create(int max_width, int max_height) {
  if (const std::optional<GlBackend> chosen = gl_backend_from_env()) {
    return create(*chosen, max_width, max_height);
  }
  // Default: OSMesa; EGL when libOSMesa cannot even be loaded (else the process is taken).
  try {
    return create(GlBackend::kOsmesa, max_width, max_height);
  } catch (const UserError& osmesa) {
    if (dlsym(RTLD_DEFAULT, "OSMesaGetProcAddress")) throw;
    try {
      return create(GlBackend::kEgl, max_width, max_height);
    } catch (const UserError& egl) {
      throw UserError(std::string("no headless GL backend works: ") + osmesa.what() + "; " +
                      egl.what());
    }
  }
}

namespace {

// Set in a child forked from a process that had made a GL context: Mesa's per-process state
// (llvmpipe's threads among it) does not survive a fork, and a context made there hangs. Like
// gl_mutex(), process state by nature.
std::atomic<bool> forked_after_gl{false};

}  // namespace

std::unique_ptr<GlContext> GlContext::create(GlBackend backend, int max_width, int max_height) {
  static const bool watching_forks =
      pthread_atfork(nullptr, nullptr, [] { forked_after_gl.store(true); }) == 0;
  (void)watching_forks;
  if (forked_after_gl.load()) {
    throw UserError(
        "this process was forked from one that had already rendered, and GL does not survive "
        "a fork: make process vectors before anything renders");
  }
  const std::lock_guard lock(gl_mutex());
  require_platform(backend);
  if (backend == GlBackend::kEgl) return std::make_unique<EglContext>();
  return std::make_unique<OsmesaContext>(max_width, max_height);
}

}  // namespace cradle::senses
