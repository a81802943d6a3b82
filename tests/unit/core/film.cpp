// Reconstruction filters, image blocks and the film: weights, radii, block accumulation, crop
// window checks and developing known samples.
#include <facet/film.h>
#include <facet/plugin.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numeric>

using namespace facet;

namespace {

std::shared_ptr<ReconstructionFilter> make_filter(const std::string &name, Properties props = {}) {
    props.set_plugin_name(name);
    return PluginRegistry::instance().create_as<ReconstructionFilter>(
        ObjectType::ReconstructionFilter, props);
}

std::shared_ptr<Film> make_film(Properties props) {
    props.set_plugin_name("hdrfilm");
    return PluginRegistry::instance().create_as<Film>(ObjectType::Film, props);
}

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "(no error)";
}

/// Weight stored at block pixel (x, y) of the storage (border included).
float block_weight(const ImageBlock &b, int x, int y) {
    const int nc = b.channel_count();
    return b.data()[(size_t(y) * b.storage_size().x + x) * nc + nc - 1];
}

} // namespace

TEST(Filters, BoxWeightsAndRadius) {
    auto box = make_filter("box");
    EXPECT_FLOAT_EQ(box->radius(), 0.5f);
    EXPECT_EQ(box->eval(0.f), 1.f);
    EXPECT_EQ(box->eval(0.49f), 1.f);
    EXPECT_EQ(box->eval(-0.5f), 1.f);
    EXPECT_EQ(box->eval(0.5f), 0.f); // half-open: a boundary sample belongs to one pixel
    EXPECT_EQ(box->eval(0.7f), 0.f);
    EXPECT_EQ(ImageBlock::border_for(*box), 1);
}

TEST(Filters, TentWeightsAndRadius) {
    auto tent = make_filter("tent");
    EXPECT_FLOAT_EQ(tent->radius(), 1.f);
    EXPECT_FLOAT_EQ(tent->eval(0.f), 1.f);
    EXPECT_FLOAT_EQ(tent->eval(0.25f), 0.75f);
    EXPECT_FLOAT_EQ(tent->eval(-0.5f), 0.5f);
    EXPECT_FLOAT_EQ(tent->eval(1.f), 0.f);
    EXPECT_FLOAT_EQ(tent->eval(1.5f), 0.f);

    Properties p;
    p.set_float("radius", 2.0);
    auto wide = make_filter("tent", p);
    EXPECT_FLOAT_EQ(wide->radius(), 2.f);
    EXPECT_FLOAT_EQ(wide->eval(1.f), 0.5f);
    EXPECT_EQ(ImageBlock::border_for(*wide), 2);

    Properties bad;
    bad.set_float("radius", -1.0);
    EXPECT_NE(error_of([&] { make_filter("tent", bad); }).find("radius"), std::string::npos);
}

TEST(Filters, GaussianWeightsAndRadius) {
    auto g = make_filter("gaussian");
    EXPECT_FLOAT_EQ(g->radius(), 2.f); // 4 standard deviations of 0.5
    const float bias = std::exp(-0.5f * 16.f);
    EXPECT_NEAR(g->eval(0.f), 1.f - bias, 1e-6f);
    EXPECT_NEAR(g->eval(0.5f), std::exp(-0.5f) - bias, 1e-6f);
    EXPECT_NEAR(g->eval(-1.f), std::exp(-2.f) - bias, 1e-6f);
    EXPECT_EQ(g->eval(2.f), 0.f);
    EXPECT_EQ(g->eval(3.f), 0.f);
    EXPECT_EQ(ImageBlock::border_for(*g), 2);

    Properties p;
    p.set_float("stddev", 0.25);
    auto narrow = make_filter("gaussian", p);
    EXPECT_FLOAT_EQ(narrow->radius(), 1.f);
    EXPECT_NEAR(narrow->eval(0.25f), std::exp(-0.5f) - std::exp(-8.f), 1e-6f);

    Properties bad;
    bad.set_float("stddev", 0.0);
    EXPECT_NE(error_of([&] { make_filter("gaussian", bad); }).find("stddev"), std::string::npos);
}

