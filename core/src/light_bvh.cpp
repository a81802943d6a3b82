#include "light_bvh.h"

#include "direction_cone.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace facet::detail {

namespace {

/// The bounds of a group of emitters: box, normals' cone, emission spread, power.
struct Group {
    BoundingBox3f bbox;
    DirectionCone normals;
    float theta_emission = 0.f;
    double power = 0.0;
    bool two_sided = false;

    void add(const LightBounds &b) {
        bbox.expand(b.bbox);
        const float theta = b.cos_normals <= -1.f ? Pi : std::acos(std::min(b.cos_normals, 1.f));
        normals = merge(normals, DirectionCone{normalize(b.axis), theta});
        // At most a hemisphere (LightBounds): beyond it the falloff bound would be negative.
        theta_emission = std::max(theta_emission, std::acos(std::clamp(b.cos_emission, 0.f, 1.f)));
        power += double(b.power);
        two_sided = two_sided || b.two_sided;
    }
};

/// Four floats, one per child of a node, with the operations the importance needs: SSE where
/// the target has it, else a loop the compiler may vectorise. Both give the same bits (each
/// operation is the IEEE one, lane by lane).
#if defined(__SSE2__)
struct F4 {
    __m128 v;
    static F4 load(const float *p) { return {_mm_load_ps(p)}; }
    static F4 all(float x) { return {_mm_set1_ps(x)}; }
    void store(float *p) const { _mm_storeu_ps(p, v); }
};
inline F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
inline F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
inline F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
inline F4 operator/(F4 a, F4 b) { return {_mm_div_ps(a.v, b.v)}; }
inline F4 sqrt(F4 a) { return {_mm_sqrt_ps(a.v)}; }
/// max(a, b) as std::max(b, a) reads: b unless a > b (so a NaN in a gives b).
inline F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }
inline F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.f), a.v)}; }
struct M4 {
    __m128 v;
};
inline M4 operator>(F4 a, F4 b) { return {_mm_cmpgt_ps(a.v, b.v)}; }
inline M4 operator>=(F4 a, F4 b) { return {_mm_cmpge_ps(a.v, b.v)}; }
inline M4 operator<(F4 a, F4 b) { return {_mm_cmplt_ps(a.v, b.v)}; }
inline M4 operator<=(F4 a, F4 b) { return {_mm_cmple_ps(a.v, b.v)}; }
inline M4 operator&(M4 a, M4 b) { return {_mm_and_ps(a.v, b.v)}; }
/// m ? a : b, lane by lane.
inline F4 select(M4 m, F4 a, F4 b) {
    return {_mm_or_ps(_mm_and_ps(m.v, a.v), _mm_andnot_ps(m.v, b.v))};
}
#else
struct F4 {
    float v[4];
    static F4 load(const float *p) { return {{p[0], p[1], p[2], p[3]}}; }
    static F4 all(float x) { return {{x, x, x, x}}; }
    void store(float *p) const { std::copy(v, v + 4, p); }
};
template <typename Op> F4 lanes(F4 a, F4 b, Op op) {
    return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
}
inline F4 operator+(F4 a, F4 b) {
    return lanes(a, b, [](float x, float y) { return x + y; });
}
inline F4 operator-(F4 a, F4 b) {
    return lanes(a, b, [](float x, float y) { return x - y; });
}
inline F4 operator*(F4 a, F4 b) {
    return lanes(a, b, [](float x, float y) { return x * y; });
}
inline F4 operator/(F4 a, F4 b) {
    return lanes(a, b, [](float x, float y) { return x / y; });
}
inline F4 sqrt(F4 a) {
    return lanes(a, a, [](float x, float) { return std::sqrt(x); });
}
inline F4 max(F4 a, F4 b) {
    return lanes(a, b, [](float x, float y) { return x > y ? x : y; });
}
inline F4 abs(F4 a) {
    return lanes(a, a, [](float x, float) { return std::abs(x); });
}
struct M4 {
    bool v[4];
};
template <typename Op> M4 compare(F4 a, F4 b, Op op) {
    return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
}
inline M4 operator>(F4 a, F4 b) {
    return compare(a, b, [](float x, float y) { return x > y; });
}
inline M4 operator>=(F4 a, F4 b) {
    return compare(a, b, [](float x, float y) { return x >= y; });
}
inline M4 operator<(F4 a, F4 b) {
    return compare(a, b, [](float x, float y) { return x < y; });
}
inline M4 operator<=(F4 a, F4 b) {
    return compare(a, b, [](float x, float y) { return x <= y; });
}
inline M4 operator&(M4 a, M4 b) {
    return {{a.v[0] && b.v[0], a.v[1] && b.v[1], a.v[2] && b.v[2], a.v[3] && b.v[3]}};
}
inline F4 select(M4 m, F4 a, F4 b) {
    return {{m.v[0] ? a.v[0] : b.v[0], m.v[1] ? a.v[1] : b.v[1], m.v[2] ? a.v[2] : b.v[2],
             m.v[3] ? a.v[3] : b.v[3]}};
}
#endif

