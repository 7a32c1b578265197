// Closest-hit ray tracing against every triangle of the scene: a binary BVH (each object's
// tree under a tree of the objects, built by Embree's SAH builder, cpp/scene/bvh.cpp, flattened
// into one array) traversed with a stack, and the watertight
// ray-triangle test of Woop, Benthin and Wald (JCGT 2(1), 2013): the ray is sheared onto +z
// and every edge function of a shared edge is computed from the same values, so a ray can
// neither slip between two triangles that share an edge nor hit both.

// The nodes (BvhNode bvh_nodes[]) and triangles (BvhTriangle bvh_triangles[]), as
// cpp/render/gpu_structs.def declares them for the host and these shaders alike.
#include "generated/BvhNodes.glsl"
#include "generated/BvhTriangles.glsl"

struct TraceHit {
    float t;       // ray parameter (unit direction: distance)
    int triangle;  // index into bvh_triangles, -1 for a miss
    float b1, b2;  // barycentric weights of v1 and v2 (v0 gets 1 - b1 - b2)
};

struct ShearedRay {
    vec3 origin;
    int kx, ky, kz;  // permuted axes: kz is the direction's largest component
    vec3 shear;      // (Sx, Sy, Sz)
};

ShearedRay shear_ray(vec3 origin, vec3 dir) {
    ShearedRay r;
    r.origin = origin;
    vec3 a = abs(dir);
    r.kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    r.kx = (r.kz + 1) % 3;
    r.ky = (r.kx + 1) % 3;
    if (dir[r.kz] < 0.0) {  // keep the winding
        int tmp = r.kx;
        r.kx = r.ky;
        r.ky = tmp;
    }
    r.shear = vec3(dir[r.kx] / dir[r.kz], dir[r.ky] / dir[r.kz], 1.0 / dir[r.kz]);
    return r;
}

bool intersect_triangle(ShearedRay r, vec3 p0, vec3 p1, vec3 p2, float t_min, float t_max, out float t,
                        out float b1, out float b2) {
    vec3 a = p0 - r.origin, b = p1 - r.origin, c = p2 - r.origin;
    float ax = a[r.kx] - r.shear.x * a[r.kz], ay = a[r.ky] - r.shear.y * a[r.kz];
    float bx = b[r.kx] - r.shear.x * b[r.kz], by = b[r.ky] - r.shear.y * b[r.kz];
    float cx = c[r.kx] - r.shear.x * c[r.kz], cy = c[r.ky] - r.shear.y * c[r.kz];
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
    if (u == 0.0 || v == 0.0 || w == 0.0) {  // on an edge in single precision: decide in double
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    t = 0.0;
    b1 = 0.0;
    b2 = 0.0;
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
    float det = u + v + w;
    if (det == 0.0) return false;
    float az = r.shear.z * a[r.kz], bz = r.shear.z * b[r.kz], cz = r.shear.z * c[r.kz];
    t = (u * az + v * bz + w * cz) / det;
    if (!(t > t_min && t < t_max)) return false;
    b1 = v / det;
    b2 = w / det;
    return true;
}

// Slab test against [lo, hi] with the far distance widened by 2 gamma(3) (Ize, "Robust BVH
// Ray Traversal", JCGT 2(2), 2013) so rounding never culls a box the ray touches.
bool intersect_box(vec3 lo, vec3 hi, vec3 origin, vec3 inv_dir, float t_min, float t_max) {
    vec3 t0 = (lo - origin) * inv_dir, t1 = (hi - origin) * inv_dir;
    vec3 tn = min(t0, t1), tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, t_min));
    float leave = min(min(tf.x, tf.y), min(tf.z, t_max)) * 1.0000004;
    return enter <= leave;
}

// glTF alphaMode MASK (BLEND at 0.5): a hit on a hole of an alpha-tested material is no hit,
// the ray goes on, as the rasterised passes discard the same texels (lib/material.glsl's
// material_alpha_hole, on the base colour texture's level 0 here). Needs scene_data.glsl.
#include "../lib/scene_geometry.glsl"
#include "../lib/scene_textures.glsl"

bool bvh_alpha_hole(BvhTriangle tri, float b1, float b2) {
    ObjectData o = objects[floatBitsToInt(tri.v0.w)];
    MaterialData m = materials[o.material.x];
    // (the vertex colour's alpha is a factor too: glTF COLOR_0)
    SurfaceAttributes s = triangle_attributes(o, floatBitsToInt(tri.v1.w), b1, b2);
    vec4 base_texel = vec4(1.0);
    if (m.flags.x != 0) base_texel = sample_image(m.images.x, texture_uv(m, 0, s.uv), m.wraps.x, false);
    float alpha = m.base_color.a * base_texel.a * s.color.a;
    return m.emissive.w >= 0.0 && alpha < m.emissive.w;
}

#if defined(EXTERNAL_TRACE) && EXTERNAL_TRACE
#include "../lib/trace_external.glsl"
#else
const int BVH_STACK = 64;

// Hits on object bvh_skip_object nearer than bvh_skip_t are no hits (-1: none skipped): a ray
// leaving a point rebuilt from the G-buffer, which knows its own surface only to within its
// pixel (passes/trace_bvh.comp's screen hits), does not meet that surface again there.
int bvh_skip_object = -1;
float bvh_skip_t = 0.0;

TraceHit trace_closest(vec3 origin, vec3 dir, float t_min, float t_max) {
    TraceHit hit;
    hit.t = t_max;
    hit.triangle = -1;
    hit.b1 = 0.0;
    hit.b2 = 0.0;
    if (bvh_nodes.length() == 0) return hit;
    ShearedRay sr = shear_ray(origin, dir);
    vec3 safe = vec3(abs(dir.x) > 1e-30 ? dir.x : 1e-30, abs(dir.y) > 1e-30 ? dir.y : 1e-30,
                     abs(dir.z) > 1e-30 ? dir.z : 1e-30);
    vec3 inv_dir = 1.0 / safe;
    int stack[BVH_STACK];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        BvhNode node = bvh_nodes[stack[--top]];
        if (!intersect_box(node.lo.xyz, node.hi.xyz, origin, inv_dir, t_min, hit.t)) continue;
        int first = floatBitsToInt(node.lo.w), second = floatBitsToInt(node.hi.w);
        if (second < 0) {  // leaf
            for (int i = first; i < first - second; ++i) {
                BvhTriangle tri = bvh_triangles[i];
                float t, b1, b2;
                if (intersect_triangle(sr, tri.v0.xyz, tri.v1.xyz, tri.v2.xyz, t_min, hit.t, t, b1, b2) &&
                    (floatBitsToInt(tri.v2.w) == 0 || !bvh_alpha_hole(tri, b1, b2)) &&
                    (t >= bvh_skip_t || floatBitsToInt(tri.v0.w) != bvh_skip_object)) {
                    hit.t = t;
                    hit.triangle = i;
                    hit.b1 = b1;
                    hit.b2 = b2;
                }
            }
        } else if (top + 2 <= BVH_STACK) {  // the builder's depth limit keeps this from ever failing
            stack[top++] = second;
            stack[top++] = first;
        }
    }
    return hit;
}

// Any hit in (t_min, t_max): a shadow ray.
bool trace_occluded(vec3 origin, vec3 dir, float t_min, float t_max) {
    return trace_closest(origin, dir, t_min, t_max).triangle >= 0;
}

// Without a replay every run is complete (lib/trace_external.glsl).
void trace_chain_begin(int chain) {}
bool trace_complete() { return true; }
void trace_finish() {}
#endif
