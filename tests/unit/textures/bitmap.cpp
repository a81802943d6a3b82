// The bitmap texture: images written with write_image and read back through the plugin: sRGB
// decoding of 8-bit files, raw data, linear EXR, the uv layout, nearest and bilinear lookups,
// every wrap mode, to_uv, mean/max/eval_1, file resolution, errors, and use as a BSDF parameter.

#include "texture_lookup.h"

#include <facet/bsdf.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/resolver.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <tuple>
#include <unistd.h>
#include <vector>

using namespace facet;
namespace fs = std::filesystem;

namespace {

float srgb_decode(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

class Bitmap : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("facet_bitmap_" + std::to_string(::getpid()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    std::string path(const std::string &name) const { return (m_dir / name).string(); }

    /// A 4 × 2 RGB image whose pixel (x, y) holds (x, y, c) codes, distinct everywhere.
    static Image pattern() {
        Image img(4, 2, 3);
        img.channel_names = {"R", "G", "B"};
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x)
                for (int c = 0; c < 3; ++c)
                    img.at(x, y, c) = float(40 * x + 100 * y + 10 * c + 5) / 255.f;
        return img;
    }

    /// Writes `img` to a PNG with the exact 8-bit codes round(255·v) (the Raw view).
    /// (Read back with format = variant where a test needs the codes exactly: the default
    /// stores 8-bit images in half precision.)
    void write_png_codes(const std::string &name, const Image &img) const {
        ImageWriteOptions raw;
        raw.view = "Raw";
        write_image(path(name), img, raw);
    }

    static std::shared_ptr<Texture> make_texture(const std::string &plugin, Properties &props) {
        props.set_plugin_name(plugin);
        return PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
    }
    std::shared_ptr<Texture> make_bitmap(const std::string &file, const std::string &filter = "",
                                         const std::string &wrap = "", bool raw = false,
                                         const std::string &format = "") const {
        Properties props("bitmap");
        props.set_string("filename", path(file));
        if (!format.empty()) props.set_string("format", format);
        if (!filter.empty()) props.set_string("filter_type", filter);
        if (!wrap.empty()) props.set_string("wrap_mode", wrap);
        if (raw) props.set_bool("raw", true);
        return make_texture("bitmap", props);
    }

    void expect_bitmap_error(Properties &props, const std::string &fragment) const {
        try {
            make_texture("bitmap", props);
            ADD_FAILURE() << "expected an error containing \"" << fragment << "\"";
        } catch (const Error &e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    }

    fs::path m_dir;
};

/// uv of the centre of pixel (x, y) of a w × h image.
Point2f centre(int x, int y, int w, int h) {
    return {(float(x) + 0.5f) / float(w), (float(y) + 0.5f) / float(h)};
}

void expect_color_near(const Color3f &a, const Color3f &b, float tol, const std::string &what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

} // namespace

TEST_F(Bitmap, EightBitIsSrgbDecodedUnlessRaw) {
    // format = variant keeps 32-bit floats, so the decoded values are exact (the default
    // stores 8-bit images in half precision: FormatSelectsTheStoragePrecision).
    Image img = pattern();
    write_png_codes("codes.png", img);
    auto decoded = make_bitmap("codes.png", "nearest", "", false, "variant");
    auto raw = make_bitmap("codes.png", "nearest", "", true, "variant");
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            Point2f uv = centre(x, y, 4, 2);
            Color3f d = decoded->eval(at_uv(uv.x, uv.y)), r = raw->eval(at_uv(uv.x, uv.y));
            for (int c = 0; c < 3; ++c) {
                EXPECT_FLOAT_EQ(r[c], img.at(x, y, c)) << x << "," << y;
                EXPECT_NEAR(d[c], srgb_decode(img.at(x, y, c)), 1e-6f) << x << "," << y;
            }
        }
    EXPECT_NE(decoded->to_string().find("codes.png"), std::string::npos);
    EXPECT_NE(raw->to_string().find("raw = true"), std::string::npos);

    // A linear value written through the sRGB display transform comes back (8-bit quantisation).
    Image grey(2, 2, 3);
    grey.channel_names = {"R", "G", "B"};
    for (float &v : grey.data) v = 0.5f;
    grey.at(1, 1, 0) = 0.05f;
    write_image(path("display.png"), grey);
    auto back = make_bitmap("display.png", "nearest", "", false, "variant");
    EXPECT_NEAR(back->eval(at_uv(0.25f, 0.25f)).g, 0.5f, 0.004f);
    EXPECT_NEAR(back->eval(at_uv(0.75f, 0.75f)).r, 0.05f, 0.002f);
}

TEST_F(Bitmap, ExrIsLinearAndExact) {
    Image img(3, 2, 3);
    img.channel_names = {"R", "G", "B"};
    for (size_t i = 0; i < img.data.size(); ++i)
        img.data[i] = 0.1f * float(i) + (i == 7 ? 20.f : 0.f);
    write_image(path("linear.exr"), img);
    for (bool raw : {false, true}) {
        auto tex = make_bitmap("linear.exr", "nearest", "", raw);
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x) {
                Point2f uv = centre(x, y, 3, 2);
                Color3f v = tex->eval(at_uv(uv.x, uv.y));
                for (int c = 0; c < 3; ++c)
                    EXPECT_EQ(v[c], img.at(x, y, c)) << x << "," << y << " raw " << raw;
            }
        // mean() is the image average, max() its largest value.
        Color3f mean;
        for (int c = 0; c < 3; ++c) {
            double s = 0;
            for (int p = 0; p < 6; ++p) s += img.data[size_t(p * 3 + c)];
            mean[c] = float(s / 6);
        }
        expect_color_near(tex->mean(), mean, 1e-6f, "mean");
        EXPECT_FLOAT_EQ(tex->max(), 0.7f + 20.f);
        EXPECT_TRUE(tex->is_spatially_varying());
    }
}

namespace {
/// True when f is exactly a normal IEEE half value: its 13 lowest mantissa bits are zero.
bool is_half_value(float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    return std::fabs(f) >= 0x1p-14f && std::fabs(f) <= 65504.f && (bits & 0x1fffu) == 0;
}
} // namespace

TEST_F(Bitmap, FormatSelectsTheStoragePrecision) {
    // As in Mitsuba: `auto` (the default) stores images of 16 bits per channel or fewer in half
    // precision after decoding, `fp16` always, `variant` never.
    Image img = pattern();
    write_png_codes("codes.png", img);
    for (bool raw : {false, true})
        for (const char *format : {"", "auto", "fp16"}) {
            auto tex = make_bitmap("codes.png", "nearest", "", raw, format);
            for (int y = 0; y < 2; ++y)
                for (int x = 0; x < 4; ++x) {
                    Point2f uv = centre(x, y, 4, 2);
                    Color3f v = tex->eval(at_uv(uv.x, uv.y));
                    for (int c = 0; c < 3; ++c) {
                        float exact = raw ? img.at(x, y, c) : srgb_decode(img.at(x, y, c));
                        EXPECT_TRUE(is_half_value(v[c])) << v[c] << " format " << format;
                        EXPECT_NEAR(v[c], exact, exact * 0x1p-11f) << "format " << format;
                    }
                }
        }
    // A 32-bit EXR keeps its values under `auto` and `variant`, and is rounded by `fp16`.
    Image lin(2, 2, 3);
    lin.channel_names = {"R", "G", "B"};
    for (float &v : lin.data) v = 0.1f;
    write_image(path("float.exr"), lin);
    EXPECT_EQ(make_bitmap("float.exr", "nearest")->eval(at_uv(0.2f, 0.2f)).r, 0.1f);
    EXPECT_EQ(make_bitmap("float.exr", "nearest", "", false, "variant")->eval(at_uv(0.2f, 0.2f)).r,
              0.1f);
    EXPECT_EQ(make_bitmap("float.exr", "nearest", "", false, "fp16")->eval(at_uv(0.2f, 0.2f)).r,
              0.0999755859375f); // the half nearest to 0.1
}

TEST_F(Bitmap, TopRowIsAtVZero) {
    // As in Mitsuba: uv (0, 0) is the top-left pixel, v grows downwards. (The OBJ loader flips
    // v, so in an OBJ file's own coordinates the top row is at v = 1.)
    Image img(1, 2, 1);
    img.channel_names = {"Y"};
    img.at(0, 0, 0) = 1.f; // top row
    img.at(0, 1, 0) = 0.25f;
    write_image(path("rows.exr"), img);
    auto tex = make_bitmap("rows.exr", "nearest");
    EXPECT_EQ(tex->eval(at_uv(0.5f, 0.1f)), Color3f(1.f));
    EXPECT_EQ(tex->eval(at_uv(0.5f, 0.9f)), Color3f(0.25f));
}

TEST_F(Bitmap, NearestAndBilinear) {
    Image img = pattern();
    write_png_codes("p.png", img);
    auto nearest = make_bitmap("p.png", "nearest", "clamp", true, "variant");
    auto bilinear = make_bitmap("p.png", "bilinear", "clamp", true, "variant");
    auto px = [&](int x, int y) {
        return Color3f(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2));
    };
    // At pixel centres both give the pixel.
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            Point2f uv = centre(x, y, 4, 2);
            expect_color_near(nearest->eval(at_uv(uv.x, uv.y)), px(x, y), 1e-6f, "nearest centre");
            expect_color_near(bilinear->eval(at_uv(uv.x, uv.y)), px(x, y), 1e-6f,
                              "bilinear centre");
        }
    // Between centres: nearest takes the pixel the point falls in, bilinear interpolates.
    // u = 1.3/4: x = u·4 − 0.5 = 0.8, i.e. 20 % of pixel 0 and 80 % of pixel 1 on the top row's
    // centre line; the point itself lies in pixel 1.
    float u = 1.3f / 4.f;
    expect_color_near(bilinear->eval(at_uv(u, 0.25f)), px(0, 0) * 0.2f + px(1, 0) * 0.8f, 1e-5f,
                      "bilinear x");
    expect_color_near(nearest->eval(at_uv(u, 0.25f)), px(1, 0), 1e-6f, "nearest x");
    // Halfway between the two rows and two columns: the average of four pixels.
    expect_color_near(bilinear->eval(at_uv(0.5f, 0.5f)),
                      (px(1, 0) + px(2, 0) + px(1, 1) + px(2, 1)) * 0.25f, 1e-5f,
                      "bilinear corner");
    expect_color_near(nearest->eval(at_uv(0.5f, 0.5f)), px(2, 1), 1e-6f, "nearest corner");
}

