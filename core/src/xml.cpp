// The Mitsuba 3 XML scene loader.
//
// Loading runs in three passes:
//  1. parse: pugixml reads each file; every element becomes part of a tree of object descriptions
//     (ObjectNode) holding typed property values, child objects and unresolved references.
//     `$name` substitution, <default>, <include>, <path> and the pre-2.0 upgrade happen here.
//  2. resolve: aliases are bound, references are replaced by the nodes they name, and cycles are
//     reported.
//  3. instantiate: children first, each node once; then parameters_changed() on every object.
// Every error is a facet::Error carrying the file:line:col of the element it concerns.

#include "scene_description.h"

#include <facet/frame.h>
#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/resolver.h>
#include <facet/scene.h>
#include <facet/shape.h>
#include <facet/spectrum.h>
#include <facet/texture.h>
#include <facet/transform.h>
#include <facet/xml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>
#include <new>
#include <pugixml.hpp>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace facet {
namespace {

namespace fs = std::filesystem;

constexpr size_t NoNode = size_t(-1);
constexpr int MaxIncludeDepth = 15;
/// Deepest chain of objects inside objects (nested tags and references together), far above real
/// scenes (a shape, its BSDF, a texture of that: a handful). Parsing, instantiation and some
/// plugins recurse along such chains, so a deeper one is refused instead of exhausting the stack.
constexpr size_t MaxObjectDepth = 256;

// Budgets of one load, far above real scenes (which include tens to hundreds of files and hold up
// to a few million elements) and low enough that a hostile scene (files that include each other
// many times, `$name` values that grow tenfold per <default>) ends in a located error within
// seconds instead of exhausting time or memory. README.md ("Scene compatibility") lists them.
/// Bytes of one XML file.
constexpr size_t MaxFileBytes = size_t(256) << 20;
/// Inclusions of files, each <include> of each included copy counted.
constexpr size_t MaxIncludes = 100000;
/// Bytes of XML a load walks through: every file once per inclusion (a file is read and parsed
/// once, but each inclusion reads all its elements and attributes again).
constexpr size_t MaxSceneBytes = size_t(1) << 30;
/// Elements read again because their file is included more than once (a file included once,
/// however large, is bounded by the byte limits alone).
constexpr size_t MaxRepeatedElements = 1000000;
/// Length of one attribute value after `$name` substitution.
constexpr size_t MaxExpandedValue = size_t(1) << 20;
/// Bytes of all attribute values that `$name` substitution produces in one load.
constexpr size_t MaxExpandedText = size_t(256) << 20;

// =============================================================================================
// Tags
// =============================================================================================

struct ObjectTag {
    const char *tag;
    ObjectType kind;
};

/// The object tags of the grammar. `<spectrum type="...">` is handled separately (a texture).
constexpr ObjectTag OBJECT_TAGS[] = {
    {"scene", ObjectType::Scene},     {"shape", ObjectType::Shape},
    {"bsdf", ObjectType::BSDF},       {"emitter", ObjectType::Emitter},
    {"sensor", ObjectType::Sensor},   {"film", ObjectType::Film},
    {"sampler", ObjectType::Sampler}, {"integrator", ObjectType::Integrator},
    {"texture", ObjectType::Texture}, {"rfilter", ObjectType::ReconstructionFilter},
    {"medium", ObjectType::Medium},   {"phase", ObjectType::PhaseFunction},
    {"volume", ObjectType::Volume},
};

ObjectType object_tag_kind(const std::string &tag) {
    for (const ObjectTag &t : OBJECT_TAGS)
        if (tag == t.tag) return t.kind;
    return ObjectType::Unknown;
}

/// The tag name used in messages for an object kind ("bsdf", "texture", ...).
const char *object_kind_name(ObjectType kind) {
    for (const ObjectTag &t : OBJECT_TAGS)
        if (t.kind == kind) return t.tag;
    return "object";
}

bool is_property_tag(const std::string &tag) {
    return tag == "boolean" || tag == "integer" || tag == "float" || tag == "string" ||
           tag == "point" || tag == "vector" || tag == "rgb" || tag == "spectrum";
}

bool is_transform_op(const std::string &tag, bool upgrade) {
    return tag == "translate" || tag == "rotate" || tag == "scale" || tag == "matrix" ||
           tag == "lookat" || (upgrade && tag == "lookAt");
}

// =============================================================================================
// Source files and locations
// =============================================================================================

struct Version {
    int major = 0, minor = 0, patch = 0;
    bool before(int ma, int mi, int pa) const {
        if (major != ma) return major < ma;
        if (minor != mi) return minor < mi;
        return patch < pa;
    }
};

/// One XML text (a file or a string), its parsed document (parsed once, however often the file is
/// included) and what turns pugixml's byte offsets into line:column.
struct SourceFile {
    std::string name;      ///< shown in locations: the path as given, or "string"
    fs::path dir;          ///< folder for relative <include> and <path> values
    std::string canonical; ///< for include-cycle detection; empty for strings
    std::string text;      ///< parsed in place: only its size is used once `doc` is loaded
    size_t bom = 0;        ///< bytes of a UTF-8 byte order mark skipped before parsing
    size_t size = 0;       ///< bytes of the text, for the scene's budget
    size_t inclusions = 0; ///< times included so far in this load
    std::unique_ptr<pugi::xml_document> doc;
    std::vector<size_t> line_starts;
    Version version;
    bool upgrade = false; ///< version < 2.0.0: apply the 0.x upgrade to this file's nodes

    SourceFile(std::string name_, fs::path dir_, std::string canonical_, std::string text_)
        : name(std::move(name_)), dir(std::move(dir_)), canonical(std::move(canonical_)),
          text(std::move(text_)) {
        if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) bom = 3;
        size = text.size();
        line_starts.push_back(0);
        for (size_t i = 0; i < text.size(); ++i)
            if (text[i] == '\n') line_starts.push_back(i + 1);
    }

    /// Location of a byte offset into the parsed buffer (pugixml's offset_debug()).
    Location location(ptrdiff_t parsed_offset) const {
        size_t offset = std::min(size_t(std::max<ptrdiff_t>(parsed_offset, 0)) + bom, text.size());
        auto it = std::upper_bound(line_starts.begin(), line_starts.end(), offset);
        size_t line = size_t(it - line_starts.begin());
        return Location{name, int(line), int(offset - line_starts[line - 1] + 1)};
    }
};

/// An element being read: the pugixml node, its file and its location.
struct Element {
    pugi::xml_node node;
    SourceFile *src;
    Location loc;

    Element(pugi::xml_node n, SourceFile *s)
        : node(n), src(s), loc(s->location(n.offset_debug())) {}
    std::string tag() const { return node.name(); }
    /// "<float>", for messages.
    std::string bracketed() const { return "<" + tag() + ">"; }
};

