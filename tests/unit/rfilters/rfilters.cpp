// The cubic and windowed-sinc reconstruction filters (mitchell, catmullrom, lanczos): values at
// known points, the film's tabulation of every filter (as Mitsuba's), radii, normalisation,
// parameters, and how the film treats their negative lobes; every filter's parameter ranges and
// weight checks.
#include <facet/film.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

using namespace facet;

namespace {

std::shared_ptr<ReconstructionFilter> make_filter(const std::string &name, Properties props = {}) {
    props.set_plugin_name(name);
    return PluginRegistry::instance().create_as<ReconstructionFilter>(
        ObjectType::ReconstructionFilter, props);
}

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "(no error)";
}

/// ∫ f over [-r, r] by the composite Simpson rule on a fine grid.
double integral(const std::function<double(double)> &f, double r) {
    const int n = 200000;
    const double h = 2.0 * r / n;
    double sum = f(-r) + f(r);
    for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * f(-r + i * h);
    return sum * h / 3.0;
}

/// Mitchell–Netravali cubic of the paper, evaluated in double from its piecewise form.
double mn_reference(double x, double b, double c) {
    x = std::abs(x);
    if (x < 1.0)
        return ((12 - 9 * b - 6 * c) * x * x * x + (-18 + 12 * b + 6 * c) * x * x + (6 - 2 * b)) /
               6.0;
    if (x < 2.0)
        return ((-b - 6 * c) * x * x * x + (6 * b + 30 * c) * x * x + (-12 * b - 48 * c) * x +
                (8 * b + 24 * c)) /
               6.0;
    return 0.0;
}

double lanczos_reference(double x, double lobes) {
    x = std::abs(x);
    if (x == 0.0) return 1.0;
    if (x >= lobes) return 0.0;
    const double a = M_PI * x;
    return std::sin(a) * std::sin(a / lobes) / (a * a / lobes);
}

/// What Mitsuba's scalar image block applies: the exact filter at the left end of the table
/// interval (31 intervals over the radius) that holds |x|.
double tabulated(const std::function<double(double)> &exact, double r, double x) {
    const double s = std::abs(x) * 31.0 / r;
    if (s >= 31.0) return 0.0;
    return exact(r * std::floor(s) / 31.0);
}

/// Checks the weight the film applies against the tabulated reference over [-1.2 r, 1.2 r]: in the
/// middle of every table interval and on a sweep (points within rounding of an interval end are
/// skipped).
void expect_tabulates(const ReconstructionFilter &f, const std::function<double(double)> &exact) {
    const double r = f.radius();
    for (int i = -37; i < 37; ++i) {
        const double mid = r * (i + 0.5) / 31.0;
        EXPECT_NEAR(f.weight(float(mid)), tabulated(exact, r, mid), 2e-6)
            << f.to_string() << " " << mid;
    }
    for (double x = -1.2 * r; x <= 1.2 * r; x += 0.0137) {
        const double s = std::abs(x) * 31.0 / r;
        if (std::abs(s - std::round(s)) < 1e-3) continue;
        EXPECT_NEAR(f.weight(float(x)), tabulated(exact, r, x), 2e-6) << f.to_string() << " " << x;
    }
}

} // namespace

TEST(Filters, MitchellValuesAndRadius) {
    auto f = make_filter("mitchell");
    EXPECT_FLOAT_EQ(f->radius(), 2.f);
    EXPECT_EQ(ImageBlock::border_for(*f), 2);
    const double third = 1.0 / 3.0;
    // B = C = 1/3: k(0) = (6 - 2B)/6 = 8/9, k(1) = B/6 = 1/18, k(1.5) = -5/144 (by hand).
    EXPECT_NEAR(mn_reference(1.0, third, third), 1.0 / 18.0, 1e-12);
    EXPECT_NEAR(mn_reference(1.5, third, third), -5.0 / 144.0, 1e-12);
    EXPECT_NEAR(f->eval(0.f), 8.0 / 9.0, 1e-6);
    EXPECT_LT(f->eval(1.5f), 0.f); // the negative lobe
    EXPECT_EQ(f->eval(2.f), 0.f);
    EXPECT_EQ(f->eval(-2.5f), 0.f);
    expect_tabulates(*f, [&](double x) { return mn_reference(x, third, third); });
}

