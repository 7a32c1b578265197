// Screen-space hits for a fallback exact enough to replace a doubtful one (passes/trace_bvh.comp:
// fallback "bvh"): the surface a hit pixel shows, rebuilt from the G-buffer, where a ray meets
// it, and the confidence test of the hit.
// Needs frame_uniforms, depth_convention, gbuffer, and the including shader's samplers
// u_linear_depth, u_albedo, u_normal, u_material (the G-buffer's layers).
//
// The surface of a pixel (screen_surface): its sample (material, shading normal), its point,
// and the plane of the triangle it lies on. The shading normal is interpolated across a
// triangle and does not follow it (5.6 degrees off on a 64-segment sphere), so a point put on
// the shading normal's plane lies inside the mesh, and a traced shadow leaving it is blocked
// by the very triangle it stands on; the face's plane passes through the pixel's point and its
// neighbours' on the same triangle (depth samples lie exactly on their triangles), one
// neighbour per axis, the one nearer in depth (the other may lie across the triangle's edge).
//
// The confidence test. A depth buffer cannot tell a surface from the volume behind it, so a
// screen-space tracer accepts any crossing of a layer's [depth, depth + thickness] slab. The
// tracer hands over every ray that went out of the G-buffer's sight before its hit (STOP_UNSEEN
// in passes/trace_linear.comp and lib/hiz_walk.glsl); at the hit, the G-buffer can still check
// that the ray meets the surface the hit pixel shows:
//   1. the face is in front of the ray (its plane's normal against the ray's direction): a ray
//      cannot meet the back of a face, so a back-facing "hit" passed behind or along it; nor
//      may the ray graze it (cosine below CONFIDENCE_GRAZING): there a tenth of a footprint of
//      depth moves the crossing by ten footprints, and the G-buffer cannot tell a graze from a
//      near miss (a ray skimming a sphere's top into the sky);
//   2. the ray crosses that face there, in pixels and in depth: the ray is intersected with the
//      face's plane at the hit pixel; where the crossing projects into another pixel, with that
//      pixel's plane, and so on (CONFIDENCE_ITERATIONS), until a crossing lies inside the pixel
//      whose plane it is on. The hit is that pixel's: the same object as the tracer's pixel,
//      within CONFIDENCE_PIXELS of it, and the crossing within CONFIDENCE_DEPTH pixel
//      footprints of the pixel's depth (a face seen so obliquely that one pixel spans more
//      depth is not resolved by its one sample). A ray that passes behind a surface inside its
//      slab, or beside its edge, crosses the planes outside the surface's own pixels and never
//      settles. The test is in pixels of the image itself, so at any resolution it asks for
//      the sub-pixel agreement a depth buffer can give;
//   3. the pixel's object and surface are its 4 neighbours' (same layer: same object id,
//      shading normals within CONFIDENCE_CREASE): at a silhouette the layer's depth jumps and
//      at a crease (a box's edge) the surface turns within the pixel, and a ray crossing there
//      may pass just beside the surface the pixel shows (sub-pixel geometry);
//   4. the ray goes into the surface: where it reaches the centre of the next pixel along its
//      image's major axis, it lies behind the face's plane through that pixel's sample, on the
//      same object. A curved surface falls away behind the face's plane, and a ray that grazes
//      a sphere near its silhouette crosses the plane and passes over the sphere (with deep
//      layers, within the slab of a small sphere's front, thicker than the sphere is there).
// The settled pixel, not the tracer's, is the one the fallback shades: near a silhouette the
// tracer's pixel is often the neighbour of the one the ray meets (it reaches the slab a pixel
// before the surface), and its normal, point and shadow are that neighbour's.
const float CONFIDENCE_PIXELS = 2.0;
const float CONFIDENCE_DEPTH = 1.0;  // pixel footprints between the crossing and the pixel's depth
const float CONFIDENCE_CREASE = 0.9;  // cosine between the hit's normal and a neighbour's
const int CONFIDENCE_ITERATIONS = 3;
const float CONFIDENCE_GRAZING = 0.1;  // least cosine between the ray and the face's normal