[[noreturn]] void fail(const Location &loc, const std::string &msg) { throw Error(loc, msg); }

std::string canonical_name(const fs::path &path) {
    std::error_code ec;
    fs::path p = fs::weakly_canonical(path, ec);
    return ec ? fs::absolute(path).lexically_normal().string() : p.string();
}

// =============================================================================================
// Text: numbers, lists, booleans, names
// =============================================================================================

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace((unsigned char)s.front())) s.remove_prefix(1);
    while (!s.empty() && std::isspace((unsigned char)s.back())) s.remove_suffix(1);
    return s;
}

/// Locale-independent; the whole text must be the number (no trailing garbage).
bool parse_double(std::string_view text, double &out) {
    text = trim(text);
    if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
    if (text.empty()) return false;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
    return ec == std::errc() && end == text.data() + text.size();
}

bool parse_int(std::string_view text, int64_t &out) {
    text = trim(text);
    if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
    if (text.empty()) return false;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
    return ec == std::errc() && end == text.data() + text.size();
}

/// Splits at commas and white space (the grammar's ", " delimiters); empty pieces are dropped.
std::vector<std::string> tokenize(const std::string &text) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : text) {
        if (c == ',' || std::isspace((unsigned char)c)) {
            if (!cur.empty()) out.push_back(std::move(cur));
            cur.clear();
        } else {
            cur += c;
        }
    }
    if (!cur.empty()) out.push_back(std::move(cur));
    return out;
}

double to_double(const Element &el, const std::string &text) {
    double v;
    if (!parse_double(text, v))
        fail(el.loc, fmt::format("could not parse floating point value \"{}\"", text));
    return v;
}

std::vector<double> to_doubles(const Element &el, const std::string &text) {
    std::vector<double> out;
    for (const std::string &tok : tokenize(text)) out.push_back(to_double(el, tok));
    return out;
}

int64_t to_int(const Element &el, const std::string &text) {
    int64_t v;
    if (!parse_int(text, v))
        fail(el.loc, fmt::format("could not parse integer value \"{}\"", text));
    return v;
}

bool to_bool(const Element &el, const std::string &text) {
    std::string s(trim(text));
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (s == "true") return true;
    if (s == "false") return false;
    fail(el.loc,
         fmt::format("could not parse boolean value \"{}\" (expected true or false)", text));
}

/// 0.x scenes: `intIOR` -> `int_ior`. An underscore goes before a capital that follows a
/// lower-case letter; all capitals become lower case.
std::string camel_to_snake(const std::string &name) {
    std::string out;
    for (size_t i = 0; i < name.size(); ++i) {
        unsigned char c = (unsigned char)name[i];
        if (std::isupper(c)) {
            if (i > 0 && std::islower((unsigned char)name[i - 1])) out += '_';
            out += char(std::tolower(c));
        } else {
            out += char(c);
        }
    }
    return out;
}

bool is_ident_char(char c) { return std::isalnum((unsigned char)c) || c == '_'; }

bool all_finite(const Matrix4f &m) {
    for (const auto &row : m.m)
        for (float v : row)
            if (!std::isfinite(v)) return false;
    return true;
}

// =============================================================================================
// The description tree
// =============================================================================================

/// One entry of an object's future Properties, in declaration order.
struct Entry {
    enum class Kind { Value, Child, Ref };
    Kind kind = Kind::Value;
    std::string name;
    Location location;
    Properties::Value value; ///< Kind::Value
    size_t child = NoNode;   ///< Kind::Child (and Kind::Ref once resolved)
    std::string ref_id;      ///< Kind::Ref
};

/// An object as declared in the scene, before instantiation.
struct ObjectNode {
    ObjectType kind = ObjectType::Unknown;
    std::string plugin; ///< the `type` attribute ("scene" for scenes)
    std::string id;
    Location location;
    std::vector<Entry> entries;
    std::unordered_map<std::string, Location> names; ///< entry names, for duplicate checks
    size_t arg_counter = 0;                          ///< next `_arg_N`
    std::shared_ptr<Object> instance;
    std::vector<std::string> requested; ///< the names the plugin asked for

    Entry *find(const std::string &name) {
        for (Entry &e : entries)
            if (e.name == name) return &e;
        return nullptr;
    }
    /// Fails when `name` is taken already (scenes can have many entries: no linear search).
    void claim_name(const std::string &name, const Location &loc) {
        auto [it, inserted] = names.emplace(name, loc);
        if (!inserted)
            throw Error(loc, fmt::format("duplicate property \"{}\" (first declared at {})", name,
                                         it->second.to_string()));
    }
    /// "a" for an object with an id, `<bsdf type="diffuse">` otherwise.
    std::string describe() const {
        return id.empty() ? fmt::format("<{} type=\"{}\">", object_kind_name(kind), plugin) : id;
    }
};

struct IdEntry {
    size_t node;
    Location location;
};

struct Alias {
    std::string source, target;
    Location location;
};

struct Parameter {
    std::string value;
    bool from_options = false; ///< given by LoadOptions::params (else by a <default>)
    bool used = false;
};

/// Saves facet::file_resolver() and restores it when the load ends, successful or not.
class ResolverGuard {
public:
    ResolverGuard() : m_saved(file_resolver()) {}
    ~ResolverGuard() { file_resolver() = m_saved; }
    ResolverGuard(const ResolverGuard &) = delete;
    ResolverGuard &operator=(const ResolverGuard &) = delete;

private:
    FileResolver m_saved;
};

// =============================================================================================
// The loader
// =============================================================================================

class Loader {
public:
    explicit Loader(const LoadOptions &opts)
        : m_opts(opts),
          m_mode(colour_mode(opts.mode.empty() ? default_mode() : resolve_mode(opts.mode))) {
        for (const auto &[key, value] : opts.params) m_params[key] = Parameter{value, true, false};
        update_keys();
    }

    std::shared_ptr<Object> load_file(const std::string &path, bool require_scene) {
        // The checks every file reader shares: a folder, a FIFO or a device is refused, and so
        // is a file larger than MaxFileBytes.
        std::string text = read_file(path, "scene file", MaxFileBytes);
        fs::path dir = fs::path(path).parent_path();
        SourceFile *src = add_source(path, dir, canonical_name(path), std::move(text));

        ResolverGuard guard;
        file_resolver().prepend(
            fs::absolute(dir.empty() ? fs::path(".") : dir).lexically_normal().string());
        return load(src, require_scene);
    }

    std::shared_ptr<Object> load_string(const std::string &xml, bool require_scene) {
        SourceFile *src = add_source("string", fs::path(), "", xml);
        ResolverGuard guard;
        return load(src, require_scene);
    }

