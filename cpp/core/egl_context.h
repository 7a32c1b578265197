// The headless OpenGL 4.5 core context that owns every GL object of a Renderer.
//
// Device choice: "gpu" takes a hardware EGL device (EGL_EXT_platform_device, e.g. the
// NVIDIA driver's), "cpu" takes Mesa's software device (llvmpipe), and "auto" tries the
// hardware devices first and falls back to the software one. Without any EGL device
// enumeration, Mesa's surfaceless platform is the last resort.
#pragma once

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <map>
#include <string>
#include <vector>

namespace ssr {

enum class DeviceKind { Auto, Gpu, Cpu };

DeviceKind parse_device_kind(const std::string& name);

struct DeviceInfo {
    std::string requested;      // "auto" | "gpu" | "cpu"
    std::string chosen;         // "gpu" | "cpu"
    std::string egl_platform;   // "device" | "surfaceless"
    std::string egl_vendor;
    std::string egl_version;
    std::string egl_device_extensions;
    std::string gl_vendor;
    std::string gl_renderer;
    std::string gl_version;
    std::string glsl_version;
    std::vector<std::string> rejected;  // devices tried and why they were not taken

    std::map<std::string, std::string> as_dict() const;
};

class EglContext {
public:
    explicit EglContext(DeviceKind kind);
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    // Makes the context current on the calling thread (cheap when it already is). Prefer
    // CurrentContext, which also gives the thread back afterwards.
    void make_current();
    EGLDisplay display() const { return display_; }
    EGLContext handle() const { return context_; }
    const DeviceInfo& info() const { return info_; }

    // Errors reported by GL debug output since the last call, then cleared.
    std::vector<std::string> take_debug_errors();

private:
    // want: Gpu takes a hardware renderer only, Cpu a software one only, Auto either.
    bool try_display(EGLDisplay display, const std::string& platform, DeviceKind want,
                     std::string* why_not);
    void enable_debug_output();

    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    DeviceInfo info_;
    std::vector<std::string> debug_errors_;

    friend void debug_callback_trampoline(EglContext*, const std::string&);
};

// Makes a context current for one native call and restores whatever was current before
// (usually nothing). No context stays bound to a thread between calls, so a Renderer can be
// used, and destroyed, from any thread: a context left current on a thread that has since
// ended could never be made current again, and its GL objects would be deleted in whichever
// context happened to be current.
class CurrentContext {
public:
    explicit CurrentContext(EglContext& ctx);
    ~CurrentContext();
    CurrentContext(const CurrentContext&) = delete;
    CurrentContext& operator=(const CurrentContext&) = delete;

private:
    EglContext& ctx_;
    EGLDisplay prev_display_;
    EGLSurface prev_draw_, prev_read_;
    EGLContext prev_context_;
    bool switched_ = false;
};

// Raises GLError if GL reported an error since the last check; `where` names the pass.
void check_gl(EglContext& ctx, const char* where);

}  // namespace ssr