TEST_F(Bitmap, WrapModes) {
    Image img = pattern();
    write_png_codes("w.png", img);
    auto px = [&](int x, int y) {
        return Color3f(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2));
    };
    float row0 = 0.25f;
    // Nearest: pixel index −1 and 4 (one past each edge), and far away.
    struct Case {
        const char *mode;
        int left, right, far; // pixel for x = −1, x = 4, x = 4·3 + 1 = 13 (u = 3.375)
    };
    for (const Case &c :
         {Case{"repeat", 3, 0, 1}, Case{"mirror", 0, 3, 2}, Case{"clamp", 0, 3, 3}}) {
        auto tex = make_bitmap("w.png", "nearest", c.mode, true, "variant");
        expect_color_near(tex->eval(at_uv(-0.5f / 4.f, row0)), px(c.left, 0), 1e-6f,
                          std::string(c.mode) + " left");
        expect_color_near(tex->eval(at_uv(4.5f / 4.f, row0)), px(c.right, 0), 1e-6f,
                          std::string(c.mode) + " right");
        expect_color_near(tex->eval(at_uv(13.5f / 4.f, row0)), px(c.far, 0), 1e-6f,
                          std::string(c.mode) + " far");
        // In v as well: row −1.
        int row = std::string(c.mode) == "repeat" ? 1 : 0;
        expect_color_near(tex->eval(at_uv(centre(2, 0, 4, 2).x, -0.25f)), px(2, row), 1e-6f,
                          std::string(c.mode) + " v");
    }
    // Bilinear across the left edge (u = 0, x = −0.5): repeat blends pixels 3 and 0, mirror and
    // clamp see pixel 0 twice.
    auto repeat = make_bitmap("w.png", "bilinear", "repeat", true, "variant");
    auto mirror = make_bitmap("w.png", "bilinear", "mirror", true, "variant");
    auto clamp_ = make_bitmap("w.png", "bilinear", "clamp", true, "variant");
    expect_color_near(repeat->eval(at_uv(0.f, row0)), (px(3, 0) + px(0, 0)) * 0.5f, 1e-5f,
                      "bilinear repeat");
    expect_color_near(mirror->eval(at_uv(0.f, row0)), px(0, 0), 1e-5f, "bilinear mirror");
    expect_color_near(clamp_->eval(at_uv(0.f, row0)), px(0, 0), 1e-5f, "bilinear clamp");
    // Repeat is periodic: u and u + 7 agree.
    for (float u : {0.1f, 0.37f, 0.8f})
        expect_color_near(repeat->eval(at_uv(u + 7.f, 0.3f)), repeat->eval(at_uv(u, 0.3f)), 1e-5f,
                          "period");
    // Mirror is symmetric about u = 1.
    for (float u : {0.1f, 0.37f, 0.8f})
        expect_color_near(mirror->eval(at_uv(2.f - u, 0.3f)), mirror->eval(at_uv(u, 0.3f)), 1e-5f,
                          "mirror");
    // Non-finite coordinates do not crash or read outside the image.
    Color3f nan_value = repeat->eval(at_uv(std::nanf(""), 1e30f));
    EXPECT_TRUE(nan_value.is_finite());
}