    SceneInfo info_file(const std::string &path) {
        std::string text = read_file(path, "scene file", MaxFileBytes);
        fs::path dir = fs::path(path).parent_path();
        SourceFile *src = add_source(path, dir, canonical_name(path), std::move(text));
        ResolverGuard guard;
        file_resolver().prepend(
            fs::absolute(dir.empty() ? fs::path(".") : dir).lexically_normal().string());
        for (const std::string &d : m_opts.search_path) file_resolver().append(d);
        size_t root = parse_document(src, NoNode, "");
        if (m_nodes[root].kind != ObjectType::Scene)
            fail(m_nodes[root].location, fmt::format("expected a <scene> root element, found <{}>",
                                                     object_kind_name(m_nodes[root].kind)));
        check_unused_parameters(src->name);
        apply_aliases();
        resolve_references();
        check_cycles(root);

        SceneInfo info;
        std::map<std::string, std::set<std::string>> plugins;
        for (const ObjectNode &node : m_nodes)
            if (node.kind != ObjectType::Scene)
                plugins[object_kind_name(node.kind)].insert(node.plugin);
        auto child_of = [&](const ObjectNode &node, ObjectType kind) -> const ObjectNode * {
            for (const Entry &e : node.entries)
                if (e.child != NoNode && m_nodes[e.child].kind == kind) return &m_nodes[e.child];
            return nullptr;
        };
        auto integer = [](const ObjectNode &node, const char *name, int fallback) {
            for (const Entry &e : node.entries)
                if (e.kind == Entry::Kind::Value && e.name == name)
                    if (const int64_t *v = std::get_if<int64_t>(&e.value))
                        return int(std::clamp<int64_t>(*v, 0, std::numeric_limits<int>::max()));
            return fallback;
        };
        for (const Entry &e : m_nodes[root].entries) {
            if (e.child == NoNode) continue;
            const ObjectNode &node = m_nodes[e.child];
            if (node.kind == ObjectType::Integrator) info.integrator = node.plugin;
            if (node.kind != ObjectType::Sensor) continue;
            SceneInfo::SensorInfo s;
            s.plugin = node.plugin;
            s.film = s.sampler = "";
            if (const ObjectNode *film = child_of(node, ObjectType::Film)) {
                s.film = film->plugin;
                s.width = integer(*film, "width", s.width);
                s.height = integer(*film, "height", s.height);
            }
            if (const ObjectNode *sampler = child_of(node, ObjectType::Sampler)) {
                s.sampler = sampler->plugin;
                s.spp = integer(*sampler, "sample_count", s.spp);
            }
            info.sensors.push_back(s);
        }
        if (info.sensors.empty()) info.sensors.push_back({"perspective", "", "", 768, 576, 4});
        for (SceneInfo::SensorInfo &s : info.sensors) {
            // The defaults the sensor creates (hdrfilm, independent) are plugins the render uses.
            if (s.film.empty()) s.film = "hdrfilm";
            if (s.sampler.empty()) s.sampler = "independent";
            plugins["film"].insert(s.film);
            plugins["sampler"].insert(s.sampler);
            plugins["sensor"].insert(s.plugin);
        }
        plugins["integrator"].insert(info.integrator);
        for (const auto &[kind, names] : plugins)
            info.plugins[kind].assign(names.begin(), names.end());
        return info;
    }

private:
    std::shared_ptr<Object> load(SourceFile *src, bool require_scene) {
        try {
            return load_checked(src, require_scene);
        } catch (const std::bad_alloc &) {
            // Parsing locates its own allocation failures (parse_child()); these come from
            // resolving references or from the objects' construction.
            FACET_THROW("{}: out of memory while loading the scene", src->name);
        }
    }

    std::shared_ptr<Object> load_checked(SourceFile *src, bool require_scene) {
        m_scene_bytes = src->size;
        for (const std::string &dir : m_opts.search_path) file_resolver().append(dir);

        size_t root = parse_document(src, NoNode, "");
        if (require_scene && m_nodes[root].kind != ObjectType::Scene)
            fail(m_nodes[root].location, fmt::format("expected a <scene> root element, found <{}>",
                                                     object_kind_name(m_nodes[root].kind)));
        check_unused_parameters(src->name);
        apply_aliases();
        resolve_references();
        check_cycles(root);

        std::shared_ptr<Object> result = instantiate(root);
        for (size_t index : m_created) {
            ObjectNode &node = m_nodes[index];
            try {
                node.instance->parameters_changed();
            } catch (const std::exception &e) {
                throw instantiation_error(
                    node, e,
                    fmt::format("failed to initialise {} plugin of type \"{}\"",
                                object_kind_name(node.kind), node.plugin));
            }
        }
        check_shape_textures();
        if (auto *scene = dynamic_cast<Scene *>(result.get()))
            scene->set_description(describe(root));
        return result;
    }

    /// The descriptions of the instantiated objects, for traverse() (scene_description.h).
    std::shared_ptr<SceneDescription> describe(size_t root) const {
        auto d = std::make_shared<SceneDescription>();
        d->lenient = m_opts.lenient;
        d->mode = m_mode;
        d->resolver = file_resolver(); // this load's folders (the guard restores the caller's)
        std::unordered_map<size_t, size_t> index; // m_nodes -> d->nodes
        for (size_t i : m_created) {
            const ObjectNode &node = m_nodes[i];
            SceneDescription::Node out;
            out.kind = node.kind;
            out.plugin = node.plugin;
            out.id = node.id;
            out.location = node.location;
            out.requested = node.requested;
            if (i != root) out.instance = node.instance;
            for (const Entry &e : node.entries) {
                SceneDescription::Entry entry;
                entry.name = e.name;
                entry.location = e.location;
                if (e.kind == Entry::Kind::Value)
                    entry.value = e.value;
                else
                    entry.child = index.at(e.child);
                out.entries.push_back(std::move(entry));
            }
            index[i] = d->nodes.size();
            d->nodes.push_back(std::move(out));
        }
        d->root = index.at(root);
        return d;
    }

    /// Lets every texture reached from a shape (through its BSDF, emitter and their nested
    /// objects, not through nested shapes) check that it can be evaluated on that shape.
    void check_shape_textures() {
        std::vector<size_t> seen(m_nodes.size(), NoNode); // the shape that last reached a node
        std::vector<size_t> stack;
        for (size_t index : m_created) {
            const ObjectNode &shape_node = m_nodes[index];
            if (shape_node.kind != ObjectType::Shape) continue;
            const auto *shape = dynamic_cast<const Shape *>(shape_node.instance.get());
            if (!shape) continue;
            stack.assign(1, index);
            while (!stack.empty()) {
                size_t i = stack.back();
                stack.pop_back();
                for (const Entry &e : m_nodes[i].entries) {
                    if (e.child == NoNode || seen[e.child] == index) continue;
                    seen[e.child] = index;
                    const ObjectNode &child = m_nodes[e.child];
                    if (child.kind == ObjectType::Shape) continue;
                    auto *texture = dynamic_cast<const Texture *>(child.instance.get());
                    if (texture) {
                        try {
                            texture->check_shape(*shape);
                        } catch (const Error &err) {
                            throw Error(child.location,
                                        fmt::format("{} (used by {} at {})", err.message(),
                                                    shape_node.describe(),
                                                    shape_node.location.to_string()));
                        }
                    }
                    stack.push_back(e.child);
                }
            }
        }
    }

