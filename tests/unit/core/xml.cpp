// The XML scene loader: grammar, substitution, includes, references, the 0.x upgrade and the
// error messages with their file:line:col. Plugins are small test classes registered statically,
// so these tests depend on no real plugin (except the scene tests, which use the default sensor).

#include <facet/bsdf.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/resolver.h>
#include <facet/scene.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <clocale>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

// ------------------------------------------------------------------------------------------------
// Test plugins
// ------------------------------------------------------------------------------------------------

std::map<std::string, int> g_constructed;      ///< constructions per id
std::vector<std::string> g_parameters_changed; ///< ids, in call order

/// Records its Properties and marks every entry queried.
class RecorderBSDF final : public BSDF {
public:
    explicit RecorderBSDF(const Properties &p) : props(p) {
        for (const std::string &n : p.names()) p.mark_queried(n);
        ++g_constructed[p.id()];
    }
    std::pair<BSDFSample, Color3f> sample(const BSDFContext &, const SurfaceInteraction &, float,
                                          const Point2f &) const override {
        return {BSDFSample(), Color3f(0.f)};
    }
    Color3f eval(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return Color3f(0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return 0.f;
    }
    void parameters_changed() override {
        ++changed;
        g_parameters_changed.push_back(id());
    }
    Properties props;
    int changed = 0;
};

/// Reads only `alpha` (float) and `reflectance` (colour): everything else is unqueried.
class StrictBSDF final : public BSDF {
public:
    explicit StrictBSDF(const Properties &p) {
        alpha = p.get_float("alpha", 0.5);
        reflectance = p.get_color("reflectance", Color3f(0.5f));
    }
    std::pair<BSDFSample, Color3f> sample(const BSDFContext &, const SurfaceInteraction &, float,
                                          const Point2f &) const override {
        return {BSDFSample(), Color3f(0.f)};
    }
    Color3f eval(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return Color3f(0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return 0.f;
    }
    double alpha;
    Color3f reflectance;
};

/// Throws from its constructor.
class FailingBSDF final : public BSDF {
public:
    explicit FailingBSDF(const Properties &) { throw std::runtime_error("boom"); }
    std::pair<BSDFSample, Color3f> sample(const BSDFContext &, const SurfaceInteraction &, float,
                                          const Point2f &) const override {
        return {BSDFSample(), Color3f(0.f)};
    }
    Color3f eval(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return Color3f(0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return 0.f;
    }
};

/// Records its Properties (like RecorderBSDF) as a texture.
class RecorderTexture final : public Texture {
public:
    explicit RecorderTexture(const Properties &p) : props(p) {
        for (const std::string &n : p.names()) p.mark_queried(n);
    }
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }
    Color3f mean() const override { return Color3f(0.f); }
    Properties props;
};

/// Needs an existing `filename`, found through file_resolver() (like a mesh loader).
class FileTexture final : public Texture {
public:
    explicit FileTexture(const Properties &p) {
        std::string name = p.get_string("filename");
        path = file_resolver().resolve(name);
        if (!fs::exists(path))
            FACET_THROW_AT(p.location("filename"), "mesh file \"{}\" not found", name);
    }
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }
    Color3f mean() const override { return Color3f(0.f); }
    std::string path;
};

class RecorderIntegrator final : public Integrator {
public:
    explicit RecorderIntegrator(const Properties &p) : props(p) {
        for (const std::string &n : p.names()) p.mark_queried(n);
    }
    Properties props;
};

template <typename T> Object *make(const Properties &p) { return new T(p); }

const PluginDescriptor TEST_PLUGINS[] = {
    {FACET_ABI_VERSION, ObjectType::BSDF, "test_recorder", "records its properties", "",
     &make<RecorderBSDF>},
    // 0.x upgrade tests need a BSDF called "diffuse"; this process never loads the real one.
    {FACET_ABI_VERSION, ObjectType::BSDF, "diffuse", "records its properties", "",
     &make<RecorderBSDF>},
    {FACET_ABI_VERSION, ObjectType::BSDF, "test_strict", "alpha and reflectance", "",
     &make<StrictBSDF>},
    {FACET_ABI_VERSION, ObjectType::BSDF, "test_failing", "throws", "", &make<FailingBSDF>},
    {FACET_ABI_VERSION, ObjectType::Texture, "test_texture", "records", "", &make<RecorderTexture>},
    {FACET_ABI_VERSION, ObjectType::Texture, "test_file", "needs a file", "", &make<FileTexture>},
    {FACET_ABI_VERSION, ObjectType::Integrator, "test_integrator", "records", "",
     &make<RecorderIntegrator>},
};

// ------------------------------------------------------------------------------------------------
// Helpers
// ------------------------------------------------------------------------------------------------

bool contains(const std::string &s, const std::string &part) {
    return s.find(part) != std::string::npos;
}

/// The facet::Error thrown by `f`; a test failure when nothing (or something else) is thrown.
Error error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e;
    } catch (const std::exception &e) {
        ADD_FAILURE() << "unexpected exception type: " << e.what();
        return Error("");
    }
    ADD_FAILURE() << "no error was thrown";
    return Error("");
}

Error string_error(const std::string &xml, const LoadOptions &opts = {}) {
    return error_of([&] { load_string(xml, opts); });
}

/// Loads `xml` and returns the root as the given test class (which must match).
template <typename T>
std::shared_ptr<T> load_as(const std::string &xml, const LoadOptions &opts = {}) {
    auto obj = std::dynamic_pointer_cast<T>(load_string(xml, opts));
    EXPECT_TRUE(obj != nullptr);
    return obj;
}

/// A bsdf recorder root around `body`; the body starts on line 2.
std::string wrap(const std::string &body) {
    return "<bsdf version=\"3.0.0\" type=\"test_recorder\">\n" + body + "</bsdf>\n";
}

Properties root_props(const std::string &body, const LoadOptions &opts = {}) {
    auto root = load_as<RecorderBSDF>(wrap(body), opts);
    return root ? root->props : Properties();
}

void expect_matrix_near(const Matrix4f &a, const Matrix4f &b, float eps = 1e-5f) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            EXPECT_NEAR(a.m[i][j], b.m[i][j], eps) << "entry " << i << "," << j;
}

