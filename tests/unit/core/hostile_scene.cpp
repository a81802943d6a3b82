// Hostile scenes: inputs built to exhaust the stack, memory or Embree's assumptions must end in a
// located facet::Error, never in a crash, an abort or gigabytes of allocations.

#include <facet/bsdf.h>
#include <facet/film.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace facet;

namespace {

/// `count` copies of `open`, then `middle`, then `count` copies of `close`.
std::string nested(const std::string &open, const std::string &middle, const std::string &close,
                   int count) {
    std::string s;
    for (int i = 0; i < count; ++i) s += open;
    s += middle;
    for (int i = 0; i < count; ++i) s += close;
    return s;
}

/// Loads `xml` and expects a facet::Error whose message contains `needle`, located in the string
/// (line `line`, any column when `line` is 0). Returns the message.
std::string expect_load_error(const std::string &xml, const std::string &needle, int line = 0) {
    try {
        load_string(xml);
    } catch (const Error &e) {
        EXPECT_NE(e.message().find(needle), std::string::npos) << e.what();
        EXPECT_EQ(e.location().file, "string") << e.what();
        EXPECT_GT(e.location().line, 0) << e.what();
        if (line > 0) {
            EXPECT_EQ(e.location().line, line) << e.what();
        }
        return e.what();
    }
    ADD_FAILURE() << "no error for a hostile scene (expected \"" << needle << "\")";
    return {};
}

} // namespace

// -- Depth --------------------------------------------------------------------------------------

TEST(HostileScene, DeeplyNestedElementsAreRefusedNotAStackOverflow) {
    // Thousands of nested objects overflowed the loader's recursion (a segfault).
    std::string xml =
        "<scene version=\"3.0.0\">\n<shape type=\"sphere\">\n" +
        nested("<bsdf type=\"twosided\">", "<bsdf type=\"diffuse\"/>", "</bsdf>", 100000) +
        "</shape></scene>";
    expect_load_error(xml, "nested more than 256 objects deep", 3);
}

TEST(HostileScene, NestingUpToTheLimitLoads) {
    // A root texture and 255 nested ones are 256 objects: the limit. One more is refused.
    auto chain = [](int nested_textures) {
        return "<texture version=\"3.0.0\" type=\"checkerboard\">" +
               nested("<texture type=\"checkerboard\" name=\"color0\">", "", "</texture>",
                      nested_textures) +
               "</texture>";
    };
    EXPECT_TRUE(load_string(chain(255)));
    expect_load_error(chain(256), "nested more than 256 objects deep", 1);
}

TEST(HostileScene, LongReferenceChainsAreRefused) {
    // Each texture refers to the next one: a flat file whose object graph is deep. Checking
    // cycles and instantiating both recurse along it.
    auto chain = [](int first, int count, bool last = true) {
        std::string xml;
        for (int i = first; i < first + count; ++i)
            xml += "<texture type=\"checkerboard\" id=\"t" + std::to_string(i) +
                   "\"><ref name=\"color0\" id=\"t" + std::to_string(i + 1) + "\"/></texture>\n";
        if (!last) return xml;
        return xml + "<texture type=\"checkerboard\" id=\"t" + std::to_string(first + count) +
               "\"/>\n";
    };
    const std::string head = "<scene version=\"3.0.0\">\n";
    const std::string tail = "<shape type=\"sphere\"><bsdf type=\"diffuse\"><ref "
                             "name=\"reflectance\" id=\"t0\"/></bsdf></shape></scene>";
    expect_load_error(head + chain(0, 20000) + tail,
                      "nested more than 256 deep through references");
    // Chains declared in the order they are used never recurse deeply while loading, but the
    // plugins' evaluation recurses along the whole graph: its depth is what counts.
    std::string reversed;
    for (int block = 9; block >= 0; --block) reversed += chain(block * 100, 100, block == 9);
    expect_load_error(head + reversed + tail, "nested more than 256 deep through references");
    EXPECT_TRUE(load_string(head + chain(0, 250) + tail));
}

// -- Non-finite parameters ------------------------------------------------------------------------

