// Reading textures back to the host: float formats downloaded as stored (halves widened with
// F16C where the CPU has it), other formats through shaders/passes/readback.comp; and the
// Frame's reads, which go through it.
#include "render/renderer.h"
#include "render/auto_choice.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <thread>
#include <limits>

#include "core/errors.h"

#ifndef GL_PACK_INVERT_MESA
#define GL_PACK_INVERT_MESA 0x8758  // GL_MESA_pack_invert, where the GL headers lack it
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SSR_HAVE_F16C_PATH 1
#else
#define SSR_HAVE_F16C_PATH 0
#endif

namespace ssr {

namespace {

#if SSR_HAVE_F16C_PATH
// Half floats to floats with the CPU's F16C conversion (exact, NaN and infinity kept): an
// RGBA16F texture downloaded as stored (into memory not zeroed first) and widened here took
// 0.52-0.53x the time of asking llvmpipe for GL_FLOAT at 640x360, 0.65-0.69x at 1920x1080
// (benchmarks/timing/readback.py).
// Compiled for F16C alone and called only where the CPU has it.
__attribute__((target("avx,f16c"))) void widen_halves_f16c(const uint16_t* in, float* out, size_t n) {
    size_t i = 0;
    for (; i + 8 <= n; i += 8)
        _mm256_storeu_ps(out + i, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i))));
    for (; i < n; ++i) out[i] = _cvtsh_ss(in[i]);
}

bool cpu_has_f16c() {
    static const bool has = __builtin_cpu_supports("avx") && __builtin_cpu_supports("f16c");
    return has;
}
#else
void widen_halves_f16c(const uint16_t*, float*, size_t) {}
bool cpu_has_f16c() { return false; }
#endif

}  // namespace

void Renderer::set_readback_path(const std::string& path) {
    check_choice("Renderer.readback_path", path, kReadbackPaths);
    readback_path_ = path;
}

void Renderer::set_clear_path(const std::string& path) {
    check_choice("Renderer.clear_path", path, kClearPaths);
    clear_path_ = path;
}

void Renderer::set_visibility_tiles(const std::string& mode) {
    check_choice("Renderer.visibility_tiles", mode, kVisibilityTiles);
    visibility_tiles_ = mode;
}

bool Renderer::marks_visibility_tiles() const {
    if (visibility_tiles_ == "auto") return auto_visibility_tiles(ctx_->info().chosen == "cpu");
    return visibility_tiles_ == "on";
}

bool Renderer::clear_by_compute() const {
    if (clear_path_ == "auto") return auto_clear_by_compute(ctx_->info().chosen == "cpu");
    return clear_path_ == "compute";
}

bool Renderer::readback_staged() const {
    if (readback_path_ == "auto") return auto_readback_staged(ctx_->info().chosen == "cpu");
    return readback_path_ == "staged";
}

namespace {
// memcpy in up to 8 threads of at least 4 MiB each: one core's copy of a 1920x1080 RGBA32F
// image (33 MB) takes several ms, longer than the transfer.
void parallel_copy(float* dst, const char* src, size_t bytes) {
    const size_t chunk_min = size_t(4) << 20;
    const size_t threads = std::min<size_t>({8, std::max(1u, std::thread::hardware_concurrency()),
                                             std::max<size_t>(1, bytes / chunk_min)});
    char* out = reinterpret_cast<char*>(dst);
    if (threads <= 1) {
        std::memcpy(out, src, bytes);
        return;
    }
    const size_t chunk = (bytes / threads + 63) & ~size_t(63);
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) {
        const size_t begin = std::min(bytes, t * chunk), end = std::min(bytes, (t + 1) * chunk);
        if (begin < end) pool.emplace_back([=] { std::memcpy(out + begin, src + begin, end - begin); });
    }
    std::memcpy(out, src, std::min(bytes, chunk));
    for (auto& th : pool) th.join();
}
}  // namespace