class XmlTest : public ::testing::Test {
protected:
    void SetUp() override {
        for (const PluginDescriptor &d : TEST_PLUGINS)
            PluginRegistry::instance().register_static(&d);
        static int counter = 0;
        m_dir = fs::temp_directory_path() /
                ("facet_xml_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
        m_dir = fs::canonical(m_dir);
        g_constructed.clear();
        g_parameters_changed.clear();
    }
    void TearDown() override { fs::remove_all(m_dir); }

    /// Writes `text` to `<temp dir>/name` and returns the full path.
    std::string write(const std::string &name, const std::string &text) {
        fs::path p = m_dir / name;
        fs::create_directories(p.parent_path());
        std::ofstream(p) << text;
        return p.string();
    }

    fs::path m_dir;
};

// ------------------------------------------------------------------------------------------------
// Root element, version, syntax errors
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, MalformedXmlReportsPugixmlErrorWithLocation) {
    Error e = string_error("<bsdf version=\"3.0.0\" type=\"test_recorder\">\n"
                           "  <float name=\"a\" value=\"1\">\n"
                           "</bsdf>\n");
    EXPECT_EQ(e.message(), "Parsing of XML file \"string\" failed: Start-end tags mismatch");
    EXPECT_EQ(e.location().to_string(), "string:3:3");

    std::string path = write(
        "broken.xml", "<scene version=\"3.0.0\">\n  <float name=\"a\" value=\"1\"/>\n  <oops\n");
    Error f = error_of([&] { load_file(path); });
    EXPECT_EQ(f.message(),
              "Parsing of XML file \"" + path + "\" failed: Error parsing start element tag");
    EXPECT_EQ(f.location().to_string(), path + ":3:8");
}

TEST_F(XmlTest, MissingVersionOnRoot) {
    Error e = string_error("<bsdf type=\"test_recorder\"/>");
    EXPECT_EQ(e.message(), "missing version attribute in root element");
    EXPECT_EQ(e.location().to_string(), "string:1:2");
}

TEST_F(XmlTest, VersionMustBeThreeIntegers) {
    Error e = string_error("<bsdf version=\"3.0\" type=\"test_recorder\"/>");
    EXPECT_TRUE(contains(e.message(), "invalid version \"3.0\"")) << e.what();
    e = string_error("<bsdf version=\"3.0.x\" type=\"test_recorder\"/>");
    EXPECT_TRUE(contains(e.message(), "invalid version \"3.0.x\"")) << e.what();
}

TEST_F(XmlTest, VersionOnlyAllowedOnRoot) {
    Error e = string_error(wrap("  <bsdf version=\"3.0.0\" type=\"test_recorder\"/>\n"));
    EXPECT_EQ(e.message(), "unexpected attribute \"version\" in element <bsdf>");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
}

TEST_F(XmlTest, NonSceneRootNeedsType) {
    Error e = string_error("<bsdf version=\"3.0.0\"/>");
    EXPECT_EQ(e.message(), "missing required attribute \"type\" in element <bsdf>");
    EXPECT_EQ(e.location().to_string(), "string:1:2");
}

TEST_F(XmlTest, PropertyTagAsRootIsRejected) {
    Error e = string_error("<float version=\"3.0.0\" name=\"a\" value=\"1\"/>");
    EXPECT_TRUE(contains(e.message(), "root element must be <scene> or an object tag")) << e.what();
}

TEST_F(XmlTest, NonSceneRootAndSpectrumTexture) {
    auto root = load_as<RecorderBSDF>(wrap("  <spectrum type=\"test_texture\" name=\"tex\">\n"
                                           "    <float name=\"scale\" value=\"2\"/>\n"
                                           "  </spectrum>\n"));
    ASSERT_TRUE(root);
    EXPECT_EQ(root->props.plugin_name(), "test_recorder");
    EXPECT_EQ(root->props.location().to_string(), "string:1:2");
    auto tex = root->props.get_object<RecorderTexture>("tex");
    ASSERT_TRUE(tex);
    EXPECT_DOUBLE_EQ(tex->props.get_float("scale"), 2.0);

    auto tex_root = std::dynamic_pointer_cast<RecorderTexture>(
        load_string("<spectrum version=\"3.0.0\" type=\"test_texture\"/>"));
    EXPECT_TRUE(tex_root);
}

// ------------------------------------------------------------------------------------------------
// Plugins: unknown names, unqueried properties, wrong types, failures
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, UnknownPluginListsKnownOnes) {
    Error e = string_error(wrap("  <bsdf type=\"test_recorde\"/>\n"));
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    EXPECT_TRUE(contains(e.message(), "unknown bsdf plugin \"test_recorde\"")) << e.what();
    EXPECT_TRUE(contains(e.message(), "did you mean \"test_recorder\"")) << e.what();
    EXPECT_TRUE(contains(e.message(), "test_strict")) << e.what();
}

TEST_F(XmlTest, WrongObjectKindIsReported) {
    Error e = string_error(wrap("  <texture type=\"test_strict\"/>\n"));
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    EXPECT_TRUE(contains(e.message(), "test_strict")) << e.what();
    EXPECT_TRUE(contains(e.message(), "texture")) << e.what();
}

TEST_F(XmlTest, TypoInParameterIsAnUnqueriedError) {
    std::string xml = "<bsdf version=\"3.0.0\" type=\"test_strict\">\n"
                      "  <float name=\"alpah\" value=\"0.1\"/>\n"
                      "</bsdf>\n";
    Error e = string_error(xml);
    EXPECT_EQ(e.location().to_string(), "string:1:2");
    EXPECT_TRUE(contains(e.message(),
                         "Found 1 unreferenced property in bsdf plugin of type \"test_strict\""))
        << e.what();
    EXPECT_TRUE(contains(e.message(), "\"alpah\" (string:2:4)")) << e.what();
    // The parameter the plugin asked for and did not get is offered as the intended name.
    EXPECT_TRUE(contains(e.message(), "did you mean \"alpha\"?")) << e.what();

    // Lenient: a warning instead.
    LoadOptions lenient;
    lenient.lenient = true;
    size_t warnings = Logger::warning_count();
    EXPECT_NO_THROW(load_string(xml, lenient));
    EXPECT_EQ(Logger::warning_count(), warnings + 1);
}

