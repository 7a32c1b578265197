#include "core/gpu_timer.h"

#include "core/errors.h"

namespace ssr {

GpuTimer::~GpuTimer() { reset(); }

void GpuTimer::reset() {
    if (!pool_.empty()) glDeleteQueries(GLsizei(pool_.size()), pool_.data());
    pool_.clear();
    used_ = 0;
    intervals_.clear();
}

void GpuTimer::begin_frame() {
    used_ = 0;
    intervals_.clear();
}

GLuint GpuTimer::query() {
    if (used_ == pool_.size()) {
        GLuint q = 0;
        glGenQueries(1, &q);
        pool_.push_back(q);
    }
    return pool_[used_++];
}

void GpuTimer::begin(const std::string& name) {
    Interval iv;
    iv.name = name;
    iv.start = query();
    glQueryCounter(iv.start, GL_TIMESTAMP);
    intervals_.push_back(iv);
}

void GpuTimer::end(const std::string& name) {
    for (auto it = intervals_.rbegin(); it != intervals_.rend(); ++it) {
        if (it->name == name && it->stop == 0) {
            it->stop = query();
            glQueryCounter(it->stop, GL_TIMESTAMP);
            return;
        }
    }
    throw GLError("GpuTimer::end('" + name + "') without a matching begin");
}

std::map<std::string, double> GpuTimer::resolve() {
    std::map<std::string, double> out;
    for (const Interval& iv : intervals_) {
        if (!iv.stop) continue;
        GLuint64 t0 = 0, t1 = 0;
        glGetQueryObjectui64v(iv.start, GL_QUERY_RESULT, &t0);
        glGetQueryObjectui64v(iv.stop, GL_QUERY_RESULT, &t1);
        out[iv.name] += double(t1 >= t0 ? t1 - t0 : 0) * 1e-6;
    }
    return out;
}

}  // namespace ssr
