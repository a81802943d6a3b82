// Fresnel equations, reflection/refraction directions and the IOR tables: closed forms, Snell's
// law, total internal reflection, the conductor/dielectric agreement at k = 0.

#include "draws.h"

#include <facet/frame.h>
#include <facet/fresnel.h>
#include <facet/ior.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/warp.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

/// The lecture's form: F_p, F_s with η1 on the incident side, η2 on the other, R = ½(F_p² + F_s²).
double lecture_fresnel(double cos1, double eta1, double eta2) {
    double sin1 = std::sqrt(std::max(0.0, 1.0 - cos1 * cos1));
    double sin2 = eta1 / eta2 * sin1;
    if (sin2 >= 1.0) return 1.0;
    double cos2 = std::sqrt(1.0 - sin2 * sin2);
    double fp = (eta2 * cos1 - eta1 * cos2) / (eta2 * cos1 + eta1 * cos2);
    double fs = (eta1 * cos1 - eta2 * cos2) / (eta1 * cos1 + eta2 * cos2);
    return 0.5 * (fp * fp + fs * fs);
}

} // namespace

TEST(Fresnel, NormalIncidenceIsFourPercentForGlass) {
    // ((η − 1)/(η + 1))² = (0.5/2.5)² = 0.04, from either side.
    EXPECT_NEAR(fresnel_dielectric(1.f, 1.5f).F, 0.04f, 1e-6f);
    EXPECT_NEAR(fresnel_dielectric(-1.f, 1.5f).F, 0.04f, 1e-6f);
    EXPECT_NEAR(fresnel_dielectric(1.f, 1.333f).F, sqr(0.333f / 2.333f), 1e-6f);
}

TEST(Fresnel, GoesToOneAtGrazingIncidence) {
    EXPECT_EQ(fresnel_dielectric(0.f, 1.5f).F, 1.f);
    EXPECT_GT(fresnel_dielectric(1e-4f, 1.5f).F, 0.999f);
    EXPECT_GT(fresnel_dielectric(-1e-4f, 1.5f).F, 0.999f);
    // Monotonic towards grazing from outside (past Brewster's angle it climbs to 1).
    float prev = 0.f;
    for (int i = 0; i <= 100; ++i) {
        float theta = deg_to_rad(60.f + 0.3f * i);
        float F = fresnel_dielectric(std::cos(theta), 1.5f).F;
        EXPECT_GE(F, prev);
        prev = F;
    }
}

TEST(Fresnel, IndexMatchedInterfaceReflectsNothing) {
    for (float c : {1.f, 0.5f, 0.01f, 0.f, -0.3f}) {
        auto r = fresnel_dielectric(c, 1.f);
        EXPECT_EQ(r.F, 0.f);
        EXPECT_NEAR(r.cos_t, -c, 1e-6f);
    }
}

TEST(Fresnel, MatchesTheLectureFormulas) {
    // Float evaluation against double: near the critical angle F is steep in cos θi, hence 2e-5.
    for (float eta : {1.1f, 1.33f, 1.5046f, 2.419f, 0.7f}) {
        for (int i = 0; i <= 50; ++i) {
            double cos_i = i / 50.0;
            // From outside: η1 = 1, η2 = η. From inside: η1 = η, η2 = 1.
            EXPECT_NEAR(fresnel_dielectric(float(cos_i), eta).F, lecture_fresnel(cos_i, 1.0, eta),
                        2e-5)
                << "eta " << eta << " cos " << cos_i;
            EXPECT_NEAR(fresnel_dielectric(-float(cos_i), eta).F, lecture_fresnel(cos_i, eta, 1.0),
                        2e-5)
                << "eta " << eta << " cos " << -cos_i;
        }
    }
}