TEST_F(XmlTest, WrongParameterTypeNamesTheEntry) {
    Error e = string_error("<bsdf version=\"3.0.0\" type=\"test_strict\">\n"
                           "  <string name=\"alpha\" value=\"rough\"/>\n"
                           "</bsdf>\n");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    EXPECT_TRUE(contains(e.message(), "failed to instantiate bsdf plugin of type \"test_strict\""))
        << e.what();
    EXPECT_TRUE(
        contains(e.message(), "parameter \"alpha\" has type string, but float was expected"))
        << e.what();
}

TEST_F(XmlTest, MissingFileIsReportedAtItsEntry) {
    Error e = string_error(wrap("  <texture type=\"test_file\">\n"
                                "    <string name=\"filename\" value=\"missing.obj\"/>\n"
                                "  </texture>\n"));
    EXPECT_EQ(e.location().to_string(), "string:3:6");
    EXPECT_EQ(e.message(), "failed to instantiate texture plugin of type \"test_file\": mesh file "
                           "\"missing.obj\" not found");
}

TEST_F(XmlTest, InnerFailureIsNotWrappedTwice) {
    Error e = string_error(wrap("  <bsdf type=\"test_recorder\">\n"
                                "    <bsdf type=\"test_failing\"/>\n"
                                "  </bsdf>\n"));
    EXPECT_EQ(e.location().to_string(), "string:3:6");
    EXPECT_EQ(e.message(), "failed to instantiate bsdf plugin of type \"test_failing\": boom");
}

// ------------------------------------------------------------------------------------------------
// Property tags
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, PropertyValueTypes) {
    Properties p = root_props("  <boolean name=\"b\" value=\"true\"/>\n"
                              "  <integer name=\"i\" value=\"-42\"/>\n"
                              "  <float name=\"f\" value=\"2.5e-1\"/>\n"
                              "  <string name=\"s\" value=\"hello world\"/>\n"
                              "  <point name=\"p\" value=\"1, 2, 3\"/>\n"
                              "  <vector name=\"v\" x=\"4\" y=\"5\" z=\"6\"/>\n"
                              "  <rgb name=\"c\" value=\"0.1 0.2,0.3\"/>\n"
                              "  <rgb name=\"g\" value=\"0.5\"/>\n"
                              "  <point name=\"one\" value=\"7\"/>\n");
    EXPECT_EQ(p.type("b"), Properties::Type::Bool);
    EXPECT_EQ(p.type("i"), Properties::Type::Integer);
    EXPECT_EQ(p.type("f"), Properties::Type::Float);
    EXPECT_EQ(p.type("s"), Properties::Type::String);
    EXPECT_EQ(p.type("p"), Properties::Type::Vector);
    EXPECT_EQ(p.type("c"), Properties::Type::Color);
    EXPECT_TRUE(p.get_bool("b"));
    EXPECT_EQ(p.get_int("i"), -42);
    EXPECT_DOUBLE_EQ(p.get_float("f"), 0.25);
    EXPECT_EQ(p.get_string("s"), "hello world");
    EXPECT_EQ(p.get_vector("p"), Vector3f(1, 2, 3));
    EXPECT_EQ(p.get_vector("v"), Vector3f(4, 5, 6));
    EXPECT_EQ(p.get_vector("one"), Vector3f(7, 7, 7));
    Color3f c = p.get_color("c", SpectrumKind::Unbounded);
    EXPECT_FLOAT_EQ(c.r, 0.1f);
    EXPECT_FLOAT_EQ(c.g, 0.2f);
    EXPECT_FLOAT_EQ(c.b, 0.3f);
    EXPECT_FLOAT_EQ(p.get_color("g").g, 0.5f);
    EXPECT_EQ(p.location("i").to_string(), "string:3:4");
}