    SourceFile *add_source(std::string name, fs::path dir, std::string canonical,
                           std::string text) {
        m_sources.push_back(std::make_unique<SourceFile>(std::move(name), std::move(dir),
                                                         std::move(canonical), std::move(text)));
        SourceFile *src = m_sources.back().get();
        if (!src->canonical.empty()) m_files.emplace(src->canonical, src);
        return src;
    }

    // -- Attributes and $name substitution ------------------------------------------------------

    void update_keys() {
        m_keys.clear();
        for (const auto &kv : m_params) m_keys.push_back(kv.first);
        std::stable_sort(
            m_keys.begin(), m_keys.end(),
            [](const std::string &a, const std::string &b) { return a.size() > b.size(); });
    }

    /// Replaces `$key` by its value (longest keys first), `\$` by `$`; a `$name` that matches no
    /// key is an error. The result of each substitution and the total of a load are bounded
    /// (MaxExpandedValue, MaxExpandedText): <default> values made of copies of other values
    /// grow geometrically.
    std::string substitute(const Element &el, const std::string &text) {
        if (text.find('$') == std::string::npos) return text;
        std::string out;
        out.reserve(text.size());
        for (size_t i = 0; i < text.size();) {
            size_t special = std::min(text.find('$', i), text.find("\\$", i));
            if (special == std::string::npos) special = text.size();
            out.append(text, i, special - i);
            i = special;
            if (i == text.size()) break;
            if (text[i] == '\\') { // `\$`
                out += '$';
                i += 2;
                continue;
            }
            const std::string *key = nullptr;
            for (const std::string &k : m_keys)
                if (text.compare(i + 1, k.size(), k) == 0) {
                    key = &k;
                    break;
                }
            if (key) {
                Parameter &p = m_params[*key];
                p.used = true;
                if (p.value.size() > MaxExpandedValue - std::min(out.size(), MaxExpandedValue))
                    fail(el.loc, fmt::format("substituting ${} makes a value of {} longer than "
                                             "{} MiB (the loader's limit)",
                                             *key, el.bracketed(), MaxExpandedValue >> 20));
                out += p.value;
                i += 1 + key->size();
                continue;
            }
            size_t j = i + 1;
            while (j < text.size() && is_ident_char(text[j])) ++j;
            if (j > i + 1) fail(el.loc, "undefined parameter: $" + text.substr(i + 1, j - i - 1));
            out += text[i++];
        }
        m_expanded += out.size();
        if (m_expanded > MaxExpandedText)
            fail(el.loc, fmt::format("$name substitution has produced more than {} MiB of text in "
                                     "this scene (the loader's limit)",
                                     MaxExpandedText >> 20));
        return out;
    }

    static void check_attributes(const Element &el, std::initializer_list<const char *> allowed) {
        for (pugi::xml_attribute a : el.node.attributes()) {
            bool ok = std::any_of(allowed.begin(), allowed.end(),
                                  [&](const char *n) { return std::strcmp(n, a.name()) == 0; });
            if (!ok)
                fail(el.loc, fmt::format("unexpected attribute \"{}\" in element {}", a.name(),
                                         el.bracketed()));
        }
    }

    static bool has_attr(const Element &el, const char *name) {
        return !el.node.attribute(name).empty();
    }

    /// A required attribute, substituted.
    std::string attr(const Element &el, const char *name) {
        pugi::xml_attribute a = el.node.attribute(name);
        if (a.empty())
            fail(el.loc, fmt::format("missing required attribute \"{}\" in element {}", name,
                                     el.bracketed()));
        return substitute(el, a.value());
    }

    std::string attr(const Element &el, const char *name, const std::string &def) {
        pugi::xml_attribute a = el.node.attribute(name);
        return a.empty() ? def : substitute(el, a.value());
    }

    /// The `name` attribute as a property name (required unless `optional`), upgraded for 0.x.
    std::string property_name(const Element &el, bool optional = false) {
        if (optional && !has_attr(el, "name")) return {};
        std::string name = attr(el, "name");
        if (name.empty() && !optional)
            fail(el.loc, fmt::format("empty \"name\" attribute in element {}", el.bracketed()));
        return el.src->upgrade ? camel_to_snake(name) : name;
    }

    static void check_no_children(const Element &el) {
        for (pugi::xml_node c : el.node.children())
            if (c.type() == pugi::node_element)
                fail(Element(c, el.src).loc,
                     fmt::format("unexpected element <{}> inside {}: this element cannot have "
                                 "children",
                                 c.name(), el.bracketed()));
    }

    /// A 3-vector from `value` (1 or 3 numbers) or from x/y/z attributes. A missing x/y/z takes
    /// `def`; without `def` all three are required.
    Vector3f read_vector(const Element &el, const float *def) {
        bool has_xyz = has_attr(el, "x") || has_attr(el, "y") || has_attr(el, "z");
        if (has_attr(el, "value")) {
            if (has_xyz)
                fail(el.loc, fmt::format("{} can have either a \"value\" attribute or x/y/z "
                                         "attributes, not both",
                                         el.bracketed()));
            return vector_from_text(el, "value", attr(el, "value"));
        }
        if (!def && !has_xyz)
            fail(el.loc, fmt::format("{} needs a \"value\" attribute or x, y and z attributes",
                                     el.bracketed()));
        Vector3f v;
        const char *names[3] = {"x", "y", "z"};
        for (int i = 0; i < 3; ++i) {
            if (has_attr(el, names[i]))
                v[i] = float(to_double(el, attr(el, names[i])));
            else if (def)
                v[i] = *def;
            else
                attr(el, names[i]); // reports the missing attribute
        }
        return v;
    }

    /// "x, y, z" or a single value for all three components.
    static Vector3f vector_from_text(const Element &el, const char *attr_name,
                                     const std::string &text) {
        std::vector<double> v = to_doubles(el, text);
        if (v.size() == 1) return Vector3f(float(v[0]));
        if (v.size() != 3)
            fail(el.loc, fmt::format("attribute \"{}\" of {} needs 1 or 3 values, found {}",
                                     attr_name, el.bracketed(), v.size()));
        return Vector3f(float(v[0]), float(v[1]), float(v[2]));
    }

    // -- Tree building --------------------------------------------------------------------------