TEST(Filters, MitchellParameters) {
    Properties p;
    p.set_float("B", 1.0);
    p.set_float("C", 0.0);
    auto bspline = make_filter("mitchell", p); // the cubic B-spline: k(0) = 2/3, no negative lobe
    EXPECT_NEAR(bspline->eval(0.f), 2.0 / 3.0, 1e-6);
    EXPECT_GE(bspline->eval(1.5f), 0.f);
    expect_tabulates(*bspline, [](double x) { return mn_reference(x, 1.0, 0.0); });

    // A NaN parameter does not reach the plugin: Properties refuses it (the plugin's own check
    // guards the range).
    Properties bad;
    EXPECT_NE(error_of([&] { bad.set_float("B", std::nan("")); }).find("\"B\" contains NaN"),
              std::string::npos);
}

TEST(Filters, CatmullRomValuesAndRadius) {
    auto f = make_filter("catmullrom");
    EXPECT_FLOAT_EQ(f->radius(), 2.f);
    EXPECT_EQ(ImageBlock::border_for(*f), 2);
    // An interpolating cubic: 1 at 0 and 0 at the other integers; k(0.5) = 0.5625 and
    // k(1.5) = -0.0625 by hand.
    EXPECT_NEAR(mn_reference(0.5, 0.0, 0.5), 0.5625, 1e-12);
    EXPECT_NEAR(mn_reference(1.5, 0.0, 0.5), -0.0625, 1e-12);
    EXPECT_NEAR(mn_reference(1.0, 0.0, 0.5), 0.0, 1e-12);
    EXPECT_FLOAT_EQ(f->eval(0.f), 1.f);
    EXPECT_LT(f->eval(1.5f), 0.f);
    EXPECT_EQ(f->eval(2.f), 0.f);
    expect_tabulates(*f, [](double x) { return mn_reference(x, 0.0, 0.5); });
}

TEST(Filters, LanczosValuesAndRadius) {
    auto f = make_filter("lanczos");
    EXPECT_FLOAT_EQ(f->radius(), 3.f);
    EXPECT_EQ(ImageBlock::border_for(*f), 3);
    EXPECT_FLOAT_EQ(f->eval(0.f), 1.f);
    // sinc(x)·sinc(x/3): zero at the integers, 6/π² at 1/2.
    EXPECT_NEAR(lanczos_reference(0.5, 3.0), 6.0 / (M_PI * M_PI), 1e-12);
    EXPECT_NEAR(lanczos_reference(2.0, 3.0), 0.0, 1e-12);
    EXPECT_LT(f->eval(1.3f), 0.f); // first negative lobe
    EXPECT_EQ(f->eval(3.f), 0.f);
    EXPECT_EQ(f->eval(4.f), 0.f);
    expect_tabulates(*f, [](double x) { return lanczos_reference(x, 3.0); });

    Properties p;
    p.set_int("lobes", 2);
    auto two = make_filter("lanczos", p);
    EXPECT_FLOAT_EQ(two->radius(), 2.f);
    EXPECT_EQ(two->eval(2.5f), 0.f);
    expect_tabulates(*two, [](double x) { return lanczos_reference(x, 2.0); });

    Properties bad;
    bad.set_int("lobes", 0);
    EXPECT_NE(error_of([&] { make_filter("lanczos", bad); }).find("lobes"), std::string::npos);
}

TEST(Filters, EveryFilterIsAppliedThroughTheSameTable) {
    // The film tabulates every filter's eval() alike, the smooth ones too.
    auto g = make_filter("gaussian");
    expect_tabulates(*g, [](double x) {
        return std::max(0.0, std::exp(-2.0 * x * x) - std::exp(-8.0)); // stddev 0.5, radius 2
    });
    Properties p;
    p.set_float("radius", 1.5);
    auto tent = make_filter("tent", p);
    expect_tabulates(*tent, [](double x) { return std::max(0.0, 1.0 - std::abs(x) / 1.5); });
    // eval() itself at exactly -radius and radius: the box keeps its half-open support, so a
    // sample on a pixel edge counts for exactly one pixel.
    auto box = make_filter("box");
    EXPECT_EQ(box->weight(-0.5f), 1.f);
    EXPECT_EQ(box->weight(0.5f), 0.f);
    EXPECT_EQ(box->weight(std::nextafter(0.5f, 0.f)), 1.f);
    EXPECT_EQ(box->weight(std::nextafter(-0.5f, -1.f)), 0.f);
    EXPECT_EQ(box->weight(std::nanf("")), 0.f);
    EXPECT_EQ(g->weight(-2.f), 0.f);
}

