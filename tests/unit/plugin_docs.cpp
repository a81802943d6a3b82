// Every plugin documents what it reads: each parameter its constructor asks for (present or not)
// appears as a row of the Markdown table in its doc string, which `facet plugins <name>` prints.

#include <facet/plugin.h>

#include <gtest/gtest.h>

#include <regex>

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
        // Construct with no parameters: plugins with required parameters throw, but every name
        // asked for up to that point is recorded, and the defaults path covers the rest.
        Properties props(name);
        try {
            registry.create(desc.kind, props, /*lenient=*/true);
        } catch (const std::exception &) {}
        for (const std::string &requested : props.requested_names())
            EXPECT_TRUE(documented.count(requested))
                << name << " reads \"" << requested
                << "\" but its parameter table does not list it";
    }
}