struct ScreenSurface {
    GSample g;     // the pixel's sample (shading normal in g.normal)
    vec3 point;    // view space, at the pixel's centre
    vec3 face;     // unit normal of the face's plane, on the shading normal's side
    bool uniform_; // the 4 neighbours show the same object with shading normals within CONFIDENCE_CREASE
};

// One pixel's footprint in view units at view depth z (positive).
float pixel_footprint(float z) {
    return 2.0 * z / (frame.proj[1][1] * frame.viewport.y);
}

GSample screen_sample(ivec2 p, int layer) {
    return gbuffer_decode(texelFetch(u_albedo, ivec3(p, layer), 0), texelFetch(u_normal, ivec3(p, layer), 0),
                          texelFetch(u_material, ivec3(p, layer), 0));
}

vec3 screen_point(ivec2 p, int layer) {
    return view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, layer), 0).r);
}

// One axis of the face's plane: toward the neighbour a or b (one pixel either side of the
// centre c) on the same object and nearer in depth; zero where neither is on it.
vec3 face_axis(vec3 c, vec3 a, bool a_ok, vec3 b, bool b_ok) {
    bool use_a = a_ok && (!b_ok || abs(a.z - c.z) <= abs(c.z - b.z));
    return use_a ? a - c : b_ok ? c - b : vec3(0.0);
}

