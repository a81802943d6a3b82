static const char *DOC = R"DOC(
# plainarea: a constant area light through the emitter interface alone

Emits a constant `radiance` from the front side of the shape it is nested in, sampling
directions with the shape's own strategy. The same light as facet's `area` with a constant
radiance, written only against the Emitter interface: it does not declare constant_radiance(),
so the scene asks it for every sample. Built out of tree by facet's SDK test.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| radiance | spectrum | 1 | Emitted radiance |
)DOC";

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/shape.h>

#include <fmt/format.h>

#include <algorithm>

namespace facet {

class PlainArea final : public Emitter {
public:
    explicit PlainArea(const Properties &props) {
        m_radiance = props.get_color("radiance", Color3f(1.f), SpectrumKind::Emission);
        m_flags = EmitterFlags::Surface;
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        DirectionSample ds = shape().sample_direction(ref, u);
        ds.emitter = this;
        if (!(ds.pdf > 0.f) || dot(ds.n, ds.d) >= 0.f) { // only the front side emits
            ds.pdf = 0.f;
            return {ds, Color3f(0.f)};
        }
        return {ds, m_radiance / ds.pdf};
    }

    float pdf_direction(const Interaction &ref, const DirectionSample &ds) const override {
        if (dot(ds.n, ds.d) >= 0.f) return 0.f;
        return shape().pdf_direction(ref, ds);
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        return Frame::cos_theta(si.wi) > 0.f ? m_radiance : Color3f(0.f);
    }

    /// What the scene picks light samples by (radiance · area · π, as `area` estimates it):
    /// without it, plainarea's lights would be picked uniformly, area's by power.
    float power() const override {
        return Pi * shape().surface_area() * std::max(m_radiance.luminance(), 0.f);
    }

    std::string to_string() const override {
        return fmt::format("PlainArea[radiance = {}, {}, {}]", m_radiance[0], m_radiance[1],
                           m_radiance[2]);
    }

private:
    const Shape &shape() const {
        if (!m_shape) FACET_THROW("plainarea: not nested in a shape");
        return *m_shape;
    }

    Color3f m_radiance;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::PlainArea, Emitter, "plainarea", "Constant area light (SDK test)", DOC)