TEST(HostileScene, NonFiniteParametersAreRefusedWhereTheyAreWritten) {
    // A NaN reflectance used to render with a warning and an infinite radiance rendered black,
    // both with success.
    const std::string head = "<scene version=\"3.0.0\">\n";
    expect_load_error(head + "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"nan\"/>"
                             "</bsdf></scene>",
                      "rgb \"reflectance\" contains NaN", 2);
    expect_load_error(head +
                          "<shape type=\"sphere\">\n<emitter type=\"area\">\n"
                          "<rgb name=\"radiance\" value=\"1, inf, 1\"/></emitter></shape></scene>",
                      "rgb \"radiance\" contains an infinite", 4);
    expect_load_error(head + "<emitter type=\"constant\"><float name=\"radiance\" value=\"-inf\"/>"
                             "</emitter></scene>",
                      "float \"radiance\" contains an infinite", 2);
    // Finite as a double, infinite as the float the plugin computes with.
    expect_load_error(head + "<shape type=\"sphere\"><float name=\"radius\" value=\"1e300\"/>"
                             "</shape></scene>",
                      "out-of-range", 2);
    // Finite as a float, but its area and frame overflow: said so, not "collapses".
    expect_load_error(head + "<shape type=\"cylinder\">\n<float name=\"radius\" value=\"1e30\"/>"
                             "</shape></scene>",
                      "cylinder: too large", 3);
    expect_load_error(head + "<shape type=\"sphere\"><point name=\"center\" value=\"0, nan, 0\"/>"
                             "</shape></scene>",
                      "vector \"center\" contains NaN", 2);
    expect_load_error(head + "<bsdf type=\"diffuse\"><spectrum name=\"reflectance\" "
                             "value=\"400:0.5, 500:nan\"/></bsdf></scene>",
                      "spectrum \"reflectance\" contains NaN", 2);
    expect_load_error(head + "<shape type=\"sphere\"><transform name=\"to_world\">"
                             "<rotate x=\"1\" angle=\"nan\"/></transform></shape></scene>",
                      "transform \"to_world\" contains NaN", 2);
    expect_load_error(head + "<shape type=\"sphere\"><transform name=\"to_world\">"
                             "<scale value=\"1e39\"/></transform></shape></scene>",
                      "transform \"to_world\" contains an infinite", 2);
}

TEST(HostileScene, NonFiniteParameterValuesFromTheCommandLine) {
    LoadOptions opts;
    opts.params["r"] = "NaN";
    try {
        load_string("<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\">\n"
                    "<float name=\"reflectance\" value=\"$r\"/></bsdf></scene>",
                    opts);
        ADD_FAILURE() << "a NaN from -D was accepted";
    } catch (const Error &e) {
        EXPECT_EQ(e.location().line, 3) << e.what();
        EXPECT_NE(e.message().find("contains NaN"), std::string::npos) << e.what();
    }
}

TEST(HostileScene, NonFiniteValuesAreRefusedByPropertiesItself) {
    // Scenes built in code (not from XML) go through the same check.
    Properties props("diffuse");
    EXPECT_THROW(props.set_float("reflectance", std::nan("")), Error);
    EXPECT_THROW(props.set_color("reflectance", Color3f(1.f, INFINITY, 1.f)), Error);
    EXPECT_THROW(props.set_vector("center", Vector3f(NAN, 0.f, 0.f)), Error);
    props.set_float("reflectance", 0.5);
    EXPECT_EQ(props.get_float("reflectance"), 0.5);
}

// -- What reaches Embree --------------------------------------------------------------------------

namespace {

/// A scene with a perspective camera placed by `sensor_transform` (the contents of its
/// <transform name="to_world">) around `body`; the sensor's transform is on line 3.
std::string scene_with(const std::string &body,
                       const std::string &sensor_transform =
                           "<lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>",
                       const std::string &film = "") {
    return "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\n"
           "<transform name=\"to_world\">" +
           sensor_transform + "</transform>\n<film type=\"hdrfilm\">" + film +
           "<integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/>"
           "</film></sensor>\n" +
           body + "</scene>";
}

} // namespace