    size_t new_node(ObjectType kind, const std::string &plugin, const std::string &id,
                    const Location &loc) {
        ObjectNode node;
        node.kind = kind;
        node.plugin = plugin;
        node.id = id;
        node.location = loc;
        m_nodes.push_back(std::move(node));
        size_t index = m_nodes.size() - 1;
        if (!id.empty()) {
            auto it = m_ids.find(id);
            if (it != m_ids.end())
                fail(loc, fmt::format("duplicate id \"{}\" (first declared at {})", id,
                                      it->second.location.to_string()));
            m_ids.emplace(id, IdEntry{index, loc});
        }
        return index;
    }

    /// Appends an entry to `parent`, naming it `_arg_N` when it has no name.
    void add_entry(size_t parent, Entry entry) {
        ObjectNode &node = m_nodes[parent];
        if (entry.name.empty()) entry.name = fmt::format("_arg_{}", node.arg_counter++);
        node.claim_name(entry.name, entry.location);
        node.entries.push_back(std::move(entry));
    }

    void add_value(size_t parent, const std::string &name, Properties::Value value,
                   const Location &loc) {
        Entry e;
        e.kind = Entry::Kind::Value;
        e.name = name;
        e.location = loc;
        e.value = std::move(value);
        add_entry(parent, std::move(e));
    }

    void add_child(size_t parent, const std::string &name, size_t child, const Location &loc) {
        Entry e;
        e.kind = Entry::Kind::Child;
        e.name = name;
        e.location = loc;
        e.child = child;
        add_entry(parent, std::move(e));
    }

    // -- Documents and <include> ----------------------------------------------------------------

    /// Parses one file. At the top (`parent` == NoNode) returns the root node. For an include,
    /// a <scene> root's children are spliced into `parent`; another root becomes its child,
    /// named `include_name` (or the root's own name).
    size_t parse_document(SourceFile *src, size_t parent, const std::string &include_name) {
        if (!src->doc) {
            // Parsed once, in place (the text is not needed again), however often it is included.
            src->doc = std::make_unique<pugi::xml_document>();
            pugi::xml_parse_result result = src->doc->load_buffer_inplace(
                src->text.data() + src->bom, src->text.size() - src->bom, pugi::parse_default,
                pugi::encoding_utf8);
            if (!result)
                fail(src->location(result.offset),
                     fmt::format("Parsing of XML file \"{}\" failed: {}", src->name,
                                 result.description()));
        }
        Element root(src->doc->document_element(), src);
        count_element(root);
        parse_version(root, parent != NoNode ? &m_include_stack.back()->version : nullptr);

        m_include_stack.push_back(src);
        size_t index = NoNode;
        std::string tag = root.tag();
        if (tag == "scene") {
            check_attributes(root, {"version", "id", "name"});
            if (parent == NoNode) {
                index = new_node(ObjectType::Scene, "scene", attr(root, "id", ""), root.loc);
                parse_children(root, index, true);
            } else {
                parse_children(root, parent, true);
            }
        } else if (object_tag_kind(tag) != ObjectType::Unknown ||
                   (tag == "spectrum" && has_attr(root, "type"))) {
            index = parse_object(root, parent, true, include_name);
        } else if (is_property_tag(tag) || tag == "transform" || tag == "ref" || tag == "default" ||
                   tag == "include" || tag == "alias" || tag == "path" ||
                   is_transform_op(tag, src->upgrade)) {
            fail(root.loc, fmt::format("the root element must be <scene> or an object tag such as "
                                       "<bsdf>, not {}",
                                       root.bracketed()));
        } else {
            fail(root.loc,
                 fmt::format("encountered an unsupported XML element: {}", root.bracketed()));
        }
        m_include_stack.pop_back();
        return index;
    }

    /// Reads `version="X.Y.Z"`: required at the top, inherited by included files without one.
    void parse_version(const Element &root, const Version *inherited) {
        SourceFile *src = root.src;
        if (!has_attr(root, "version")) {
            if (!inherited) fail(root.loc, "missing version attribute in root element");
            src->version = *inherited;
        } else {
            std::string text = attr(root, "version");
            std::vector<std::string> parts;
            std::stringstream ss(text);
            for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
            int64_t v[3];
            if (parts.size() != 3 || !parse_int(parts[0], v[0]) || !parse_int(parts[1], v[1]) ||
                !parse_int(parts[2], v[2]) || v[0] < 0 || v[1] < 0 || v[2] < 0)
                fail(root.loc,
                     fmt::format("invalid version \"{}\" (expected X.Y.Z, e.g. 3.0.0)", text));
            src->version = Version{int(v[0]), int(v[1]), int(v[2])};
        }
        src->upgrade = src->version.before(2, 0, 0);
    }

    void parse_include(const Element &el, size_t parent) {
        check_attributes(el, {"filename", "name"});
        check_no_children(el);
        std::string filename = attr(el, "filename");
        std::string name = property_name(el, true);

        // Resolved once per folder and name: a scene may include a file many times.
        auto [resolved, is_new] = m_resolved.try_emplace(el.src->dir.string() + '\n' + filename);
        if (is_new) {
            fs::path p(filename), found;
            std::error_code ec;
            if (p.is_absolute()) {
                found = p;
            } else if (fs::is_regular_file(el.src->dir / p, ec)) {
                found = (el.src->dir / p).lexically_normal();
            } else {
                found = file_resolver().resolve(filename);
            }
            if (!fs::exists(found, ec)) {
                m_resolved.erase(resolved);
                fail(el.loc, fmt::format("included file \"{}\" not found", filename));
            }
            resolved->second = {found, canonical_name(found)};
        }
        const fs::path found = resolved->second.first; // copies: <path> clears the map
        const std::string canonical = resolved->second.second;
        for (size_t i = 0; i < m_include_stack.size(); ++i) {
            if (m_include_stack[i]->canonical != canonical) continue;
            std::string chain;
            for (size_t j = i; j < m_include_stack.size(); ++j)
                chain += m_include_stack[j]->name + " -> ";
            fail(el.loc, "include cycle detected: " + chain + found.string());
        }
        if (int(m_include_stack.size()) > MaxIncludeDepth)
            fail(el.loc, fmt::format("maximum include depth of {} exceeded while including \"{}\"",
                                     MaxIncludeDepth, filename));
        if (++m_includes > MaxIncludes)
            fail(el.loc, fmt::format("including \"{}\" makes more than {} inclusions of files in "
                                     "this scene (the loader's limit)",
                                     filename, MaxIncludes));

        SourceFile *src = nullptr;
        if (auto cached = m_files.find(canonical); cached != m_files.end()) {
            src = cached->second;
        } else {
            std::string text;
            try {
                text = read_file(found.string(), "included file", MaxFileBytes);
            } catch (const Error &e) {
                fail(el.loc, e.message());
            }
            src = add_source(found.string(), found.parent_path(), canonical, std::move(text));
        }
        m_scene_bytes += src->size;
        if (m_scene_bytes > MaxSceneBytes)
            fail(el.loc, fmt::format("including \"{}\" takes the XML of this scene past {} MiB, "
                                     "each inclusion of a file counted (the loader's limit)",
                                     filename, MaxSceneBytes >> 20));
        const bool repeated = src->inclusions++ > 0;
        if (repeated && m_repeating++ == 0) m_repeated_include = {el.loc, filename};
        parse_document(src, parent, name);
        if (repeated) --m_repeating;
    }

