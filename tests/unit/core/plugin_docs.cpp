// Every plugin documents what it reads: each parameter its constructor asks for (present or not)
// appears as a row of the Markdown table in its doc string, which `facet plugins <name>` prints.

#include <facet/plugin.h>

#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

using namespace facet;

namespace {

/// Names in the first column of the doc's Markdown table rows ("| name | type | ...").
std::set<std::string> documented_names(const std::string &doc) {
    std::set<std::string> names;
    std::regex row(R"(^\|\s*`?([A-Za-z_][A-Za-z0-9_]*)`?\s*\|)");
    size_t start = 0;
    while (start < doc.size()) {
        size_t end = doc.find('\n', start);
        if (end == std::string::npos) end = doc.size();
        std::string line = doc.substr(start, end - start);
        std::smatch m;
        if (std::regex_search(line, m, row)) names.insert(m[1]);
        start = end + 1;
    }
    return names;
}

/// Files the file-reading plugins get (small assets in the repository).
std::string asset(const std::string &relative) {
    return std::string(FACET_SOURCE_DIR) + "/tests/" + relative;
}

std::shared_ptr<Object> make(ObjectType kind, Properties props) {
    return PluginRegistry::instance().create(kind, props);
}

/// Valid parameters for plugins that cannot be built without any (files to read, required
/// values, children), so that their constructor runs to the end and every name it asks for is
/// checked. A plugin that throws with no parameters and has no entry here fails the test: add one.
Properties valid_properties(const std::string &name) {
    Properties p(name);
    if (name == "envmap" || name == "bitmap") {
        p.set_string("filename", asset("chi2/envmap_spot.exr"));
    } else if (name == "obj" || name == "ply" || name == "serialized") {
        p.set_string("filename", asset("data/plugin_docs/triangle." + name));
    } else if (name == "sdfgrid") {
        p.set_string("filename", asset("data/plugin_docs/sdfgrid.vol"));
    } else if (name == "merge") {
        p.set_object("ball", make(ObjectType::Shape, Properties("sphere")));
    } else if (name == "aov") {
        p.set_string("aovs", "dd:depth");
    } else if (name == "specfilm") {
        // A film of the spectral modes; its bands are spectra of any name (not parameters).
        p.set_mode(ColourMode::Spectral);
        p.set("band", parse_spectrum_pairs("400:0, 500:1, 600:0"));
    } else if (name == "thinlens") {
        p.set_float("aperture_radius", 0.1);
        p.set_float("focus_distance", 2.0);
    } else if (name == "mesh_attribute") {
        p.set_string("name", "vertex_color");
    } else if (name == "shapegroup") {
        p.set_object("ball", make(ObjectType::Shape, Properties("sphere")));
    } else if (name == "instance") {
        Properties group("shapegroup");
        group.set_object("ball", make(ObjectType::Shape, Properties("sphere")));
        p.set_object("group", make(ObjectType::Shape, group));
    } else if (name == "twosided" || name == "mask") {
        p.set_object("nested", make(ObjectType::BSDF, Properties("diffuse")));
    } else if (name == "blendbsdf") {
        p.set_float("weight", 0.5);
        p.set_object("_arg_0", make(ObjectType::BSDF, Properties("diffuse")));
        p.set_object("_arg_1", make(ObjectType::BSDF, Properties("diffuse")));
    } else if (name == "radiancemeter" || name == "distant") {
        Properties film("hdrfilm");
        film.set_int("width", 1);
        film.set_int("height", 1);
        p.set_object("film", make(ObjectType::Film, film));
    } else if (name == "moment" || name == "stokes") {
        p.set_object("_arg_0", make(ObjectType::Integrator, Properties("path")));
    } else if (name == "blackbody") {
        p.set_float("temperature", 5000.0);
    } else if (name == "uniform" || name == "rawconstant") {
        p.set_float("value", 0.5);
    } else if (name == "srgb") {
        p.set_color("color", Color3f(0.2f, 0.4f, 0.6f));
    } else if (name == "regular") {
        p.set_float("wavelength_min", 400.0);
        p.set_float("wavelength_max", 700.0);
        p.set_string("values", "0.2, 0.5, 0.8");
    } else if (name == "irregular") {
        p.set_string("wavelengths", "400, 550, 700");
        p.set_string("values", "0.2, 0.5, 0.8");
    } else if (name == "normalmap" || name == "bumpmap") {
        Properties map("bitmap");
        map.set_string("filename", asset(name == "normalmap" ? "chi2/normal_tilt.exr"
                                                             : "chi2/height_ramp.exr"));
        map.set_bool("raw", true);
        p.set_object(name == "normalmap" ? "normalmap" : "_arg_0", make(ObjectType::Texture, map));
        p.set_object("nested", make(ObjectType::BSDF, Properties("diffuse")));
    }
    return p;
}

} // namespace

TEST(PluginDocs, EveryRequestedParameterIsInTheTable) {
    auto &registry = PluginRegistry::instance();
    auto plugins = registry.available();
    ASSERT_GE(plugins.size(), 30u);
    for (const std::string &name : plugins) {
        SCOPED_TRACE(name);
        const PluginDescriptor &desc = registry.descriptor(name);
        ASSERT_NE(desc.doc, nullptr);
        ASSERT_NE(desc.description, nullptr);
        EXPECT_FALSE(std::string(desc.description).empty());
        std::set<std::string> documented = documented_names(desc.doc);
        EXPECT_FALSE(documented.empty() &&
                     std::string(desc.doc).find("no parameters") == std::string::npos)
            << "no parameter table in the doc of " << name;
        // With no parameters (the defaults path), and with valid ones when the plugin needs
        // some: both constructions run to the end, and every name asked for is in the table.
        std::vector<Properties> constructions{Properties(name)};
        try {
            registry.create(desc.kind, constructions[0], /*lenient=*/true);
        } catch (const std::exception &e) {
            constructions.push_back(valid_properties(name));
            try {
                registry.create(desc.kind, constructions[1], /*lenient=*/true);
            } catch (const std::exception &e2) {
                ADD_FAILURE() << name << " cannot be built with no parameters (" << e.what()
                              << ") nor with those of valid_properties() (" << e2.what()
                              << "): give it valid parameters there";
                continue;
            }
        }
        for (const Properties &props : constructions)
            for (const std::string &requested : props.requested_names())
                EXPECT_TRUE(documented.count(requested))
                    << name << " reads \"" << requested
                    << "\" but its parameter table does not list it";
    }
}
