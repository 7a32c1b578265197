#include "core/egl_context.h"

#include "core/gl.h"

#include <algorithm>
#include <cstring>
#include <sstream>

#include "core/errors.h"

namespace ssr {

int parse_device_index(const std::string& name) {
    if (name.rfind("gpu:", 0) != 0) return -1;
    const std::string digits = name.substr(4);
    if (digits.empty() || digits.size() > 6 ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
        throw std::invalid_argument("device: expected 'auto', 'gpu', 'gpu:N' (N = 0, 1, ...) or 'cpu', got '" +
                                    name + "'");
    return std::stoi(digits);
}

DeviceKind parse_device_kind(const std::string& name) {
    if (name == "auto") return DeviceKind::Auto;
    if (name == "gpu") return DeviceKind::Gpu;
    if (name == "cpu") return DeviceKind::Cpu;
    if (parse_device_index(name) >= 0) return DeviceKind::Gpu;
    throw std::invalid_argument("device: expected 'auto', 'gpu', 'gpu:N' (N = 0, 1, ...) or 'cpu', got '" + name +
                                "'");
}

std::map<std::string, std::string> DeviceInfo::as_dict() const {
    std::string rejected_all;
    for (const auto& r : rejected) rejected_all += (rejected_all.empty() ? "" : "; ") + r;
    return {{"requested", requested},        {"device", chosen},
            {"device_index", device_index},
            {"egl_platform", egl_platform},  {"egl_vendor", egl_vendor},
            {"egl_version", egl_version},    {"egl_device_extensions", egl_device_extensions},
            {"vendor", gl_vendor},           {"renderer", gl_renderer},
            {"gl_version", gl_version},      {"glsl_version", glsl_version},
            {"rejected", rejected_all}};
}

namespace {

template <typename F>
F egl_proc(const char* name) {
    return reinterpret_cast<F>(eglGetProcAddress(name));
}

bool has_extension(const char* list, const char* ext) {
    if (!list) return false;
    const size_t n = std::strlen(ext);
    for (const char* p = std::strstr(list, ext); p; p = std::strstr(p + 1, ext)) {
        const bool starts = (p == list) || p[-1] == ' ';
        const bool ends = p[n] == '\0' || p[n] == ' ';
        if (starts && ends) return true;
    }
    return false;
}

bool is_software_renderer(const std::string& renderer) {
    for (const char* s : {"llvmpipe", "softpipe", "lavapipe", "SwiftShader"})
        if (renderer.find(s) != std::string::npos) return true;
    return false;
}

std::string gl_string(GLenum e) {
    const GLubyte* s = glGetString(e);
    return s ? reinterpret_cast<const char*>(s) : "";
}

std::string egl_error_name(EGLint e) {
    std::ostringstream os;
    os << "EGL error 0x" << std::hex << e;
    return os.str();
}

struct Enumeration {
    bool can_enumerate = false;
    const char* client_ext = nullptr;
    std::vector<EGLDeviceEXT> hardware, software;  // hardware in eglQueryDevicesEXT order
};

Enumeration enumerate_devices() {
    Enumeration e;
    e.client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display = egl_proc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
    auto query_devices = egl_proc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
    auto query_device_string = egl_proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
    // NVIDIA's libEGL offers enumeration through EGL_EXT_device_base (device_enumeration and
    // device_query in one older extension) and does not list EGL_EXT_device_enumeration itself.
    e.can_enumerate = (has_extension(e.client_ext, "EGL_EXT_device_enumeration") ||
                       has_extension(e.client_ext, "EGL_EXT_device_base")) &&
                      has_extension(e.client_ext, "EGL_EXT_platform_device") && query_devices &&
                      query_device_string && get_platform_display;
    if (!e.can_enumerate) return e;
    EGLint count = 0;
    query_devices(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(size_t(std::max(count, 0)));
    if (count > 0) query_devices(count, devices.data(), &count);
    devices.resize(size_t(std::max(count, 0)));
    for (EGLDeviceEXT d : devices) {
        const char* ext = query_device_string(d, EGL_EXTENSIONS);
        (has_extension(ext, "EGL_MESA_device_software") ? e.software : e.hardware).push_back(d);
    }
    return e;
}

std::string device_extensions(EGLDeviceEXT d) {
    auto query_device_string = egl_proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
    const char* ext = query_device_string ? query_device_string(d, EGL_EXTENSIONS) : nullptr;
    return ext ? ext : "";
}

}  // namespace

std::vector<DeviceEntry> list_devices(bool probe) {
    Enumeration e = enumerate_devices();
    auto query_device_string = egl_proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
    auto query_device_attrib = egl_proc<PFNEGLQUERYDEVICEATTRIBEXTPROC>("eglQueryDeviceAttribEXT");
    auto get_platform_display = egl_proc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
    std::vector<DeviceEntry> out;
    auto describe = [&](EGLDeviceEXT d, int index) {
        DeviceEntry entry;
        entry.index = index;
        entry.software = index < 0;
        entry.extensions = device_extensions(d);
        if (has_extension(entry.extensions.c_str(), "EGL_EXT_device_drm") && query_device_string) {
            const char* file = query_device_string(d, EGL_DRM_DEVICE_FILE_EXT);
            entry.drm_device = file ? file : "";
        }
#ifdef EGL_CUDA_DEVICE_NV
        EGLAttrib cuda = -1;
        if (has_extension(entry.extensions.c_str(), "EGL_NV_device_cuda") && query_device_attrib &&
            query_device_attrib(d, EGL_CUDA_DEVICE_NV, &cuda))
            entry.cuda_device = int(cuda);
#else
        (void)query_device_attrib;
#endif
        if (probe) {
            // A context made and destroyed at once: what a Renderer on this device would report.
            EGLDisplay dpy = get_platform_display(EGL_PLATFORM_DEVICE_EXT, d, nullptr);
            EGLint major = 0, minor = 0;
            const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
            EGLContext ctx = EGL_NO_CONTEXT;
            if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor) || !eglBindAPI(EGL_OPENGL_API) ||
                (ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs)) == EGL_NO_CONTEXT) {
                entry.error = "no OpenGL 4.5 core context (" + egl_error_name(eglGetError()) + ")";
            } else {
                EGLDisplay prev_display = eglGetCurrentDisplay();
                EGLContext prev_context = eglGetCurrentContext();
                EGLSurface prev_draw = eglGetCurrentSurface(EGL_DRAW), prev_read = eglGetCurrentSurface(EGL_READ);
                if (eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
                    entry.gl_vendor = gl_string(GL_VENDOR);
                    entry.gl_renderer = gl_string(GL_RENDERER);
                    entry.gl_version = gl_string(GL_VERSION);
                    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
                } else {
                    entry.error = "eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")";
                }
                eglDestroyContext(dpy, ctx);
                if (prev_context != EGL_NO_CONTEXT) eglMakeCurrent(prev_display, prev_draw, prev_read, prev_context);
            }
        }
        out.push_back(entry);
    };
    for (size_t i = 0; i < e.hardware.size(); ++i) describe(e.hardware[i], int(i));
    for (EGLDeviceEXT d : e.software) describe(d, -1);
    return out;
}

