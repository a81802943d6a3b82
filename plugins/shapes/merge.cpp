static const char *DOC = R"DOC(
# merge

Combines the meshes nested in it that render alike into one mesh each, so that Embree builds one
geometry per group instead of one per mesh (faster scenes of many small meshes). As in Mitsuba 3,
meshes are merged when they share the same BSDF object (the same `<ref>` or id), have no emitter
and no sensor, no mesh attributes (such as `vertex_color`), and agree on having vertex normals
and texture coordinates; facet also requires equal `flip_normals`. A mesh without a BSDF is never
merged (Mitsuba gives each such mesh its own default BSDF). Everything else (other shapes,
emitting meshes, meshes with attributes, a lone mesh of its group) is passed through unchanged.
The scene then holds the merged meshes and the passed-through shapes, in the order their first
member appears; `merge` itself takes no parameters and is not a shape of the scene.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| (nested) | shape | — | The shapes to merge (any number; nested `merge` shapes are flattened) |

```xml
<bsdf type="diffuse" id="wood"/>
<shape type="merge">
    <shape type="ply"> <string name="filename" value="plank1.ply"/> <ref id="wood"/> </shape>
    <shape type="ply"> <string name="filename" value="plank2.ply"/> <ref id="wood"/> </shape>
</shape>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/shapegroup.h>

#include <vector>

namespace facet {

namespace {

/// One mesh made of several: their world-space arrays concatenated, with the BSDF they share.
class MergedMesh final : public Mesh {
public:
    MergedMesh(const std::vector<std::shared_ptr<Mesh>> &meshes, const std::string &name)
        : Mesh(Properties("merge")) {
        const Mesh &first = *meshes.front();
        m_name = name;
        set_bsdf(first.bsdf_ptr());
        for (const auto &mesh : meshes) {
            // The members' arrays are already in world space (one float of Embree padding
            // follows their positions).
            const uint32_t offset = uint32_t(vertex_count_so_far());
            const size_t nv = mesh->vertex_count();
            m_positions.insert(m_positions.end(), mesh->positions().begin(),
                               mesh->positions().begin() + 3 * nv);
            m_normals.insert(m_normals.end(), mesh->normals().begin(), mesh->normals().end());
            m_uvs.insert(m_uvs.end(), mesh->uvs().begin(), mesh->uvs().end());
            for (uint32_t index : mesh->faces()) m_faces.push_back(index + offset);
        }
        std::vector<float> normals = m_normals;
        initialize(Transform(), /*face_normals=*/false, first.flip_normals());
        // initialize() renormalises the normals; the members' values are kept bit for bit so
        // that the merged scene renders exactly like the separate meshes.
        m_normals = std::move(normals);
        build_face_table(); // from the members' normals, as each member built its own
    }

private:
    size_t vertex_count_so_far() const { return m_positions.size() / 3; }
};

/// What must agree for two meshes to become one (Mitsuba's merge key, plus flip_normals, which
/// facet applies when shading rather than to the arrays).
struct MergeKey {
    const BSDF *bsdf;
    bool has_normals, has_uvs, flip_normals;
    bool operator==(const MergeKey &o) const {
        return bsdf == o.bsdf && has_normals == o.has_normals && has_uvs == o.has_uvs &&
               flip_normals == o.flip_normals;
    }
};

} // namespace

class Merge final : public ShapeList {
public:
    explicit Merge(const Properties &props) {
        // Output slots in order of first appearance: a passed-through shape, or a group.
        struct Slot {
            std::shared_ptr<Shape> shape;
            MergeKey key{};
            std::vector<std::shared_ptr<Mesh>> group;
        };
        std::vector<Slot> slots;
        size_t merged_inputs = 0;
        for (const auto &[name, obj] : props.objects()) {
            auto shape = std::dynamic_pointer_cast<Shape>(obj);
            if (!shape)
                FACET_THROW_AT(props.location(name),
                               "merge: only shapes can be nested (\"{}\" is a {})", name,
                               object_type_name(obj->type()));
            props.mark_queried(name);
            for (auto &part : expand_shape(shape)) { // a nested merge is flattened
                auto mesh = std::dynamic_pointer_cast<Mesh>(part);
                if (!mesh || !mesh->bsdf() || mesh->emitter() || mesh->sensor_ptr() ||
                    !mesh->attributes().empty()) {
                    slots.push_back(Slot{part, {}, {}});
                    continue;
                }
                MergeKey key{mesh->bsdf(), mesh->has_vertex_normals(), mesh->has_uvs(),
                             mesh->flip_normals()};
                Slot *slot = nullptr;
                for (Slot &s : slots)
                    if (!s.shape && s.key == key) slot = &s;
                if (!slot) {
                    slots.push_back(Slot{nullptr, key, {}});
                    slot = &slots.back();
                }
                slot->group.push_back(std::move(mesh));
                ++merged_inputs;
            }
        }
        if (slots.empty()) FACET_THROW_AT(props.location(), "merge: no shapes are nested in it");

        size_t groups = 0;
        std::shared_ptr<Mesh> merged;
        for (Slot &s : slots) {
            if (s.shape) {
                m_shapes.push_back(std::move(s.shape));
            } else if (s.group.size() == 1) {
                m_shapes.push_back(std::move(s.group.front()));
                ++groups;
            } else {
                std::string name = props.id().empty() ? fmt::format("merge[{}]", groups)
                                                      : fmt::format("{}[{}]", props.id(), groups);
                merged = std::make_shared<MergedMesh>(s.group, name);
                m_shapes.push_back(merged);
                ++groups;
            }
        }
        // As in Mitsuba, the merge's id goes to the merged mesh when there is one group.
        if (groups == 1 && merged && !props.id().empty()) merged->set_id(props.id());
        FACET_LOG(Debug, "merge: collapsed {} meshes into {} ({} shapes passed through)",
                  merged_inputs, groups, m_shapes.size() - groups);
    }

    std::string to_string() const override {
        return fmt::format("Merge[{} shapes]", m_shapes.size());
    }
};

} // namespace facet

using facet::Merge;
FACET_EXPORT_PLUGIN_MODES(Merge, Shape, "merge",
                          "Merges nested meshes that share a BSDF into one mesh per group", DOC,
                          ::facet::AllModes)