TEST(HostileScene, SensorTransformsEmbreeCannotTakeAreRefused) {
    // Each of these aborted the process in Embree's ray assertion.
    expect_load_error(scene_with("", "<scale value=\"0\"/>"), "to_world is singular", 3);
    expect_load_error(scene_with("", "<translate x=\"1e18\"/>"), "to_world has an entry", 3);
    expect_load_error(
        scene_with("", "<lookat origin=\"1e30, 0, 0\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>"),
        "to_world has an entry", 3);
    expect_load_error(scene_with("", "<scale value=\"1e-20\"/>"), "nearly singular", 3);
    EXPECT_TRUE(load_string(scene_with("", "<scale x=\"-1\"/><translate x=\"1e6\"/>")));
}

TEST(HostileScene, ShapesBeyondEmbreesRangeAreRefused) {
    expect_load_error(scene_with("<shape type=\"sphere\"><transform name=\"to_world\">"
                                 "<translate x=\"1e30\"/></transform></shape>\n"),
                      "bounding box reaches", 5);
    expect_load_error(scene_with("<shape type=\"rectangle\"><transform name=\"to_world\">"
                                 "<scale value=\"1e20\"/></transform></shape>\n"),
                      "bounding box reaches", 5);
}

TEST(HostileScene, NestedInstancesAreRefused) {
    // Embree (one instance level in this build) aborted on an instance inside a shapegroup.
    expect_load_error(scene_with("<shape type=\"shapegroup\" id=\"inner\"><shape type=\"sphere\"/>"
                                 "</shape>\n<shape type=\"shapegroup\" id=\"outer\">\n"
                                 "<shape type=\"instance\"><ref id=\"inner\"/></shape></shape>\n"
                                 "<shape type=\"instance\"><ref id=\"outer\"/></shape>\n"),
                      "cannot contain an instance", 7);
}

TEST(HostileScene, InstanceTransformsEmbreeCannotTakeAreRefused) {
    const std::string group =
        "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>\n";
    auto instance = [&](const std::string &ops) {
        return scene_with(group +
                          "<shape type=\"instance\"><ref id=\"g\"/>\n"
                          "<transform name=\"to_world\">" +
                          ops + "</transform></shape>\n");
    };
    expect_load_error(instance("<scale value=\"0\"/>"), "instance: to_world is singular", 7);
    expect_load_error(instance("<scale value=\"1e-6\"/>"), "nearly singular", 7);
    EXPECT_TRUE(load_string(instance("<scale value=\"1e-3\"/><translate x=\"100\"/>")));
}

TEST(HostileScene, RaysEmbreeCannotTakeMissInsteadOfAborting) {
    auto scene =
        std::dynamic_pointer_cast<Scene>(load_string(scene_with("<shape type=\"sphere\"/>")));
    ASSERT_TRUE(scene);
    SurfaceInteraction si;
    Ray good(Point3f(0.f, 0.f, 5.f), Vector3f(0.f, 0.f, -1.f), 0.f, Infinity);
    EXPECT_TRUE(scene->ray_intersect(good, si));
    // A NaN direction (from a NaN normal map texel, say) and an origin beyond Embree's range.
    Ray nan_dir(Point3f(0.f, 0.f, 5.f), Vector3f(NAN, 0.f, -1.f), 0.f, Infinity);
    EXPECT_FALSE(scene->ray_intersect(nan_dir, si));
    EXPECT_FALSE(scene->ray_test(nan_dir));
    Ray far(Point3f(1e19f, 0.f, 5.f), Vector3f(0.f, 0.f, -1.f), 0.f, Infinity);
    EXPECT_FALSE(scene->ray_intersect(far, si));
    EXPECT_FALSE(scene->ray_test(far));
    // Each field on its own: NaN anywhere, or beyond the range in the origin or direction.
    auto field = [](Ray &r, int k) -> float & {
        float *f[8] = {&r.o.x, &r.o.y, &r.o.z, &r.d.x, &r.d.y, &r.d.z, &r.mint, &r.maxt};
        return *f[k];
    };
    for (int k = 0; k < 8; ++k)
        for (float bad : {float(NAN), 1e19f, -1e19f}) {
            if (k >= 6 && !std::isnan(bad)) continue; // a huge mint or maxt is valid (below)
            Ray r = good;
            field(r, k) = bad;
            EXPECT_FALSE(scene->ray_intersect(r, si)) << "field " << k << " = " << bad;
            EXPECT_FALSE(scene->ray_test(r)) << "field " << k << " = " << bad;
        }
    Ray long_ray = good;
    long_ray.maxt = 1e19f;
    EXPECT_TRUE(scene->ray_intersect(long_ray, si));
    EXPECT_TRUE(scene->ray_test(long_ray));
}

