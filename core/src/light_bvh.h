// The scene's light hierarchy: a tree over the emitters that have bounds (LightBounds), four
// children per node, which picks an emitter for a point in proportion to a bound of its
// importance there (power over squared distance, times the best cosines the bounds allow),
// choosing a child at each node. Emitters that cannot reach the point get nothing; far, dim or
// turned-away ones little. The probability of an emitter for a point is recomputed along the
// emitter's path from the root with the same arithmetic, so that sampling and pmf() agree to the
// last bit.
#pragma once

#include <facet/bbox.h>
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
    /// The probability of every emitter by the same tree for a whole box of points, in `out`
    /// by scene index (0 for one not in the tree): each node's children in proportion to a
    /// bound of their importance over the box (at least their importance at any point of it,
    /// for any normal), each node evaluated once. An emitter with a probability at some point
    /// of the box has one for the box (the light guide's floor).
    void pmf(const BoundingBox3f &box, std::vector<float> &out) const;

    /// Children per node: the importances of a node's children are computed together, one
    /// child per lane of a 4-wide vector.
    static constexpr int Arity = 4;

private:
    /// A node: the bounds of its (up to four) children, as the importance reads them, one
    /// array per quantity (a lane per child). An unused slot has power 0.
    struct alignas(16) Node {
        float cx[Arity], cy[Arity], cz[Arity]; ///< centre of the child's bounding box
        float radius[Arity];                   ///< of the box's bounding sphere
        float radius2[Arity];                  ///< its square
        float ax[Arity], ay[Arity], az[Arity]; ///< axis of the normals' cone
        float cos_normals[Arity];              ///< of the normals' cone's half-angle
        float sin_normals[Arity];              ///< of the same
        float cos_emission[Arity];             ///< of the emission's spread beyond the normals
        float power[Arity];
        float inside[Arity];    ///< power / radius2 (0 for radius 0): the value inside the sphere
        float two_sided[Arity]; ///< 1 for a two-sided child, else 0
        /// Inner child: its node; leaf child: the emitter's scene index.
        uint32_t child[Arity];
        uint8_t count = 0; ///< slots in use (the first ones)
        uint8_t leaf = 0;  ///< bit k: slot k is an emitter
    };
    /// The importances of a node's children for (p, n).
    static void importance(const Node &node, const Point3f &p, const Normal3f &n,
                           float (&out)[Arity]);
    /// The bound of the importances of a node's children over the points of a box.
    static void importance(const Node &node, const BoundingBox3f &box, float (&out)[Arity]);
    uint32_t build_range(std::vector<std::pair<uint32_t, LightBounds>> &items, size_t begin,
                         size_t end, uint64_t path, int depth);

    std::vector<Node> m_nodes;
    /// Per scene index: the emitter's path from the root (two bits per level: the slot taken
    /// at depth k in bits 2k and 2k+1) and its depth; depth -1 for an emitter not in the tree.
    std::vector<std::pair<uint64_t, int>> m_paths;
};

} // namespace facet::detail