    /// Counts an element read again (its file included before) against MaxRepeatedElements.
    void count_element(const Element &el) {
        if (m_repeating == 0 || ++m_repeated_elements <= MaxRepeatedElements) return;
        fail(el.loc, fmt::format("including \"{}\" at {} makes the scene read more than {} "
                                 "elements again, in files included more than once (the loader's "
                                 "limit)",
                                 m_repeated_include.second, m_repeated_include.first.to_string(),
                                 MaxRepeatedElements));
    }

    // -- Elements inside objects ----------------------------------------------------------------

    void parse_children(const Element &el, size_t node, bool is_root) {
        for (pugi::xml_node c : el.node.children())
            if (c.type() == pugi::node_element) parse_child(Element(c, el.src), node, is_root);
    }

    void parse_child(const Element &el, size_t parent, bool parent_is_root) {
        count_element(el);
        try {
            parse_element(el, parent, parent_is_root);
        } catch (const std::bad_alloc &) {
            // The innermost element names where memory ran out (outer ones see a facet::Error).
            fail(el.loc, fmt::format("out of memory while reading {}", el.bracketed()));
        }
    }

    void parse_element(const Element &el, size_t parent, bool parent_is_root) {
        std::string tag = el.tag();
        if (tag == "scene")
            fail(el.loc, "<scene> may only appear as the root element of a file");
        else if (object_tag_kind(tag) != ObjectType::Unknown ||
                 (tag == "spectrum" && has_attr(el, "type")))
            parse_object(el, parent, false, "");
        else if (is_property_tag(tag))
            parse_property(el, parent);
        else if (tag == "transform")
            parse_transform(el, parent);
        else if (is_transform_op(tag, el.src->upgrade))
            fail(el.loc, fmt::format("{} may only appear inside a <transform>", el.bracketed()));
        else if (tag == "ref")
            parse_ref(el, parent);
        else if (tag == "default")
            parse_default(el);
        else if (tag == "include")
            parse_include(el, parent);
        else if (tag == "alias")
            parse_alias(el);
        else if (tag == "path")
            parse_path(el, parent_is_root);
        else
            fail(el.loc, fmt::format("encountered an unsupported XML element: {}", el.bracketed()));
    }

    /// An object tag (also a non-scene root). Returns its node.
    size_t parse_object(const Element &el, size_t parent, bool is_root,
                        const std::string &name_override) {
        if (is_root)
            check_attributes(el, {"version", "type", "id", "name"});
        else
            check_attributes(el, {"type", "id", "name"});
        std::string tag = el.tag();
        ObjectType kind = tag == "spectrum" ? ObjectType::Texture : object_tag_kind(tag);
        std::string type = attr(el, "type");
        if (type.empty())
            fail(el.loc, fmt::format("empty \"type\" attribute in element {}", el.bracketed()));
        std::string id = attr(el, "id", "");
        std::string name = name_override.empty() ? property_name(el, true) : name_override;

        if (m_object_depth >= MaxObjectDepth)
            fail(el.loc, fmt::format("{} is nested more than {} objects deep (the limit of the "
                                     "scene loader)",
                                     el.bracketed(), MaxObjectDepth));
        size_t index = new_node(kind, type, id, el.loc);
        if (parent != NoNode) add_child(parent, name, index, el.loc);
        ++m_object_depth;
        parse_children(el, index, is_root);
        --m_object_depth;
        if (el.src->upgrade) upgrade_node(index);
        return index;
    }

    void parse_property(const Element &el, size_t parent) {
        std::string tag = el.tag();
        if (tag == "point" || tag == "vector")
            check_attributes(el, {"name", "value", "x", "y", "z"});
        else if (tag == "spectrum")
            check_attributes(el, {"name", "value", "filename"});
        else
            check_attributes(el, {"name", "value"});
        check_no_children(el);
        std::string name = property_name(el);

        Properties::Value value;
        if (tag == "boolean") {
            value = to_bool(el, attr(el, "value"));
        } else if (tag == "integer") {
            value = to_int(el, attr(el, "value"));
        } else if (tag == "float") {
            value = to_double(el, attr(el, "value"));
        } else if (tag == "string") {
            value = attr(el, "value");
        } else if (tag == "point" || tag == "vector") {
            value = read_vector(el, nullptr);
        } else if (tag == "rgb") {
            std::vector<double> v = to_doubles(el, attr(el, "value"));
            if (v.size() == 1) v = {v[0], v[0], v[0]};
            if (v.size() != 3)
                fail(el.loc, fmt::format("<rgb> needs 1 or 3 values, found {}", v.size()));
            value = Color3f(float(v[0]), float(v[1]), float(v[2]));
        } else {
            value = read_spectrum(el);
        }
        add_value(parent, name, std::move(value), el.loc);
    }

    SpectrumData read_spectrum(const Element &el) {
        bool has_value = has_attr(el, "value"), has_file = has_attr(el, "filename");
        if (has_value == has_file)
            fail(el.loc,
                 "<spectrum> needs exactly one of the attributes \"value\" and \"filename\"");
        try {
            if (has_value) return parse_spectrum_pairs(attr(el, "value"));
            std::string filename = attr(el, "filename");
            std::string path = file_resolver().resolve(filename);
            if (!fs::is_regular_file(path))
                fail(el.loc, fmt::format("spectrum file \"{}\" not found", filename));
            return read_spd_file(path);
        } catch (const Error &e) {
            if (e.location().valid()) throw;
            fail(el.loc, e.message());
        }
    }

    void parse_transform(const Element &el, size_t parent) {
        check_attributes(el, {"name"});
        std::string name = property_name(el);
        Transform t;
        for (pugi::xml_node c : el.node.children()) {
            if (c.type() != pugi::node_element) continue;
            Element op(c, el.src);
            count_element(op);
            if (!is_transform_op(op.tag(), el.src->upgrade))
                fail(op.loc, fmt::format("{} cannot appear inside <transform>: only translate, "
                                         "rotate, scale, matrix and lookat can",
                                         op.bracketed()));
            // Each operation is applied after the previous ones.
            t = parse_transform_op(op) * t;
        }
        add_value(parent, name, t, el.loc);
    }