TEST_F(Bitmap, ToUvTransform) {
    Image img = pattern();
    write_png_codes("t.png", img);
    auto px = [&](int x, int y) {
        return Color3f(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2));
    };
    Properties props("bitmap");
    props.set_string("filename", path("t.png"));
    props.set_string("filter_type", "nearest");
    props.set_bool("raw", true);
    props.set_string("format", "variant");
    // uv' = (2u + 0.25, 0.5v): uv (0.2, 0.9) -> (0.65, 0.45) = pixel (2, 0).
    props.set_transform("to_uv", Transform::translate(Vector3f(0.25f, 0.f, 0.f)) *
                                     Transform::scale(Vector3f(2.f, 0.5f, 1.f)));
    auto tex = make_texture("bitmap", props);
    expect_color_near(tex->eval(at_uv(0.2f, 0.9f)), px(2, 0), 1e-6f, "to_uv");
    expect_color_near(tex->eval(at_uv(0.45f, 3.5f)), px(0, 1), 1e-6f,
                      "to_uv repeat"); // (1.15, 1.75)
}

TEST_F(Bitmap, GreyImagesAndEval1) {
    Image grey(2, 1, 1);
    grey.channel_names = {"Y"};
    grey.at(0, 0, 0) = 0.25f;
    grey.at(1, 0, 0) = 0.75f;
    write_image(path("grey.exr"), grey);
    auto tex = make_bitmap("grey.exr", "nearest");
    EXPECT_EQ(tex->eval(at_uv(0.25f, 0.5f)), Color3f(0.25f));
    EXPECT_EQ(tex->eval_1(at_uv(0.75f, 0.5f)), 0.75f);
    EXPECT_EQ(tex->mean(), Color3f(0.5f));

    // Colour images: eval_1 is the luminance.
    Image rgb(1, 1, 3);
    rgb.channel_names = {"R", "G", "B"};
    rgb.data = {1.f, 0.5f, 0.25f};
    write_image(path("rgb.exr"), rgb);
    auto c = make_bitmap("rgb.exr");
    EXPECT_NEAR(c->eval_1(at_uv(0.3f, 0.6f)), Color3f(1.f, 0.5f, 0.25f).luminance(), 1e-6f);

    // Grey + alpha and RGBA: alpha is dropped.
    Image rgba(1, 1, 4);
    rgba.channel_names = {"R", "G", "B", "A"};
    rgba.data = {0.2f, 0.4f, 0.6f, 0.5f};
    write_image(path("rgba.exr"), rgba);
    EXPECT_EQ(make_bitmap("rgba.exr")->eval(at_uv(0.5f, 0.5f)), Color3f(0.2f, 0.4f, 0.6f));
    Image ya(1, 1, 2);
    ya.channel_names = {"Y", "A"};
    ya.data = {0.3f, 0.9f};
    write_image(path("ya.exr"), ya);
    EXPECT_EQ(make_bitmap("ya.exr")->eval(at_uv(0.5f, 0.5f)), Color3f(0.3f));
}

