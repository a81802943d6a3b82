// The chi-square heat map (write_chi2_heatmap): its size and layout, the centring of the panels
// on the mirror azimuth (a rotation of the columns for display, which leaves the statistics
// alone), and that it carries text.

#include <facet/chi2.h>
#include <facet/image.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

using namespace facet;
namespace fs = std::filesystem;

namespace {

/// A glossy lobe around the mirror direction of wi = (45°, φ = 30°): it peaks at φ = 210°.
BSDFAdapter glossy_adapter() {
    return BSDFAdapter(
        chi2_object_xml(ObjectType::BSDF, "roughconductor", {"distribution=ggx", "alpha=0.15"}),
        direction_from_angles(45.f, 30.f));
}

Chi2Options small_options() {
    Chi2Options opts;
    opts.res = 16;
    opts.samples = 200000;
    return opts;
}

/// The same routine, with another picture centre.
class RecentredAdapter final : public Chi2Adapter {
public:
    RecentredAdapter(const Chi2Adapter &inner, double center) : m_inner(inner), m_center(center) {}
    int sample_dim() const override { return m_inner.sample_dim(); }
    Chi2Sample sample(const float *u) const override { return m_inner.sample(u); }
    double pdf(const Vector3f &d) const override { return m_inner.pdf(d); }
    bool bounded_weights() const override { return m_inner.bounded_weights(); }
    double plot_phi_center() const override { return m_center; }
    std::string to_string() const override { return m_inner.to_string(); }

private:
    const Chi2Adapter &m_inner;
    double m_center;
};

fs::path scratch(const std::string &name) {
    fs::path dir = fs::temp_directory_path() / "facet_chi2_plot";
    fs::create_directories(dir);
    return dir / name;
}

float luminance(const Image &img, int x, int y) {
    return img.at(x, y, 0) + img.at(x, y, 1) + img.at(x, y, 2);
}

} // namespace

TEST(Chi2Heatmap, CentresOnTheMirrorAzimuth) {
    BSDFAdapter adapter = glossy_adapter();
    EXPECT_NEAR(adapter.plot_phi_center(), (30.0 + 180.0) * M_PI / 180.0, 1e-5);
    Chi2Result r = run_chi2(adapter, small_options());
    ASSERT_TRUE(r.passed) << r.summary();
    Chi2HeatmapLayout l = chi2_heatmap_layout(r);

    // The histogram's own peak column lies near φ = 210° = -150°, far from the middle of -π..π.
    std::vector<double> column(r.phi_res, 0.0);
    for (int jc = 0; jc < r.cos_res; ++jc)
        for (int ip = 0; ip < r.phi_res; ++ip)
            column[ip] += r.observed[size_t(jc) * r.phi_res + ip];
    int peak = int(std::max_element(column.begin(), column.end()) - column.begin());
    EXPECT_GT(std::abs(peak - r.phi_res / 2), r.phi_res / 4) << "peak column " << peak;
    int displayed = ((peak - l.column_shift) % r.phi_res + r.phi_res) % r.phi_res;
    EXPECT_LE(std::abs(displayed + 0.5 - r.phi_res / 2.0), 1.5) << "displayed at " << displayed;

    // In the picture, the brightest column of the observed panel is in the middle.
    fs::path png = scratch("glossy.png");
    write_chi2_heatmap(png.string(), r);
    Image img = read_image(png.string());
    ASSERT_EQ(img.width, l.width);
    ASSERT_EQ(img.height, l.height);
    ASSERT_GE(img.channels, 3);
    EXPECT_EQ(l.panel_width, r.phi_res * l.cell);
    EXPECT_EQ(l.panel_height, r.cos_res * l.cell);
    EXPECT_GE(l.width, 3 * l.panel_width);
    int best = -1;
    float best_sum = -1.f;
    for (int c = 0; c < r.phi_res; ++c) {
        float sum = 0.f;
        int x = l.panel_x[0] + c * l.cell + l.cell / 2;
        for (int y = l.panel_y; y < l.panel_y + l.panel_height; ++y) sum += luminance(img, x, y);
        if (sum > best_sum) best_sum = sum, best = c;
    }
    EXPECT_LE(std::abs(best + 0.5 - r.phi_res / 2.0), 1.5) << "brightest column " << best;
}