TEST(ImageBlock, BoxSampleLandsInOnePixel) {
    auto box = make_filter("box");
    ImageBlock block;
    block.reset({10, 20}, {4, 4}, ImageBlock::border_for(*box));
    ASSERT_EQ(block.channel_count(), 4);
    ASSERT_EQ(block.storage_size(), Point2i(6, 6));
    // Film pixel (12, 21) is storage pixel (12 - 10 + 1, 21 - 20 + 1) = (3, 2).
    block.put({12.3f, 21.9f}, Color3f(1.f, 2.f, 3.f), *box);
    // A sample exactly on the left/top edge of a pixel belongs to that pixel.
    block.put({11.0f, 20.0f}, Color3f(4.f), *box);
    float total = 0.f;
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 6; ++x) total += block_weight(block, x, y);
    EXPECT_EQ(total, 2.f);
    EXPECT_EQ(block_weight(block, 3, 2), 1.f);
    EXPECT_EQ(block_weight(block, 2, 1), 1.f);
    const float *p = block.data().data() + (2 * 6 + 3) * 4;
    EXPECT_EQ(p[0], 1.f);
    EXPECT_EQ(p[1], 2.f);
    EXPECT_EQ(p[2], 3.f);
}

/// A user's filter with the box's weights, not made by the plugin registry.
class UserBox final : public ReconstructionFilter {
public:
    float eval(float x) const override { return (x >= -0.5f && x < 0.5f) ? 1.f : 0.f; }
    std::string to_string() const override { return "UserBox"; }
};

TEST(ImageBlock, BoxPutsEverySampleIntoTheOnePixelOfItsHalfOpenFootprint) {
    // put() sends a sample of a filter with weight 1 on [-1/2, 1/2) straight to the pixel it
    // lies in; it must agree bit for bit with the footprint rule, here written out: the weight
    // of storage pixel i is 1 when the offset (pos - 0.5) - (its film pixel) is in
    // [-0.5, 0.5). Checked on pixel edges, just below them, at 0, at the block's edges (border
    // included), beyond the block, and past 2^23 (where pos - 0.5 is rounded, so the pixel is
    // no longer floor(pos)).
    // An out-of-tree filter with the same weights takes the same path.
    auto box = make_filter("box");
    const UserBox user_box;
    auto half_open = [](float x) { return (x >= -0.5f && x < 0.5f) ? 1.f : 0.f; };
    std::vector<float> coords = {0.f,         1e-30f,    0.25f,     0.5f,     3.f,
                                 4194303.75f, 4194304.f, 4194305.f, 8388609.f};
    for (int i = 6; i <= 30; ++i) {
        const float v = 0.25f * float(i);
        coords.push_back(v);
        coords.push_back(std::nextafter(v, 0.f));
        coords.push_back(std::nextafter(v, 100.f));
    }
    for (Point2i offset :
         {Point2i(0, 0), Point2i(3, 4), Point2i(4194300, 4194301), Point2i(8388609, 8388609)}) {
        std::vector<float> shifted;
        for (float c : coords) shifted.push_back(c + float(offset.x));
        ImageBlock fast, user;
        fast.reset(offset, {3, 3}, ImageBlock::border_for(*box));
        user.reset(offset, {3, 3}, ImageBlock::border_for(user_box));
        const Point2i s = fast.storage_size();
        const int nc = fast.channel_count();
        std::vector<float> expected(fast.data().size(), 0.f);
        float value = 1.f;
        for (float x : shifted)
            for (float y : shifted) {
                const Point2f pos(x, y + float(offset.y - offset.x));
                const Color3f L(value, 2.f * value, 0.5f);
                fast.put(pos, L, *box);
                user.put(pos, L, user_box);
                for (int j = 0; j < s.y; ++j)
                    for (int i = 0; i < s.x; ++i) {
                        const float w = half_open((pos.x - 0.5f) - float(offset.x - 1 + i)) *
                                        half_open((pos.y - 0.5f) - float(offset.y - 1 + j));
                        if (w == 0.f) continue;
                        float *p = expected.data() + (size_t(j) * size_t(s.x) + size_t(i)) * nc;
                        p[0] += w * L.r;
                        p[1] += w * L.g;
                        p[2] += w * L.b;
                        p[3] += w;
                    }
                value += 1.f;
            }
        float total = 0.f;
        for (size_t k = 0; k < fast.data().size(); ++k) {
            EXPECT_EQ(fast.data()[k], expected[k]) << "offset " << offset.x << ", " << k;
            EXPECT_EQ(user.data()[k], expected[k]) << "offset " << offset.x << ", " << k;
            total += fast.data()[k];
        }
        EXPECT_GT(total, 0.f) << "offset " << offset.x; // some samples landed
    }
}