/// cos(max(a - b, 0)) and sin(max(a - b, 0)) from the cosines and sines of the angles a, b in
/// [0, π], lane by lane.
inline F4 cos_minus(F4 sin_a, F4 cos_a, F4 sin_b, F4 cos_b) {
    return select(cos_a >= cos_b, F4::all(1.f), cos_a * cos_b + sin_a * sin_b);
}
inline F4 sin_minus(F4 sin_a, F4 cos_a, F4 sin_b, F4 cos_b) {
    return select(cos_a >= cos_b, F4::all(0.f), sin_a * cos_b - cos_a * sin_b);
}

/// Levels a path can record: two bits each in 64.
constexpr int MaxDepth = 32;

} // namespace

void LightBVH::build(const std::vector<std::pair<uint32_t, LightBounds>> &items) {
    m_nodes.clear();
    m_paths.clear();
    if (items.empty()) return;
    uint32_t max_index = 0;
    for (const auto &item : items) max_index = std::max(max_index, item.first);
    m_paths.assign(size_t(max_index) + 1, {0, -1});
    std::vector<std::pair<uint32_t, LightBounds>> work = items;
    m_nodes.reserve(work.size());
    build_range(work, 0, work.size(), 0, 0);
}

namespace {

/// Splits items[begin, end) at the median of the centres along the longest side of their box:
/// returns the first item of the second half.
size_t split_at_median(std::vector<std::pair<uint32_t, LightBounds>> &items, size_t begin,
                       size_t end) {
    BoundingBox3f centres;
    for (size_t i = begin; i < end; ++i) centres.expand(items[i].second.bbox.center());
    const Vector3f extent = centres.max - centres.min;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0
                     : extent.y >= extent.z                       ? 1
                                                                  : 2;
    const size_t mid = begin + (end - begin) / 2;
    std::nth_element(items.begin() + long(begin), items.begin() + long(mid),
                     items.begin() + long(end), [axis](const auto &a, const auto &b) {
                         const Point3f ca = a.second.bbox.center(), cb = b.second.bbox.center();
                         if (ca[axis] != cb[axis]) return ca[axis] < cb[axis];
                         return a.first < b.first; // a strict order also for equal centres
                     });
    return mid;
}

} // namespace