TEST(Filters, IntegralNormalisation) {
    // The exact functions the tables hold: every Mitchell–Netravali cubic has unit integral and
    // sums to one over unit-spaced pixels; the Lanczos window comes close.
    for (auto bc : {std::pair{1.0 / 3.0, 1.0 / 3.0}, std::pair{0.0, 0.5}, std::pair{0.2, 0.6}}) {
        auto k = [bc](double x) { return mn_reference(x, bc.first, bc.second); };
        EXPECT_NEAR(integral(k, 2.0), 1.0, 1e-9);
        for (double x = -0.5; x <= 0.5; x += 0.05) {
            double sum = 0.0;
            for (int j = -3; j <= 3; ++j) sum += k(x + j);
            EXPECT_NEAR(sum, 1.0, 1e-12) << x;
        }
    }
    EXPECT_NEAR(integral([](double x) { return lanczos_reference(x, 3.0); }, 3.0), 1.0, 0.01);

    // The tabulated filters integrate to the left Riemann sum of their table, a little above one
    // (the film divides by the summed weights, so the scale does not matter).
    for (auto f : {make_filter("mitchell"), make_filter("catmullrom"), make_filter("lanczos")}) {
        const double r = f->radius(), h = r / 31.0;
        double riemann = 0.0;
        for (int i = 0; i < 31; ++i) riemann += 2.0 * h * f->weight(float(r * (i + 0.5) / 31.0));
        const double numeric = integral([&](double x) { return f->weight(float(x)); }, r);
        EXPECT_NEAR(numeric, riemann, 1e-3) << f->to_string();
        // Left ends overestimate a falling filter by about h·k(0) over the unit integral.
        EXPECT_NEAR(riemann, 1.0 + h * f->eval(0.f), 0.015) << f->to_string();
    }
}

TEST(Filters, NegativeLobesAreSummedWithTheirSign) {
    // A sample half-way between pixel centres gives the pixels 1.5 away a negative Catmull-Rom
    // weight; the block keeps it with its sign, and the developed pixel is Σw·L / Σw, as in
    // Mitsuba (which divides by any non-zero weight sum).
    auto f = make_filter("catmullrom");
    ImageBlock block;
    block.reset({0, 0}, {8, 1}, ImageBlock::border_for(*f));
    block.put({4.f, 0.5f}, Color3f(2.f, 1.f, 0.5f), *f);
    const int nc = block.channel_count();
    auto weight = [&](int x) {
        const int sx = x + block.border(), sy = block.border();
        return block.data()[(size_t(sy) * block.storage_size().x + sx) * nc + nc - 1];
    };
    auto k = [](double x) {
        return tabulated([](double y) { return mn_reference(y, 0.0, 0.5); }, 2.0, x);
    };
    EXPECT_NEAR(weight(3), k(0.5), 1e-6); // offset 0.5, times k(0) = 1 along y
    EXPECT_NEAR(weight(4), k(0.5), 1e-6);
    EXPECT_NEAR(weight(2), k(1.5), 1e-6); // offset 1.5: negative
    EXPECT_NEAR(weight(5), k(1.5), 1e-6);
    EXPECT_LT(weight(2), 0.f);
    EXPECT_EQ(weight(1), 0.f);

    Properties fp;
    fp.set_plugin_name("hdrfilm");
    fp.set_int("width", 8);
    fp.set_int("height", 1);
    fp.set_object("rfilter", f);
    auto film = PluginRegistry::instance().create_as<Film>(ObjectType::Film, fp);
    FilmBuffer buffer(film->crop_offset(), film->crop_size(), {});
    buffer.put_block(block);
    Image img = film->develop(buffer);
    for (int x : {2, 3, 4, 5}) {
        EXPECT_NEAR(img.at(x, 0, 0), 2.f, 1e-5f) << x;
        EXPECT_NEAR(img.at(x, 0, 2), 0.5f, 1e-5f) << x;
    }
    EXPECT_EQ(img.at(1, 0, 0), 0.f); // no weight at all
}

namespace {

/// A scene whose film uses `rfilter`: an 8 x 8 render of a lit diffuse sphere.
std::string filter_scene(const std::string &rfilter) {
    return R"(<scene version="3.0.0">
<integrator type="path"><integer name="max_depth" value="3"/></integrator>
<sensor type="perspective">
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
)" + rfilter +
           R"(
    </film>
</sensor>
<emitter type="constant"><rgb name="radiance" value="1"/></emitter>
<shape type="sphere"><bsdf type="diffuse"/></shape>
</scene>)";
}

} // namespace