Readback Renderer::read_texture(const Texture& tex, int level) {
    CurrentContext current(*ctx_);
    if (level < 0 || level >= tex.levels())
        throw std::invalid_argument("mip level " + std::to_string(level) + " out of range (texture has " +
                                    std::to_string(tex.levels()) + ")");
    // A cube-map array (the point lights' shadow cubes) reads as its 6 x cubes layer-faces.
    if (tex.target() == GL_TEXTURE_CUBE_MAP_ARRAY) return read_texture(Texture::view_as_2d_array(tex), level);
    Readback out;
    out.width = std::max(tex.width() >> level, 1);
    out.height = std::max(tex.height() >> level, 1);
    out.layers = tex.target() == GL_TEXTURE_2D_ARRAY ? tex.layers() : 1;
    const size_t bytes = size_t(out.width) * size_t(out.height) * size_t(out.layers) * 4 * sizeof(float);
    const GLenum f = tex.format();
    const size_t row = size_t(out.width) * 4;  // floats
    const size_t layer_floats = row * size_t(out.height);
    const bool float_format =
        f == GL_RGBA32F || f == GL_RGBA16F || f == GL_RG32F || f == GL_RG16F || f == GL_R32F || f == GL_R16F;
    if (!readback_staged() && float_format && layer_floats * sizeof(float) <= size_t(std::numeric_limits<GLsizei>::max())) {
        // Float formats, whose GL_RGBA/GL_FLOAT download is exactly what a texelFetch returns
        // (halves widen exactly; absent channels read 0, 0, 1): downloaded as stored, a layer
        // at a time (GL sizes are 32-bit), no copy pass (on llvmpipe the copy pass
        // was most of a readback). Rows come top first from the driver where it has
        // GL_MESA_pack_invert (llvmpipe: the colour's readback 0.54-0.55x at 1920x1080, 0.7-0.8x
        // at 640x360, benchmarks/timing/readback.py), else they are swapped on the CPU. Normalised, sRGB
        // and depth formats are decoded by readback.comp's fetch.
        out.data.resize(layer_floats * size_t(out.layers));
        // Shader image stores reach glGetTextureSubImage only after this barrier (GL 4.5, 7.13.2).
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        // Where the driver has GL_MESA_pack_invert (Mesa), it writes the rows top first itself.
        if (pack_invert_) glPixelStorei(GL_PACK_INVERT_MESA, GL_TRUE);
        // RGBA16F: downloaded as halves and widened on the CPU where it has F16C.
        const bool halves = f == GL_RGBA16F && cpu_has_f16c();
        std::vector<uint16_t, UninitialisedAllocator<uint16_t>> half_layer(halves ? layer_floats : 0);
        for (int l = 0; l < out.layers; ++l) {
            float* layer = out.data.data() + size_t(l) * layer_floats;
            if (halves) {
                glGetTextureSubImage(tex.id(), level, 0, 0, l, out.width, out.height, 1, GL_RGBA, GL_HALF_FLOAT,
                                     GLsizei(layer_floats * sizeof(uint16_t)), half_layer.data());
                widen_halves_f16c(half_layer.data(), layer, layer_floats);
            } else {
                glGetTextureSubImage(tex.id(), level, 0, 0, l, out.width, out.height, 1, GL_RGBA, GL_FLOAT,
                                     GLsizei(layer_floats * sizeof(float)), layer);
            }
            if (pack_invert_) continue;
            for (int y = 0; y < out.height / 2; ++y)
                std::swap_ranges(layer + size_t(y) * row, layer + size_t(y + 1) * row,
                                 layer + size_t(out.height - 1 - y) * row);
        }
        if (pack_invert_) glPixelStorei(GL_PACK_INVERT_MESA, GL_FALSE);
        check_gl(*ctx_, "readback");
        ++readbacks_;
        readback_bytes_ += bytes;
        return out;
    }
    if (readback_ssbo_.size() < bytes) readback_ssbo_ = Buffer::create(bytes);
    const bool staged = readback_staged();
    Defines d;
    d["READ_ARRAY"] = tex.target() == GL_TEXTURE_2D_ARRAY ? "1" : "0";
    // The texture read, by name (TEXTURE_SOURCE), at the unit its sampler object is bound to.
    constexpr GLuint kSourceUnit = 0;
    d["TEXTURE_SOURCE"] = std::to_string(kSourceUnit);
    const GLuint prog = shaders_->program({"passes/readback.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_level"), level);
    glUniform2i(glGetUniformLocation(prog, "u_size"), out.width, out.height);
    glBindTextureUnit(kSourceUnit, tex.id());
    glBindSampler(kSourceUnit, readback_sampler_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTexelsBinding, readback_ssbo_.id());
    glDispatchCompute(GLuint((out.width + 7) / 8), GLuint((out.height + 7) / 8), GLuint(out.layers));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindSampler(kSourceUnit, 0);
    out.data.resize(bytes / sizeof(float));
    if (staged) {
        // A GPU's glGetBufferSubData goes through the driver's own staging copy into pageable
        // memory; here the copy engine writes into pinned client memory and the CPU copies
        // from it in parallel, once the fence has passed.
        if (readback_staging_.size() < bytes) {
            readback_staging_.reset();
            readback_staging_ = Buffer::create_readable(bytes);
        }
        glCopyNamedBufferSubData(readback_ssbo_.id(), readback_staging_.id(), 0, 0, GLsizeiptr(bytes));
        glMemoryBarrier(GL_CLIENT_MAPPED_BUFFER_BARRIER_BIT);
        GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        GLenum waited = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000ull);
        while (waited == GL_TIMEOUT_EXPIRED) waited = glClientWaitSync(fence, 0, 1000000000ull);
        glDeleteSync(fence);
        if (waited == GL_WAIT_FAILED) throw GLError("readback: waiting for the GPU failed");
        parallel_copy(out.data.data(), static_cast<const char*>(readback_staging_.mapped()), bytes);
    } else {
        glGetNamedBufferSubData(readback_ssbo_.id(), 0, GLsizeiptr(bytes), out.data.data());
    }
    check_gl(*ctx_, "readback");
    ++readbacks_;
    readback_bytes_ += bytes;
    return out;
}