TEST_F(Bitmap, RejectsBadParameters) {
    Image img = pattern();
    write_png_codes("ok.png", img);
    Properties missing("bitmap");
    expect_bitmap_error(missing, "filename");
    Properties nofile("bitmap");
    nofile.set_string("filename", path("nope.png"));
    expect_bitmap_error(nofile, "no such file");
    auto with = [&](const std::string &name, Properties::Value value) {
        Properties p("bitmap");
        p.set_string("filename", path("ok.png"));
        p.set(name, std::move(value));
        return p;
    };
    std::vector<std::tuple<std::string, Properties::Value, std::string>> cases = {
        {"filter_type", std::string("trilinear"), "filter_type must be bilinear or nearest"},
        {"wrap_mode", std::string("wrap"), "wrap_mode must be repeat, mirror or clamp"},
        {"format", std::string("fp64"), "format must be auto, variant or fp16"},
        {"format", std::string("fp32"), "format must be auto, variant or fp16"},
        {"raw", std::string("yes"), "raw"},
        {"to_uv", 2.0, "to_uv"},
        {"gamma", 2.2, "gamma"},
    };
    for (auto &[name, value, fragment] : cases) {
        Properties p = with(name, value);
        expect_bitmap_error(p, fragment);
    }

    // Every parameter read is in the doc table.
    Properties all = with("filter_type", std::string("nearest"));
    make_texture("bitmap", all);
    std::string doc = PluginRegistry::instance().descriptor("bitmap", ObjectType::Texture).doc;
    EXPECT_EQ(all.requested_names().size(), 7u);
    for (const std::string &name : all.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST_F(Bitmap, RelativeNamesGoThroughTheFileResolver) {
    write_png_codes("rel.png", pattern());
    std::vector<std::string> saved = file_resolver().dirs();
    file_resolver().prepend(m_dir.string());
    Properties props("bitmap");
    props.set_string("filename", "rel.png");
    std::shared_ptr<Texture> tex;
    EXPECT_NO_THROW(tex = make_texture("bitmap", props));
    file_resolver().clear();
    for (const auto &d : saved) file_resolver().append(d);
    ASSERT_TRUE(tex);
    EXPECT_GT(tex->mean().r, 0.f);
}

TEST_F(Bitmap, WorksAsABSDFParameter) {
    Image img(2, 1, 3);
    img.channel_names = {"R", "G", "B"};
    img.data = {0.8f, 0.1f, 0.1f, 0.1f, 0.1f, 0.8f};
    write_image(path("albedo.exr"), img);
    std::string xml = R"(<bsdf version="3.0.0" type="diffuse">
        <texture type="bitmap" name="reflectance">
            <string name="filename" value=")" +
                      path("albedo.exr") + R"("/>
            <string name="filter_type" value="nearest"/>
        </texture>
    </bsdf>)";
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(xml));
    ASSERT_TRUE(bsdf);
    EXPECT_TRUE(has_flag(bsdf->flags(), BSDFFlags::SpatiallyVarying));
    SurfaceInteraction si = at_uv(0.25f, 0.5f);
    Color3f left = bsdf->eval(BSDFContext(), si, Vector3f(0.f, 0.f, 1.f));
    expect_color_near(left, Color3f(0.8f, 0.1f, 0.1f) * InvPi, 1e-6f, "left");
    si.uv = Point2f(0.75f, 0.5f);
    expect_color_near(bsdf->eval_diffuse_reflectance(si), Color3f(0.1f, 0.1f, 0.8f), 1e-6f,
                      "right");

    // A scalar parameter (roughness) reads eval_1.
    Image rough(1, 1, 1);
    rough.channel_names = {"Y"};
    rough.data = {0.3f};
    write_image(path("rough.exr"), rough);
    Properties props("roughconductor");
    Properties tex_props("bitmap");
    tex_props.set_string("filename", path("rough.exr"));
    props.set_object("alpha", make_texture("bitmap", tex_props));
    auto textured = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
    Properties plain_props("roughconductor");
    plain_props.set_float("alpha", 0.3);
    auto plain = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, plain_props);
    SurfaceInteraction s2 = at_uv(0.5f, 0.5f);
    s2.wi = normalize(Vector3f(0.3f, 0.f, 0.8f));
    Vector3f wo = normalize(Vector3f(-0.2f, 0.1f, 0.9f));
    EXPECT_NEAR(textured->eval(BSDFContext(), s2, wo).r, plain->eval(BSDFContext(), s2, wo).r,
                1e-6f);
}