TEST(Chi2Heatmap, CentringLeavesTheStatisticsAlone) {
    BSDFAdapter adapter = glossy_adapter();
    RecentredAdapter plain(adapter, 0.0);
    Chi2Result a = run_chi2(adapter, small_options()), b = run_chi2(plain, small_options());
    EXPECT_NE(a.phi_center, b.phi_center);
    EXPECT_EQ(a.statistic, b.statistic);
    EXPECT_EQ(a.dof, b.dof);
    EXPECT_EQ(a.p_value, b.p_value);
    EXPECT_EQ(a.observed, b.observed);
    EXPECT_EQ(a.expected, b.expected);
    EXPECT_EQ(a.passed, b.passed);
    // The two pictures show the same panels, their columns rotated by the shift difference.
    Chi2HeatmapLayout la = chi2_heatmap_layout(a), lb = chi2_heatmap_layout(b);
    EXPECT_EQ(lb.column_shift, 0);
    EXPECT_NE(la.column_shift, 0);
    fs::path pa = scratch("a.png"), pb = scratch("b.png");
    write_chi2_heatmap(pa.string(), a);
    write_chi2_heatmap(pb.string(), b);
    Image ia = read_image(pa.string()), ib = read_image(pb.string());
    ASSERT_EQ(ia.width, ib.width);
    ASSERT_EQ(ia.height, ib.height);
    for (int p = 0; p < 3; ++p)
        for (int jc = 0; jc < a.cos_res; ++jc)
            for (int c = 0; c < a.phi_res; ++c) {
                int cb = (c + la.column_shift) % a.phi_res; // the same histogram column in b
                int y = la.panel_y + jc * la.cell + la.cell / 2;
                int xa = la.panel_x[p] + c * la.cell + la.cell / 2;
                int xb = lb.panel_x[p] + cb * lb.cell + lb.cell / 2;
                for (int k = 0; k < 3; ++k)
                    ASSERT_EQ(ia.at(xa, y, k), ib.at(xb, y, k))
                        << "panel " << p << " row " << jc << " column " << c;
            }
}

TEST(Chi2Heatmap, HasATitleAxesAndScales) {
    BSDFAdapter adapter = glossy_adapter();
    Chi2Result r = run_chi2(adapter, small_options());
    r.description += ", θ and φ are not ASCII"; // drawn as '?', not an error
    Chi2HeatmapLayout l = chi2_heatmap_layout(r);
    fs::path png = scratch("text.png");
    write_chi2_heatmap(png.string(), r);
    Image img = read_image(png.string());
    ASSERT_EQ(img.width, l.width);
    ASSERT_EQ(img.height, l.height);
    // Count the pixels that differ from the background in a band of the picture.
    float background = luminance(img, 0, 0);
    auto inked = [&](int x0, int y0, int x1, int y1) {
        int n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) n += std::abs(luminance(img, x, y) - background) > 0.1f;
        return n;
    };
    EXPECT_GE(l.title_lines, 1);
    EXPECT_GT(inked(0, 0, l.width, l.panel_y - 1), 500) << "no title";
    EXPECT_GT(inked(0, l.panel_y, l.panel_x[0] - 1, l.panel_y + l.panel_height), 50)
        << "no theta labels";
    EXPECT_GT(
        inked(l.panel_x[0], l.panel_y + l.panel_height + 1, l.panel_x[0] + l.panel_width, l.bar_y),
        100)
        << "no phi labels";
    EXPECT_GT(inked(0, l.bar_y + 20, l.width, l.height), 500) << "no colour-scale labels";
    // The colour scale of the difference runs from blue through white to red.
    int mid_y = l.bar_y + 7, x2 = l.panel_x[2];
    EXPECT_GT(img.at(x2 + 2, mid_y, 2), img.at(x2 + 2, mid_y, 0));
    EXPECT_GT(img.at(x2 + l.panel_width - 3, mid_y, 0), img.at(x2 + l.panel_width - 3, mid_y, 2));
    EXPECT_THROW(chi2_heatmap_layout(Chi2Result()), Error);
}
