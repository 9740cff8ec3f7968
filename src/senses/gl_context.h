// Headless OpenGL contexts for MuJoCo's renderer: OSMesa (software, the default) or EGL (a GPU
// when there is one, else Mesa's software rasteriser). Neither needs a display.
//
// The platform library is opened at run time, never linked: MuJoCo 2.2.2 takes its GL entry
// points once per process from the first visible eglGetProcAddress, OSMesaGetProcAddress or
// glXGetProcAddressARB, so a linked libEGL makes OSMesa rendering abort ("gladLoadGL error"), and
// a missing library becomes a clear error instead of a load failure. For the same reason a process
// uses one backend for its whole life; asking for the other one afterwards is a UserError.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace cradle::senses {

enum class GlBackend { kOsmesa, kEgl };

std::string_view gl_backend_name(GlBackend backend);  // "osmesa", "egl"
std::optional<GlBackend> gl_backend_from_name(std::string_view name);

// The backend named by the CRADLE_GL environment variable; nullopt when unset or empty. Throws
// UserError for any other value.
std::optional<GlBackend> gl_backend_from_env();

// The process's one GL lock. Mesa keeps per-process state under every context (OSMesa draws all
// contexts through one llvmpipe screen, a process singleton) and MuJoCo 2.2.2 reloads its
// process-wide GL function table in every mjr_makeContext, so two threads inside GL at once, even
// in different contexts, are the likely cause of the libOSMesa crashes seen in hand-regard
// training (two envs rendering on two pool threads while contexts are built and freed). All GL
// work, context creation and destruction included, happens under this lock; GlScope takes it.
std::mutex& gl_mutex();

// One GL context with a compatibility profile (MuJoCo's fixed-function renderer), owned by this
// object. It is current on at most one thread at a time; make_current() binds it to the caller.
// create() and the destructor take gl_mutex() themselves; make_current() and release() must be
// called under it (use GlScope).
class GlContext {
 public:
  // Backend from CRADLE_GL; unset: OSMesa, or EGL where libOSMesa is missing. max_width and
  // max_height bound what the context draws into. Throws UserError with a one-line reason when
  // no usable context can be had.
  static std::unique_ptr<GlContext> create(int max_width, int max_height);
  static std::unique_ptr<GlContext> create(GlBackend backend, int max_width, int max_height);

  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Binds the context to the calling thread (no-op when already bound here).
  virtual void make_current() = 0;
  // Unbinds it from the calling thread, so that another thread may bind it.
  virtual void release() = 0;
  virtual bool is_current() const = 0;
  virtual GlBackend backend() const = 0;
  // Backend, GL renderer and version, e.g. "osmesa: llvmpipe (LLVM 15.0.6, 256 bits), GL 4.5".
  const std::string& description() const { return description_; }

 protected:
  GlContext() = default;
  void set_description(std::string text) { description_ = std::move(text); }

 private:
  std::string description_;
};

// Holds gl_mutex() and keeps a context bound to the calling thread for one scope, unbinding it on
// exit so that any thread may use it next.
class GlScope {
 public:
  explicit GlScope(GlContext& gl) : lock_(gl_mutex()), gl_(gl) { gl_.make_current(); }
  ~GlScope() { gl_.release(); }
  GlScope(const GlScope&) = delete;
  GlScope& operator=(const GlScope&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
  GlContext& gl_;
};

}  // namespace cradle::senses
