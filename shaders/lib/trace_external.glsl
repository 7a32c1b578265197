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
// Chains: the queries are numbered per chain (trace_chain_begin), chains being independent ray
// sequences of one invocation (the camera ray; each reflection ray and its shadow rays; the
// pixel's own shadow rays), so that one phase traces the k-th ray of every chain at once and a
// pass with many rays per invocation needs as many phases as its longest chain, not their sum.
// Chain 0 (the camera ray) comes first: until it is answered (u_trace_known0) the other chains
// wait, since they start from its hit.

struct TraceQuery {
    vec4 origin_t_min;  // world-space origin, t_min
    vec4 dir_t_max;     // direction, t_max
    ivec4 info;         // x: 0 no query, 1 closest hit, 2 any hit (shadow ray)
};

// queries: [chain][invocation]; answers: [query][chain][invocation], (t, triangle bits, b1, b2)
layout(std430, binding = BUFFER_TRACE_QUERIES) writeonly buffer TraceQueries { TraceQuery trace_queries[]; };
layout(std430, binding = BUFFER_TRACE_ANSWERS) readonly buffer TraceAnswers { vec4 trace_answers[]; };

uniform int u_trace_known;   // queries answered for every chain but chain 0 (the phase)
uniform int u_trace_known0;  // queries answered for chain 0
uniform int u_trace_chains;  // chains per invocation
uniform int u_trace_stride;  // invocations

int trace_invocation = 0;  // this invocation's index, set by the pass before any trace
int trace_chain = 0;
int trace_chain_queries = 0;
int trace_most = 0;        // the most queries any chain but chain 0 made
bool trace_pending = false;
bool trace_waiting = false;  // chain 0 is not answered yet
uint trace_emitted = 0u;     // chains whose query slot this phase filled (at most 32 chains)

void trace_chain_begin(int chain) {
    trace_chain = chain;
    trace_chain_queries = 0;
}

TraceHit trace_query(vec3 origin, vec3 dir, float t_min, float t_max, int kind) {
    TraceHit hit;
    hit.t = t_max;
    hit.triangle = -1;
    hit.b1 = 0.0;
    hit.b2 = 0.0;
    int q = trace_chain_queries++;
    int known = trace_chain == 0 ? u_trace_known0 : u_trace_known;
    if (trace_chain != 0) trace_most = max(trace_most, q + 1);
    if (q < known) {
        vec4 a = trace_answers[(q * u_trace_chains + trace_chain) * u_trace_stride + trace_invocation];
        int triangle = floatBitsToInt(a.y);
        if (triangle >= 0) {
            hit.t = a.x;
            hit.triangle = triangle;
            hit.b1 = a.z;
            hit.b2 = a.w;
        }
    } else if (q == known) {
        if (trace_chain == 0) trace_waiting = true;
        if (!trace_waiting || trace_chain == 0) {
            trace_queries[trace_chain * u_trace_stride + trace_invocation] =
                TraceQuery(vec4(origin, t_min), vec4(dir, t_max), ivec4(kind, 0, 0, 0));
            trace_emitted |= 1u << uint(trace_chain);
        }
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

// True when this invocation's run is the one to keep: every query it made was answered and its
// longest chain needed exactly this phase's answers (fewer: it completed in an earlier phase).
// In the phase that answers chain 0 (u_trace_known 0) an invocation with no other query completes.
bool trace_complete() { return !trace_pending && trace_most == u_trace_known; }

// Ends the phase: every chain slot this invocation did not fill says "no query" (the host reads
// every slot).
void trace_finish() {
    for (int c = 0; c < u_trace_chains; ++c)
        if ((trace_emitted & (1u << uint(c))) == 0u) trace_queries[c * u_trace_stride + trace_invocation].info = ivec4(0);
}
