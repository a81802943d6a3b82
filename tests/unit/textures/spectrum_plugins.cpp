// The spectrum plugins (d65, uniform, regular, irregular, srgb, blackbody) and rawconstant: the
// RGB-mode conversions per parameter kind (reflectance, emission), their errors, their use from
// XML, and the blackbody colour against an independent integral of Planck's law.

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/spectrum.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace facet;

namespace {

std::shared_ptr<Object> make(const std::string &plugin, Properties props) {
    props.set_plugin_name(plugin);
    return PluginRegistry::instance().create(ObjectType::Texture, props);
}

/// The colour a parameter of kind `kind` reads from the plugin, through Properties::texture()
/// and through get_color().
Color3f as_kind(const std::shared_ptr<Object> &obj, SpectrumKind kind) {
    Properties holder("holder");
    holder.set_object("value", obj);
    auto tex = holder.texture("value", kind);
    EXPECT_FALSE(tex->is_spatially_varying());
    Color3f via_color = holder.get_color("value", kind);
    Color3f via_texture = tex->eval(SurfaceInteraction());
    for (int c = 0; c < 3; ++c) EXPECT_EQ(via_color[c], via_texture[c]);
    return via_texture;
}

void expect_near(const Color3f &a, const Color3f &b, float tol) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << "channel " << c;
}

void expect_throws(const std::string &plugin, Properties props, const std::string &fragment) {
    try {
        make(plugin, std::move(props));
        ADD_FAILURE() << plugin << ": expected an error containing \"" << fragment << "\"";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

} // namespace

TEST(SpectrumPlugins, D65IsAPlainValueOrTheColour) {
    Properties plain;
    plain.set_float("scale", 2.0);
    auto d65 = make("d65", plain);
    expect_near(as_kind(d65, SpectrumKind::Emission), Color3f(2.f), 0.f);
    expect_near(as_kind(d65, SpectrumKind::Reflectance), Color3f(2.f), 0.f);
    Properties tinted;
    tinted.set_color("color", Color3f(0.9f, 0.5f, 0.2f));
    tinted.set_float("scale", 2.0);
    expect_near(as_kind(make("d65", tinted), SpectrumKind::Emission), Color3f(1.8f, 1.f, 0.4f),
                1e-6f);
    expect_near(as_kind(make("d65", Properties()), SpectrumKind::Emission), Color3f(1.f), 0.f);
}

TEST(SpectrumPlugins, UniformIsPlainUnlikeTheEmitterShorthand) {
    Properties p;
    p.set_float("value", 1.5);
    auto uniform = make("uniform", p);
    expect_near(as_kind(uniform, SpectrumKind::Emission), Color3f(1.5f), 0.f);
    expect_near(as_kind(uniform, SpectrumKind::Reflectance), Color3f(1.5f), 0.f);
    // The shorthand <spectrum value="1.5"/> on an emitter is the slightly purple CIE white.
    Color3f shorthand = spectrum_to_rgb(SpectrumData::constant(1.5), SpectrumKind::Emission);
    EXPECT_GT(std::abs(shorthand.g - 1.5f), 1e-2f);
    expect_throws("uniform", Properties(), "\"value\" is required");
    Properties bad_range;
    bad_range.set_float("value", 1.0);
    bad_range.set_float("wavelength_min", 600.0);
    bad_range.set_float("wavelength_max", 500.0);
    expect_throws("uniform", bad_range, "must be below wavelength_max");
}

TEST(SpectrumPlugins, RegularAndIrregularMatchTheWavelengthList) {
    SpectrumData list = parse_spectrum_pairs("400:0.1, 500:0.8, 600:0.3, 700:0.6");
    Properties reg;
    reg.set_float("wavelength_min", 400.0);
    reg.set_float("wavelength_max", 700.0);
    reg.set_string("values", "0.1, 0.8 0.3,0.6");
    Properties irr;
    irr.set_string("wavelengths", "400, 500, 600, 700");
    irr.set_string("values", "0.1, 0.8, 0.3, 0.6");
    for (auto kind : {SpectrumKind::Reflectance, SpectrumKind::Emission}) {
        Color3f expected = spectrum_to_rgb(list, kind);
        expect_near(as_kind(make("regular", reg), kind), expected, 1e-6f);
        expect_near(as_kind(make("irregular", irr), kind), expected, 1e-6f);
    }
    // Reflectance and emission differ (D65 weighting).
    Color3f r = as_kind(make("irregular", irr), SpectrumKind::Reflectance);
    Color3f e = as_kind(make("irregular", irr), SpectrumKind::Emission);
    EXPECT_GT(std::abs(r.b - e.b), 1e-3f);
}

TEST(SpectrumPlugins, RegularAndIrregularErrors) {
    Properties one;
    one.set_float("wavelength_min", 400.0);
    one.set_float("wavelength_max", 700.0);
    one.set_string("values", "0.5");
    expect_throws("regular", one, "at least two entries");
    Properties bad = one;
    bad.set("values", std::string("0.5, x"), {}, true);
    expect_throws("regular", bad, "\"x\"");
    Properties missing;
    missing.set_string("values", "0.5, 0.6");
    expect_throws("regular", missing, "\"wavelength_min\" is required");
    Properties sizes;
    sizes.set_string("wavelengths", "400, 500, 600");
    sizes.set_string("values", "0.1, 0.2");
    expect_throws("irregular", sizes, "same size (3 vs 2)");
    Properties order;
    order.set_string("wavelengths", "400, 600, 500");
    order.set_string("values", "0.1, 0.2, 0.3");
    expect_throws("irregular", order, "strictly ascending");
}

TEST(SpectrumPlugins, SrgbReflectancesMustBeInRange) {
    Properties ok;
    ok.set_color("color", Color3f(0.8f, 0.3f, 0.1f));
    expect_near(as_kind(make("srgb", ok), SpectrumKind::Reflectance), Color3f(0.8f, 0.3f, 0.1f),
                0.f);
    Properties bright;
    bright.set_color("color", Color3f(2.f, 1.f, 0.5f));
    auto srgb = make("srgb", bright);
    expect_near(as_kind(srgb, SpectrumKind::Emission), Color3f(2.f, 1.f, 0.5f), 0.f);
    Properties holder("holder");
    holder.set_object("reflectance", srgb);
    try {
        holder.texture("reflectance", SpectrumKind::Reflectance);
        ADD_FAILURE() << "a reflectance of 2 was accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("parameter \"reflectance\""), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("invalid RGB reflectance"), std::string::npos);
    }
    expect_throws("srgb", Properties(), "\"color\" is required");
}