TEST(Fresnel, RefractionFollowsSnellsLaw) {
    PCG32 rng(3);
    for (int i = 0; i < 1000; ++i) {
        float eta = 1.f + 1.5f * rng.next_float();
        Vector3f wi = warp::square_to_uniform_sphere(next_point2f(rng));
        auto [F, cos_t, eta_it, eta_ti] = fresnel_dielectric(wi.z, eta);
        EXPECT_NEAR(eta_it * eta_ti, 1.f, 1e-6f);
        EXPECT_EQ(eta_it, wi.z >= 0.f ? eta : 1.f / eta);
        if (F == 1.f) continue; // total internal reflection
        Vector3f wt = refract(wi, cos_t, eta_ti);
        EXPECT_NEAR(norm(wt), 1.f, 1e-5f);
        EXPECT_LE(wt.z * wi.z, 0.f); // the other side
        // η_i sin θi = η_t sin θt, with η_i = 1 outside and η inside.
        float eta_i = wi.z >= 0.f ? 1.f : eta, eta_t = wi.z >= 0.f ? eta : 1.f;
        EXPECT_NEAR(eta_i * Frame::sin_theta(wi), eta_t * Frame::sin_theta(wt), 1e-4f);
        // The refracted ray lies in the plane of incidence, on the far side of the normal.
        EXPECT_LE(wt.x * wi.x + wt.y * wi.y, 1e-6f);
    }
}

TEST(Fresnel, TotalInternalReflectionBeyondTheCriticalAngle) {
    float eta = 1.5f;
    float critical = std::asin(1.f / eta);
    // From the dense side (cos θi < 0): beyond the critical angle everything is reflected.
    for (float offset : {1e-3f, 0.1f, 0.5f}) {
        float theta = critical + offset;
        if (theta >= 0.5f * Pi) continue;
        auto r = fresnel_dielectric(-std::cos(theta), eta);
        EXPECT_EQ(r.F, 1.f) << "theta " << theta;
        EXPECT_EQ(r.cos_t, 0.f);
    }
    // Just below the critical angle light still gets out.
    auto below = fresnel_dielectric(-std::cos(critical - 1e-2f), eta);
    EXPECT_LT(below.F, 1.f);
    EXPECT_GT(below.cos_t, 0.f);
    // Never from the light side.
    EXPECT_LT(fresnel_dielectric(std::cos(critical + 0.5f), eta).F, 1.f);
}

TEST(Fresnel, ReflectanceIsTheSameForTheReversedRay) {
    // Stokes: light refracted from θi to θt reflects the same fraction when going back.
    for (int i = 1; i < 50; ++i) {
        float cos_i = i / 50.f;
        auto fwd = fresnel_dielectric(cos_i, 1.5f);
        auto back = fresnel_dielectric(fwd.cos_t, 1.5f);
        EXPECT_NEAR(fwd.F, back.F, 1e-5f);
        EXPECT_NEAR(back.cos_t, cos_i, 1e-5f);
    }
}

TEST(Fresnel, ConductorWithZeroKEqualsDielectric) {
    for (float eta : {1.2f, 1.5f, 2.4f, 4.f}) {
        for (int i = 1; i <= 40; ++i) {
            float c = i / 40.f;
            EXPECT_NEAR(fresnel_conductor(c, eta, 0.f), fresnel_dielectric(c, eta).F, 2e-5f)
                << "eta " << eta << " cos " << c;
        }
    }
}

TEST(Fresnel, ConductorClosedForms) {
    // Normal incidence: ((η − 1)² + k²) / ((η + 1)² + k²).
    float eta = 0.27f, k = 2.78f;
    float expected = (sqr(eta - 1.f) + k * k) / (sqr(eta + 1.f) + k * k);
    EXPECT_NEAR(fresnel_conductor(1.f, eta, k), expected, 1e-5f);
    // η = 0, k = 1 is a perfect mirror at every angle; grazing reflects everything.
    for (float c : {1.f, 0.7f, 0.2f, 1e-3f})
        EXPECT_NEAR(fresnel_conductor(c, 0.f, 1.f), 1.f, 1e-5f);
    EXPECT_NEAR(fresnel_conductor(1e-5f, 1.3f, 2.f), 1.f, 1e-3f);
    Color3f F = fresnel_conductor(0.5f, Color3f(0.2f, 1.f, 1.5f), Color3f(3.f, 2.f, 0.f));
    EXPECT_EQ(F.g, fresnel_conductor(0.5f, 1.f, 2.f));
    EXPECT_NEAR(F.b, fresnel_dielectric(0.5f, 1.5f).F, 1e-5f);
}