TEST_F(Bitmap, PrefetchSaysWhereALoadStartedAndChangesNoValue) {
    Image img = pattern();
    write_png_codes("p.png", img);
    const std::string texture = R"(<texture type="bitmap" name="NAME">
            <string name="filename" value=")" +
                                path("p.png") + R"("/>
        </texture>)";
    auto with = [&](const std::string &name) {
        std::string t = texture;
        t.replace(t.find("NAME"), 4, name);
        return t;
    };
    auto bsdf = [&](std::string xml) { // a top-level element states the scene version
        xml.insert(6, R"(version="3.0.0" )");
        auto b = std::dynamic_pointer_cast<BSDF>(load_string(xml));
        EXPECT_TRUE(b);
        return b;
    };
    SurfaceInteraction si = at_uv(0.3f, 0.6f);
    si.wi = normalize(Vector3f(0.2f, 0.1f, 0.9f));
    const Vector3f wo = normalize(Vector3f(-0.3f, 0.2f, 0.8f));
    // Every bitmap starts a load, at any uv (wrapped, or not finite).
    auto tex = make_bitmap("p.png");
    auto near = make_bitmap("p.png", "nearest", "clamp");
    for (Point2f uv : {Point2f(0.3f, 0.6f), Point2f(-7.2f, 1e6f), Point2f(std::nanf(""), 2.f)}) {
        SurfaceInteraction at = at_uv(uv.x, uv.y);
        const Color3f before = tex->eval(at);
        EXPECT_TRUE(tex->prefetch(at));
        EXPECT_TRUE(near->prefetch(at));
        EXPECT_EQ(tex->eval(at), before);
    }
    // BSDFs pass it on: true where a bitmap is reached, false for constants and procedures.
    const std::string d = R"(<bsdf type="diffuse">)" + with("reflectance") + "</bsdf>";
    auto diffuse = bsdf(d);
    const Color3f value = diffuse->eval(BSDFContext(), si, wo);
    EXPECT_TRUE(diffuse->prefetch(si));
    EXPECT_EQ(diffuse->eval(BSDFContext(), si, wo), value);
    EXPECT_TRUE(bsdf(R"(<bsdf type="twosided">)" + d + "</bsdf>")->prefetch(si));
    EXPECT_TRUE(bsdf(R"(<bsdf type="mask">)" + with("opacity") + R"(<bsdf type="diffuse"/></bsdf>)")
                    ->prefetch(si));
    EXPECT_TRUE(bsdf(R"(<bsdf type="roughplastic">)" + with("diffuse_reflectance") + "</bsdf>")
                    ->prefetch(si));
    EXPECT_FALSE(bsdf(R"(<bsdf type="diffuse"/>)")->prefetch(si));
    EXPECT_FALSE(bsdf(R"(<bsdf type="diffuse">
            <texture type="checkerboard" name="reflectance"/></bsdf>)")
                     ->prefetch(si));
    // A roughness texture too (MicrofacetParameters::prefetch()), for both axes or one.
    EXPECT_TRUE(bsdf(R"(<bsdf type="roughconductor">)" + with("alpha") + "</bsdf>")->prefetch(si));
    EXPECT_TRUE(bsdf(R"(<bsdf type="roughdielectric"><float name="alpha_u" value="0.2"/>)" +
                     with("alpha_v") + "</bsdf>")
                    ->prefetch(si));
    EXPECT_FALSE(bsdf(R"(<bsdf type="roughconductor"/>)")->prefetch(si));
}