TEST(SpectrumPlugins, RawConstantIsUsedAsStored) {
    Properties vec;
    vec.set_vector("value", Vector3f(0.5f, -2.f, 3.f));
    auto raw = std::dynamic_pointer_cast<Texture>(make("rawconstant", vec));
    ASSERT_TRUE(raw);
    Properties holder("holder");
    holder.set_object("value", raw);
    // Not a spectrum: the texture itself, whatever the kind.
    EXPECT_EQ(holder.texture("value", SpectrumKind::Reflectance), raw);
    expect_near(raw->eval(SurfaceInteraction()), Color3f(0.5f, -2.f, 3.f), 0.f);
    EXPECT_EQ(raw->eval_1_grad(SurfaceInteraction()).x, 0.f);
    Properties one;
    one.set_float("value", 0.25);
    auto scalar = std::dynamic_pointer_cast<Texture>(make("rawconstant", one));
    expect_near(scalar->eval(SurfaceInteraction()), Color3f(0.25f), 0.f);
    EXPECT_EQ(scalar->eval_1(SurfaceInteraction()), 0.25f);
    Properties colour;
    colour.set_color("value", Color3f(0.5f));
    expect_throws("rawconstant", colour, "must be a float or a 3D vector");
    expect_throws("rawconstant", Properties(), "\"value\" is required");
}

namespace {

/// Planck's law in W·m⁻²·sr⁻¹·nm⁻¹, written out independently of the plugin.
double planck_reference(double lambda_nm, double t) {
    const double h = 6.62607015e-34, c = 2.99792458e8, kb = 1.380649e-23;
    double l = lambda_nm * 1e-9;
    return 2.0 * h * c * c / (l * l * l * l * l) / (std::exp(h * c / (l * kb * t)) - 1.0) * 1e-9;
}

/// Simpson's rule over 360-830 nm with 0.05 nm steps of Planck × CIE, divided by ∫ȳ.
Color3f blackbody_reference(double t) {
    const int n = 9400; // even
    const double a = 360.0, b = 830.0, step = (b - a) / n;
    double xyz[3] = {0, 0, 0};
    for (int i = 0; i <= n; ++i) {
        double l = a + step * i, w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        Color3f cmf = cie1931_xyz(l);
        double p = planck_reference(l, t) * w * step / 3.0;
        for (int c = 0; c < 3; ++c) xyz[c] += p * cmf[c];
    }
    const double y_integral = 106.7502593994140625;
    return xyz_to_srgb(Color3f(float(xyz[0] / y_integral), float(xyz[1] / y_integral),
                               float(xyz[2] / y_integral)));
}

} // namespace