TEST(ImageBlock, GaussianSpreadsSymmetricallyAndDevelopsToTheSample) {
    auto g = make_filter("gaussian");
    ImageBlock block;
    block.reset({0, 0}, {8, 8}, ImageBlock::border_for(*g));
    // A sample at the centre of film pixel (4, 4) = storage pixel (6, 6).
    block.put({4.5f, 4.5f}, Color3f(2.f, 1.f, 0.5f), *g);
    const float w0 = block_weight(block, 6, 6);
    EXPECT_NEAR(w0, g->weight(0.f) * g->weight(0.f), 1e-6f);
    // Separable weights, symmetric around the centre, reaching 1 pixel in each direction
    // (pixel centres 2 away sit on the radius and get zero).
    EXPECT_NEAR(block_weight(block, 7, 6), g->weight(1.f) * g->weight(0.f), 1e-6f);
    EXPECT_EQ(block_weight(block, 7, 6), block_weight(block, 5, 6));
    EXPECT_EQ(block_weight(block, 6, 7), block_weight(block, 6, 5));
    EXPECT_NEAR(block_weight(block, 7, 7), g->weight(1.f) * g->weight(1.f), 1e-6f);
    EXPECT_EQ(block_weight(block, 8, 6), 0.f);
    int touched = 0;
    for (int y = 0; y < block.storage_size().y; ++y)
        for (int x = 0; x < block.storage_size().x; ++x) touched += block_weight(block, x, y) > 0.f;
    EXPECT_EQ(touched, 9);

    // Developed, every touched pixel holds exactly the sample's value (Σ w·L / Σ w).
    Properties fp;
    fp.set_int("width", 8);
    fp.set_int("height", 8);
    auto film = make_film(fp);
    FilmBuffer buffer(film->crop_offset(), film->crop_size(), {});
    buffer.put_block(block);
    Image img = film->develop(buffer);
    ASSERT_EQ(img.channels, 3);
    for (int y = 3; y <= 5; ++y)
        for (int x = 3; x <= 5; ++x) {
            EXPECT_NEAR(img.at(x, y, 0), 2.f, 1e-6f);
            EXPECT_NEAR(img.at(x, y, 1), 1.f, 1e-6f);
            EXPECT_NEAR(img.at(x, y, 2), 0.5f, 1e-6f);
        }
    EXPECT_EQ(img.at(2, 4, 0), 0.f); // no weight -> 0
}

TEST(ImageBlock, OffCentreGaussianWeightsFollowTheFilter) {
    auto g = make_filter("gaussian");
    ImageBlock block;
    block.reset({0, 0}, {8, 8}, 2);
    block.put({3.2f, 5.9f}, Color3f(1.f), *g);
    // Film pixel (x, y) is storage (x + 2, y + 2); the filter argument is pos - centre.
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            float expected = g->weight(3.2f - (x + 0.5f)) * g->weight(5.9f - (y + 0.5f));
            EXPECT_NEAR(block_weight(block, x + 2, y + 2), expected, 1e-6f) << x << "," << y;
        }
}