TEST_F(Bitmap, AlphaIsDroppedAndTheStoredColourKept) {
    // As Mitsuba: a texel of RGB (200, 120, 40) under alpha 128 is the colour as stored (sRGB
    // decoded), not the colour times alpha (0.128 for the red channel). The files are written
    // with OpenImageIO told that their colour is not premultiplied, so the bytes are the ones
    // given; PNG, Targa and TIFF are the formats whose readers would premultiply.
    for (const char *ext : {".png", ".tga", ".tif"}) {
        for (int channels : {2, 4}) {
            const std::string name = std::string("alpha") + std::to_string(channels) + ext;
            std::vector<unsigned char> texels;
            for (int x = 0; x < 2; ++x) {
                const unsigned char alpha = x == 0 ? 128 : 0;
                if (channels == 2)
                    texels.insert(texels.end(), {200, alpha});
                else
                    texels.insert(texels.end(), {200, 120, 40, alpha});
            }
            auto out = OIIO::ImageOutput::create(path(name));
            ASSERT_TRUE(out) << name;
            OIIO::ImageSpec spec(2, 1, channels, OIIO::TypeDesc::UINT8);
            spec.alpha_channel = channels - 1;
            spec.attribute("oiio:UnassociatedAlpha", 1);
            ASSERT_TRUE(out->open(path(name), spec)) << name;
            ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data())) << name;
            out->close();

            // The image as read: colour as stored, alpha kept as its own channel.
            Image img = read_image(path(name));
            ASSERT_EQ(img.channels, channels) << name;
            EXPECT_FLOAT_EQ(img.at(0, 0, 0), 200.f / 255.f) << name;
            EXPECT_FLOAT_EQ(img.at(0, 0, channels - 1), 128.f / 255.f) << name;
            EXPECT_FLOAT_EQ(img.at(1, 0, 0), 200.f / 255.f) << name << " (alpha 0)";

            auto tex = make_bitmap(name, "nearest", "", false, "variant");
            const Color3f expected =
                channels == 2 ? Color3f(srgb_decode(200.f / 255.f))
                              : Color3f(srgb_decode(200.f / 255.f), srgb_decode(120.f / 255.f),
                                        srgb_decode(40.f / 255.f));
            for (float u : {0.25f, 0.75f}) {
                expect_color_near(tex->eval(at_uv(u, 0.5f)), expected, 1e-6f, name);
                // Scalar queries (a mask's opacity, a roughness) read the colour too, never
                // the alpha channel.
                EXPECT_NEAR(tex->eval_1(at_uv(u, 0.5f)), expected.luminance(), 1e-6f) << name;
            }
        }
    }
}
