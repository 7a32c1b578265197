// Ray queries answered outside the shader: the wavefront form of lib/bvh.glsl's trace_closest,
// for a device where another tracer is faster than this GLSL traversal (on the CPU device,
// Embree: cpp/scene/embree_scene.h, driven by cpp/passes/reference.cpp).
//
// Why a replay: ray generation and shading stay in this one GLSL source, shared with the GPU
// path, so the two devices cannot drift apart; only the intersection moves. A pass runs the
// same invocation in phases. Every trace call is a numbered query; in phase k the first k
// queries of each invocation are answered from the answers buffer (slot q holds query q's
// answers for every invocation), query k is written to the query buffer for the host to trace
// (the call returns a miss and the rest of the run is discarded), and an invocation that makes
// no query beyond the answered ones completes: only then may it write its outputs. The host
// traces query k's rays, stores them as slot k, and runs phase k + 1 until no query is left.
// Every phase recomputes the same values from the same inputs and the same RNG streams, so the
// answered rays are exactly the ones the GLSL traversal would have traced.

struct TraceQuery {
    vec4 origin_t_min;  // world-space origin, t_min
    vec4 dir_t_max;     // direction, t_max
    ivec4 info;         // x: 0 no query, 1 closest hit, 2 any hit (shadow ray)
};

layout(std430, binding = 11) writeonly buffer TraceQueries { TraceQuery trace_queries[]; };
layout(std430, binding = 12) readonly buffer TraceAnswers { vec4 trace_answers[]; };  // (t, triangle bits, b1, b2)

uniform int u_trace_known;   // queries answered for every invocation (the phase)
uniform int u_trace_stride;  // invocations per answer slot

int trace_invocation = 0;    // this invocation's index, set by the pass before any trace
int trace_queries_made = 0;
bool trace_pending = false;

TraceHit trace_query(vec3 origin, vec3 dir, float t_min, float t_max, int kind) {
    TraceHit hit;
    hit.t = t_max;
    hit.triangle = -1;
    hit.b1 = 0.0;
    hit.b2 = 0.0;
    int q = trace_queries_made++;
    if (q < u_trace_known) {
        vec4 a = trace_answers[q * u_trace_stride + trace_invocation];
        int triangle = floatBitsToInt(a.y);
        if (triangle >= 0) {
            hit.t = a.x;
            hit.triangle = triangle;
            hit.b1 = a.z;
            hit.b2 = a.w;
        }
    } else if (q == u_trace_known) {
        trace_queries[trace_invocation] = TraceQuery(vec4(origin, t_min), vec4(dir, t_max), ivec4(kind, 0, 0, 0));
        trace_pending = true;
    }
    return hit;
}

TraceHit trace_closest(vec3 origin, vec3 dir, float t_min, float t_max) {
    return trace_query(origin, dir, t_min, t_max, 1);
}

bool trace_occluded(vec3 origin, vec3 dir, float t_min, float t_max) {
    return trace_query(origin, dir, t_min, t_max, 2).triangle >= 0;
}

// True when this invocation's run is the one to keep: every query it made was answered and it
// made no more than this phase's (fewer: it completed in an earlier phase).
bool trace_complete() { return !trace_pending && trace_queries_made == u_trace_known; }

// Ends the phase: an invocation with nothing to trace says so (the host reads every slot).
void trace_finish() {
    if (!trace_pending) trace_queries[trace_invocation].info = ivec4(0);
}