TEST(ImageBlock, EveryFootprintAddsAsTheLoopOfBlocksWithAovs) {
    // put() of a block of r, g, b adds a footprint of up to 8 x 8 pixels its own way; a block
    // with an AOV takes the general loop. Their colour and weight channels must agree bit for
    // bit for every filter (the gaussian's 5 x 5, lanczos's 7 x 7, a tent of 9 x 9 beyond the
    // short way), at positions on and off pixel edges, across the block's edges and beyond
    // them, and NaN positions; then again after samples of an infinite colour (where a weight
    // is zero they must add nothing, not NaN).
    Properties wide;
    wide.set_float("radius", 4.2);
    Properties lobes;
    lobes.set_int("lobes", 3);
    const std::vector<std::shared_ptr<ReconstructionFilter>> filters = {
        make_filter("box"),       make_filter("tent"),       make_filter("gaussian"),
        make_filter("mitchell"),  make_filter("catmullrom"), make_filter("lanczos", lobes),
        make_filter("tent", wide)};
    uint32_t state = 12345u;
    auto next = [&state] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / 16777216.f;
    };
    for (const auto &filter : filters) {
        const int border = ImageBlock::border_for(*filter);
        ImageBlock plain, with_aov;
        plain.reset({16, 8}, {8, 6}, border);
        with_aov.reset({16, 8}, {8, 6}, border, 1);
        const size_t pixels = size_t(plain.storage_size().x) * size_t(plain.storage_size().y);
        ASSERT_EQ(pixels * 5, with_aov.data().size());
        auto put = [&](const Point2f &pos, const Color3f &L) {
            const float aov = next();
            plain.put(pos, L, *filter);
            with_aov.put(pos, L, &aov, *filter);
        };
        // Pixels whose four values differ, and pixels with weight.
        auto compare = [&](size_t &touched) {
            size_t differing = 0;
            touched = 0;
            for (size_t i = 0; i < pixels; ++i) {
                const float *a = plain.data().data() + 4 * i, *b = with_aov.data().data() + 5 * i;
                const float bs[4] = {b[0], b[1], b[2], b[4]};
                touched += a[3] != 0.f;
                differing += std::memcmp(a, bs, sizeof bs) != 0;
            }
            return differing;
        };
        for (int k = 0; k < 400; ++k)
            put({12.f + 16.f * next(), 4.f + 14.f * next()},
                Color3f(next(), 2.f * next(), 0.5f + next()));
        for (float x = 12.f; x <= 28.f; x += 0.5f) put({x, 11.f}, Color3f(0.25f, 0.5f, 1.f));
        put({std::nanf(""), 10.f}, Color3f(1.f));
        put({20.f, std::nanf("")}, Color3f(1.f));
        size_t touched = 0;
        EXPECT_EQ(compare(touched), 0u) << filter->to_string();
        EXPECT_GT(touched, pixels / 2) << filter->to_string();
        // At pixel centres: the pixels at ±radius (the tent's, the gaussian's) weigh zero.
        put({19.5f, 12.5f}, Color3f(INFINITY, 1.f, 2.f));
        put({21.5f, 10.5f}, Color3f(1.f, INFINITY, 2.f));
        EXPECT_EQ(compare(touched), 0u) << filter->to_string() << " (infinite colours)";
    }
}

TEST(ImageBlock, AOVChannels) {
    auto box = make_filter("box");
    ImageBlock block;
    block.reset({0, 0}, {2, 2}, 1, 2);
    EXPECT_EQ(block.channel_count(), 6);
    const float aovs[2] = {0.25f, 7.f};
    block.put({1.5f, 0.5f}, Color3f(1.f), aovs, *box);
    block.put({1.5f, 0.5f}, Color3f(3.f), aovs, *box);

    Properties fp;
    fp.set_int("width", 2);
    fp.set_int("height", 2);
    auto film = make_film(fp);
    FilmBuffer buffer(film->crop_offset(), film->crop_size(), {"albedo.R", "depth"});
    buffer.put_block(block);
    Image img = film->develop(buffer);
    ASSERT_EQ(img.channels, 5);
    EXPECT_EQ(img.channel_names, (std::vector<std::string>{"R", "G", "B", "albedo.R", "depth"}));
    EXPECT_FLOAT_EQ(img.at(1, 0, 0), 2.f);
    EXPECT_FLOAT_EQ(img.at(1, 0, 3), 0.25f);
    EXPECT_FLOAT_EQ(img.at(1, 0, 4), 7.f);
    EXPECT_EQ(img.at(0, 0, 4), 0.f);

    ImageBlock plain;
    plain.reset({0, 0}, {2, 2}, 1);
    EXPECT_THROW(buffer.put_block(plain), Error); // channel count mismatch
}