TEST(Filters, ParametersOutsideTheirRangeAreLocatedErrors) {
    // B = 1e30 used to load and give an all-NaN image (weights whose products overflow).
    const std::pair<const char *, const char *> cases[] = {
        {R"(<rfilter type="mitchell"><float name="B" value="1e30"/></rfilter>)",
         "B must be a number in [-2, 2], got 1e+30"},
        {R"(<rfilter type="mitchell"><float name="C" value="-3"/></rfilter>)",
         "C must be a number in [-2, 2], got -3"},
        {R"(<rfilter type="tent"><float name="radius" value="1e-30"/></rfilter>)",
         "radius must be a number of pixels in [0.015625, 64]"},
        {R"(<rfilter type="gaussian"><float name="stddev" value="0.001"/></rfilter>)",
         "stddev must be a number of pixels in [0.00390625, 16]"},
        {R"(<rfilter type="lanczos"><integer name="lobes" value="65"/></rfilter>)",
         "lobes must be a whole number between 1 and 64"},
    };
    for (const auto &[rfilter, message] : cases) {
        const std::string scene = filter_scene(rfilter); // (C++17 lambdas capture no bindings)
        std::string error = error_of([&] { load_string(scene); });
        EXPECT_NE(error.find(message), std::string::npos) << error;
        // Located at the parameter, on line 7 of the scene.
        EXPECT_EQ(error.rfind("string:7:", 0), 0u) << error;
    }
}

TEST(Filters, ExtremeLegalValuesGiveFiniteImages) {
    std::vector<std::string> filters = {
        R"(<rfilter type="box"/>)",
        R"(<rfilter type="catmullrom"/>)",
        R"(<rfilter type="gaussian"><float name="stddev" value="0.00390625"/></rfilter>)",
        R"(<rfilter type="gaussian"><float name="stddev" value="16"/></rfilter>)",
        R"(<rfilter type="tent"><float name="radius" value="0.015625"/></rfilter>)",
        R"(<rfilter type="tent"><float name="radius" value="64"/></rfilter>)",
        R"(<rfilter type="lanczos"><integer name="lobes" value="1"/></rfilter>)",
        R"(<rfilter type="lanczos"><integer name="lobes" value="64"/></rfilter>)",
    };
    for (const char *b : {"-2", "2"})
        for (const char *c : {"-2", "2"})
            filters.push_back(fmt::format(
                R"(<rfilter type="mitchell"><float name="B" value="{}"/><float name="C" value="{}"/></rfilter>)",
                b, c));
    for (const std::string &rfilter : filters) {
        auto scene = std::dynamic_pointer_cast<Scene>(load_string(filter_scene(rfilter)));
        ASSERT_TRUE(scene) << rfilter;
        RenderOptions opts;
        opts.threads = 1;
        opts.progress = false;
        Image img = render(*scene, *scene->sensors().at(0), opts).image;
        ASSERT_EQ(img.width, 8) << rfilter;
        for (float v : img.data) ASSERT_TRUE(std::isfinite(v)) << rfilter;
    }
}

namespace {

/// An out-of-tree filter whose weight is `value` everywhere: its constructor checks its weights
/// as every filter does.
class ConstantFilter final : public ReconstructionFilter {
public:
    ConstantFilter(const Properties &props, float value) : m_value(value) {
        m_radius = 1.f;
        check_weights(props);
    }
    float eval(float) const override { return m_value; }

private:
    float m_value;
};

} // namespace

TEST(Filters, WeightsMustBeFiniteBoundedAndSumToMoreThanZero) {
    Properties props;
    props.set_location(Location{"scene.xml", 12, 5});
    EXPECT_NO_THROW(ConstantFilter(props, 1.f));
    EXPECT_NO_THROW(ConstantFilter(props, MaxFilterWeight));
    for (float bad : {std::nanf(""), INFINITY, 2.f * MaxFilterWeight, 0.f, -1.f}) {
        std::string error = error_of([&] { ConstantFilter(props, bad); });
        EXPECT_EQ(error.rfind("scene.xml:12:5: ", 0), 0u) << bad << ": " << error;
        EXPECT_NE(error.find(bad > 0.f || !(bad <= 0.f) ? "within +-1000" : "sum to"),
                  std::string::npos)
            << bad << ": " << error;
    }
}