TEST_F(XmlTest, BooleanIsCaseInsensitive) {
    Properties p = root_props("  <boolean name=\"a\" value=\"TRUE\"/>\n"
                              "  <boolean name=\"b\" value=\"False\"/>\n");
    EXPECT_TRUE(p.get_bool("a"));
    EXPECT_FALSE(p.get_bool("b"));
    Error e = string_error(wrap("  <boolean name=\"a\" value=\"yes\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse boolean value \"yes\" (expected true or false)");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
}

TEST_F(XmlTest, TrailingGarbageInNumbersIsAnError) {
    Error e = string_error(wrap("  <float name=\"a\" value=\"1.5x\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse floating point value \"1.5x\"");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    e = string_error(wrap("  <integer name=\"a\" value=\"3.0\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse integer value \"3.0\"");
    e = string_error(wrap("  <integer name=\"a\" value=\"12abc\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse integer value \"12abc\"");
    e = string_error(wrap("  <point name=\"a\" value=\"1, 2, 3q\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse floating point value \"3q\"");
    e = string_error(wrap("  <float name=\"a\" value=\"\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse floating point value \"\"");
}

TEST_F(XmlTest, NumbersIgnoreTheLocale) {
    // A locale with a decimal comma must not change how "0.5" reads (if such a locale exists).
    const char *old = std::setlocale(LC_NUMERIC, nullptr);
    std::string saved = old ? old : "C";
    std::setlocale(LC_NUMERIC, "de_DE.UTF-8");
    Properties p = root_props("  <float name=\"a\" value=\"0.5\"/>\n"
                              "  <float name=\"b\" value=\" +1e3 \"/>\n");
    std::setlocale(LC_NUMERIC, saved.c_str());
    EXPECT_DOUBLE_EQ(p.get_float("a"), 0.5);
    EXPECT_DOUBLE_EQ(p.get_float("b"), 1000.0);
    Error e = string_error(wrap("  <float name=\"a\" value=\"0,5\"/>\n"));
    EXPECT_EQ(e.message(), "could not parse floating point value \"0,5\"");
}

TEST_F(XmlTest, RgbNeedsOneOrThreeValues) {
    Error e = string_error(wrap("  <rgb name=\"c\" value=\"0.1, 0.2\"/>\n"));
    EXPECT_EQ(e.message(), "<rgb> needs 1 or 3 values, found 2");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
}

TEST_F(XmlTest, PointValueAndXyzCannotBeMixed) {
    Error e = string_error(wrap("  <point name=\"p\" value=\"1, 2, 3\" x=\"1\"/>\n"));
    EXPECT_EQ(e.message(),
              "<point> can have either a \"value\" attribute or x/y/z attributes, not both");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    e = string_error(wrap("  <vector name=\"p\" x=\"1\" y=\"2\"/>\n"));
    EXPECT_EQ(e.message(), "missing required attribute \"z\" in element <vector>");
}

TEST_F(XmlTest, UnexpectedAndMissingAttributes) {
    Error e = string_error(wrap("  <float name=\"x\" value=\"1\" foo=\"2\"/>\n"));
    EXPECT_EQ(e.message(), "unexpected attribute \"foo\" in element <float>");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    e = string_error(wrap("  <float name=\"x\"/>\n"));
    EXPECT_EQ(e.message(), "missing required attribute \"value\" in element <float>");
    e = string_error(wrap("  <float value=\"1\"/>\n"));
    EXPECT_EQ(e.message(), "missing required attribute \"name\" in element <float>");
    e = string_error(wrap("  <bsdf type=\"test_recorder\" foo=\"1\"/>\n"));
    EXPECT_EQ(e.message(), "unexpected attribute \"foo\" in element <bsdf>");
}

TEST_F(XmlTest, UnsupportedElement) {
    Error e = string_error(wrap("\n  <foo name=\"x\"/>\n"));
    EXPECT_EQ(e.message(), "encountered an unsupported XML element: <foo>");
    EXPECT_EQ(e.location().to_string(), "string:3:4");
}

TEST_F(XmlTest, PropertyTagsCannotHaveChildren) {
    Error e = string_error(wrap("  <float name=\"x\" value=\"1\">\n"
                                "    <float name=\"y\" value=\"2\"/>\n"
                                "  </float>\n"));
    EXPECT_TRUE(contains(e.message(), "unexpected element <float> inside <float>")) << e.what();
    EXPECT_EQ(e.location().to_string(), "string:3:6");
}

TEST_F(XmlTest, DuplicatePropertyName) {
    Error e = string_error(wrap("  <float name=\"x\" value=\"1\"/>\n"
                                "  <integer name=\"x\" value=\"2\"/>\n"));
    EXPECT_EQ(e.message(), "duplicate property \"x\" (first declared at string:2:4)");
    EXPECT_EQ(e.location().to_string(), "string:3:4");
}

TEST_F(XmlTest, SpectrumUniformPairsAndFile) {
    write("data/red.spd", "# wavelength value\n400 0.1\n500 0.2\n\n600 0.9\n");
    std::string path =
        write("scene.xml", wrap("  <spectrum name=\"u\" value=\"0.5\"/>\n"
                                "  <spectrum name=\"p\" value=\"400:0.56, 500:0.18\"/>\n"
                                "  <spectrum name=\"f\" filename=\"data/red.spd\"/>\n"));
    auto root = std::dynamic_pointer_cast<RecorderBSDF>(load_file(path));
    ASSERT_TRUE(root);
    const Properties &p = root->props;
    ASSERT_EQ(p.type("u"), Properties::Type::Spectrum);
    EXPECT_EQ(p.type("p"), Properties::Type::Spectrum);
    EXPECT_EQ(p.type("f"), Properties::Type::Spectrum);
    // Uniform spectra stay uniform (a reflectance of 0.5 is grey 0.5).
    Color3f u = p.get_color("u");
    EXPECT_NEAR(u.r, 0.5f, 1e-3f);
    EXPECT_NEAR(u.b, 0.5f, 1e-3f);
    // A red spectrum from the file comes out red.
    Color3f f = p.get_color("f");
    EXPECT_GT(f.r, f.b);

    Error e = string_error(wrap("  <spectrum name=\"s\" value=\"1\" filename=\"a.spd\"/>\n"));
    EXPECT_EQ(e.message(),
              "<spectrum> needs exactly one of the attributes \"value\" and \"filename\"");
    e = string_error(wrap("  <spectrum name=\"s\" filename=\"nothing_here.spd\"/>\n"));
    EXPECT_EQ(e.message(), "spectrum file \"nothing_here.spd\" not found");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    e = string_error(wrap("  <spectrum name=\"s\" value=\"400:0.5, oops\"/>\n"));
    EXPECT_EQ(e.location().to_string(), "string:2:4");
}

// ------------------------------------------------------------------------------------------------
// Transforms
// ------------------------------------------------------------------------------------------------

Transform transform_of(const std::string &ops) {
    Properties p = root_props("  <transform name=\"t\">\n" + ops + "  </transform>\n");
    return p.get_transform("t");
}

TEST_F(XmlTest, TransformOperationsAreLeftMultiplied) {
    Transform t = transform_of("    <translate x=\"1\"/>\n"
                               "    <rotate y=\"1\" angle=\"90\"/>\n");
    Transform expected =
        Transform::rotate(Vector3f(0, 1, 0), 90.f) * Transform::translate(Vector3f(1, 0, 0));
    expect_matrix_near(t.matrix, expected.matrix);
    // The translation happens first: the origin goes to (1,0,0) and is then rotated to (0,0,-1).
    Point3f p = t.apply_point(Point3f(0, 0, 0));
    EXPECT_NEAR(p.x, 0.f, 1e-6f);
    EXPECT_NEAR(p.z, -1.f, 1e-6f);
    expect_matrix_near(t.inverse_matrix, expected.inverse_matrix);
}

TEST_F(XmlTest, TranslateScaleRotateForms) {
    expect_matrix_near(transform_of("    <translate value=\"1 2 3\"/>\n").matrix,
                       Transform::translate(Vector3f(1, 2, 3)).matrix);
    expect_matrix_near(transform_of("    <translate z=\"3\"/>\n").matrix,
                       Transform::translate(Vector3f(0, 0, 3)).matrix);
    expect_matrix_near(transform_of("    <scale value=\"2\"/>\n").matrix,
                       Transform::scale(Vector3f(2, 2, 2)).matrix);
    expect_matrix_near(transform_of("    <scale x=\"-1\"/>\n").matrix,
                       Transform::scale(Vector3f(-1, 1, 1)).matrix);
    expect_matrix_near(transform_of("    <rotate value=\"0, 0, 2\" angle=\"30\"/>\n").matrix,
                       Transform::rotate(Vector3f(0, 0, 1), 30.f).matrix);
    expect_matrix_near(transform_of("").matrix, Matrix4f::identity());
}

TEST_F(XmlTest, RotateNeedsAnAxis) {
    Error e = string_error(wrap("  <transform name=\"t\">\n"
                                "    <rotate angle=\"45\"/>\n"
                                "  </transform>\n"));
    EXPECT_EQ(e.message(), "<rotate> needs a non-zero rotation axis");
    EXPECT_EQ(e.location().to_string(), "string:3:6");
    e = string_error(wrap("  <transform name=\"t\">\n"
                          "    <rotate x=\"1\"/>\n"
                          "  </transform>\n"));
    EXPECT_EQ(e.message(), "missing required attribute \"angle\" in element <rotate>");
}

TEST_F(XmlTest, MatrixWith16Or9Values) {
    Transform t16 = transform_of("    <matrix value=\"1 0 0 5  0 2 0 6  0 0 3 7  0 0 0 1\"/>\n");
    float rows[16] = {1, 0, 0, 5, 0, 2, 0, 6, 0, 0, 3, 7, 0, 0, 0, 1};
    expect_matrix_near(t16.matrix, Matrix4f::from_rows(rows));
    Point3f p = t16.apply_point(Point3f(1, 1, 1));
    EXPECT_EQ(p, Point3f(6, 8, 10));

    Transform t9 = transform_of("    <matrix value=\"0 -1 0, 1 0 0, 0 0 1\"/>\n");
    float rows9[16] = {0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    expect_matrix_near(t9.matrix, Matrix4f::from_rows(rows9));

    Error e = string_error(wrap("  <transform name=\"t\">\n"
                                "    <matrix value=\"1 2 3 4 5\"/>\n"
                                "  </transform>\n"));
    EXPECT_EQ(e.message(), "<matrix> needs 9 or 16 values, found 5");
    EXPECT_EQ(e.location().to_string(), "string:3:6");
}

TEST_F(XmlTest, LookAt) {
    Transform t =
        transform_of("    <lookat origin=\"1, 2, 3\" target=\"1, 2, 4\" up=\"0, 1, 0\"/>\n");
    expect_matrix_near(
        t.matrix, Transform::look_at(Point3f(1, 2, 3), Point3f(1, 2, 4), Vector3f(0, 1, 0)).matrix);
    // Without up one is chosen perpendicular to the view direction.
    Transform n = transform_of("    <lookat origin=\"0, 0, 0\" target=\"0, 0, -5\"/>\n");
    Vector3f dir = n.apply_vector(Vector3f(0, 0, 1));
    EXPECT_NEAR(dir.z, -1.f, 1e-6f);
    Vector3f up = n.apply_vector(Vector3f(0, 1, 0));
    EXPECT_NEAR(dot(up, dir), 0.f, 1e-6f);

    Error e = string_error(wrap("  <transform name=\"t\">\n"
                                "    <lookat origin=\"1, 1, 1\" target=\"1, 1, 1\"/>\n"
                                "  </transform>\n"));
    EXPECT_TRUE(contains(e.message(), "invalid <lookat>")) << e.what();
    EXPECT_EQ(e.location().to_string(), "string:3:6");
}

TEST_F(XmlTest, TransformOpsOnlyInsideTransform) {
    Error e = string_error(wrap("  <translate x=\"1\"/>\n"));
    EXPECT_EQ(e.message(), "<translate> may only appear inside a <transform>");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    e = string_error(wrap("  <transform name=\"t\">\n"
                          "    <float name=\"x\" value=\"1\"/>\n"
                          "  </transform>\n"));
    EXPECT_TRUE(contains(e.message(), "<float> cannot appear inside <transform>")) << e.what();
    EXPECT_EQ(e.location().to_string(), "string:3:6");
    // <lookAt> is a 0.x spelling only.
    e = string_error(wrap("  <transform name=\"t\">\n"
                          "    <lookAt origin=\"0,0,0\" target=\"0,0,1\"/>\n"
                          "  </transform>\n"));
    EXPECT_TRUE(contains(e.message(), "<lookAt> cannot appear inside <transform>")) << e.what();
}

// ------------------------------------------------------------------------------------------------
// Names, ids, references, aliases
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, UnnamedChildrenGetArgNames) {
    Properties p = root_props("  <bsdf type=\"test_recorder\" id=\"a\"/>\n"
                              "  <bsdf type=\"test_recorder\" name=\"named\"/>\n"
                              "  <texture type=\"test_texture\"/>\n"
                              "  <ref id=\"a\"/>\n");
    std::vector<std::string> names;
    for (const auto &[name, obj] : p.objects()) names.push_back(name);
    EXPECT_EQ(names, (std::vector<std::string>{"_arg_0", "named", "_arg_1", "_arg_2"}));
    EXPECT_EQ(p.get_object<Object>("_arg_0"), p.get_object<Object>("_arg_2"));
    EXPECT_EQ(p.location("_arg_1").to_string(), "string:4:4");
}

TEST_F(XmlTest, ForwardReferenceSharesOneInstance) {
    auto root =
        load_as<RecorderBSDF>(wrap("  <ref id=\"later\" name=\"first\"/>\n"
                                   "  <bsdf type=\"test_recorder\" id=\"later\" name=\"second\"/>\n"
                                   "  <bsdf type=\"test_recorder\" name=\"third\">\n"
                                   "    <ref id=\"later\"/>\n"
                                   "  </bsdf>\n"));
    ASSERT_TRUE(root);
    auto first = root->props.get_object<RecorderBSDF>("first");
    auto second = root->props.get_object<RecorderBSDF>("second");
    ASSERT_TRUE(first);
    EXPECT_EQ(first, second);
    EXPECT_EQ(first->id(), "later");
    EXPECT_EQ(g_constructed["later"], 1);
    EXPECT_EQ(first->changed, 1);
    EXPECT_EQ(root->changed, 1);
    // Children get parameters_changed() before their parents; the root comes last.
    ASSERT_EQ(g_parameters_changed.size(), 3u);
    EXPECT_EQ(g_parameters_changed.front(), "later");
    EXPECT_EQ(g_parameters_changed.back(), "");
}

TEST_F(XmlTest, ReferenceCycleIsReported) {
    Error e = string_error(wrap("  <bsdf type=\"test_recorder\" id=\"a\">\n"
                                "    <ref id=\"b\"/>\n"
                                "  </bsdf>\n"
                                "  <bsdf type=\"test_recorder\" id=\"b\">\n"
                                "    <ref id=\"a\"/>\n"
                                "  </bsdf>\n"));
    EXPECT_EQ(e.message(), "circular reference detected: a -> b -> a");
    EXPECT_EQ(e.location().to_string(), "string:6:6");
}

TEST_F(XmlTest, UnknownReference) {
    Error e = string_error(wrap("  <bsdf type=\"test_recorder\" id=\"metal\"/>\n"
                                "  <ref id=\"metl\"/>\n"));
    EXPECT_EQ(e.message(), "reference to unknown id \"metl\" (did you mean \"metal\"?)");
    EXPECT_EQ(e.location().to_string(), "string:3:4");
}

TEST_F(XmlTest, DuplicateIdNamesTheEarlierLocation) {
    Error e = string_error(wrap("  <bsdf type=\"test_recorder\" id=\"a\"/>\n"
                                "  <texture type=\"test_texture\" id=\"a\"/>\n"));
    EXPECT_EQ(e.message(), "duplicate id \"a\" (first declared at string:2:4)");
    EXPECT_EQ(e.location().to_string(), "string:3:4");
}

TEST_F(XmlTest, AliasBindsASecondId) {
    Properties p = root_props("  <bsdf type=\"test_recorder\" id=\"a\" name=\"orig\"/>\n"
                              "  <alias id=\"a\" as=\"b\"/>\n"
                              "  <ref id=\"b\" name=\"via_alias\"/>\n");
    EXPECT_EQ(p.get_object<Object>("orig"), p.get_object<Object>("via_alias"));
    EXPECT_EQ(g_constructed["a"], 1);

    Error e = string_error(wrap("  <alias id=\"nope\" as=\"b\"/>\n"));
    EXPECT_EQ(e.message(), "<alias> refers to unknown id \"nope\"");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
    e = string_error(wrap("  <bsdf type=\"test_recorder\" id=\"a\"/>\n"
                          "  <bsdf type=\"test_recorder\" id=\"b\"/>\n"
                          "  <alias id=\"a\" as=\"b\"/>\n"));
    EXPECT_EQ(e.message(), "<alias> target id \"b\" already exists (declared at string:3:4)");
    EXPECT_EQ(e.location().to_string(), "string:4:4");
}

// ------------------------------------------------------------------------------------------------
// $name substitution and <default>
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, UndefinedParameter) {
    Error e = string_error(wrap("  <float name=\"x\" value=\"$foo\"/>\n"));
    EXPECT_EQ(e.message(), "undefined parameter: $foo");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
}

TEST_F(XmlTest, UnusedParameterIsReported) {
    LoadOptions opts;
    opts.params = {{"spp", "4"}, {"used", "1"}};
    std::string xml = wrap("  <integer name=\"x\" value=\"$used\"/>\n");
    Error e = string_error(xml, opts);
    EXPECT_TRUE(contains(e.message(), "unused parameter \"spp\"")) << e.what();
    EXPECT_FALSE(contains(e.message(), "\"used\"")) << e.what();

    opts.lenient = true;
    size_t warnings = Logger::warning_count();
    EXPECT_NO_THROW(load_string(xml, opts));
    EXPECT_EQ(Logger::warning_count(), warnings + 1);
}

TEST_F(XmlTest, LongestKeyIsSubstitutedFirst) {
    LoadOptions opts;
    opts.params = {{"spp", "4"}, {"sppx", "8"}};
    Properties p = root_props("  <integer name=\"a\" value=\"$spp\"/>\n"
                              "  <integer name=\"b\" value=\"$sppx\"/>\n"
                              "  <string name=\"s\" value=\"x$spp-$sppx\"/>\n",
                              opts);
    EXPECT_EQ(p.get_int("a"), 4);
    EXPECT_EQ(p.get_int("b"), 8);
    EXPECT_EQ(p.get_string("s"), "x4-8");
}

TEST_F(XmlTest, SubstitutionInTypeAndTransformAttributes) {
    LoadOptions opts;
    opts.params = {{"kind", "test_recorder"}, {"dx", "2"}};
    auto root = load_as<RecorderBSDF>("<bsdf version=\"3.0.0\" type=\"$kind\">\n"
                                      "  <transform name=\"t\"><translate x=\"$dx\"/></transform>\n"
                                      "</bsdf>\n",
                                      opts);
    ASSERT_TRUE(root);
    expect_matrix_near(root->props.get_transform("t").matrix,
                       Transform::translate(Vector3f(2, 0, 0)).matrix);
}

TEST_F(XmlTest, EscapedDollar) {
    Properties p = root_props("  <string name=\"s\" value=\"costs \\$5 or \\$x\"/>\n");
    EXPECT_EQ(p.get_string("s"), "costs $5 or $x");
}

TEST_F(XmlTest, DefaultAndParameterOverride) {
    std::string body = "  <default name=\"spp\" value=\"16\"/>\n"
                       "  <integer name=\"n\" value=\"$spp\"/>\n";
    EXPECT_EQ(root_props(body).get_int("n"), 16);
    LoadOptions opts;
    opts.params = {{"spp", "4"}};
    EXPECT_EQ(root_props(body, opts).get_int("n"), 4);

    // Defaults are never reported as unused.
    EXPECT_NO_THROW(load_string(wrap("  <default name=\"unused\" value=\"1\"/>\n")));

    // A default must come before its use.
    Error e = string_error(wrap("  <integer name=\"n\" value=\"$late\"/>\n"
                                "  <default name=\"late\" value=\"1\"/>\n"));
    EXPECT_EQ(e.message(), "undefined parameter: $late");
}

// ------------------------------------------------------------------------------------------------
// <include>
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, IncludedSceneIsSplicedAndObjectBecomesChild) {
    write("parts.xml", "<scene version=\"3.0.0\">\n"
                       "  <float name=\"a\" value=\"1\"/>\n"
                       "  <bsdf type=\"test_recorder\" id=\"shared\"/>\n"
                       "</scene>\n");
    write("tex.xml", "<texture version=\"3.0.0\" type=\"test_texture\"/>\n");
    std::string main =
        write("main.xml", wrap("  <include filename=\"parts.xml\"/>\n"
                               "  <include filename=\"tex.xml\" name=\"reflectance\"/>\n"
                               "  <ref id=\"shared\" name=\"again\"/>\n"));
    auto root = std::dynamic_pointer_cast<RecorderBSDF>(load_file(main));
    ASSERT_TRUE(root);
    const Properties &p = root->props;
    EXPECT_DOUBLE_EQ(p.get_float("a"), 1.0);
    EXPECT_EQ(p.location("a").to_string(), (m_dir / "parts.xml").string() + ":2:4");
    EXPECT_TRUE(p.get_object<RecorderBSDF>("_arg_0"));
    EXPECT_EQ(p.get_object<RecorderBSDF>("_arg_0"), p.get_object<RecorderBSDF>("again"));
    EXPECT_TRUE(p.get_object<RecorderTexture>("reflectance"));
}

TEST_F(XmlTest, IncludeResolutionOrder) {
    // Relative to the including file's folder first, then the search path.
    write("leaf.xml", "<bsdf version=\"3.0.0\" type=\"test_recorder\" id=\"top_leaf\"/>\n");
    write("sub/leaf.xml", "<bsdf version=\"3.0.0\" type=\"test_recorder\" id=\"sub_leaf\"/>\n");
    write("sub/inner.xml",
          "<scene version=\"3.0.0\"><include filename=\"leaf.xml\" name=\"leaf\"/></scene>\n");
    write("lib/extra.xml", "<bsdf version=\"3.0.0\" type=\"test_recorder\" id=\"extra\"/>\n");
    std::string main =
        write("main.xml", wrap("  <include filename=\"sub/inner.xml\"/>\n"
                               "  <include filename=\"extra.xml\" name=\"extra\"/>\n"));
    LoadOptions opts;
    opts.search_path = {(m_dir / "lib").string()};
    auto root = std::dynamic_pointer_cast<RecorderBSDF>(load_file(main, opts));
    ASSERT_TRUE(root);
    EXPECT_EQ(root->props.get_object<Object>("leaf")->id(), "sub_leaf");
    EXPECT_EQ(root->props.get_object<Object>("extra")->id(), "extra");

    Error e = error_of([&] { load_file(main); });
    EXPECT_EQ(e.message(), "included file \"extra.xml\" not found");
    EXPECT_EQ(e.location().to_string(), main + ":3:4");
}

TEST_F(XmlTest, IncludeCycleShowsTheChain) {
    std::string a =
        write("a.xml", "<scene version=\"3.0.0\">\n  <include filename=\"b.xml\"/>\n</scene>\n");
    std::string b =
        write("b.xml", "<scene version=\"3.0.0\">\n\n  <include filename=\"a.xml\"/>\n</scene>\n");
    Error e = error_of([&] { load_file(a); });
    EXPECT_EQ(e.message(), "include cycle detected: " + a + " -> " + b + " -> " + a);
    EXPECT_EQ(e.location().to_string(), b + ":3:4");
}

TEST_F(XmlTest, IncludeDepthIsLimitedTo15) {
    // f0 (a bsdf root, so that no Scene is needed) includes f1, which includes f2 ... fn (a bsdf).
    auto make_chain = [&](int n) {
        std::string dir = "chain" + std::to_string(n) + "/";
        auto file = [&](int i) { return "f" + std::to_string(i) + ".xml"; };
        write(dir + file(0), wrap("  <include filename=\"f1.xml\"/>\n"));
        for (int i = 1; i < n; ++i)
            write(dir + file(i), "<scene version=\"3.0.0\">\n  <include filename=\"" + file(i + 1) +
                                     "\"/>\n</scene>\n");
        write(dir + file(n), "<bsdf version=\"3.0.0\" type=\"test_recorder\"/>\n");
        return (m_dir / dir / file(0)).string();
    };
    EXPECT_NO_THROW(load_file(make_chain(15)));
    std::string too_deep = make_chain(16);
    Error e = error_of([&] { load_file(too_deep); });
    EXPECT_EQ(e.message(), "maximum include depth of 15 exceeded while including \"f16.xml\"");
    EXPECT_EQ(e.location().to_string(), (m_dir / "chain16" / "f15.xml").string() + ":2:4");
}

TEST_F(XmlTest, ErrorsInIncludedFilesCarryTheirFileName) {
    std::string inc = write("inc.xml", "<scene version=\"3.0.0\">\n"
                                       "  <float name=\"a\" value=\"oops\"/>\n"
                                       "</scene>\n");
    std::string main = write("main.xml", wrap("  <include filename=\"inc.xml\"/>\n"));
    Error e = error_of([&] { load_file(main); });
    EXPECT_EQ(e.location().to_string(), inc + ":2:4");
    EXPECT_EQ(e.message(), "could not parse floating point value \"oops\"");
}

// ------------------------------------------------------------------------------------------------
// <path> and the file resolver
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, PathTagAddsASearchFolder) {
    write("common/meshes/sphere.obj", "v 0 0 0\n");
    std::string scene =
        write("scenes/main.xml", "<texture version=\"3.0.0\" type=\"test_file\">\n"
                                 "  <path value=\"../common\"/>\n"
                                 "  <string name=\"filename\" value=\"meshes/sphere.obj\"/>\n"
                                 "</texture>\n");
    std::vector<std::string> before = file_resolver().dirs();
    auto tex = std::dynamic_pointer_cast<FileTexture>(load_file(scene));
    ASSERT_TRUE(tex);
    EXPECT_TRUE(fs::equivalent(tex->path, m_dir / "common/meshes/sphere.obj"));
    // The resolver is restored, so successive loads do not accumulate folders.
    EXPECT_EQ(file_resolver().dirs(), before);
    load_file(scene);
    EXPECT_EQ(file_resolver().dirs(), before);
}

TEST_F(XmlTest, SceneFolderIsSearchedForFiles) {
    write("scenes/mesh.obj", "v 0 0 0\n");
    std::string scene =
        write("scenes/main.xml", "<texture version=\"3.0.0\" type=\"test_file\">\n"
                                 "  <string name=\"filename\" value=\"mesh.obj\"/>\n"
                                 "</texture>\n");
    auto tex = std::dynamic_pointer_cast<FileTexture>(load_file(scene));
    ASSERT_TRUE(tex);
    EXPECT_TRUE(fs::equivalent(tex->path, m_dir / "scenes/mesh.obj"));
}

TEST_F(XmlTest, PathErrors) {
    std::string scene = write("main.xml", wrap("  <path value=\"no_such_folder\"/>\n"));
    Error e = error_of([&] { load_file(scene); });
    EXPECT_EQ(e.message(), "folder \"no_such_folder\" does not exist");
    EXPECT_EQ(e.location().to_string(), scene + ":2:4");

    e = string_error(wrap("  <bsdf type=\"test_recorder\">\n"
                          "    <path value=\".\"/>\n"
                          "  </bsdf>\n"));
    EXPECT_EQ(e.message(), "<path> may only appear directly inside the root element");
    EXPECT_EQ(e.location().to_string(), "string:3:6");
}

// ------------------------------------------------------------------------------------------------
// The 0.x upgrade
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, OldVersionsAreUpgraded) {
    auto root =
        load_as<RecorderBSDF>("<bsdf version=\"0.6.0\" type=\"test_recorder\">\n"
                              "  <default name=\"myValue\" value=\"3\"/>\n"
                              "  <float name=\"intIOR\" value=\"1.5\"/>\n"
                              "  <integer name=\"maxDepth\" value=\"$myValue\"/>\n"
                              "  <string name=\"fovAxis\" value=\"x\"/>\n"
                              "  <transform name=\"toWorld\">\n"
                              "    <lookAt origin=\"0, 0, 0\" target=\"0, 0, 1\" up=\"0, 1, 0\"/>\n"
                              "  </transform>\n"
                              "  <bsdf type=\"diffuse\" name=\"inner\">\n"
                              "    <rgb name=\"diffuseReflectance\" value=\"0.2\"/>\n"
                              "  </bsdf>\n"
                              "  <texture type=\"test_texture\" name=\"tex\">\n"
                              "    <float name=\"uoffset\" value=\"0.5\"/>\n"
                              "    <float name=\"uscale\" value=\"2\"/>\n"
                              "    <integer name=\"vscale\" value=\"3\"/>\n"
                              "  </texture>\n"
                              "</bsdf>\n");
    ASSERT_TRUE(root);
    const Properties &p = root->props;
    EXPECT_DOUBLE_EQ(p.get_float("int_ior"), 1.5);
    EXPECT_EQ(p.get_int("max_depth"), 3);
    EXPECT_EQ(p.get_string("fov_axis"), "x");
    expect_matrix_near(
        p.get_transform("to_world").matrix,
        Transform::look_at(Point3f(0, 0, 0), Point3f(0, 0, 1), Vector3f(0, 1, 0)).matrix);
    auto inner = p.get_object<RecorderBSDF>("inner");
    ASSERT_TRUE(inner);
    EXPECT_TRUE(inner->props.has("reflectance"));
    EXPECT_FALSE(inner->props.has("diffuse_reflectance"));
    auto tex = p.get_object<RecorderTexture>("tex");
    ASSERT_TRUE(tex);
    EXPECT_FALSE(tex->props.has("uoffset"));
    EXPECT_FALSE(tex->props.has("uscale"));
    Transform expected =
        Transform::scale(Vector3f(2, 3, 1)) * Transform::translate(Vector3f(0.5f, 0, 0));
    expect_matrix_near(tex->props.get_transform("to_uv").matrix, expected.matrix);
}

TEST_F(XmlTest, UpgradeRenamingCanCollide) {
    Error e = string_error("<bsdf version=\"0.6.0\" type=\"diffuse\">\n"
                           "  <rgb name=\"reflectance\" value=\"0.2\"/>\n"
                           "  <rgb name=\"diffuseReflectance\" value=\"0.3\"/>\n"
                           "</bsdf>\n");
    EXPECT_EQ(e.message(), "duplicate property \"reflectance\" (first declared at string:2:4)");
    EXPECT_EQ(e.location().to_string(), "string:3:4");
}

TEST_F(XmlTest, UpgradeIsPerSourceFile) {
    write("old.xml",
          "<scene version=\"0.5.0\">\n  <float name=\"sampleCount\" value=\"1\"/>\n</scene>\n");
    std::string main = write("main.xml", wrap("  <include filename=\"old.xml\"/>\n"
                                              "  <float name=\"keepCase\" value=\"2\"/>\n"));
    auto root = std::dynamic_pointer_cast<RecorderBSDF>(load_file(main));
    ASSERT_TRUE(root);
    EXPECT_TRUE(root->props.has("sample_count"));
    EXPECT_TRUE(root->props.has("keepCase"));
    EXPECT_FALSE(root->props.has("keep_case"));
}

// ------------------------------------------------------------------------------------------------
// Scenes
// ------------------------------------------------------------------------------------------------

TEST_F(XmlTest, SceneRootHoldsItsChildren) {
    std::string path =
        write("scene.xml", "<scene version=\"3.0.0\">\n"
                           "  <integrator type=\"test_integrator\">\n"
                           "    <integer name=\"max_depth\" value=\"5\"/>\n"
                           "  </integrator>\n"
                           "  <bsdf type=\"test_recorder\" id=\"unused_material\"/>\n"
                           "</scene>\n");
    std::shared_ptr<Scene> scene = load_scene(path);
    ASSERT_TRUE(scene);
    auto integrator = std::dynamic_pointer_cast<RecorderIntegrator>(scene->integrator());
    ASSERT_TRUE(integrator);
    EXPECT_EQ(integrator->props.get_int("max_depth"), 5);
    EXPECT_EQ(g_constructed["unused_material"], 1);
    EXPECT_FALSE(scene->sensors().empty());
}

TEST_F(XmlTest, SceneReportsUnqueriedProperties) {
    Error e = string_error("<scene version=\"3.0.0\">\n"
                           "  <integrator type=\"test_integrator\"/>\n"
                           "  <float name=\"stray\" value=\"1\"/>\n"
                           "</scene>\n");
    EXPECT_EQ(e.location().to_string(), "string:1:2");
    EXPECT_TRUE(contains(e.message(), "unreferenced property in scene")) << e.what();
    EXPECT_TRUE(contains(e.message(), "\"stray\"")) << e.what();
}

TEST_F(XmlTest, LoadSceneRequiresASceneRoot) {
    std::string path = write("bsdf.xml", "<bsdf version=\"3.0.0\" type=\"test_recorder\"/>\n");
    Error e = error_of([&] { load_scene(path); });
    EXPECT_EQ(e.message(), "expected a <scene> root element, found <bsdf>");
    EXPECT_EQ(e.location().to_string(), path + ":1:2");
}

TEST_F(XmlTest, NestedSceneIsAnError) {
    Error e = string_error(wrap("  <scene/>\n"));
    EXPECT_EQ(e.message(), "<scene> may only appear as the root element of a file");
    EXPECT_EQ(e.location().to_string(), "string:2:4");
}

} // namespace