uint32_t LightBVH::build_range(std::vector<std::pair<uint32_t, LightBounds>> &items, size_t begin,
                               size_t end, uint64_t path, int depth) {
    // The node's children: the range split at its median, each half split again when it holds
    // more than one emitter (a binary tree's two levels in one node). At the deepest level the
    // paths can record (never reached: the median splits make the tree log4 n deep) a child
    // keeps the first emitter of its range.
    std::vector<std::pair<size_t, size_t>> parts;
    if (end - begin == 1) {
        parts.emplace_back(begin, begin + 1);
    } else {
        const size_t mid = split_at_median(items, begin, end);
        for (const auto &[b, e] : {std::pair<size_t, size_t>{begin, mid}, {mid, end}}) {
            if (e - b == 1) {
                parts.emplace_back(b, e);
            } else {
                const size_t m = split_at_median(items, b, e);
                parts.emplace_back(b, m);
                parts.emplace_back(m, e);
            }
        }
    }
    const uint32_t at = uint32_t(m_nodes.size());
    m_nodes.emplace_back();
    Node node;
    for (int k = 0; k < Arity; ++k) {
        // An unused slot: no power, far from nothing.
        node.cx[k] = node.cy[k] = node.cz[k] = 0.f;
        node.radius[k] = node.radius2[k] = 0.f;
        node.ax[k] = node.ay[k] = 0.f;
        node.az[k] = 1.f;
        node.cos_normals[k] = -1.f;
        node.sin_normals[k] = 0.f;
        node.cos_emission[k] = 0.f;
        node.power[k] = 0.f;
        node.inside[k] = 0.f;
        node.two_sided[k] = 0.f;
        node.child[k] = 0;
    }
    node.count = uint8_t(parts.size());
    for (size_t k = 0; k < parts.size(); ++k) {
        const auto [b, e] = parts[k];
        Group group;
        for (size_t i = b; i < e; ++i) group.add(items[i].second);
        const Point3f c = group.bbox.center();
        const float radius = group.bbox.bounding_sphere_radius();
        node.cx[k] = c.x;
        node.cy[k] = c.y;
        node.cz[k] = c.z;
        node.radius[k] = radius;
        node.radius2[k] = radius * radius;
        node.ax[k] = group.normals.axis.x;
        node.ay[k] = group.normals.axis.y;
        node.az[k] = group.normals.axis.z;
        const float cos_n = group.normals.everything() ? -1.f : std::cos(group.normals.theta);
        node.cos_normals[k] = cos_n;
        node.sin_normals[k] = std::sqrt(std::max(0.f, 1.f - cos_n * cos_n));
        node.cos_emission[k] = std::cos(group.theta_emission);
        node.power[k] = float(group.power);
        // (The division importance() made at every call, the same float operation.)
        node.inside[k] = node.radius2[k] > 0.f ? node.power[k] / node.radius2[k] : 0.f;
        node.two_sided[k] = group.two_sided ? 1.f : 0.f;
        const uint64_t child_path = path | (uint64_t(k) << (2 * depth));
        if (e - b == 1 || depth + 1 == MaxDepth) {
            node.leaf = uint8_t(node.leaf | (1u << k));
            node.child[k] = items[b].first;
            m_paths[items[b].first] = {child_path, depth + 1};
        } else {
            node.child[k] = build_range(items, b, e, child_path, depth + 1);
        }
    }
    m_nodes[at] = node;
    return at;
}