ScreenSurface screen_surface(ivec2 p, int layer) {
    ivec2 last = ivec2(frame.viewport.xy) - 1;
    ScreenSurface s;
    s.g = screen_sample(p, layer);
    s.point = screen_point(p, layer);
    s.uniform_ = true;
    // +x, -x, +y, -y (+y up: GL's window coordinates)
    const ivec2 nb[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    vec3 q[4];
    bool same[4];
    for (int i = 0; i < 4; ++i) {
        ivec2 n = p + nb[i];
        bool inside = all(greaterThanEqual(n, ivec2(0))) && all(lessThanEqual(n, last));
        GSample g = screen_sample(clamp(n, ivec2(0), last), layer);
        q[i] = screen_point(clamp(n, ivec2(0), last), layer);
        same[i] = inside && g.covered && g.object_id == s.g.object_id;
        s.uniform_ = s.uniform_ && g.object_id == s.g.object_id && dot(g.normal, s.g.normal) >= CONFIDENCE_CREASE;
    }
    vec3 dx = face_axis(s.point, q[0], same[0], q[1], same[1]);
    vec3 dy = face_axis(s.point, q[2], same[2], q[3], same[3]);
    vec3 f = cross(dx, dy);
    s.face = dot(f, f) > 0.0 ? normalize(f) : s.g.normal;
    if (dot(s.face, s.g.normal) < 0.0) s.face = -s.face;
    return s;
}

// Where the ray origin + t dir (view space) crosses the face's plane; false where it runs away
// from the face or grazes it (within CONFIDENCE_GRAZING), or crosses behind its origin or the
// camera.
bool face_crossing(ScreenSurface s, vec3 origin, vec3 dir, out vec3 x) {
    float facing = dot(dir, s.face);
    float t = facing < -CONFIDENCE_GRAZING ? dot(s.point - origin, s.face) / facing : -1.0;
    x = origin + t * dir;
    return t > 0.0 && x.z < 0.0;
}

// The shading normal at window position q (inside pixel p's area), interpolated bilinearly
// between the 4 pixel centres around q that show the same object as p, as the rasteriser
// interpolated the vertex normals between them: the pixel's own normal is its centre's, and
// across a pixel of a curved surface near its silhouette the normal turns by several degrees.
vec3 screen_normal_at(ivec2 p, int layer, vec2 q, GSample g) {
    ivec2 last = ivec2(frame.viewport.xy) - 1;
    vec2 t = q - 0.5;
    ivec2 b = ivec2(floor(t));
    vec2 f = t - vec2(b);
    vec3 n = vec3(0.0);
    for (int i = 0; i < 4; ++i) {
        ivec2 o = ivec2(i & 1, i >> 1);
        ivec2 c = clamp(b + o, ivec2(0), last);
        GSample s = c == p ? g : screen_sample(c, layer);
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        if (s.covered && s.object_id == g.object_id && dot(s.normal, g.normal) >= CONFIDENCE_CREASE) n += w * s.normal;
    }
    return dot(n, n) > 0.0 ? normalize(n) : g.normal;
}

vec2 view_to_window(vec3 x) {
    vec2 ndc = x.xy * vec2(frame.proj[0][0], frame.proj[1][1]) / -x.z - vec2(frame.proj[2][0], frame.proj[2][1]);
    return (ndc * 0.5 + 0.5) * frame.viewport.xy;
}

#if CONFIDENCE
// Whether the screen-space hit `hit` (rays.hit: GL pixel, 1-based layer) of the ray
// origin + t dir (view space) passes the test; on success `hit.xy` is moved to where the ray
// crosses the settled pixel's face.
bool screen_hit_confident(inout vec4 hit, vec3 origin, vec3 dir) {
    ivec2 size = ivec2(frame.viewport.xy);
    int layer = int(hit.z) - 1;
    ivec2 first = clamp(ivec2(hit.xy), ivec2(0), size - 1);
    ivec2 hp = first;
    ScreenSurface s = screen_surface(hp, layer);
    int object = s.g.object_id;
    bool settled = false;
    vec2 q = hit.xy;
    for (int i = 0; i < CONFIDENCE_ITERATIONS && !settled; ++i) {
        vec3 x;
        if (!s.g.covered || s.g.object_id != object || !face_crossing(s, origin, dir, x)) return false;
        q = view_to_window(x);
        if (any(greaterThan(abs(q - (vec2(first) + 0.5)), vec2(CONFIDENCE_PIXELS)))) return false;
        ivec2 qp = ivec2(floor(q));
        if (any(lessThan(qp, ivec2(0))) || any(greaterThanEqual(qp, size))) return false;
        if (qp == hp) {
            if (abs(x.z - s.point.z) > CONFIDENCE_DEPTH * pixel_footprint(-s.point.z)) return false;
            settled = true;
        } else {
            hp = qp;
            s = screen_surface(hp, layer);
        }
    }
    if (!settled || !s.uniform_) return false;
    // 4. The ray goes into the surface: where it reaches the centre of the next pixel along its
    // image's major axis, it lies behind the face's plane through that pixel's sample, on the
    // same object.
    vec3 x = origin + dot(s.point - origin, s.face) / dot(dir, s.face) * dir;
    vec2 image_dir = view_to_window(x + dir * pixel_footprint(-x.z)) - q;
    int k = abs(image_dir.x) >= abs(image_dir.y) ? 0 : 1;
    float centre = (floor(q[k]) + (image_dir[k] > 0.0 ? 1.5 : -0.5)) * frame.viewport[k + 2] * 2.0 - 1.0;
    vec4 c0 = frame.proj * vec4(x, 1.0), c1 = frame.proj * vec4(dir, 0.0);
    float t1 = (centre * c0.w - c0[k]) / (c1[k] - centre * c1.w);  // NDC along axis k reaches `centre`
    vec3 x1 = x + t1 * dir;
    ivec2 p1 = ivec2(floor(view_to_window(x1)));
    p1[k] = int(floor(q[k])) + (image_dir[k] > 0.0 ? 1 : -1);
    if (!(t1 > 0.0) || x1.z >= 0.0 || any(lessThan(p1, ivec2(0))) || any(greaterThanEqual(p1, size))) return false;
    GSample g1 = screen_sample(p1, layer);
    if (!g1.covered || g1.object_id != object || dot(x1 - screen_point(p1, layer), s.face) > 0.0) return false;
    hit.xy = clamp(q, vec2(hp) + 0.001, vec2(hp) + 0.999);
    return true;
}
#endif
