// traverse(): the parameters of a loaded scene, changed in place (facet/params.h).
//
// The scene keeps the descriptions the loader built its objects from (scene_description.h).
// update() builds again, from their edited descriptions, the objects whose values changed and
// every object that holds one of them, children first and each once, as the loader does; a shape
// that only holds a changed BSDF or emitter is given the new one instead (its geometry stays).
// The scene is then rebuilt from its children, keeping its Embree scene when no shape changed.
// So an updated scene is made of the objects a fresh load of the edited scene would make.

#include "scene_description.h"

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/logger.h>
#include <facet/params.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/shape.h>

#include <algorithm>
#include <map>

namespace facet {
namespace {

using Node = SceneDescription::Node;
using NoNodeT = decltype(SceneDescription::NoNode);
constexpr NoNodeT NoNode = SceneDescription::NoNode;

bool is_arg_name(const std::string &name) { return name.rfind("_arg_", 0) == 0; }

/// The path of every node (see SceneParameters); the root's is empty.
std::vector<std::string> node_paths(const SceneDescription &d) {
    const size_t n = d.nodes.size();
    std::vector<std::string> path(n);
    // Parents come after their children in creation order: name from the root down.
    for (size_t p = n; p-- > 0;) {
        const Node &parent = d.nodes[p];
        if (p != d.root && path[p].empty()) continue; // unreachable (cannot happen)
        std::map<std::string, size_t> unnamed;        // tag -> count of `_arg_N` children
        for (const auto &e : parent.entries)
            if (e.child != NoNode && is_arg_name(e.name))
                ++unnamed[object_type_name(d.nodes[e.child].kind)];
        std::map<std::string, size_t> seen;
        for (const auto &e : parent.entries) {
            if (e.child == NoNode) continue;
            const Node &child = d.nodes[e.child];
            std::string name = e.name;
            if (is_arg_name(name)) {
                std::string tag = object_type_name(child.kind);
                size_t k = seen[tag]++;
                name = unnamed[tag] > 1 || p == d.root ? fmt::format("{}_{}", tag, k) : tag;
                if (p == d.root && unnamed[tag] == 1 &&
                    (child.kind == ObjectType::Sensor || child.kind == ObjectType::Integrator))
                    name = tag; // the scene's one sensor and integrator
            }
            if (!child.id.empty())
                path[e.child] = child.id;
            else if (path[e.child].empty())
                path[e.child] = p == d.root ? name : path[p] + "." + name;
        }
    }
    return path;
}

} // namespace

SceneParameters traverse(const std::shared_ptr<Scene> &scene) {
    if (!scene) FACET_THROW("traverse(): no scene");
    const std::shared_ptr<SceneDescription> &d = scene->description();
    if (!d)
        FACET_THROW("traverse(): the scene was not loaded from a scene description, so its "
                    "parameters are not known");
    SceneParameters params;
    params.m_scene = scene;
    std::vector<std::string> path = node_paths(*d);
    std::vector<std::string> settable;
    for (size_t i = 0; i < d->nodes.size(); ++i) {
        if (i == d->root) continue;
        const Node &node = d->nodes[i];
        for (const auto &e : node.entries) {
            if (e.child != NoNode) continue;
            if (std::holds_alternative<std::shared_ptr<Object>>(e.value)) continue;
            std::string key = path[i] + "." + e.name;
            if (params.m_slots.emplace(key, SceneParameters::Slot{i, e.name}).second)
                params.m_keys.push_back(key);
        }
        for (const std::string &name : node.requested) {
            std::string key = path[i] + "." + name;
            bool child = std::any_of(node.entries.begin(), node.entries.end(),
                                     [&](const auto &e) { return e.name == name; });
            if (!child) params.m_slots.emplace(key, SceneParameters::Slot{i, name});
        }
    }
    return params;
}

void SceneParameters::unknown_key(const std::string &key) const {
    std::vector<std::string> all;
    all.reserve(m_slots.size());
    for (const auto &kv : m_slots) all.push_back(kv.first);
    std::string close = closest_name(key, all);
    FACET_THROW("unknown scene parameter \"{}\"{}", key,
                close.empty() ? std::string(" (keys() lists them)")
                              : fmt::format(" (did you mean \"{}\"?)", close));
}

const SceneParameters::Slot &SceneParameters::slot(const std::string &key) const {
    auto it = m_slots.find(key);
    if (it == m_slots.end()) unknown_key(key);
    return it->second;
}

namespace {

const SceneDescription::Entry *find_entry(const Node &node, const std::string &name) {
    for (const auto &e : node.entries)
        if (e.name == name) return &e;
    return nullptr;
}

} // namespace

bool SceneParameters::is_set(const std::string &key) const {
    const Slot &s = slot(key);
    for (const auto &p : m_pending)
        if (p.first == key) return true;
    return find_entry(m_scene->description()->nodes[s.node], s.name) != nullptr;
}

const Properties::Value &SceneParameters::get(const std::string &key) const {
    const Slot &s = slot(key);
    for (auto it = m_pending.rbegin(); it != m_pending.rend(); ++it)
        if (it->first == key) return it->second;
    const auto *e = find_entry(m_scene->description()->nodes[s.node], s.name);
    if (!e)
        FACET_THROW("scene parameter \"{}\" is not set in the scene (the plugin's default "
                    "applies); set() gives it a value",
                    key);
    return e->value;
}

Properties::Type SceneParameters::type(const std::string &key) const {
    return Properties::Type(get(key).index());
}

void SceneParameters::set(const std::string &key, Properties::Value value) {
    const Slot &s = slot(key);
    if (std::holds_alternative<std::shared_ptr<Object>>(value))
        FACET_THROW("scene parameter \"{}\": objects cannot be set, only values", key);
    if (is_set(key)) {
        const auto want = Properties::Type(get(key).index());
        const auto have = Properties::Type(value.index());
        if (want == Properties::Type::Float && have == Properties::Type::Integer)
            value = double(std::get<int64_t>(value));
        else if (want == Properties::Type::Color && have == Properties::Type::Float)
            value = Color3f(float(std::get<double>(value)));
        else if (want == Properties::Type::Color && have == Properties::Type::Integer)
            value = Color3f(float(std::get<int64_t>(value)));
        else if (want != have)
            FACET_THROW("scene parameter \"{}\" has type {}, not {}", key,
                        Properties::type_name(want), Properties::type_name(have));
    }
    (void)s; // slot() has checked the key
    m_pending.emplace_back(key, std::move(value));
}

SceneUpdate SceneParameters::update() {
    SceneUpdate stats;
    if (m_pending.empty()) return stats;
    std::vector<std::pair<std::string, Properties::Value>> pending;
    pending.swap(m_pending); // dropped on an error too
    SceneDescription &d = *m_scene->description();
    const size_t n = d.nodes.size();

    // The edited entries of the nodes whose values change.
    std::vector<bool> changed(n, false);
    std::map<size_t, std::vector<SceneDescription::Entry>> edited;
    for (auto &[key, value] : pending) {
        const Slot &s = slot(key);
        auto it = edited.find(s.node);
        if (it == edited.end()) it = edited.emplace(s.node, d.nodes[s.node].entries).first;
        auto e = std::find_if(it->second.begin(), it->second.end(),
                              [&](const auto &x) { return x.name == s.name; });
        if (e == it->second.end()) {
            SceneDescription::Entry entry;
            entry.name = s.name;
            entry.location = d.nodes[s.node].location;
            it->second.push_back(std::move(entry));
            e = it->second.end() - 1;
        }
        e->value = value;
        changed[s.node] = true;
    }
    auto entries_of = [&](size_t i) -> const std::vector<SceneDescription::Entry> & {
        auto it = edited.find(i);
        return it == edited.end() ? d.nodes[i].entries : it->second;
    };

    // Which objects are built again, and which shapes only take a new BSDF or emitter.
    std::vector<bool> recreate(n, false), relink(n, false);
    for (size_t i = 0; i < n; ++i) {
        if (i == d.root) continue;
        const Node &node = d.nodes[i];
        bool other = false, linkable = false;
        for (const auto &e : node.entries) {
            if (e.child == NoNode || !recreate[e.child]) continue;
            ObjectType kind = d.nodes[e.child].kind;
            if (node.kind == ObjectType::Shape &&
                (kind == ObjectType::BSDF || kind == ObjectType::Emitter))
                linkable = true;
            else
                other = true;
        }
        if (changed[i] || other)
            recreate[i] = true;
        else if (linkable)
            relink[i] = true;
    }
    // A shape built again takes new emitters and sensors (each belongs to one shape), as a
    // fresh load gives it; they hold nothing that depends on them.
    for (size_t i = 0; i < n; ++i)
        if (recreate[i] && d.nodes[i].kind == ObjectType::Shape)
            for (const auto &e : d.nodes[i].entries)
                if (e.child != NoNode && (d.nodes[e.child].kind == ObjectType::Emitter ||
                                          d.nodes[e.child].kind == ObjectType::Sensor))
                    recreate[e.child] = true;

    std::vector<std::shared_ptr<Object>> fresh(n);
    std::vector<std::vector<std::string>> requested(n);
    auto instance = [&](size_t i) { return recreate[i] ? fresh[i] : d.nodes[i].instance; };
    auto &registry = PluginRegistry::instance();
    // File names are found as the load found them; the caller's resolver comes back after.
    struct ResolverScope {
        FileResolver saved = file_resolver();
        explicit ResolverScope(const FileResolver &r) { file_resolver() = r; }
        ~ResolverScope() { file_resolver() = saved; }
    } resolver_scope(d.resolver);
    for (size_t i = 0; i < n; ++i) {
        if (!recreate[i]) continue;
        const Node &node = d.nodes[i];
        Properties props(node.plugin);
        props.set_mode(d.mode);
        props.set_id(node.id);
        props.set_location(node.location);
        for (const auto &e : entries_of(i)) {
            if (e.child == NoNode)
                props.set(e.name, e.value, e.location);
            else
                props.set(e.name, instance(e.child), e.location);
        }
        fresh[i] = registry.create(node.kind, props, d.lenient);
        if (!node.id.empty()) fresh[i]->set_id(node.id);
        requested[i] = props.requested_names();
        ++stats.objects_created;
        if (node.kind == ObjectType::Shape) ++stats.shapes_created;
    }

    // Relink shapes (undone on an error), then let the new objects finish, then the scene.
    struct Link {
        Shape *shape;
        std::shared_ptr<BSDF> bsdf;
        std::shared_ptr<Emitter> emitter;
    };
    std::vector<Link> undo;
    try {
        for (size_t i = 0; i < n; ++i) {
            if (!relink[i]) continue;
            auto *shape = static_cast<Shape *>(d.nodes[i].instance.get());
            undo.push_back(Link{shape, shape->bsdf_ptr(), shape->emitter_ptr()});
            for (const auto &e : d.nodes[i].entries) {
                if (e.child == NoNode || !recreate[e.child]) continue;
                if (d.nodes[e.child].kind == ObjectType::BSDF)
                    shape->set_bsdf(std::static_pointer_cast<BSDF>(fresh[e.child]));
                else
                    shape->set_emitter(std::static_pointer_cast<Emitter>(fresh[e.child]));
            }
            ++stats.shapes_relinked;
        }
        for (size_t i = 0; i < n; ++i)
            if (recreate[i]) fresh[i]->parameters_changed();

        const Node &root = d.nodes[d.root];
        Properties props(root.plugin);
        props.set_mode(d.mode);
        props.set_id(root.id);
        props.set_location(root.location);
        for (const auto &e : root.entries) {
            if (e.child == NoNode)
                props.set(e.name, e.value, e.location);
            else
                props.set(e.name, instance(e.child), e.location);
        }
        stats.geometries_built = m_scene->rebuild(props);
        stats.accel_rebuilt = stats.geometries_built > 0;
    } catch (...) {
        for (auto it = undo.rbegin(); it != undo.rend(); ++it) {
            it->shape->set_bsdf(it->bsdf);
            it->shape->set_emitter(it->emitter);
        }
        throw;
    }

    // The descriptions now describe the scene.
    for (size_t i = 0; i < n; ++i) {
        if (!recreate[i]) continue;
        auto it = edited.find(i);
        if (it != edited.end()) d.nodes[i].entries = std::move(it->second);
        d.nodes[i].instance = fresh[i];
        d.nodes[i].requested = std::move(requested[i]);
    }
    return stats;
}

} // namespace facet