DisplayBytes Renderer::display_bytes(const Texture& tex, float exposure, const std::vector<float>& thresholds) {
    CurrentContext current(*ctx_);
    if (tex.target() != GL_TEXTURE_2D)
        throw std::invalid_argument("display bytes are made of a 2D colour texture, not of a layered one");
    if (thresholds.size() != 255)
        throw std::invalid_argument("display bytes need the 255 thresholds of codes 1..255, got " +
                                    std::to_string(thresholds.size()));
    if (!std::isfinite(exposure)) throw std::invalid_argument("exposure must be finite");
    DisplayBytes out;
    out.width = tex.width();
    out.height = tex.height();
    const size_t pixels = size_t(out.width) * size_t(out.height);
    const size_t quads = (pixels + 3) / 4, bytes = quads * 12;  // 4 pixels of 3 bytes in 3 uints
    if (display_ssbo_.size() < bytes) display_ssbo_ = Buffer::create(bytes);
    Defines d;
    constexpr GLuint kSourceUnit = 0;
    d["TEXTURE_SOURCE"] = std::to_string(kSourceUnit);
    const GLuint prog = shaders_->program({"passes/display_bytes.comp"}, d);
    glUseProgram(prog);
    glUniform2i(glGetUniformLocation(prog, "u_size"), out.width, out.height);
    glUniform1f(glGetUniformLocation(prog, "u_exposure"), exposure);
    glUniform1fv(glGetUniformLocation(prog, "u_thresholds"), 255, thresholds.data());
    glBindTextureUnit(kSourceUnit, tex.id());
    glBindSampler(kSourceUnit, readback_sampler_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kDisplayBytesBinding, display_ssbo_.id());
    constexpr size_t kGroup = 256, kMaxGroups = 65535;  // the shader's local size; GL's least limit per axis
    const size_t groups = (quads + kGroup - 1) / kGroup;
    glDispatchCompute(GLuint(std::min(groups, kMaxGroups)), GLuint((groups + kMaxGroups - 1) / kMaxGroups), 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindSampler(kSourceUnit, 0);
    out.rgb.resize(pixels * 3);
    glGetNamedBufferSubData(display_ssbo_.id(), 0, GLsizeiptr(pixels * 3), out.rgb.data());
    check_gl(*ctx_, "display bytes");
    ++readbacks_;
    readback_bytes_ += pixels * 3;
    return out;
}

// ------------------------------------------------------------------------------------------

Frame::Frame(std::shared_ptr<EglContext> ctx, std::weak_ptr<Renderer> renderer, std::shared_ptr<FrameResources> res)
    : ctx_(std::move(ctx)), renderer_(std::move(renderer)), resources_(std::move(res)) {}

Frame::~Frame() {
    // The textures may be freed now (when the renderer is gone): in their own context.
    try {
        CurrentContext current(*ctx_);
        resources_.reset();
        if (auto r = renderer_.lock()) r->recycle();
    } catch (...) {
    }
}

void Frame::release() {
    if (!resources_) return;
    CurrentContext current(*ctx_);
    resources_.reset();
    if (auto r = renderer_.lock()) r->recycle(true);
}

FrameResources& Frame::resources() {
    if (!resources_) throw std::invalid_argument("this frame was released (Frame.release()); its textures are gone");
    return *resources_;
}

bool Frame::has(const std::string& name) const {
    if (!resources_) return false;
    if (resources_->owns(name)) return true;
    auto r = renderer_.lock();
    return r && r->scratch_of(name, serial) != nullptr;
}

Readback Frame::read(const std::string& name, int level) {
    if (!resources_)
        throw std::invalid_argument("cannot read '" + name + "': this frame was released (Frame.release()); read "
                                    "what you need before releasing it");
    auto r = renderer_.lock();
    if (!r) throw GLError("the Renderer that made this frame has been closed; read what you need before closing it");
    if (resources_->owns(name)) {
        Readback data = r->read_texture(resources_->get(name), level);
        const auto& descs = resources_->descs();
        auto d = std::find_if(descs.begin(), descs.end(), [&](const ResourceDesc& x) { return x.name == name; });
        if (d != descs.end() && !d->defined_by.empty() && resources_->owns(d->defined_by)) {
            // Texels the pass left unwritten read as 0 (ResourceDesc::defined_by).
            const Readback mask = r->read_texture(resources_->get(d->defined_by), level);
            if (mask.data.size() == data.data.size())
                for (size_t t = 0; t < data.data.size(); t += 4)
                    if (!(mask.data[t + size_t(d->defined_component)] > 0.5f))
                        std::fill(data.data.begin() + t, data.data.begin() + t + 4, 0.0f);
        }
        return data;
    }
    if (const Texture* t = r->scratch_of(name, serial)) return r->read_texture(*t, level);
    if (r->is_scratch(name))
        throw std::invalid_argument("'" + name + "' is per-renderer scratch shared by all frames, and a later render "
                                    "has overwritten it (or this frame did not make one): read it right after "
                                    "rendering the frame");
    std::string known;
    for (const auto& n : texture_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("frame has no texture '" + name + "' (it has: " + known + ")");
}

DisplayBytes Frame::display_bytes(const std::string& name, float exposure, const std::vector<float>& thresholds) {
    if (!resources_)
        throw std::invalid_argument("cannot read '" + name + "': this frame was released (Frame.release())");
    auto r = renderer_.lock();
    if (!r) throw GLError("the Renderer that made this frame has been closed; read what you need before closing it");
    if (!resources_->owns(name)) throw std::invalid_argument("frame has no texture '" + name + "' of its own");
    const auto& descs = resources_->descs();
    auto d = std::find_if(descs.begin(), descs.end(), [&](const ResourceDesc& x) { return x.name == name; });
    // A texture whose unwritten texels read as 0 (defined_by) is only read whole through read().
    if (d != descs.end() && !d->defined_by.empty())
        throw std::invalid_argument("'" + name + "' is defined only where " + d->defined_by + " says: read it with read()");
    return r->display_bytes(resources_->get(name), exposure, thresholds);
}

std::vector<std::pair<const ResourceDesc*, ChannelDesc>> Frame::channels() const {
    std::vector<std::pair<const ResourceDesc*, ChannelDesc>> out;
    if (!resources_) return out;
    for (const auto& d : resources_->descs())
        for (const auto& c : d.channels) out.emplace_back(&d, c);
    return out;
}

std::vector<std::string> Frame::texture_names() const {
    std::vector<std::string> names;
    if (!resources_) return names;
    for (const auto& d : resources_->descs()) names.push_back(d.name);
    if (auto r = renderer_.lock())
        for (const auto& n : r->scratch_names_of(serial)) names.push_back(n);
    return names;
}


}  // namespace ssr