namespace {
// The devices found, each named by its renderer where a context could be made on it (else by
// its EGL device extensions), for an error message.
std::string devices_found(const Enumeration& e) {
    if (!e.can_enumerate) return "none: this libEGL offers no device enumeration";
    std::ostringstream os;
    bool first = true;
    for (const DeviceEntry& d : list_devices(true)) {
        os << (first ? "" : ", ") << (d.software ? std::string("software") : "gpu:" + std::to_string(d.index)) << " "
           << (d.gl_renderer.empty() ? "(" + d.extensions + ")" : d.gl_renderer);
        first = false;
    }
    return first ? "none" : os.str();
}
}  // namespace

void debug_callback_trampoline(EglContext* ctx, const std::string& msg) {
    ctx->debug_errors_.push_back(msg);
}

namespace {
void GLAPIENTRY on_gl_debug(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                            const GLchar* message, const void* user) {
    // Only errors raise; performance and portability notes are not failures.
    if (type != GL_DEBUG_TYPE_ERROR) return;
    auto* ctx = const_cast<EglContext*>(static_cast<const EglContext*>(user));
    debug_callback_trampoline(ctx, std::string(message, length > 0 ? size_t(length) : std::strlen(message)));
}
}  // namespace

EglContext::EglContext(DeviceKind kind, int index) {
    static const char* kind_names[] = {"auto", "gpu", "cpu"};
    info_.requested = index >= 0 ? "gpu:" + std::to_string(index) : kind_names[int(kind)];

    const Enumeration devices = enumerate_devices();
    const char* client_ext = devices.client_ext;
    const bool can_enumerate = devices.can_enumerate;
    auto get_platform_display = egl_proc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
    auto query_device_string = egl_proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
    // Hardware ones (no EGL_MESA_device_software) and Mesa's software one.
    std::vector<EGLDeviceEXT> hardware = devices.hardware, software = devices.software;
    std::vector<int> hardware_index(hardware.size());
    for (size_t i = 0; i < hardware.size(); ++i) hardware_index[i] = int(i);
    if (index >= 0) {
        if (size_t(index) >= hardware.size()) {
            std::ostringstream os;
            os << "device='gpu:" << index << "': there is no hardware EGL device " << index << " ("
               << hardware.size() << " hardware device(s); EGL devices found: " << devices_found(devices)
               << "). `ssrlab info` lists the devices; device='cpu' renders with Mesa's llvmpipe.";
            throw DeviceError(os.str());
        }
        hardware = {devices.hardware[size_t(index)]};
        hardware_index = {index};
    } else {
        // NVIDIA devices first (EGL_NV_device_cuda), so "auto" on a CUDA machine takes the GPU.
        std::vector<size_t> order(hardware.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::stable_partition(order.begin(), order.end(), [&](size_t i) {
            return has_extension(query_device_string(devices.hardware[i], EGL_EXTENSIONS), "EGL_NV_device_cuda");
        });
        for (size_t i = 0; i < order.size(); ++i) {
            hardware[i] = devices.hardware[order[i]];
            hardware_index[i] = int(order[i]);
        }
    }

    auto try_device = [&](EGLDeviceEXT d, DeviceKind want) {
        EGLDisplay dpy = get_platform_display(EGL_PLATFORM_DEVICE_EXT, d, nullptr);
        std::string why;
        if (dpy == EGL_NO_DISPLAY) {
            info_.rejected.push_back("device display: " + egl_error_name(eglGetError()));
            return false;
        }
        if (try_display(dpy, "device", want, &why)) {
            const char* ext = query_device_string(d, EGL_EXTENSIONS);
            info_.egl_device_extensions = ext ? ext : "";
            return true;
        }
        info_.rejected.push_back(why);
        return false;
    };

    bool ok = false;
    if (kind != DeviceKind::Cpu)
        for (size_t i = 0; i < hardware.size(); ++i)
            if ((ok = try_device(hardware[i], DeviceKind::Gpu))) {
                info_.device_index = std::to_string(hardware_index[i]);
                break;
            }

    if (!ok && kind == DeviceKind::Gpu) {
        std::ostringstream os;
        os << "device='" << info_.requested << "' was requested but no hardware EGL device offers an OpenGL 4.5 core "
              "context (hardware EGL devices found: "
           << hardware.size() << ", software: " << software.size() << ")";
        if (!can_enumerate)
            os << "; this libEGL offers no device enumeration (client extensions: "
               << (client_ext ? client_ext : "none") << ")";
        for (const auto& r : info_.rejected) os << "; " << r;
        os << ". Use device='auto' or device='cpu' to render with Mesa's llvmpipe.";
        throw DeviceError(os.str());
    }
    if (!ok)
        for (EGLDeviceEXT d : software)
            if ((ok = try_device(d, DeviceKind::Cpu))) break;
    if (!ok && get_platform_display && has_extension(client_ext, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        std::string why;
        // NVIDIA's libEGL offers the surfaceless platform too: device='cpu' must not end on a GPU.
        if (dpy != EGL_NO_DISPLAY && try_display(dpy, "surfaceless", kind == DeviceKind::Cpu ? kind : DeviceKind::Auto, &why))
            ok = true;
        else info_.rejected.push_back(why.empty() ? "surfaceless: no display" : why);
    }
    if (!ok) {
        std::ostringstream os;
        os << "could not open a headless OpenGL 4.5 core context through EGL";
        for (const auto& r : info_.rejected) os << "; " << r;
        os << ". On Debian, install libegl1, libopengl0, libegl-mesa0 and libgl1-mesa-dri.";
        throw DeviceError(os.str());
    }
    enable_debug_output();
    // Give the thread back: every later call makes the context current for its duration.
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

// Displays are never terminated here: EGL returns the same EGLDisplay for the same device to
// every caller in the process, and eglTerminate would pull it from under other Renderers.
bool EglContext::try_display(EGLDisplay dpy, const std::string& platform, DeviceKind want,
                             std::string* why_not) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(dpy, &major, &minor)) {
        *why_not = platform + ": eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
        return false;
    }
    const char* vendor = eglQueryString(dpy, EGL_VENDOR);
    if (!eglBindAPI(EGL_OPENGL_API)) {
        *why_not = platform + " (" + (vendor ? vendor : "?") + "): no desktop OpenGL API";
        return false;
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4,
                              EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_CONTEXT_OPENGL_DEBUG, EGL_TRUE,
                              EGL_NONE};
    // EGL_KHR_no_config_context + EGL_KHR_surfaceless_context: no surface at all, we
    // render into framebuffer objects only.
    EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT) {
        *why_not = platform + " (" + (vendor ? vendor : "?") + "): no OpenGL 4.5 core context (" +
                   egl_error_name(eglGetError()) + ")";
        return false;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        *why_not = platform + ": eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")";
        eglDestroyContext(dpy, ctx);
        return false;
    }
    const std::string renderer = gl_string(GL_RENDERER);
    if ((want == DeviceKind::Gpu && is_software_renderer(renderer)) ||
        (want == DeviceKind::Cpu && !is_software_renderer(renderer))) {
        *why_not = platform + ": renderer '" + renderer + "' is " +
                   (want == DeviceKind::Gpu ? "a software rasterizer" : "not a software rasterizer (device='cpu')");
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(dpy, ctx);
        return false;
    }
    display_ = dpy;
    context_ = ctx;
    info_.chosen = is_software_renderer(renderer) ? "cpu" : "gpu";
    info_.egl_platform = platform;
    info_.egl_vendor = vendor ? vendor : "";
    info_.egl_version = std::to_string(major) + "." + std::to_string(minor);
    info_.gl_vendor = gl_string(GL_VENDOR);
    info_.gl_renderer = renderer;
    info_.gl_version = gl_string(GL_VERSION);
    info_.glsl_version = gl_string(GL_SHADING_LANGUAGE_VERSION);
    return true;
}