TEST(SpectrumPlugins, BlackbodyMatchesAnIndependentIntegral) {
    for (double t : {1500.0, 3200.0, 6500.0, 12000.0}) {
        Properties p;
        p.set_float("temperature", t);
        Color3f got = as_kind(make("blackbody", p), SpectrumKind::Emission);
        Color3f ref = blackbody_reference(t);
        for (int c = 0; c < 3; ++c) {
            float expected = std::max(ref[c], 0.f);
            EXPECT_NEAR(got[c], expected, 2e-3f * std::max(ref.max(), 1e-20f))
                << "T = " << t << " channel " << c;
        }
    }
    // Cool bodies are red, hot ones blue.
    Properties cool, hot;
    cool.set_float("temperature", 2000.0);
    hot.set_float("temperature", 15000.0);
    Color3f c = as_kind(make("blackbody", cool), SpectrumKind::Emission);
    Color3f h = as_kind(make("blackbody", hot), SpectrumKind::Emission);
    EXPECT_GT(c.r, c.b);
    EXPECT_GT(h.b, h.r);
    Properties cold;
    cold.set_float("temperature", -5.0);
    expect_throws("blackbody", cold, "positive number of kelvin");
    expect_throws("blackbody", Properties(), "\"temperature\" is required");
}

TEST(SpectrumPlugins, FromXml) {
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="diffuse">
        <spectrum type="irregular" name="reflectance">
            <string name="wavelengths" value="400, 500, 600, 700"/>
            <string name="values" value="0.1, 0.8, 0.3, 0.6"/>
        </spectrum>
    </bsdf>)"));
    ASSERT_TRUE(bsdf);
    expect_near(bsdf->eval_diffuse_reflectance(SurfaceInteraction()),
                spectrum_to_rgb(parse_spectrum_pairs("400:0.1, 500:0.8, 600:0.3, 700:0.6"),
                                SpectrumKind::Reflectance),
                1e-6f);
    auto d65 = std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="diffuse">
        <spectrum type="d65" name="reflectance">
            <rgb name="color" value="0.2, 0.4, 0.6"/>
        </spectrum>
    </bsdf>)"));
    ASSERT_TRUE(d65);
    expect_near(d65->eval_diffuse_reflectance(SurfaceInteraction()), Color3f(0.2f, 0.4f, 0.6f),
                1e-6f);
}

TEST(SpectrumPlugins, ParameterTablesAreComplete) {
    Properties d65, uniform, regular, irregular, srgb, blackbody, raw;
    uniform.set_float("value", 1.0);
    regular.set_float("wavelength_min", 400.0);
    regular.set_float("wavelength_max", 500.0);
    regular.set_string("values", "1, 2");
    irregular.set_string("wavelengths", "400, 500");
    irregular.set_string("values", "1, 2");
    srgb.set_color("color", Color3f(0.5f));
    blackbody.set_float("temperature", 3000.0);
    raw.set_float("value", 1.0);
    for (auto &[plugin, props] :
         std::vector<std::pair<std::string, Properties>>{{"d65", d65},
                                                         {"uniform", uniform},
                                                         {"regular", regular},
                                                         {"irregular", irregular},
                                                         {"srgb", srgb},
                                                         {"blackbody", blackbody},
                                                         {"rawconstant", raw}}) {
        props.set_plugin_name(plugin);
        PluginRegistry::instance().create(ObjectType::Texture, props);
        std::string doc = PluginRegistry::instance().descriptor(plugin, ObjectType::Texture).doc;
        EXPECT_FALSE(props.requested_names().empty()) << plugin;
        for (const std::string &name : props.requested_names())
            EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << plugin << ": " << name;
    }
}
