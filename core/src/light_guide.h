// The light-sample guide: how often a light sample (next event estimation) is worth taking at a
// point. A survey of the scene (Scene::prepare_light_sampling()) records, per cell of a grid over
// the scene's bounds, how many of its light samples came back useful: an emitter that gives
// light, a BSDF that reflects it, and nothing in the way. Where few do (a room lit by a sky it
// sees only through glass), a point takes a light sample with probability q below 1; the
// sample's weight is divided by q and its density multiplied by it, so the estimate keeps its
// expectation and MIS stays balanced. What changes is the cost: the samples that would have
// been blocked are mostly not drawn.
#pragma once

#include <facet/bbox.h>
#include <facet/vector.h>

#include <cstdint>
#include <vector>

namespace facet::detail {

class LightGuide {
public:
    /// Cells per axis of the finest level, at most (along the box's longest axis).
    static constexpr int MaxCells = 32;
    /// Records a cell needs before its own rate decides; with fewer, the coarser level's.
    static constexpr uint32_t MinRecords = 16;
    /// A rate of useful samples at or above this keeps every light sample (q = 1); below it,
    /// q falls in proportion, down to MinProbability.
    static constexpr float FullRate = 0.25f;
    static constexpr float MinProbability = 0.1f;

    explicit LightGuide(const BoundingBox3f &bounds);

    /// One light sample of the survey at p: useful or not.
    void record(const Point3f &p, bool useful);
    /// Turns the records into each cell's probability. Returns how many cells have one below 1
    /// (0: the guide changes nothing).
    size_t finish();

    /// The probability of taking a light sample at p, in (0, 1].
    float probability(const Point3f &p) const { return m_probability[cell(p)]; }

private:
    struct Level {
        int dims[3];
        std::vector<uint32_t> records, useful;
    };
    /// The finest cell's coordinates of p (points outside the box, or not finite, clamp).
    void coordinates(const Point3f &p, int (&c)[3]) const;
    size_t index(const Level &level, const int (&c)[3], int shift) const;
    size_t cell(const Point3f &p) const {
        int c[3];
        coordinates(p, c);
        return index(m_levels[0], c, 0);
    }

    Point3f m_origin;
    float m_inv_cell[3] = {0.f, 0.f, 0.f};
    std::vector<Level> m_levels; ///< finest first; each next one halves every axis (rounding up)
    std::vector<float> m_probability; ///< per finest cell, after finish()
};

} // namespace facet::detail