void EglContext::enable_debug_output() {
    glEnable(GL_DEBUG_OUTPUT);
    // Synchronous, so the callback runs inside the call that failed and check_gl() after a
    // pass sees every error of that pass.
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(on_gl_debug, this);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
}

EglContext::~EglContext() {
    if (display_ != EGL_NO_DISPLAY) {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
        // The display is shared by every context on that device in this process: leaving it
        // initialised keeps other Renderers alive (eglTerminate would destroy their contexts).
    }
}

void EglContext::make_current() {
    if (eglGetCurrentContext() == context_) return;
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
        const EGLint e = eglGetError();
        if (e == EGL_BAD_ACCESS)
            throw GLError("this Renderer's GL context is in use by a call on another thread: one call at a time per Renderer");
        throw GLError("eglMakeCurrent failed: " + egl_error_name(e));
    }
}

CurrentContext::CurrentContext(EglContext& ctx)
    : lock_(ctx.mutex()),
      ctx_(ctx),
      prev_display_(eglGetCurrentDisplay()),
      prev_draw_(eglGetCurrentSurface(EGL_DRAW)),
      prev_read_(eglGetCurrentSurface(EGL_READ)),
      prev_context_(eglGetCurrentContext()) {
    if (prev_context_ == ctx.handle()) return;
    ctx.make_current();
    switched_ = true;
}

CurrentContext::~CurrentContext() {
    if (!switched_) return;
    if (prev_context_ != EGL_NO_CONTEXT) eglMakeCurrent(prev_display_, prev_draw_, prev_read_, prev_context_);
    else eglMakeCurrent(ctx_.display(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

std::vector<std::string> EglContext::take_debug_errors() {
    std::vector<std::string> out;
    out.swap(debug_errors_);
    return out;
}

void check_gl(EglContext& ctx, const char* where) {
    std::vector<std::string> errors = ctx.take_debug_errors();
    for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
        std::ostringstream os;
        os << "glGetError 0x" << std::hex << e;
        errors.push_back(os.str());
    }
    if (errors.empty()) return;
    std::ostringstream os;
    os << "OpenGL error in " << where << ":";
    for (const auto& e : errors) os << "\n  " << e;
    throw GLError(os.str());
}

}  // namespace ssr