TEST(Film, Defaults) {
    auto film = make_film({});
    EXPECT_EQ(film->size(), Point2i(768, 576));
    EXPECT_EQ(film->crop_offset(), Point2i(0, 0));
    EXPECT_EQ(film->crop_size(), Point2i(768, 576));
    EXPECT_FLOAT_EQ(film->rfilter().radius(), 2.f); // gaussian
    EXPECT_TRUE(film->half());
    EXPECT_FALSE(film->has_alpha());
    EXPECT_EQ(film->default_extension(), ".exr");
}

TEST(Film, CropWindowValidation) {
    auto with = [](std::initializer_list<std::pair<const char *, int>> values) {
        Properties p;
        p.set_int("width", 100);
        p.set_int("height", 50);
        for (auto &[k, v] : values) p.set_int(k, v);
        return p;
    };
    auto film = make_film(with({{"crop_offset_x", 10}, {"crop_offset_y", 5}}));
    EXPECT_EQ(film->crop_offset(), Point2i(10, 5));
    EXPECT_EQ(film->crop_size(), Point2i(90, 45)); // the rest of the film
    film = make_film(with({{"crop_offset_x", 10}, {"crop_width", 20}, {"crop_height", 50}}));
    EXPECT_EQ(film->crop_size(), Point2i(20, 50));

    EXPECT_NE(error_of([&] {
                  make_film(with({{"crop_offset_x", 90}, {"crop_width", 20}}));
              }).find("crop window"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  make_film(with({{"crop_height", 51}}));
              }).find("inside the 100x50 film"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  make_film(with({{"crop_offset_y", -1}}));
              }).find("crop offset"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  make_film(with({{"crop_offset_x", 100}}));
              }).find("crop offset"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  make_film(with({{"crop_width", 0}}));
              }).find("crop window"),
              std::string::npos);
    EXPECT_NE(error_of([&] { make_film(with({{"width", 0}})); }).find("width"), std::string::npos);
}

TEST(Film, PutBlockKeepsOnlyTheCropWindow) {
    Properties p;
    p.set_int("width", 8);
    p.set_int("height", 8);
    p.set_int("crop_offset_x", 2);
    p.set_int("crop_offset_y", 3);
    p.set_int("crop_width", 4);
    p.set_int("crop_height", 2);
    auto film = make_film(p);
    auto box = make_filter("box");
    FilmBuffer buffer(film->crop_offset(), film->crop_size(), {});
    ImageBlock block;
    block.reset({2, 3}, {4, 2}, 1);
    // Inside the crop: pixel (3, 4) -> crop pixel (1, 1).
    block.put({3.5f, 4.5f}, Color3f(1.f, 2.f, 3.f), *box);
    block.put({3.5f, 4.5f}, Color3f(3.f, 2.f, 1.f), *box);
    // In the border, outside the crop window: dropped.
    block.put({1.5f, 4.5f}, Color3f(100.f), *box);
    buffer.put_block(block);
    Image img = film->develop(buffer);
    ASSERT_EQ(img.width, 4);
    ASSERT_EQ(img.height, 2);
    EXPECT_FLOAT_EQ(img.at(1, 1, 0), 2.f);
    EXPECT_FLOAT_EQ(img.at(1, 1, 1), 2.f);
    EXPECT_FLOAT_EQ(img.at(1, 1, 2), 2.f);
    float sum = std::accumulate(img.data.begin(), img.data.end(), 0.f);
    EXPECT_FLOAT_EQ(sum, 6.f);
}

