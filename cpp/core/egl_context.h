// The headless OpenGL 4.5 core context that owns every GL object of a Renderer.
//
// Device choice: "gpu" takes a hardware EGL device (EGL_EXT_platform_device, e.g. the
// NVIDIA driver's), "cpu" takes Mesa's software device (llvmpipe), and "auto" tries the
// hardware devices first and falls back to the software one. Without any EGL device
// enumeration, Mesa's surfaceless platform is the last resort. "gpu:N" takes the N-th hardware
// EGL device (in eglQueryDevicesEXT order, software devices not counted), so that processes on
// a node with several GPUs can each be pinned to their own.
#pragma once

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace ssr {

enum class DeviceKind { Auto, Gpu, Cpu };

DeviceKind parse_device_kind(const std::string& name);
// The N of "gpu:N", -1 for "auto", "gpu" and "cpu" (which parse_device_kind accepts).
int parse_device_index(const std::string& name);

// One EGL device as enumerated (EGL_EXT_device_enumeration), probed without keeping a context.
struct DeviceEntry {
    int index = -1;             // position among the hardware devices ("gpu:N"); -1 for a software one
    bool software = false;      // EGL_MESA_device_software (llvmpipe)
    std::string extensions;     // the device's EGL extension string
    std::string drm_device;     // EGL_EXT_device_drm's device file, if offered
    int cuda_device = -1;       // EGL_NV_device_cuda's CUDA device number, if offered
    std::string gl_vendor, gl_renderer, gl_version;  // from a context made and destroyed (probe)
    std::string error;          // why no OpenGL 4.5 context could be made on it (probe)
};

// Every EGL device of this process's libEGL, hardware ones numbered in enumeration order;
// with probe, each one's OpenGL vendor and renderer from a short-lived 4.5 core context.
std::vector<DeviceEntry> list_devices(bool probe);

struct DeviceInfo {
    std::string requested;      // "auto" | "gpu" | "gpu:N" | "cpu"
    std::string chosen;         // "gpu" | "cpu"
    std::string device_index;   // N of the hardware EGL device taken ("gpu:N"), "" for a software one
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
    // index >= 0 (with kind Gpu): that hardware EGL device ("gpu:N") or DeviceError naming those found.
    explicit EglContext(DeviceKind kind, int index = -1);
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

    // Held by every CurrentContext: one thread at a time in this context, even when the caller
    // released Python's GIL for a long call (a render), so that other Python threads (a viewer's
    // server, a notebook) run meanwhile without two threads ever issuing GL into one context.
    std::recursive_mutex& mutex() { return mutex_; }

private:
    // want: Gpu takes a hardware renderer only, Cpu a software one only, Auto either.
    bool try_display(EGLDisplay display, const std::string& platform, DeviceKind want,
                     std::string* why_not);
    void enable_debug_output();

    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    DeviceInfo info_;
    std::vector<std::string> debug_errors_;
    std::recursive_mutex mutex_;

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
    std::unique_lock<std::recursive_mutex> lock_;  // first: taken before, released after the rest
    EglContext& ctx_;
    EGLDisplay prev_display_;
    EGLSurface prev_draw_, prev_read_;
    EGLContext prev_context_;
    bool switched_ = false;
};

// Raises GLError if GL reported an error since the last check; `where` names the pass.
void check_gl(EglContext& ctx, const char* where);

}  // namespace ssr
