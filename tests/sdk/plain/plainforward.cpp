static const char *DOC = R"DOC(
# plainforward: facet's path tracer behind the SamplingIntegrator interface alone

Creates facet's `path` integrator with the same `max_depth` and hands every camera ray to its
sample(). It does not override takes_first_hit(), so the render loop traces each camera ray
with the path (one query per ray) instead of in packets with its neighbours. Built out of tree
by facet's SDK test.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| max_depth | integer | -1 | Longest path, as `path`'s |
| samples_per_pass | integer | (schedule) | Samples of each pixel per pass, as every sampling integrator's |
)DOC";

#include <facet/integrator.h>
#include <facet/plugin.h>

#include <fmt/format.h>

namespace facet {

class PlainForward final : public SamplingIntegrator {
public:
    explicit PlainForward(const Properties &props) : SamplingIntegrator(props) {
        Properties path("path");
        path.set_int("max_depth", props.get_int("max_depth", -1));
        m_path = std::dynamic_pointer_cast<SamplingIntegrator>(
            PluginRegistry::instance().create(ObjectType::Integrator, path));
        if (!m_path) FACET_THROW("plainforward: `path` is not a sampling integrator");
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                   float *aovs) const override {
        return m_path->sample(scene, sampler, ray, aovs);
    }

    std::string to_string() const override {
        return fmt::format("PlainForward[{}]", m_path->to_string());
    }

private:
    std::shared_ptr<SamplingIntegrator> m_path;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::PlainForward, Integrator, "plainforward",
                    "The path tracer without the camera rays' packets (SDK test)", DOC)
