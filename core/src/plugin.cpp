#include <facet/emitter.h>
#include <facet/plugin.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <dlfcn.h>
#include <filesystem>
#include <mutex>
#include <set>

namespace facet {

namespace fs = std::filesystem;

namespace {

/// The folder holding libfacet itself, found through a function defined in it.
std::string libfacet_dir() {
    Dl_info info{};
    if (dladdr(reinterpret_cast<void *>(&libfacet_dir), &info) == 0 || !info.dli_fname) return "";
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::path(info.dli_fname), ec);
    if (ec) p = fs::path(info.dli_fname);
    return p.parent_path().string();
}

std::string dl_error() {
    const char *e = dlerror();
    return e ? e : "unknown error";
}

std::string join(const std::vector<std::string> &v) {
    std::string s;
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
    return s;
}

std::string kind_name(ObjectType kind) { return object_type_name(kind); }

/// "a bsdf", "an emitter", "an integrator".
std::string with_article(ObjectType kind) {
    std::string name = kind_name(kind);
    bool vowel = !name.empty() && std::string("aeiou").find(name[0]) != std::string::npos;
    return (vowel ? "an " : "a ") + name;
}

/// Whether the scene gave `name` and nothing has read it yet.
bool is_unqueried(const Properties &props, const std::string &name) {
    const std::vector<std::string> unused = props.unqueried();
    return std::find(unused.begin(), unused.end(), name) != unused.end();
}

} // namespace

PluginRegistry::PluginRegistry() = default;

PluginRegistry &PluginRegistry::instance() {
    static PluginRegistry registry;
    return registry;
}

void PluginRegistry::add_search_dir(const std::string &dir) {
    std::lock_guard<std::recursive_mutex> lock(m_mutex);
    if (std::find(m_dirs.begin(), m_dirs.end(), dir) == m_dirs.end()) m_dirs.push_back(dir);
}

std::vector<std::string> PluginRegistry::search_path() const {
    std::vector<std::string> path;
    {
        std::lock_guard<std::recursive_mutex> lock(m_mutex);
        path = m_dirs;
    }
    if (const char *env = std::getenv("FACET_PLUGIN_PATH")) {
        std::string s(env);
        size_t start = 0;
        while (start <= s.size()) {
            size_t end = s.find(':', start);
            if (end == std::string::npos) end = s.size();
            if (end > start) path.push_back(s.substr(start, end - start));
            start = end + 1;
        }
    }
    // `<libdir>/facet/plugins`: lib/facet/plugins in the build tree, and the installed layout.
    std::string lib = libfacet_dir();
    if (!lib.empty()) path.push_back((fs::path(lib) / "facet" / "plugins").string());
    std::vector<std::string> unique;
    for (auto &d : path)
        if (std::find(unique.begin(), unique.end(), d) == unique.end()) unique.push_back(d);
    return unique;
}

void PluginRegistry::register_static(const PluginDescriptor *desc) {
    if (!desc || !desc->name) FACET_THROW("register_static: invalid plugin descriptor");
    if (desc->abi_version != FACET_ABI_VERSION)
        FACET_THROW(
            "plugin \"{}\" was built for facet ABI version {}, but this facet has ABI version "
            "{}; rebuild the plugin",
            desc->name, desc->abi_version, FACET_ABI_VERSION);
    std::lock_guard<std::recursive_mutex> lock(m_mutex);
    m_loaded[desc->name] = desc;
}

std::string PluginRegistry::find_library(const std::string &name) const {
    for (const auto &dir : search_path()) {
        fs::path p = fs::path(dir) / (name + ".so");
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) continue;
        // A library of the same name among facet's own plugins is shadowed: say so, once.
        const std::string lib = libfacet_dir();
        const fs::path builtin = fs::path(lib) / "facet" / "plugins" / (name + ".so");
        if (!lib.empty() && fs::path(dir) != builtin.parent_path() &&
            fs::is_regular_file(builtin, ec)) {
            static std::mutex mutex;
            static std::set<std::string> announced;
            std::lock_guard<std::mutex> lock(mutex);
            if (announced.insert(name).second)
                FACET_LOG(Info, "plugin \"{}\": using {}, which shadows the built-in {}", name,
                          p.string(), builtin.string());
        }
        return p.string();
    }
    return "";
}