    Transform parse_transform_op(const Element &el) {
        check_no_children(el);
        std::string tag = el.tag();
        if (tag == "translate") {
            check_attributes(el, {"value", "x", "y", "z"});
            const float zero = 0.f;
            return Transform::translate(read_vector(el, &zero));
        }
        if (tag == "scale") {
            check_attributes(el, {"value", "x", "y", "z"});
            const float one = 1.f;
            return Transform::scale(read_vector(el, &one));
        }
        if (tag == "rotate") {
            check_attributes(el, {"angle", "value", "x", "y", "z"});
            const float zero = 0.f;
            float angle = float(to_double(el, attr(el, "angle")));
            Vector3f axis = read_vector(el, &zero);
            if (axis == Vector3f(0.f)) fail(el.loc, "<rotate> needs a non-zero rotation axis");
            return Transform::rotate(normalize(axis), angle);
        }
        if (tag == "matrix") {
            check_attributes(el, {"value"});
            std::vector<double> v = to_doubles(el, attr(el, "value"));
            float rows[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
            if (v.size() == 16) {
                for (int i = 0; i < 16; ++i) rows[i] = float(v[i]);
            } else if (v.size() == 9) {
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c) rows[r * 4 + c] = float(v[r * 3 + c]);
            } else {
                fail(el.loc, fmt::format("<matrix> needs 9 or 16 values, found {}", v.size()));
            }
            return Transform(Matrix4f::from_rows(rows));
        }
        // lookat (lookAt in 0.x scenes)
        check_attributes(el, {"origin", "target", "up"});
        Point3f origin = vector_from_text(el, "origin", attr(el, "origin"));
        Point3f target = vector_from_text(el, "target", attr(el, "target"));
        Vector3f up;
        if (has_attr(el, "up")) up = vector_from_text(el, "up", attr(el, "up"));
        if (up == Vector3f(0.f)) {
            // Any direction perpendicular to the view direction will do.
            Vector3f t;
            coordinate_system(normalize(target - origin), up, t);
        }
        Transform result = Transform::look_at(origin, target, up);
        if (!all_finite(result.matrix) || !all_finite(result.inverse_matrix))
            fail(el.loc, "invalid <lookat>: origin and target coincide, or up is parallel to the "
                         "viewing direction");
        return result;
    }

    void parse_ref(const Element &el, size_t parent) {
        check_attributes(el, {"id", "name"});
        check_no_children(el);
        Entry e;
        e.kind = Entry::Kind::Ref;
        e.ref_id = attr(el, "id");
        e.name = property_name(el, true);
        e.location = el.loc;
        add_entry(parent, std::move(e));
    }

    void parse_default(const Element &el) {
        check_attributes(el, {"name", "value"});
        check_no_children(el);
        std::string name = attr(el, "name"), value = attr(el, "value");
        if (name.empty()) fail(el.loc, "empty \"name\" attribute in element <default>");
        if (m_params.count(name)) return; // given by the caller, or by an earlier <default>
        m_params[name] = Parameter{value, false, false};
        update_keys();
    }

    void parse_alias(const Element &el) {
        check_attributes(el, {"id", "as"});
        check_no_children(el);
        m_aliases.push_back(Alias{attr(el, "id"), attr(el, "as"), el.loc});
    }

    void parse_path(const Element &el, bool parent_is_root) {
        check_attributes(el, {"value"});
        check_no_children(el);
        if (!parent_is_root)
            fail(el.loc, "<path> may only appear directly inside the root element");
        std::string value = attr(el, "value");
        fs::path p(value), found = p;
        if (p.is_relative()) {
            found = el.src->dir / p;
            if (!fs::is_directory(found)) found = file_resolver().resolve(value);
        }
        if (!fs::is_directory(found))
            fail(el.loc, fmt::format("folder \"{}\" does not exist", value));
        file_resolver().prepend(fs::absolute(found).lexically_normal().string());
        m_resolved.clear(); // names may resolve elsewhere now
    }

    // -- The 0.x upgrade ------------------------------------------------------------------------

    static void rename_entry(ObjectNode &node, const std::string &from, const std::string &to) {
        Entry *e = node.find(from);
        if (!e) return;
        node.claim_name(to, e->location);
        node.names.erase(from);
        e->name = to;
    }

    /// Properties of 0.x plugins that changed: diffuse's reflectance, and uv offsets/scales
    /// that became one `to_uv` transform.
    void upgrade_node(size_t index) {
        ObjectNode &node = m_nodes[index];
        if (node.kind == ObjectType::BSDF && node.plugin == "diffuse")
            rename_entry(node, "diffuse_reflectance", "reflectance");

        const char *uv_names[4] = {"uoffset", "voffset", "uscale", "vscale"};
        float uv[4] = {0.f, 0.f, 1.f, 1.f};
        Location first;
        bool any = false;
        for (int i = 0; i < 4; ++i) {
            Entry *e = node.find(uv_names[i]);
            if (!e || e->kind != Entry::Kind::Value) continue;
            if (const double *d = std::get_if<double>(&e->value))
                uv[i] = float(*d);
            else if (const int64_t *n = std::get_if<int64_t>(&e->value))
                uv[i] = float(*n);
            else
                fail(e->location, fmt::format("\"{}\" must be a number", uv_names[i]));
            if (!any) first = e->location;
            any = true;
            node.names.erase(e->name);
            node.entries.erase(node.entries.begin() + (e - node.entries.data()));
        }
        if (!any) return;
        Transform to_uv = Transform::scale(Vector3f(uv[2], uv[3], 1.f)) *
                          Transform::translate(Vector3f(uv[0], uv[1], 0.f));
        add_value(index, "to_uv", to_uv, first);
    }

    // -- Resolution -----------------------------------------------------------------------------