void LightBVH::importance(const Node &node, const Point3f &p, const Normal3f &n,
                          float (&out)[Arity]) {
    const F4 vx = F4::all(p.x) - F4::load(node.cx), vy = F4::all(p.y) - F4::load(node.cy),
             vz = F4::all(p.z) - F4::load(node.cz);
    const F4 dist2 = vx * vx + vy * vy + vz * vz;
    const F4 radius = F4::load(node.radius), radius2 = F4::load(node.radius2);
    const F4 power = F4::load(node.power);
    const F4 one = F4::all(1.f), zero = F4::all(0.f);
    // Inside a child's sphere every direction may lead to it, and the distance is bounded
    // below by the sphere's radius.
    const M4 outside = dist2 > radius2;
    const F4 inside_value = F4::load(node.inside);
    const F4 inv_dist = one / sqrt(dist2), inv_dist2 = inv_dist * inv_dist;
    // The sphere around the child seen from p: the half-angle of its cone of directions.
    const F4 sin_bound = radius * inv_dist;
    const F4 cos2_bound = one - sin_bound * sin_bound;
    const F4 cos_bound = sqrt(max(cos2_bound, zero));
    // The angle from the normals' cone to the direction towards p, less the sphere's spread:
    // the light's best cosine towards p (1 when the cone holds every direction).
    const F4 cos_normals = F4::load(node.cos_normals), sin_normals = F4::load(node.sin_normals);
    F4 cos_w =
        (F4::load(node.ax) * vx + F4::load(node.ay) * vy + F4::load(node.az) * vz) * inv_dist;
    cos_w = select(F4::load(node.two_sided) > zero, abs(cos_w), cos_w);
    const F4 sin_w = sqrt(max(one - cos_w * cos_w, zero));
    const F4 cos_x = cos_minus(sin_w, cos_w, sin_normals, cos_normals);
    const F4 sin_x = sin_minus(sin_w, cos_w, sin_normals, cos_normals);
    const M4 has_cone = cos_normals > F4::all(-1.f);
    const F4 cos_p = select(has_cone, cos_minus(sin_x, cos_x, sin_bound, cos_bound), one);
    const M4 turned_away = has_cone & (cos_p <= F4::load(node.cos_emission));
    F4 result = power * cos_p * inv_dist2;
    if (n.x != 0.f || n.y != 0.f || n.z != 0.f) {
        // The best cosine at p (either side: p may transmit) over the sphere's directions: 1
        // when the normal's direction (or its opposite) points into the sphere.
        const F4 cos_i = abs(vx * F4::all(n.x) + vy * F4::all(n.y) + vz * F4::all(n.z)) * inv_dist;
        // (Floored: light arriving along the surface still counts where a shading normal, from
        // a bump or normal map, turns the surface towards it.)
        const F4 factor = max(cos_i * cos_bound + sqrt(max(one - cos_i * cos_i, zero)) * sin_bound,
                              F4::all(1e-3f));
        result = select(cos_i * cos_i < cos2_bound, result * factor, result);
    }
    result = select(turned_away, zero, result);
    // Never negative (cos of a float π/2 is slightly below zero: cos_p can be), and nothing
    // for a slot without power (an unused one: a NaN from a point at its centre included).
    result = max(select(outside, result, inside_value), zero);
    select(power > zero, result, zero).store(out);
}

void LightBVH::importance(const Node &node, const BoundingBox3f &box, float (&out)[Arity]) {
    // The box within the sphere of radius rb around cb. A point p of it lies at least
    // dmin = |cb - c| - rb from a child's centre c, and the direction from c to p within
    // asin(rb / |cb - c|) of the direction to cb: every distance the point importance divides
    // by is at least max(dmin, r) (r the child's radius; P / r² inside its sphere), and every
    // angle it takes from the normals' cone at least the one at cb less that spread and less
    // the child's own spread seen from dmin. (In double; a thousandth of a radian of margin
    // for the point importance's float rounding.)
    const Point3f cb = box.center();
    const double rb = double(box.bounding_sphere_radius());
    for (int k = 0; k < Arity; ++k) {
        out[k] = 0.f;
        if (!(node.power[k] > 0.f)) continue;
        const double vx = double(cb.x) - double(node.cx[k]), vy = double(cb.y) - double(node.cy[k]),
                     vz = double(cb.z) - double(node.cz[k]);
        const double dist = std::sqrt(vx * vx + vy * vy + vz * vz);
        const double r = double(node.radius[k]);
        // A point light inside the box: its importance has no bound there; the distance is
        // floored at a hundredth of the box's radius (it takes nearly all the box's share).
        const double near = std::max({dist - rb, r, 0.01 * rb});
        double cos_p = 1.0;
        if (node.cos_normals[k] > -1.f && dist > rb && dist - rb > r) {
            double cos_w =
                (double(node.ax[k]) * vx + double(node.ay[k]) * vy + double(node.az[k]) * vz) /
                dist;
            if (node.two_sided[k] > 0.f) cos_w = std::abs(cos_w);
            const double theta = std::acos(std::clamp(cos_w, -1.0, 1.0)) -
                                 std::acos(std::clamp(double(node.cos_normals[k]), -1.0, 1.0)) -
                                 std::asin(rb / dist) - std::asin(r / (dist - rb)) - 1e-3;
            if (theta > 0.0) {
                if (theta >= std::acos(std::clamp(double(node.cos_emission[k]), -1.0, 1.0)))
                    continue; // turned away from every point of the box
                cos_p = std::cos(theta);
            }
        }
        const double value = double(node.power[k]) * cos_p / (near * near);
        out[k] = float(std::min(value, double(std::numeric_limits<float>::max())));
    }
}

