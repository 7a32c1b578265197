// Device tools outside the frame chain: the trace passes' reflection sampling seen alone
// (shaders/tools/brdf_samples.comp), the roofline's microbenchmarks (shaders/tools/microbench.comp)
// and the split-sum table of the GGX directional albedo (shaders/tools/specular_albedo.comp).
#include "render/renderer.h"

#include <algorithm>
#include <cctype>

#include "core/errors.h"

namespace ssr {

namespace {
// The split-sum table (shaders/lib/specular_albedo.glsl): its size, texture unit and samples
// per cell (a Hammersley set of 4096 VNDF directions: the table is converged to ~1e-4).
constexpr int kSpecularAlbedoSize = 32;
constexpr int kSpecularAlbedoUnit = 13;
constexpr unsigned kSpecularAlbedoSamples = 4096;
}  // namespace

void Renderer::bind_specular_albedo() {
    if (!specular_albedo_) {
        specular_albedo_ = Texture::create_2d(GL_RG32F, kSpecularAlbedoSize, kSpecularAlbedoSize, 1);
        specular_albedo_.set_filter(GL_LINEAR, GL_LINEAR);
        specular_albedo_.set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
        const GLuint prog = shaders_->program({"tools/specular_albedo.comp"}, {});
        glUseProgram(prog);
        glUniform1ui(glGetUniformLocation(prog, "u_samples"), kSpecularAlbedoSamples);
        glBindImageTexture(0, specular_albedo_.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
        glDispatchCompute((kSpecularAlbedoSize + 7) / 8, (kSpecularAlbedoSize + 7) / 8, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        check_gl(*ctx_, "specular albedo table");
    }
    glBindTextureUnit(kSpecularAlbedoUnit, specular_albedo_.id());
}

Readback Renderer::specular_albedo_table() {
    {
        CurrentContext current(*ctx_);
        bind_specular_albedo();
    }
    Readback r = read_texture(specular_albedo_, 0);
    // Keep the two channels.
    ReadbackData ab;
    ab.reserve(size_t(r.width) * size_t(r.height) * 2);
    // Readback puts the texture's last row first (row 0 = top of an image); the table keeps
    // its own order: row i is roughness i / (size - 1).
    for (int y = r.height - 1; y >= 0; --y)
        for (int x = 0; x < r.width; ++x) {
            const size_t i = size_t(y) * size_t(r.width) + size_t(x);
            ab.push_back(r.data[4 * i]);
            ab.push_back(r.data[4 * i + 1]);
        }
    r.data = std::move(ab);
    r.channels = 2;
    return r;
}

std::vector<float> Renderer::sample_reflections(const std::string& sampling, float alpha, const glm::vec3& view,
                                               int count, uint32_t seed, bool stratified) {
    if (count < 1 || count > (1 << 24)) throw std::invalid_argument("count must be in [1, 2^24]");
    if (!(alpha >= 0.0f && alpha <= 1.0f)) throw std::invalid_argument("alpha must be in [0, 1]");
    if (!(view.z > 0.0f)) throw std::invalid_argument("view must point above the surface (view.z > 0)");
    const Sampling method = parse_enum<Sampling>("sampling", sampling);
    CurrentContext current(*ctx_);
    const GLuint prog = shaders_->program({"tools/brdf_samples.comp"}, {});
    glUseProgram(prog);
    glUniform3f(glGetUniformLocation(prog, "u_view"), view.x, view.y, view.z);
    glUniform1f(glGetUniformLocation(prog, "u_alpha"), alpha);
    glUniform1i(glGetUniformLocation(prog, "u_method"), int(method));
    glUniform1ui(glGetUniformLocation(prog, "u_count"), GLuint(count));
    glUniform1ui(glGetUniformLocation(prog, "u_seed"), seed);
    glUniform1i(glGetUniformLocation(prog, "u_stratified"), stratified ? 1 : 0);
    const size_t bytes = size_t(count) * 8 * sizeof(float);
    Buffer out = Buffer::create(bytes);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, out.id());
    glDispatchCompute(GLuint((count + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> data(size_t(count) * 8);
    glGetNamedBufferSubData(out.id(), 0, GLsizeiptr(bytes), data.data());
    check_gl(*ctx_, "sample_reflections");
    return data;
}

std::vector<double> Renderer::microbenchmark(const std::string& kernel, int width, int height, int iterations,
                                             int repeats) {
    static const char* kernels[] = {"coherent", "dependent", "dependent_image", "store", "bandwidth", "copy",
                                    "copy_image"};
    if (std::find_if(std::begin(kernels), std::end(kernels), [&](const char* k) { return kernel == k; }) ==
        std::end(kernels))
        throw std::invalid_argument("microbenchmark kernel '" + kernel +
                                    "' unknown (coherent, dependent, dependent_image, store, bandwidth, copy, copy_image)");
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw std::invalid_argument("microbenchmark width and height must be in [1, 16384]");
    // Store and bandwidth kernels touch one layer per iteration: bounded to keep memory small.
    const int max_iterations = (kernel == "store" || kernel == "bandwidth") ? 16 : 4096;
    if (iterations < 1 || iterations > max_iterations)
        throw std::invalid_argument("microbenchmark iterations must be in [1, " + std::to_string(max_iterations) +
                                    "] for kernel '" + kernel + "'");
    if (repeats < 1 || repeats > 1000) throw std::invalid_argument("microbenchmark repeats must be in [1, 1000]");
    CurrentContext current(*ctx_);
    constexpr int kSourceLayers = 4;
    const bool layered = kernel == "store" || kernel == "bandwidth";
    Texture source = Texture::create_2d_array(GL_RGBA16F, width, height, kSourceLayers);
    Texture chain = Texture::create_2d(GL_RG32F, width, height);
    Texture wide = Texture::create_2d_array(GL_RGBA32F, width, height, kernel == "bandwidth" ? iterations : 1);
    Texture store = Texture::create_2d_array(GL_RGBA16F, width, height, layered ? iterations : 1);
    Texture sink = Texture::create_2d(GL_RGBA32F, width, height);
    const GLuint groups_x = GLuint((width + 7) / 8), groups_y = GLuint((height + 7) / 8);
    // Selects kernel `name` (define KERNEL_<NAME>) with its two uniforms.
    auto use = [&](const std::string& name, int its, int layers) {
        std::string define = "KERNEL_";
        for (char c : name) define += char(std::toupper(static_cast<unsigned char>(c)));
        const GLuint prog = shaders_->program({"tools/microbench.comp"}, {{define, "1"}});
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_iterations"), its);
        glUniform1i(glGetUniformLocation(prog, "u_layers"), layers);
    };
    glBindTextureUnit(0, source.id());
    glBindTextureUnit(1, chain.id());
    glBindTextureUnit(2, wide.id());
    use("init", wide.layers(), kSourceLayers);
    glBindImageTexture(0, source.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    glBindImageTexture(1, chain.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
    glBindImageTexture(2, wide.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(groups_x, groups_y, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    use(kernel, iterations, kernel == "store" ? iterations : kSourceLayers);
    if (kernel == "store")
        glBindImageTexture(0, store.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    else
        glBindImageTexture(0, sink.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    if (kernel == "dependent_image") glBindImageTexture(1, chain.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32F);
    if (kernel == "copy_image") glBindImageTexture(1, source.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    std::vector<double> ms;
    GpuTimer timer;
    for (int i = -1; i < repeats; ++i) {  // i = -1: untimed (llvmpipe compiles at first dispatch)
        timer.begin_frame();
        if (i >= 0) timer.begin("run");
        glDispatchCompute(groups_x, groups_y, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        if (i >= 0) {
            timer.end("run");
            ms.push_back(timer.resolve()["run"]);
        } else {
            glFinish();
        }
    }
    check_gl(*ctx_, "microbenchmark");
    return ms;
}

}  // namespace ssr
