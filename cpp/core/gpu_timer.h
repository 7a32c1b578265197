// GPU time per pass from GL timestamp queries (ARB_timer_query).
//
// Timestamps rather than GL_TIME_ELAPSED because elapsed-time queries cannot nest, and a
// frame times both whole passes and their parts (each depth-peeling layer). Results are
// read after the frame, when the GPU has finished, so timing never stalls the pipeline
// between passes.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/gl.h"

namespace ssr {

class GpuTimer {
public:
    GpuTimer() = default;
    ~GpuTimer();
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;

    void begin_frame();
    void begin(const std::string& name);
    void end(const std::string& name);
    // Milliseconds per named interval of the frame (waits for the GPU).
    std::map<std::string, double> resolve();
    void reset();  // deletes the queries (in the current context)

private:
    GLuint query();
    struct Interval {
        std::string name;
        GLuint start = 0, stop = 0;
    };
    std::vector<GLuint> pool_;
    size_t used_ = 0;
    std::vector<Interval> intervals_;
};

// Scope guard: times the enclosing block as `name`.
class GpuScope {
public:
    GpuScope(GpuTimer& t, std::string name) : timer_(t), name_(std::move(name)) { timer_.begin(name_); }
    ~GpuScope() { timer_.end(name_); }

private:
    GpuTimer& timer_;
    std::string name_;
};

}  // namespace ssr