namespace {

/// The sum of the children's importances at a node, or 0 where they give no probabilities.
float total_of(const float (&w)[LightBVH::Arity]) {
    const float total = (w[0] + w[1]) + (w[2] + w[3]);
    // (An infinite total, a point at a point light's position, would make every share 0 or
    // NaN: nothing is picked there.)
    return total > 0.f && std::isfinite(total) ? total : 0.f;
}

/// The children's probabilities at a node: importance over their sum, in slot order.
bool shares(const float (&w)[LightBVH::Arity], float (&p)[LightBVH::Arity]) {
    const float total = total_of(w);
    if (total == 0.f) return false;
    for (int k = 0; k < LightBVH::Arity; ++k) p[k] = w[k] / total;
    return true;
}

} // namespace

std::pair<uint32_t, float> LightBVH::sample(const Point3f &p, const Normal3f &n, float &u) const {
    if (m_nodes.empty()) return {0, 0.f};
    uint32_t at = 0;
    float pmf = 1.f;
    for (;;) {
        const Node &node = m_nodes[at];
        float w[Arity], share[Arity];
        importance(node, p, n, w);
        if (!shares(w, share)) return {0, 0.f};
        // The first child whose running share passes u; past the end (rounding) the last one
        // with a share.
        int k = 0, last = -1;
        float below = 0.f;
        for (; k < node.count; ++k) {
            if (!(share[k] > 0.f)) continue;
            last = k;
            if (u < below + share[k]) break;
            below += share[k];
        }
        if (k == node.count) {
            if (last < 0) return {0, 0.f};
            k = last;
            below -= share[k];
        }
        u = std::clamp((u - below) / share[k], 0.f, OneMinusEpsilon);
        pmf *= share[k];
        if ((node.leaf >> k) & 1) return {node.child[k], pmf};
        at = node.child[k];
    }
}

float LightBVH::pmf(const Point3f &p, const Normal3f &n, uint32_t index) const {
    if (index >= m_paths.size() || m_paths[index].second < 0) return 0.f;
    const auto [path, depth] = m_paths[index];
    uint32_t at = 0;
    float pmf = 1.f;
    for (int level = 0; level < depth; ++level) {
        const Node &node = m_nodes[at];
        float w[Arity];
        importance(node, p, n, w);
        const float total = total_of(w);
        if (total == 0.f) return 0.f;
        // The share sample() takes for this child, and only that one.
        const int k = int((path >> (2 * level)) & 3);
        pmf *= w[k] / total;
        at = node.child[k];
    }
    return pmf;
}

void LightBVH::pmf(const BoundingBox3f &box, std::vector<float> &out) const {
    out.assign(m_paths.size(), 0.f);
    if (m_nodes.empty() || !box.valid()) return;
    // Depth first from the root: each node with the probability of reaching it.
    std::vector<std::pair<uint32_t, double>> pending{{0u, 1.0}};
    while (!pending.empty()) {
        const auto [at, reach] = pending.back();
        pending.pop_back();
        const Node &node = m_nodes[at];
        float w[Arity];
        importance(node, box, w);
        const double total = (double(w[0]) + double(w[1])) + (double(w[2]) + double(w[3]));
        if (!(total > 0.0)) continue;
        for (int k = 0; k < node.count; ++k) {
            const double share = reach * (double(w[k]) / total);
            if (!(share > 0.0)) continue;
            if ((node.leaf >> k) & 1)
                out[node.child[k]] = float(share);
            else
                pending.emplace_back(node.child[k], share);
        }
    }
}

} // namespace facet::detail
