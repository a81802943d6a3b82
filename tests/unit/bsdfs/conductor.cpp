// The smooth conductor and the embedded conductor data: flags, the ideal mirror default, measured
// materials, eta/k given as numbers, rgb or spectra, conflicting parameters and the back side.

#include "bsdf_checks.h"

#include <facet/conductor_data.h>
#include <facet/fresnel.h>
#include <facet/spectrum.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

void expect_color_near(const Color3f &a, const Color3f &b, float rel, const std::string &what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a[c], b[c], rel * std::abs(b[c]) + 1e-6f) << what << " channel " << c;
}

} // namespace

TEST(ConductorData, RGBValuesOfMeasuredMetals) {
    // RGB η, k of the luxpop data as published for RGB renderers (CIE 1931 integration without
    // illuminant); ours resample to the 5 nm CIE grid first, hence 1 %.
    struct Ref {
        const char *name;
        Color3f eta, k;
    };
    const Ref refs[] = {
        {"Cu", {0.200438f, 0.924033f, 1.10221f}, {3.91295f, 2.45285f, 2.14219f}},
        {"Au", {0.143119f, 0.374957f, 1.44248f}, {3.98316f, 2.38572f, 1.60322f}},
        {"Ag", {0.155265f, 0.116723f, 0.138342f}, {4.82835f, 3.12225f, 2.14696f}},
        {"Al", {1.65746f, 0.880369f, 0.521229f}, {9.22387f, 6.26952f, 4.837f}},
    };
    for (const Ref &r : refs) {
        auto [eta, k] = conductor_eta_k(r.name);
        expect_color_near(eta, r.eta, 0.01f, std::string(r.name) + " eta");
        expect_color_near(k, r.k, 0.01f, std::string(r.name) + " k");
    }
}

TEST(ConductorData, NamesNoneAndCase) {
    std::vector<std::string> names = conductor_names();
    EXPECT_EQ(names.size(), 72u); // 71 measured materials and "none"
    for (const char *n : {"none", "Cu", "Cu_palik", "a-C", "d-C_palik", "Se-e", "TiO2-e_palik",
                          "Na_palik", "Ni_palik", "V_palik", "W", "Hg", "Cr"})
        EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    auto [eta, k] = conductor_eta_k("none");
    EXPECT_EQ(eta, Color3f(0.f));
    EXPECT_EQ(k, Color3f(1.f));
    EXPECT_EQ(conductor_eta_k("cu"), conductor_eta_k("Cu"));
    // Every material converts to finite, non-negative values.
    for (const std::string &n : names) {
        auto [e, kk] = conductor_eta_k(n);
        EXPECT_TRUE(e.is_finite() && kk.is_finite()) << n;
        EXPECT_GE(std::min({e.r, e.g, e.b, kk.r, kk.g, kk.b}), 0.f) << n;
    }
}

TEST(ConductorData, UnknownMaterialSuggestsTheClosest) {
    try {
        conductor_eta_k("Cuu");
        FAIL() << "expected an error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("unknown conductor material \"Cuu\""), std::string::npos) << msg;
        EXPECT_NE(msg.find("did you mean \"Cu\""), std::string::npos) << msg;
        EXPECT_NE(msg.find("Cu_palik"), std::string::npos) << msg; // the list of valid names
    }
}

TEST(Conductor, CreationAndFlags) {
    auto bsdf = make_bsdf("conductor");
    ASSERT_EQ(bsdf->component_count(), 1u);
    EXPECT_EQ(bsdf->flags(),
              BSDFFlags::DeltaReflection | BSDFFlags::FrontSide | BSDFFlags::Polarizing);
    EXPECT_NE(bsdf->to_string().find("Conductor"), std::string::npos);
    expect_documented("conductor", {{"specular_reflectance", 0.5}});
    expect_documented("conductor", {{"eta", 0.5}, {"k", 2.0}});
}

TEST(Conductor, DefaultIsAnIdealMirror) {
    auto bsdf = make_bsdf("conductor");
    PCG32 rng(1);
    for (int i = 0; i < 100; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, true));
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, rng.next_float(), Point2f(0.3f, 0.6f));
        expect_color_near(weight, Color3f(1.f), 1e-5f, "mirror");
        EXPECT_EQ(bs.wo, reflect(si.wi));
        EXPECT_EQ(bs.pdf, 1.f);
        EXPECT_EQ(bs.eta, 1.f);
        EXPECT_EQ(bs.sampled_type, BSDFFlags::DeltaReflection);
        EXPECT_EQ(bs.sampled_component, 0u);
        EXPECT_TRUE(bsdf->eval(BSDFContext(), si, bs.wo).is_black());
        EXPECT_EQ(bsdf->pdf(BSDFContext(), si, bs.wo), 0.f);
    }
}

TEST(Conductor, MeasuredMaterialWeightIsItsFresnelReflectance) {
    auto bsdf = make_bsdf("conductor", {{"material", std::string("Au")},
                                        {"specular_reflectance", Color3f(1.f, 0.5f, 0.25f)}});
    auto [eta, k] = conductor_eta_k("Au");
    for (float cos_i : {1.f, 0.7f, 0.3f, 0.05f}) {
        SurfaceInteraction si = make_si(Vector3f(std::sqrt(1.f - cos_i * cos_i), 0.f, cos_i));
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, 0.5f, Point2f(0.5f));
        expect_color_near(weight, fresnel_conductor(cos_i, eta, k) * Color3f(1.f, 0.5f, 0.25f),
                          1e-5f, "gold");
    }
    // Gold: red reflects far better than blue at normal incidence.
    Color3f F = fresnel_conductor(1.f, eta, k);
    EXPECT_GT(F.r, 0.9f);
    EXPECT_LT(F.b, 0.6f);
}