    void check_unused_parameters(const std::string &file) {
        std::vector<std::string> unused, known;
        for (const auto &[key, p] : m_params)
            if (!p.from_options || p.used) known.push_back(key);
        for (const auto &[key, p] : m_params) {
            if (!p.from_options || p.used) continue;
            // A misspelt -D key: the nearest name the scene does use.
            std::string close = closest_name(key, known);
            unused.push_back("\"" + key + "\"" +
                             (close.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", close)));
        }
        if (unused.empty()) return;
        std::string list;
        for (size_t i = 0; i < unused.size(); ++i) list += (i ? ", " : "") + unused[i];
        std::string msg =
            unused.size() == 1
                ? fmt::format("unused parameter {}: {} never references it", list, file)
                : fmt::format("unused parameters {}: {} never references them", list, file);
        if (!m_opts.lenient) throw Error(msg);
        FACET_LOG(Warn, "{}", msg);
    }

    std::vector<std::string> known_ids() const {
        std::vector<std::string> ids;
        for (const auto &kv : m_ids) ids.push_back(kv.first);
        return ids;
    }

    std::string did_you_mean(const std::string &id) const {
        std::string close = closest_name(id, known_ids());
        return close.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", close);
    }

    void apply_aliases() {
        for (const Alias &a : m_aliases) {
            auto src = m_ids.find(a.source);
            if (src == m_ids.end())
                fail(a.location, fmt::format("<alias> refers to unknown id \"{}\"{}", a.source,
                                             did_you_mean(a.source)));
            auto dst = m_ids.find(a.target);
            if (dst != m_ids.end())
                fail(a.location,
                     fmt::format("<alias> target id \"{}\" already exists (declared at {})",
                                 a.target, dst->second.location.to_string()));
            m_ids.emplace(a.target, IdEntry{src->second.node, a.location});
        }
    }

    void resolve_references() {
        for (ObjectNode &node : m_nodes)
            for (Entry &e : node.entries) {
                if (e.kind != Entry::Kind::Ref) continue;
                auto it = m_ids.find(e.ref_id);
                if (it == m_ids.end())
                    fail(e.location, fmt::format("reference to unknown id \"{}\"{}", e.ref_id,
                                                 did_you_mean(e.ref_id)));
                e.child = it->second.node;
            }
    }

    /// Depth-first search from the root; a back edge is a reference cycle.
    void check_cycles(size_t root) {
        std::vector<int> state(m_nodes.size(), 0); // 0 new, 1 on the stack, 2 done
        std::vector<size_t> height(m_nodes.size(), 0);
        std::vector<size_t> stack;
        visit_for_cycles(root, state, height, stack);
    }

    /// Also bounds the depth of the object graph (`height`: the objects on the longest chain
    /// that starts at a node), which references can make far deeper than the nesting of the
    /// tags: instantiation and the plugins recurse along it.
    void visit_for_cycles(size_t index, std::vector<int> &state, std::vector<size_t> &height,
                          std::vector<size_t> &stack) {
        state[index] = 1;
        stack.push_back(index);
        size_t h = 1;
        for (const Entry &e : m_nodes[index].entries) {
            if (e.child == NoNode) continue;
            if (state[e.child] == 1) {
                auto start = std::find(stack.begin(), stack.end(), e.child);
                std::string chain;
                for (auto it = start; it != stack.end(); ++it)
                    chain += m_nodes[*it].describe() + " -> ";
                fail(e.location,
                     "circular reference detected: " + chain + m_nodes[e.child].describe());
            }
            if (state[e.child] == 0 && stack.size() <= MaxObjectDepth)
                visit_for_cycles(e.child, state, height, stack);
            if (state[e.child] != 2 || height[e.child] > MaxObjectDepth)
                fail(e.location, fmt::format("objects are nested more than {} deep through "
                                             "references (the limit of the scene loader)",
                                             MaxObjectDepth));
            h = std::max(h, height[e.child] + 1);
        }
        stack.pop_back();
        state[index] = 2;
        height[index] = h;
    }

    // -- Instantiation --------------------------------------------------------------------------

    /// Children first, in declaration order; each node once.
    std::shared_ptr<Object> instantiate(size_t index) {
        if (m_nodes[index].instance) return m_nodes[index].instance;
        Properties props(m_nodes[index].plugin);
        props.set_mode(m_mode);
        props.set_id(m_nodes[index].id);
        props.set_location(m_nodes[index].location);
        for (const Entry &e : m_nodes[index].entries) {
            if (e.kind == Entry::Kind::Value)
                props.set(e.name, e.value, e.location);
            else
                props.set(e.name, instantiate(e.child), e.location);
        }

        ObjectNode &node = m_nodes[index];
        std::shared_ptr<Object> obj;
        if (node.kind == ObjectType::Scene) {
            try {
                obj = std::make_shared<Scene>(props);
            } catch (const std::exception &e) {
                throw instantiation_error(node, e, "failed to instantiate the scene");
            }
            check_unqueried(props, ObjectType::Scene, m_opts.lenient);
        } else {
            // The registry's errors already say which plugin failed, at the innermost location.
            obj = PluginRegistry::instance().create(node.kind, props, m_opts.lenient);
        }
        node.requested = props.requested_names();
        if (!node.id.empty()) obj->set_id(node.id);
        node.instance = obj;
        m_created.push_back(index);
        return obj;
    }

    /// "<what>: <why>" at the innermost known location; messages that already name the failing
    /// plugin are kept as they are.
    static Error instantiation_error(const ObjectNode &node, const std::exception &e,
                                     const std::string &what) {
        const Error *err = dynamic_cast<const Error *>(&e);
        std::string msg = err ? err->message() : std::string(e.what());
        Location loc = err && err->location().valid() ? err->location() : node.location;
        if (msg.find("failed to ") != std::string::npos) return Error(loc, msg);
        return Error(loc, fmt::format("{}: {}", what, msg));
    }

    const LoadOptions &m_opts;
    const ColourMode m_mode; ///< every object's (Properties::mode())
    std::vector<std::unique_ptr<SourceFile>> m_sources;
    std::deque<ObjectNode> m_nodes;
    std::map<std::string, IdEntry> m_ids;
    std::vector<Alias> m_aliases;
    std::map<std::string, Parameter> m_params;
    std::vector<std::string> m_keys; ///< parameter names, longest first
    std::vector<SourceFile *> m_include_stack;
    std::unordered_map<std::string, SourceFile *> m_files; ///< by canonical name: read once
    /// (folder of the including file, filename) -> (path, canonical name); cleared by <path>.
    std::unordered_map<std::string, std::pair<fs::path, std::string>> m_resolved;
    size_t m_includes = 0;          ///< inclusions so far (MaxIncludes)
    size_t m_scene_bytes = 0;       ///< XML bytes so far, each inclusion counted (MaxSceneBytes)
    size_t m_repeating = 0;         ///< repeated inclusions being read (nested in one another)
    size_t m_repeated_elements = 0; ///< elements read in them (MaxRepeatedElements)
    std::pair<Location, std::string> m_repeated_include; ///< the outermost of them, its filename
    size_t m_expanded = 0;         ///< bytes produced by $name substitution (MaxExpandedText)
    std::vector<size_t> m_created; ///< nodes in creation order
    size_t m_object_depth = 0;     ///< objects open around the element being parsed
};

} // namespace

std::shared_ptr<Object> load_file(const std::string &path, const LoadOptions &opts) {
    return Loader(opts).load_file(path, false);
}

std::shared_ptr<Object> load_string(const std::string &xml, const LoadOptions &opts) {
    return Loader(opts).load_string(xml, false);
}

std::shared_ptr<Scene> load_scene(const std::string &path, const LoadOptions &opts) {
    return std::static_pointer_cast<Scene>(Loader(opts).load_file(path, true));
}

SceneInfo scene_info(const std::string &path, const LoadOptions &opts) {
    return Loader(opts).info_file(path);
}

} // namespace facet