TEST(Film, DevelopKnownSamplesWithAlphaAndLuminance) {
    Properties p;
    p.set_int("width", 2);
    p.set_int("height", 1);
    p.set_string("pixel_format", "rgba");
    auto film = make_film(p);
    auto box = make_filter("box");
    FilmBuffer buffer(film->crop_offset(), film->crop_size(), {});
    ImageBlock block;
    block.reset({0, 0}, {2, 1}, 1);
    block.put({0.2f, 0.5f}, Color3f(1.f, 0.f, 0.f), *box);
    block.put({0.7f, 0.1f}, Color3f(0.f, 1.f, 0.f), *box);
    block.put({0.9f, 0.9f}, Color3f(0.f, 0.f, 4.f), *box);
    buffer.put_block(block);
    Image img = film->develop(buffer);
    ASSERT_EQ(img.channels, 4);
    EXPECT_EQ(img.channel_names[3], "A");
    EXPECT_FLOAT_EQ(img.at(0, 0, 0), 1.f / 3.f);
    EXPECT_FLOAT_EQ(img.at(0, 0, 1), 1.f / 3.f);
    EXPECT_FLOAT_EQ(img.at(0, 0, 2), 4.f / 3.f);
    EXPECT_EQ(img.at(0, 0, 3), 1.f);
    EXPECT_EQ(img.at(1, 0, 3), 0.f); // no samples: alpha 0
    EXPECT_EQ(img.at(1, 0, 0), 0.f);

    p = Properties();
    p.set_int("width", 1);
    p.set_int("height", 1);
    p.set_string("pixel_format", "luminance");
    film = make_film(p);
    FilmBuffer one(film->crop_offset(), film->crop_size(), {});
    block.reset({0, 0}, {1, 1}, 1);
    block.put({0.5f, 0.5f}, Color3f(1.f, 0.5f, 0.25f), *box);
    one.put_block(block);
    img = film->develop(one);
    ASSERT_EQ(img.channels, 1);
    EXPECT_EQ(img.channel_names[0], "Y");
    EXPECT_NEAR(img.at(0, 0, 0), Color3f(1.f, 0.5f, 0.25f).luminance(), 1e-6f);
}

TEST(Film, HdrfilmFormatsAndErrors) {
    Properties p;
    p.set_string("component_format", "float32");
    p.set_string("file_format", "pfm");
    auto film = make_film(p);
    EXPECT_FALSE(film->half());
    EXPECT_EQ(film->default_extension(), ".pfm");

    Properties bad;
    bad.set_string("pixel_format", "cmyk");
    std::string e = error_of([&] { make_film(bad); });
    EXPECT_NE(e.find("rgb, rgba, luminance"), std::string::npos) << e;
    Properties bad2;
    bad2.set_string("component_format", "uint32");
    EXPECT_NE(error_of([&] { make_film(bad2); }).find("float16 or float32"), std::string::npos);
    Properties bad3;
    bad3.set_string("file_format", "tiff");
    EXPECT_NE(error_of([&] { make_film(bad3); }).find("openexr"), std::string::npos);
}