TEST(Conductor, EtaAndKAsNumbersRGBAndSpectra) {
    SurfaceInteraction si = make_si(normalize(Vector3f(0.2f, 0.3f, 0.8f)));
    auto numbers = make_bsdf("conductor", {{"eta", 1.5}, {"k", 0.0}});
    EXPECT_NEAR(numbers->sample(BSDFContext(), si, 0.5f, Point2f(0.5f)).second.g,
                fresnel_dielectric(si.wi.z, 1.5f).F, 2e-5f);

    auto rgb = make_bsdf("conductor",
                         {{"eta", Color3f(0.2f, 0.9f, 1.1f)}, {"k", Color3f(3.9f, 2.4f, 2.1f)}});
    expect_color_near(
        rgb->sample(BSDFContext(), si, 0.5f, Point2f(0.5f)).second,
        fresnel_conductor(si.wi.z, Color3f(0.2f, 0.9f, 1.1f), Color3f(3.9f, 2.4f, 2.1f)), 1e-6f,
        "rgb");

    // Spectra are unbounded quantities: weighted by D65 (as every non-emitter), no clamping to 1.
    SpectrumData eta_s = parse_spectrum_pairs("400:1.5, 500:1.0, 600:0.4, 700:0.2");
    SpectrumData k_s = parse_spectrum_pairs("400:2.0, 500:2.5, 600:3.5, 700:4.0");
    auto spectral = make_bsdf("conductor", {{"eta", eta_s}, {"k", k_s}});
    Color3f eta = spectrum_to_rgb(eta_s, SpectrumKind::Unbounded);
    Color3f k = spectrum_to_rgb(k_s, SpectrumKind::Unbounded);
    EXPECT_GT(k.r, 1.f);
    expect_color_near(spectral->sample(BSDFContext(), si, 0.5f, Point2f(0.5f)).second,
                      fresnel_conductor(si.wi.z, eta, k), 1e-6f, "spectrum");
}

TEST(Conductor, InlineSpectraAtNormalIncidenceMatchMitsuba) {
    // Mitsuba 3.8 (scalar_rgb) renders this conductor with a normal-incidence reflectance of
    // (0.986, 0.708, 0.404): its inline eta and k are weighted by D65. Without the weighting the
    // result is (0.974, 0.703, 0.372).
    auto bsdf = make_bsdf(
        "conductor",
        {{"eta", parse_spectrum_pairs("300:1.8, 400:1.65, 500:0.9, 600:0.2, 700:0.16, 800:0.18")},
         {"k", parse_spectrum_pairs("300:1.92, 400:1.95, 500:1.95, 600:2.97, 700:3.8, 800:5.12")}});
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    Color3f r = bsdf->sample(BSDFContext(), si, 0.5f, Point2f(0.5f)).second;
    // The figures are given to three decimals.
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(r[c], Color3f(0.986f, 0.708f, 0.404f)[c], 6e-4f) << "channel " << c;
}

TEST(Conductor, RejectsBadParameters) {
    expect_error("conductor", {{"material", std::string("Cu")}, {"eta", 1.0}},
                 "give either material=\"Cu\" or eta/k, not both");
    expect_error("conductor", {{"material", std::string("Au")}, {"k", 3.0}}, "not both");
    expect_error("conductor", {{"material", std::string("Gold")}},
                 "unknown conductor material \"Gold\"");
    expect_error("conductor", {{"material", std::string("Agg")}}, "did you mean \"Ag\"");
    expect_error("conductor", {{"eta", std::string("high")}}, "eta");
    expect_error("conductor", {{"alpha", 0.1}}, "alpha");
}

TEST(Conductor, BackSideAndDisabledLobeAreBlack) {
    auto bsdf = make_bsdf("conductor", {{"material", std::string("Cu")}});
    SurfaceInteraction below = make_si(normalize(Vector3f(0.3f, 0.f, -0.5f)));
    EXPECT_TRUE(bsdf->sample(BSDFContext(), below, 0.5f, Point2f(0.5f)).second.is_black());
    SurfaceInteraction above = make_si(normalize(Vector3f(0.3f, 0.f, 0.5f)));
    BSDFContext glossy_only;
    glossy_only.type_mask = uint32_t(BSDFFlags::Glossy);
    EXPECT_TRUE(bsdf->sample(glossy_only, above, 0.5f, Point2f(0.5f)).second.is_black());
    BSDFContext other_component;
    other_component.component = 1;
    EXPECT_TRUE(bsdf->sample(other_component, above, 0.5f, Point2f(0.5f)).second.is_black());
}

TEST(Conductor, WhiteFurnaceAtMostOne) {
    PCG32 rng(2);
    for (const char *material : {"none", "Cu", "Au", "Ag", "Al", "Cr", "W", "Hg"}) {
        auto bsdf = make_bsdf("conductor", {{"material", std::string(material)}});
        for (int i = 0; i < 20; ++i) {
            Color3f albedo = furnace(*bsdf, BSDFContext(), random_direction(rng, true), 10);
            EXPECT_LE(albedo.max(), 1.f + 1e-6f) << material;
            EXPECT_GT(albedo.max(), 0.f) << material;
        }
    }
}
