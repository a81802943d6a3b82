#include "light_bvh.h"

#include "direction_cone.h"

#include <algorithm>
#include <cmath>

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

/// cos(max(a - b, 0)) and sin(max(a - b, 0)) from the cosines and sines of the angles a, b in
/// [0, π].
inline float cos_minus(float sin_a, float cos_a, float sin_b, float cos_b) {
    return cos_a >= cos_b ? 1.f : cos_a * cos_b + sin_a * sin_b;
}
inline float sin_minus(float sin_a, float cos_a, float sin_b, float cos_b) {
    return cos_a >= cos_b ? 0.f : sin_a * cos_b - cos_a * sin_b;
}

constexpr int MaxDepth = 64;

} // namespace

void LightBVH::build(const std::vector<std::pair<uint32_t, LightBounds>> &items) {
    m_nodes.clear();
    m_paths.clear();
    if (items.empty()) return;
    uint32_t max_index = 0;
    for (const auto &item : items) max_index = std::max(max_index, item.first);
    m_paths.assign(size_t(max_index) + 1, {0, -1});
    std::vector<std::pair<uint32_t, LightBounds>> work = items;
    m_nodes.reserve(2 * work.size());
    build_range(work, 0, work.size(), 0, 0);
}

uint32_t LightBVH::build_range(std::vector<std::pair<uint32_t, LightBounds>> &items, size_t begin,
                               size_t end, uint64_t bits, int depth) {
    Group group;
    for (size_t i = begin; i < end; ++i) group.add(items[i].second);
    const uint32_t at = uint32_t(m_nodes.size());
    Node node;
    node.center = group.bbox.center();
    const float radius = group.bbox.bounding_sphere_radius();
    node.radius = radius;
    node.radius2 = radius * radius;
    node.axis = group.normals.axis;
    node.cos_normals = group.normals.everything() ? -1.f : std::cos(group.normals.theta);
    node.sin_normals = std::sqrt(std::max(0.f, 1.f - node.cos_normals * node.cos_normals));
    node.cos_emission = std::cos(group.theta_emission);
    node.power = float(group.power);
    node.two_sided = group.two_sided;
    m_nodes.push_back(node);
    // One emitter, or a tree as deep as the paths can record (only for degenerate inputs):
    // the first emitter of the range stands for it (the others keep depth -1: never picked).
    if (end - begin == 1 || depth == MaxDepth) {
        m_nodes[at].leaf = true;
        m_nodes[at].child = items[begin].first;
        m_paths[items[begin].first] = {bits, depth};
        return at;
    }
    // Split at the median of the centres along the box of the centres' longest side.
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
    build_range(items, begin, mid, bits, depth + 1);
    const uint32_t second = build_range(items, mid, end, bits | (uint64_t(1) << depth), depth + 1);
    m_nodes[at].child = second;
    return at;
}

inline float LightBVH::importance(const Node &node, const Point3f &p, const Normal3f &n) {
    const Vector3f v = p - node.center;
    const float dist2 = squared_norm(v);
    // Inside the node's sphere every direction may lead to it, and the distance is bounded
    // below by the sphere's radius.
    if (!(dist2 > node.radius2)) return node.radius2 > 0.f ? node.power / node.radius2 : 0.f;
    const float inv_dist = 1.f / std::sqrt(dist2), inv_dist2 = inv_dist * inv_dist;
    // The sphere around the node seen from p: the half-angle of its cone of directions.
    const float sin_bound = node.radius * inv_dist;
    const float cos2_bound = 1.f - sin_bound * sin_bound;
    // The angle from the normals' cone to the direction towards p, less the sphere's spread:
    // the light's best cosine towards p (1 when the cone holds every direction).
    float cos_p = 1.f;
    if (node.cos_normals > -1.f) {
        const float cos_bound = std::sqrt(std::max(cos2_bound, 0.f));
        float cos_w = dot(node.axis, v) * inv_dist;
        if (node.two_sided) cos_w = std::abs(cos_w);
        const float sin_w = std::sqrt(std::max(0.f, 1.f - cos_w * cos_w));
        const float cos_x = cos_minus(sin_w, cos_w, node.sin_normals, node.cos_normals);
        const float sin_x = sin_minus(sin_w, cos_w, node.sin_normals, node.cos_normals);
        cos_p = cos_minus(sin_x, cos_x, sin_bound, cos_bound);
        if (cos_p <= node.cos_emission) return 0.f;
    }
    float result = node.power * cos_p * inv_dist2;
    if (n.x != 0.f || n.y != 0.f || n.z != 0.f) {
        // The best cosine at p (either side: p may transmit) over the sphere's directions: 1
        // when the normal's direction (or its opposite) points into the sphere.
        const float cos_i = std::abs(dot(v, Vector3f(n))) * inv_dist;
        // (Floored: light arriving along the surface still counts where a shading normal, from
        // a bump or normal map, turns the surface towards it.)
        if (cos_i * cos_i < cos2_bound)
            result *= std::max(cos_i * std::sqrt(cos2_bound) +
                                   std::sqrt(std::max(0.f, 1.f - cos_i * cos_i)) * sin_bound,
                               1e-3f);
    }
    return result;
}

std::pair<uint32_t, float> LightBVH::sample(const Point3f &p, const Normal3f &n, float &u) const {
    if (m_nodes.empty()) return {0, 0.f};
    uint32_t at = 0;
    float pmf = 1.f;
    while (!m_nodes[at].leaf) {
        const uint32_t first = at + 1, second = m_nodes[at].child;
        const float a = importance(m_nodes[first], p, n), b = importance(m_nodes[second], p, n);
        if (!(a + b > 0.f)) return {0, 0.f};
        const float p_first = a / (a + b), p_second = b / (a + b);
        if (u < p_first) {
            u = std::min(u / p_first, OneMinusEpsilon);
            pmf *= p_first;
            at = first;
        } else {
            u = std::min((u - p_first) / p_second, OneMinusEpsilon);
            pmf *= p_second;
            at = second;
        }
    }
    return {m_nodes[at].child, pmf};
}

float LightBVH::pmf(const Point3f &p, const Normal3f &n, uint32_t index) const {
    if (index >= m_paths.size() || m_paths[index].second < 0) return 0.f;
    const auto [bits, depth] = m_paths[index];
    uint32_t at = 0;
    float pmf = 1.f;
    for (int k = 0; k < depth; ++k) {
        const uint32_t first = at + 1, second = m_nodes[at].child;
        const float a = importance(m_nodes[first], p, n), b = importance(m_nodes[second], p, n);
        if (!(a + b > 0.f)) return 0.f;
        if ((bits >> k) & 1) {
            pmf *= b / (a + b);
            at = second;
        } else {
            pmf *= a / (a + b);
            at = first;
        }
    }
    return pmf;
}

} // namespace facet::detail