// -- Memory ---------------------------------------------------------------------------------------

TEST(HostileScene, NestedAdaptersCannotMultiplyComponentsWithoutBound) {
    // 26 nested twosided took gigabytes from a 1 kB file: each level doubles the components.
    std::string twosided =
        "<bsdf version=\"3.0.0\" type=\"twosided\">" +
        nested("<bsdf type=\"twosided\">", "<bsdf type=\"diffuse\"/>", "</bsdf>", 25) + "</bsdf>";
    expect_load_error(twosided, "more than the 1024 facet supports", 1);
    // The same through references: a blendbsdf of the same BSDF twice, 26 times over.
    std::string blend = "<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"b0\"/>\n";
    for (int i = 1; i <= 26; ++i)
        blend += "<bsdf type=\"blendbsdf\" id=\"b" + std::to_string(i) + "\"><ref id=\"b" +
                 std::to_string(i - 1) + "\"/><ref id=\"b" + std::to_string(i - 1) +
                 "\"/><float name=\"weight\" value=\"0.5\"/></bsdf>\n";
    expect_load_error(blend + "</scene>", "more than the 1024 facet supports");
    // Ten levels are 1024 components: still accepted.
    auto ten = std::dynamic_pointer_cast<BSDF>(load_string(
        "<bsdf version=\"3.0.0\" type=\"twosided\">" +
        nested("<bsdf type=\"twosided\">", "<bsdf type=\"diffuse\"/>", "</bsdf>", 9) + "</bsdf>"));
    ASSERT_TRUE(ten);
    EXPECT_EQ(ten->component_count(), 1024u);
}

TEST(HostileScene, FilmSizesAreBounded) {
    expect_load_error("<film version=\"3.0.0\" type=\"hdrfilm\">\n<integer name=\"width\" "
                      "value=\"1000000\"/><integer name=\"height\" value=\"1000000\"/></film>",
                      "more than the 134217728 pixels", 1);
}

TEST(HostileScene, FilmBuffersHaveABudget) {
    // 8192x8192 is a valid film, but not with 24 AOV channels (26 GiB of buffers): refused
    // before allocating.
    std::vector<std::string> aovs;
    for (int i = 0; i < 24; ++i) aovs.push_back("aov" + std::to_string(i));
    try {
        FilmBuffer buffer({0, 0}, {8192, 8192}, aovs);
        ADD_FAILURE() << "no error for 26 GiB of film buffers";
    } catch (const Error &e) {
        EXPECT_NE(e.message().find("GiB budget"), std::string::npos) << e.what();
    }
}

TEST(HostileScene, FilterRadiiAreBounded) {
    // A huge stddev overflowed the float-to-int conversion of the block border; a large one
    // allocated terabytes of image block.
    auto filter = [](const std::string &rfilter) {
        return scene_with("", "<lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>",
                          rfilter);
    };
    expect_load_error(filter("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"1e30\"/>"
                             "</rfilter>"),
                      "stddev must be a number of pixels in [0.00390625, 16]", 4);
    expect_load_error(filter("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"1e5\"/>"
                             "</rfilter>"),
                      "in [0.00390625, 16]", 4);
    expect_load_error(filter("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"1e-30\"/>"
                             "</rfilter>"),
                      "in [0.00390625, 16]", 4);
    expect_load_error(filter("<rfilter type=\"tent\"><float name=\"radius\" value=\"1e9\"/>"
                             "</rfilter>"),
                      "radius must be a number of pixels in [0.015625, 64]", 4);
    EXPECT_TRUE(load_string(filter("<rfilter type=\"gaussian\"><float name=\"stddev\" "
                                   "value=\"16\"/></rfilter>")));
}