TEST(Film, SplatsKeepTheirEnergyAndAreScaledNotNormalised) {
    // A light tracer's splats: the filter footprint sums to one, the weight channel is left
    // alone, and develop() multiplies by the splat scale instead of dividing by weights.
    auto g = make_filter("gaussian");
    Properties fp;
    fp.set_int("width", 8);
    fp.set_int("height", 8);
    auto film = make_film(fp);
    FilmBuffer buffer(film->crop_offset(), film->crop_size(), {}, /*splats=*/true);
    ImageBlock block;
    block.reset({0, 0}, {8, 8}, ImageBlock::border_for(*g));
    block.splat({4.3f, 3.8f}, Color3f(2.f, 1.f, 0.5f), *g);
    block.splat({1.5f, 1.5f}, Color3f(4.f, 0.f, 0.f), *g);
    for (int y = 0; y < block.storage_size().y; ++y)
        for (int x = 0; x < block.storage_size().x; ++x) EXPECT_EQ(block_weight(block, x, y), 0.f);
    buffer.put_splats(block);
    buffer.set_splat_scale(0.25);
    Image img = film->develop(buffer);
    double red = 0.0, green = 0.0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            red += img.at(x, y, 0);
            green += img.at(x, y, 1);
        }
    EXPECT_NEAR(red, 0.25 * (2.0 + 4.0), 1e-5);
    EXPECT_NEAR(green, 0.25 * 1.0, 1e-5);
    EXPECT_GT(img.at(4, 3, 1), img.at(5, 4, 1)); // most of it in the pixel it landed in
    EXPECT_EQ(img.at(7, 7, 0), 0.f);

    // Splats add to what the weighted samples develop to.
    ImageBlock samples;
    samples.reset({0, 0}, {8, 8}, ImageBlock::border_for(*g));
    samples.put({6.5f, 6.5f}, Color3f(1.f), *g);
    buffer.put_block(samples);
    Image both = film->develop(buffer);
    EXPECT_NEAR(both.at(6, 6, 0), 1.f + img.at(6, 6, 0), 1e-6f);
    EXPECT_NEAR(both.at(4, 3, 1), img.at(4, 3, 1), 1e-6f);
    // A buffer without a splat buffer refuses splats; a new buffer starts at zero.
    FilmBuffer plain(film->crop_offset(), film->crop_size(), {});
    EXPECT_THROW(plain.put_splats(block), Error);
    EXPECT_EQ(film->develop(plain).at(4, 3, 1), 0.f);
}

// The raw channels of a part (its sums, rounded to float) developed again after being added up
// give what the buffer develops to; a window outside the film and a huge buffer are refused.
TEST(FilmBuffer, RawSumsRoundTripAndLimits) {
    auto g = make_filter("gaussian");
    Properties fp;
    fp.set_int("width", 8);
    fp.set_int("height", 6);
    auto film = make_film(fp);
    FilmBuffer buffer({2, 1}, {5, 4}, {"depth"}, /*splats=*/true);
    ImageBlock block;
    block.reset({0, 0}, {8, 6}, ImageBlock::border_for(*g), 1);
    const float depth = 3.f;
    block.put({3.25f, 2.5f}, Color3f(1.f, 2.f, 4.f), &depth, *g);
    buffer.put_block(block);
    ImageBlock splats;
    splats.reset({0, 0}, {8, 6}, ImageBlock::border_for(*g));
    splats.splat({4.5f, 3.5f}, Color3f(8.f), *g);
    buffer.put_splats(splats);
    EXPECT_EQ(buffer.raw_channel_names(),
              (std::vector<std::string>{"facet.sum.R", "facet.sum.G", "facet.sum.B",
                                        "facet.sum.depth", "facet.weight", "facet.splat.R",
                                        "facet.splat.G", "facet.splat.B"}));
    const std::vector<float> raw = buffer.raw_sums();
    ASSERT_EQ(raw.size(), size_t(5 * 4 * 8));
    FilmBuffer again({2, 1}, {5, 4}, {"depth"}, true);
    again.set_raw_sums(std::vector<double>(raw.begin(), raw.end()));
    const Image a = film->develop(buffer), b = film->develop(again);
    ASSERT_EQ(a.data.size(), b.data.size());
    for (size_t i = 0; i < a.data.size(); ++i) EXPECT_NEAR(a.data[i], b.data[i], 1e-6f) << i;
    EXPECT_EQ(a.x, 2);
    EXPECT_EQ(a.y, 1);
    EXPECT_EQ(a.full_width, 8);
    EXPECT_THROW(again.set_raw_sums({1.0, 2.0}), Error);
    EXPECT_THROW(film->check_crop_window({4, 0}, {5, 1}), Error);
    EXPECT_THROW(film->check_crop_window({0, 0}, {0, 1}), Error);
    EXPECT_NO_THROW(film->check_crop_window({7, 5}, {1, 1}));
    EXPECT_THROW(FilmBuffer({0, 0}, {1 << 20, 1 << 20}, {}), Error); // beyond the 8 GiB budget
}