const PluginDescriptor &PluginRegistry::load_library(const std::string &path, ObjectType expected) {
    std::lock_guard<std::recursive_mutex> lock(m_mutex);
    dlerror();
    void *handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) FACET_THROW("could not load plugin \"{}\": {}", path, dl_error());
    dlerror();
    void *sym = dlsym(handle, "facet_plugin_descriptor");
    if (!sym) {
        std::string err = dl_error();
        dlclose(handle);
        FACET_THROW("\"{}\" is not a facet plugin (no facet_plugin_descriptor: {})", path, err);
    }
    // Libraries stay loaded until exit, so the descriptor's strings stay valid.
    m_handles.push_back(handle);
    const PluginDescriptor *desc = reinterpret_cast<PluginDescriptorFn>(sym)();
    if (!desc) FACET_THROW("plugin \"{}\" returned no descriptor", path);
    // abi_version is the first member in every version, so it is safe to read before anything else.
    if (desc->abi_version != FACET_ABI_VERSION)
        FACET_THROW(
            "plugin \"{}\" was built for facet ABI version {}, but this facet has ABI version "
            "{}; rebuild the plugin",
            path, desc->abi_version, FACET_ABI_VERSION);
    std::string file_name = fs::path(path).stem().string();
    if (!desc->name || file_name != desc->name)
        FACET_THROW("plugin \"{}\" calls itself \"{}\"; the library must be named after its plugin",
                    path, desc->name ? desc->name : "");
    if (expected != ObjectType::Unknown && desc->kind != expected)
        FACET_THROW("plugin \"{}\" ({}) is {} plugin, but {} was expected here", desc->name, path,
                    with_article(desc->kind), with_article(expected));
    m_loaded[desc->name] = desc;
    return *desc;
}

const PluginDescriptor &PluginRegistry::descriptor(const std::string &name, ObjectType expected) {
    std::lock_guard<std::recursive_mutex> lock(m_mutex);
    const PluginDescriptor *desc = nullptr;
    auto it = m_loaded.find(name);
    if (it != m_loaded.end()) {
        desc = it->second;
    } else {
        std::string path = find_library(name);
        if (path.empty()) {
            std::string kind = expected == ObjectType::Unknown ? "" : kind_name(expected) + " ";
            std::vector<std::string> known = available(expected);
            std::string msg = fmt::format("unknown {}plugin \"{}\"", kind, name);
            std::string close = closest_name(name, known);
            msg += close.empty() ? "." : fmt::format("; did you mean \"{}\"?", close);
            if (known.empty())
                msg += fmt::format(" No {}plugins were found (searched: {})", kind,
                                   join(search_path()));
            else
                msg += fmt::format(" Known {}plugins: {}", kind, join(known));
            throw Error(msg);
        }
        desc = &load_library(path, ObjectType::Unknown);
        if (expected != ObjectType::Unknown && desc->kind != expected)
            FACET_THROW("plugin \"{}\" ({}) is {} plugin, but {} was expected here", name, path,
                        with_article(desc->kind), with_article(expected));
        return *desc;
    }
    if (expected != ObjectType::Unknown && desc->kind != expected)
        FACET_THROW("plugin \"{}\" is {} plugin, but {} was expected here", name,
                    with_article(desc->kind), with_article(expected));
    return *desc;
}

std::shared_ptr<Object> PluginRegistry::create(ObjectType expected, const Properties &props,
                                               bool lenient) {
    const std::string &name = props.plugin_name();
    if (expected == ObjectType::Scene)
        FACET_THROW_AT(props.location(), "the scene is built by the loader, not by a plugin");
    const PluginDescriptor *desc;
    try {
        desc = &descriptor(name, expected);
    } catch (const Error &e) {
        if (e.location().valid()) throw;
        throw Error(props.location(), e.message());
    }
    if (!(desc->modes & mode_bit(props.mode())))
        FACET_THROW_AT(props.location(),
                       "the {} plugin \"{}\" does not render in the mode {} (it renders in: {})",
                       kind_name(desc->kind), name, mode_name(props.mode()), plugin_modes(*desc));
    std::shared_ptr<Object> obj;
    try {
        obj = std::shared_ptr<Object>(desc->create(props));
    } catch (const std::exception &e) {
        const Error *fe = dynamic_cast<const Error *>(&e);
        // Keep the most precise location: the entry's if the plugin gave one, else the object's.
        Location loc = fe && fe->location().valid() ? fe->location() : props.location();
        std::string what = fe ? fe->message() : std::string(e.what());
        throw Error(loc, fmt::format("failed to instantiate {} plugin of type \"{}\": {}",
                                     kind_name(desc->kind), name, what));
    }
    if (!obj)
        FACET_THROW_AT(props.location(), "failed to instantiate {} plugin of type \"{}\"",
                       kind_name(desc->kind), name);
    if (expected != ObjectType::Unknown && obj->type() != expected)
        FACET_THROW_AT(props.location(), "plugin \"{}\" created {}, but {} was expected here", name,
                       with_article(obj->type()), with_article(expected));
    if (!props.id().empty()) obj->set_id(props.id());
    if (auto *emitter = dynamic_cast<Emitter *>(obj.get());
        emitter && is_unqueried(props, "sampling_weight")) {
        // Every emitter's parameter, as in Mitsuba 3: how often light samples go to it. (Looked
        // up among the unqueried names, so that a plugin's own parameters, which its table
        // lists, are all that it asks for.)
        const double weight = props.get_float("sampling_weight");
        if (!(weight >= 0.0) || !std::isfinite(float(weight)))
            FACET_THROW_AT(props.location("sampling_weight"),
                           "{} plugin of type \"{}\": sampling_weight must be a finite number >= "
                           "0, got {}",
                           kind_name(desc->kind), name, weight);
        emitter->set_sampling_weight(float(weight));
    }
    check_unqueried(props, obj->type(), lenient);
    return obj;
}