TEST(Fresnel, ReflectAndRefractAboutAMicronormal) {
    PCG32 rng(11);
    for (int i = 0; i < 1000; ++i) {
        Vector3f wi = warp::square_to_uniform_hemisphere(next_point2f(rng));
        Vector3f m = warp::square_to_uniform_hemisphere(next_point2f(rng));
        if (dot(wi, m) <= 1e-3f) continue;
        Vector3f r = reflect(wi, m);
        EXPECT_NEAR(norm(r), 1.f, 1e-5f);
        EXPECT_NEAR(dot(r, m), dot(wi, m), 1e-5f);
        EXPECT_NEAR(norm(normalize(wi + r) - m), 0.f, 1e-3f);

        auto [F, cos_t, eta_it, eta_ti] = fresnel_dielectric(dot(wi, m), 1.5f);
        Vector3f t = refract(wi, m, cos_t, eta_ti);
        EXPECT_NEAR(norm(t), 1.f, 1e-4f);
        EXPECT_NEAR(dot(t, m), cos_t, 1e-5f);
        // Snell about m: sin θt = sin θi / η, measured against the micronormal.
        float sin_i = std::sqrt(std::max(0.f, 1.f - sqr(dot(wi, m))));
        float sin_t = std::sqrt(std::max(0.f, 1.f - sqr(dot(t, m))));
        EXPECT_NEAR(sin_i, 1.5f * sin_t, 1e-4f);
    }
    EXPECT_EQ(reflect(Vector3f(0.3f, -0.4f, 0.5f)), Vector3f(-0.3f, 0.4f, 0.5f));
}

TEST(Fresnel, DiffuseReflectanceMatchesTheHemisphericalAverage) {
    // fdr(η) fits 2∫ F(μ, η) μ dμ; the fits are good to about 1 % (η ≥ 1) and 3 % (η < 1).
    for (float eta : {1.1f, 1.33f, 1.5f, 2.f, 1.f / 1.33f, 1.f / 1.5f}) {
        double sum = 0.0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            double mu = (i + 0.5) / n;
            sum += fresnel_dielectric(float(mu), eta).F * mu;
        }
        double average = 2.0 * sum / n;
        float tol = eta >= 1.f ? 0.01f : 0.03f;
        EXPECT_NEAR(fresnel_diffuse_reflectance(eta), average, tol * average) << "eta " << eta;
    }
}

TEST(IOR, NamedValuesAreCaseInsensitive) {
    EXPECT_FLOAT_EQ(lookup_ior("bk7"), 1.5046f);
    EXPECT_FLOAT_EQ(lookup_ior("BK7"), 1.5046f);
    EXPECT_FLOAT_EQ(lookup_ior("air"), 1.000277f);
    EXPECT_FLOAT_EQ(lookup_ior("Water Ice"), 1.31f);
    EXPECT_FLOAT_EQ(lookup_ior("diamond"), 2.419f);
    EXPECT_FLOAT_EQ(lookup_ior("polypropylene"), 1.49f);
    EXPECT_EQ(ior_table().size(), 23u);
}

TEST(IOR, UnknownNameListsTheValidOnes) {
    try {
        lookup_ior("diamnd");
        FAIL() << "expected an error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("diamnd"), std::string::npos) << msg;
        EXPECT_NE(msg.find("did you mean \"diamond\""), std::string::npos) << msg;
        EXPECT_NE(msg.find("bk7"), std::string::npos) << msg;
        EXPECT_NE(msg.find("carbon dioxide"), std::string::npos) << msg;
    }
}

TEST(IOR, ReadIORAcceptsNumbersAndNames) {
    Properties props("dielectric");
    props.set_float("int_ior", 1.7);
    props.set_string("ext_ior", "water");
    EXPECT_FLOAT_EQ(read_ior(props, "int_ior", "bk7"), 1.7f);
    EXPECT_FLOAT_EQ(read_ior(props, "ext_ior", "air"), 1.333f);
    EXPECT_FLOAT_EQ(read_ior(props, "other_ior", "pyrex"), 1.47f);
    EXPECT_TRUE(props.unqueried().empty());

    Properties negative("dielectric");
    negative.set_float("int_ior", -1.5);
    EXPECT_THROW(read_ior(negative, "int_ior", "bk7"), Error);
    Properties bad_name("dielectric");
    bad_name.set_string("int_ior", "unobtainium");
    try {
        read_ior(bad_name, "int_ior", "bk7");
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("int_ior"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("unobtainium"), std::string::npos) << e.what();
    }
}
