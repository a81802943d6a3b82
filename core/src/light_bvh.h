// The scene's light hierarchy: a binary tree over the emitters that have bounds (LightBounds),
// which picks an emitter for a point in proportion to a bound of its importance there (power
// over squared distance, times the best cosines the bounds allow), choosing a child at each
// node. Emitters that cannot reach the point get nothing; far, dim or turned-away ones little.
// The probability of an emitter for a point is recomputed along the emitter's path from the
// root with the same arithmetic, so that sampling and pmf() agree to the last bit.
#pragma once

#include <facet/emitter.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace facet::detail {

class LightBVH {
public:
    /// Builds the tree over `items`: (the emitter's index in the scene, its bounds).
    void build(const std::vector<std::pair<uint32_t, LightBounds>> &items);
    bool empty() const { return m_nodes.empty(); }

    /// Picks an emitter for the point p with geometric normal n (zero: a point in space) from
    /// u in [0, 1), which becomes a fresh uniform variate. Returns the emitter's scene index and
    /// its probability; probability 0 (and index 0) when no emitter can reach p.
    std::pair<uint32_t, float> sample(const Point3f &p, const Normal3f &n, float &u) const;
    /// The probability that sample() picks the emitter of scene index `index` for (p, n); 0 for
    /// one that is not in the tree.
    float pmf(const Point3f &p, const Normal3f &n, uint32_t index) const;

private:
    /// A node's bounds, as the importance reads them.
    struct Node {
        Point3f center;     ///< of the bounding box
        float radius = 0;   ///< of the box's bounding sphere
        float radius2 = 0;  ///< its square
        Vector3f axis;      ///< of the normals' cone
        float cos_normals;  ///< of the normals' cone's half-angle
        float sin_normals;  ///< of the same
        float cos_emission; ///< of the emission's spread beyond the normals
        float power = 0;
        bool two_sided = false;
        bool leaf = false;
        /// Inner: the second child (the first follows the node); leaf: the scene index.
        uint32_t child = 0;
    };
    static float importance(const Node &node, const Point3f &p, const Normal3f &n);
    uint32_t build_range(std::vector<std::pair<uint32_t, LightBounds>> &items, size_t begin,
                         size_t end, uint64_t bits, int depth);

    std::vector<Node> m_nodes;
    /// Per scene index: the emitter's path from the root (bit k: the second child at depth k)
    /// and its depth; depth -1 for an emitter not in the tree.
    std::vector<std::pair<uint64_t, int>> m_paths;
};

} // namespace facet::detail
