// The light-sample guide: how often a light sample (next event estimation) is worth taking at a
// point. A survey of the scene (Scene::prepare_light_sampling()) records, per cell of a grid over
// the scene's bounds, how many of its light samples came back useful: an emitter that gives
// light, a BSDF that reflects it, and nothing in the way. Where few do (a room lit by a sky it
// sees only through glass), a point takes a light sample with probability q below 1; the
// sample's weight is divided by q and its density multiplied by it, so the estimate keeps its
// expectation and MIS stays balanced. What changes is the cost: the samples that would have
// been blocked are mostly not drawn.
//
// The same survey also learns which emitters are worth a light sample, per cell of a coarser
// grid: each emitter's second moment there (the square of BSDF times radiance over density of its
// useful samples, times their MIS weight, over the probability its choice had), whose square root
// is the share that minimises the variance of a one-emitter sample. A cell's choice is the
// mixture of a tenth of the scene's own rule for the cell (finish()'s `own`: the light
// hierarchy's choice for the cell's box as a whole) and nine tenths of those shares, stored as
// one table per cell: no emitter that can reach a point of the cell gets less than a tenth of
// the share the cell gives it (a defence against what the survey missed), the ones the cell's
// points actually see get more, and a pick or a density is one lookup. Emitters at infinity
// keep their share (finish()'s `fixed`).
#pragma once

#include <facet/bbox.h>
#include <facet/vector.h>

#include <algorithm>
#include <cstdint>
#include <functional>
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

    /// Cells per axis of the grid the choice of emitters is learned on, at most.
    static constexpr int ChoiceCells = 16;
    /// Light samples a cell needs before its own sums decide; with fewer, the coarser level's.
    static constexpr uint32_t MinChoiceRecords = 64;
    /// The choice is learned for scenes with this many emitters, or fewer (and at least two).
    static constexpr size_t MaxChoiceEmitters = 32;
    /// The share of a cell's choice that follows the scene's own rule for the cell. 0.1 against
    /// 0.5 (when the rule was taken at each point):
    /// 0.90x the squared error of Veach's four lights (each pixel's error clipped to 1, 7 seeds),
    /// 0.98x the staircase's 13 (5 seeds), at the same spp and cost.
    static constexpr float OwnChoiceShare = 0.1f;

    /// A guide over `bounds`; `emitters` > 1 (at most MaxChoiceEmitters) also learns which
    /// emitters to choose.
    LightGuide(const BoundingBox3f &bounds, size_t emitters);

    /// One light sample of the survey at p: useful or not; `emitter` (its scene index) and
    /// `contribution` (>= 0) for the choice of emitters.
    void record(const Point3f &p, bool useful, size_t emitter = 0, float contribution = 0.f);
    /// Turns the records into each cell's probability and choice. Returns how many cells have a
    /// probability below 1 or a choice (0: the guide changes nothing). `fixed` (empty, or one
    /// value per emitter): an emitter's probability in every choice where it is >= 0 (the
    /// emitters at infinity, whose light reaches points at scales finer than a cell); the others
    /// share the rest by what the survey learned. `own(box, out)` writes the scene's own
    /// probability of each emitter for the points of a box (a cell of the choice); the choice
    /// mixes OwnChoiceShare of it (normalised to sum 1; where it is all zero, the learned
    /// shares take its place) with what was learned. Without it the own rule is uniform.
    using OwnChoice = std::function<void(const BoundingBox3f &box, float *out)>;
    size_t finish(const std::vector<float> &fixed = {}, const OwnChoice &own = {});

    /// The probability of taking a light sample at p, in (0, 1].
    float probability(const Point3f &p) const { return m_probability[cell(p)]; }
    /// The choice of emitters for p (the mixture of the own rule and what was learned): per
    /// scene index its probability (they sum to 1), then their running sums; null where none
    /// was learned, and for a point outside the grid (in no cell's box: the scene's own rule
    /// at the point decides there).
    const float *choice(const Point3f &p) const {
        int c[3];
        if (m_choice_offset.empty() || !coordinates(p, c)) return nullptr;
        const int32_t offset =
            m_choice_offset[index(m_levels[m_choice_level], c, int(m_choice_level))];
        return offset >= 0 ? m_choice.data() + offset : nullptr;
    }
    /// The number of emitters a choice covers.
    size_t emitters() const { return m_emitters; }
    /// Whether a choice was learned anywhere.
    bool chooses() const { return !m_choice_offset.empty(); }

private:
    struct Level {
        int dims[3];
        std::vector<uint32_t> records, useful;
        std::vector<double> contribution; ///< per cell, per emitter (choice levels only)
    };
    /// The finest cell's coordinates of p (points outside the box, or not finite, clamp).
    /// Returns whether p lies within the grid (its far faces included), unclamped; false for a
    /// point that is not finite. Inline, with index(): every light sample and every density of
    /// a light hit looks a cell up, from the scene's file.
    bool coordinates(const Point3f &p, int (&c)[3]) const {
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            const float x = (p[a] - m_origin[a]) * m_inv_cell[a];
            const float last = float(m_levels[0].dims[a] - 1);
            c[a] = x >= 0.f ? int(std::min(x, last)) : 0; // NaN compares false: cell 0
            inside = inside && x >= 0.f && x <= last + 1.f;
        }
        return inside;
    }
    size_t index(const Level &level, const int (&c)[3], int shift) const {
        return (size_t(c[2] >> shift) * size_t(level.dims[1]) + size_t(c[1] >> shift)) *
                   size_t(level.dims[0]) +
               size_t(c[0] >> shift);
    }
    /// finish()'s part for the choice of emitters; returns the cells that have one.
    size_t finish_choice(const std::vector<float> &fixed, const OwnChoice &own);
    /// The box of cell c of level l, widened by a thousandth of a finest cell on every side
    /// (points whose float coordinates round into the cell lie in it).
    BoundingBox3f cell_box(size_t l, const int (&c)[3]) const;
    size_t cell(const Point3f &p) const {
        int c[3];
        coordinates(p, c);
        return index(m_levels[0], c, 0);
    }

    Point3f m_origin;
    float m_inv_cell[3] = {0.f, 0.f, 0.f};
    std::vector<Level> m_levels; ///< finest first; each next one halves every axis (rounding up)
    std::vector<float> m_probability; ///< per finest cell, after finish()
    size_t m_emitters = 0;            ///< emitters the choice covers (0: no choice learned)
    size_t m_choice_level = 0;        ///< the finest level the choice is learned on
    /// Per cell of the choice level: where its choice starts in m_choice, or -1.
    std::vector<int32_t> m_choice_offset;
    std::vector<float> m_choice; ///< per cell: the emitters' probabilities, then their sums
};

} // namespace facet::detail