std::string plugin_modes(const PluginDescriptor &desc) {
    std::vector<std::string> names;
    for (const std::string &mode : modes())
        if (desc.modes & mode_bit(colour_mode(mode))) names.push_back(mode);
    return names.empty() ? std::string("no mode") : fmt::format("{}", fmt::join(names, ", "));
}

std::vector<std::string> PluginRegistry::available(ObjectType kind) {
    std::lock_guard<std::recursive_mutex> lock(m_mutex);
    std::set<std::string> names;
    for (const auto &[name, desc] : m_loaded)
        if (kind == ObjectType::Unknown || desc->kind == kind) names.insert(name);
    for (const auto &dir : search_path()) {
        std::error_code ec;
        for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
            const fs::path &p = it->path();
            if (p.extension() != ".so") continue;
            std::string name = p.stem().string();
            auto loaded = m_loaded.find(name);
            const PluginDescriptor *desc = loaded != m_loaded.end() ? loaded->second : nullptr;
            if (!desc) {
                try {
                    desc = &load_library(p.string());
                } catch (const Error &) {
                    continue; // not a usable plugin: leave it out of the list
                }
            }
            if (kind == ObjectType::Unknown || desc->kind == kind) names.insert(name);
        }
    }
    return std::vector<std::string>(names.begin(), names.end());
}

void check_unqueried(const Properties &props, ObjectType kind, bool lenient) {
    std::vector<std::string> unused = props.unqueried();
    if (unused.empty()) return;
    std::string msg =
        fmt::format("Found {} unreferenced propert{} in {} plugin of type \"{}\":", unused.size(),
                    unused.size() == 1 ? "y" : "ies", object_type_name(kind), props.plugin_name());
    // Parameters the plugin asked for but did not get: the likely intended names of typos.
    std::vector<std::string> missing;
    const std::vector<std::string> requested = props.requested_names(); // has() may append
    for (const auto &r : requested)
        if (!props.has(r)) missing.push_back(r);
    for (const auto &name : unused) {
        std::string entry = props.entry_to_string(name);
        const Location &loc = props.location(name);
        // entry_to_string gives `type "name": value`; put the location after the name.
        size_t colon = entry.find("\": ");
        if (loc.valid() && colon != std::string::npos)
            entry =
                entry.substr(0, colon + 1) + " (" + loc.to_string() + ")" + entry.substr(colon + 1);
        std::string suggestion = closest_name(name, missing);
        if (!suggestion.empty()) entry += fmt::format(" (did you mean \"{}\"?)", suggestion);
        msg += "\n  - " + entry;
    }
    if (!lenient) throw Error(props.location(), msg);
    if (props.location().valid()) msg = props.location().to_string() + ": " + msg;
    FACET_LOG(Warn, "{}", msg);
}

size_t edit_distance(const std::string &a, const std::string &b) {
    std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            size_t subst = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, subst});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

std::string closest_name(const std::string &name, const std::vector<std::string> &candidates) {
    std::string best;
    size_t best_dist = std::numeric_limits<size_t>::max();
    for (const auto &c : candidates) {
        size_t d = edit_distance(name, c);
        if (d < best_dist) {
            best_dist = d;
            best = c;
        }
    }
    size_t limit = std::max<size_t>(2, name.size() / 3);
    return best_dist <= limit ? best : std::string();
}

} // namespace facet
