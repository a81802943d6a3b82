// Parts of one render: crop windows (bit-identical to the same pixels of the whole film, EXR data
// window inside the display window) and independent sample passes (--pass I --passes N) that
// merge by their raw sums (Σ w·L, Σ w) into the render of all their samples, bit-identical to
// the render of all the passes in one process for every reconstruction filter, crop split and
// integrator (path, aov, ptracer).
#include <facet/film.h>
#include <facet/image.h>
#include <facet/merge.h>
#include <facet/output_metadata.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
    fs::path dir = fs::temp_directory_path() / fmt::format("facet-parts-{}", ::getpid());
    fs::create_directories(dir);
    return dir;
}

std::shared_ptr<Scene> load_temp_scene(const std::string &xml,
                                       const std::string &mode = "scalar_rgb") {
    fs::path file = temp_dir() / "scene.xml";
    std::ofstream(file) << xml;
    LoadOptions lo;
    lo.mode = mode;
    return load_scene(file.string(), lo);
}

/// A sphere on a plane under a sky and a point light; `film_extra` goes inside the film.
std::string
scene_xml(const std::string &sampler, int spp, const std::string &film_extra, int width = 29,
          int height = 21,
          const std::string &integrator =
              R"(<integrator type="path"><integer name="max_depth" value="5"/></integrator>)") {
    return fmt::format(R"(<scene version="3.0.0">
    {integrator}
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 1.5, 5" target="0, 0.3, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="{sampler}">
            <integer name="sample_count" value="{spp}"/>
            <integer name="seed" value="5"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{w}"/>
            <integer name="height" value="{h}"/>
            {film_extra}
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.3, 0.4, 0.5"/></emitter>
    <emitter type="point">
        <point name="position" x="2" y="3" z="2"/>
        <rgb name="intensity" value="20, 18, 15"/>
    </emitter>
    <shape type="sphere">
        <point name="center" x="0" y="0.5" z="0"/>
        <float name="radius" value="0.5"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.3, 0.2"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
</scene>)",
                       fmt::arg("integrator", integrator), fmt::arg("sampler", sampler),
                       fmt::arg("spp", spp), fmt::arg("film_extra", film_extra),
                       fmt::arg("w", width), fmt::arg("h", height));
}

RenderOptions options(int threads = 2) {
    RenderOptions opts;
    opts.threads = threads;
    opts.block_size = 8;
    opts.progress = false;
    return opts;
}

/// Checks that the parts, averaged with their spp as weights, are the whole render.
void expect_parts_merge_to_whole(const std::string &sampler, int spp, int parts) {
    SCOPED_TRACE(sampler);
    // A box filter gives every sample the weight 1, so a pixel is the plain mean of its samples
    // and the weighted mean of the parts is exactly the mean of all samples.
    auto scene = load_temp_scene(scene_xml(sampler, spp, "<rfilter type=\"box\"/>"));
    const Sensor &sensor = *scene->sensors().at(0);
    RenderOptions opts = options();
    std::vector<RenderResult> results;
    uint32_t next_sample = 0, total = 0;
    for (int i = 0; i < parts; ++i) {
        opts.pass_index = i;
        opts.pass_count = parts;
        results.push_back(render(*scene, sensor, opts));
        const RenderResult &r = results.back();
        EXPECT_EQ(r.pass_index, i);
        EXPECT_EQ(r.pass_count, parts);
        EXPECT_EQ(r.sample_offset, next_sample) << "the parts cover consecutive samples";
        EXPECT_GT(r.spp, 0u);
        EXPECT_EQ(r.spp, r.spp_target);
        next_sample += r.spp;
        total = r.spp_total;
    }
    EXPECT_EQ(next_sample, total) << "the parts cover every sample once";
    EXPECT_GE(total, uint32_t(spp * parts));

    RenderOptions whole_opts = options(1);
    whole_opts.spp = int(total);
    RenderResult whole = render(*scene, sensor, whole_opts);
    EXPECT_EQ(whole.spp, total);
    // The parts carry their raw sums after the developed channels.
    const size_t nc = size_t(whole.image.channels), np = size_t(results[0].image.channels);
    ASSERT_EQ(whole.image.data.size() / nc, results[0].image.data.size() / np);
    ASSERT_GT(np, nc);
    size_t differing = 0;
    double max_rel = 0.0;
    for (size_t k = 0; k < whole.image.data.size(); ++k) {
        double sum = 0.0;
        for (const RenderResult &r : results)
            sum += double(r.image.data[k / nc * np + k % nc]) * double(r.spp);
        const double merged = sum / double(total), ref = whole.image.data[k];
        const double rel = std::abs(merged - ref) / std::max(std::abs(ref), 1e-3);
        max_rel = std::max(max_rel, rel);
        if (merged != ref) ++differing;
    }
    // Float rounding only: the samples are the same, summed in other groups.
    EXPECT_LT(max_rel, 2e-6);
    // The parts differ from each other (they are not the same samples over again).
    EXPECT_NE(0, std::memcmp(results[0].image.data.data(), results[1].image.data.data(),
                             results[0].image.data.size() * sizeof(float)));
    std::printf("%s: %d parts of %u spp in all, %zu of %zu values not bit-equal, max relative "
                "difference %.3g\n",
                sampler.c_str(), parts, total, differing, whole.image.data.size(), max_rel);
}

bool same_pixels(const Image &crop, const Image &full, int x0, int y0) {
    for (int y = 0; y < crop.height; ++y)
        for (int x = 0; x < crop.width; ++x)
            for (int c = 0; c < crop.channels; ++c) {
                float a = crop.at(x, y, c), b = full.at(x0 + x, y0 + y, c);
                if (std::memcmp(&a, &b, sizeof(float)) != 0) {
                    ADD_FAILURE() << "pixel (" << x0 + x << ", " << y0 + y << ") channel " << c
                                  << ": crop " << a << ", full render " << b;
                    return false;
                }
            }
    return true;
}

/// A part as `facet render` writes it: the image and the attributes a merge checks.
merge::Part part_of(const RenderResult &r, const Sensor &sensor, const std::string &name) {
    merge::Part p;
    p.name = name;
    p.full_width = r.image.full_width;
    p.full_height = r.image.full_height;
    p.x = r.image.x;
    p.y = r.image.y;
    p.image = r.image;
    p.metadata =
        render_file_metadata(render_file_info(r, sensor, "0123456789abcdef", "", 0, "scalar_rgb"));
    return p;
}

/// Values (pixel-channels) whose bits differ; the images must have the same shape.
size_t differing_values(const Image &a, const Image &b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.channel_names, b.channel_names);
    if (a.data.size() != b.data.size()) return std::max(a.data.size(), b.data.size());
    size_t n = 0;
    for (size_t k = 0; k < a.data.size(); ++k)
        n += std::memcmp(&a.data[k], &b.data[k], sizeof(float)) != 0;
    return n;
}

/// The crop windows pass i of a 29x21 film is split into: the whole film, two rows, four tiles
/// (none aligned to the 8-pixel blocks; every filter reaches across their edges).
std::vector<std::array<int, 4>> split_of_pass(int i) {
    switch (i % 3) {
    case 0:
        return {{{0, 0, 29, 21}}};
    case 1:
        return {{{0, 0, 29, 9}}, {{0, 9, 29, 21}}};
    default:
        return {{{0, 0, 11, 13}}, {{11, 0, 29, 13}}, {{0, 13, 17, 21}}, {{17, 13, 29, 21}}};
    }
}

/// Renders `passes` parts of `xml`, each pass cut into the crops of split_of_pass(), merges them
/// and checks the merge is bit-identical to the render of all the passes in one process. Prints
/// how far the earlier merge (the parts' developed pixels averaged with their spp as weights) was
/// from it, and how far both are from one render of all the samples (other float rounding).
void expect_exact_pass_merge(const std::string &what, const std::string &xml, int passes,
                             const std::string &mode = "scalar_rgb") {
    SCOPED_TRACE(what);
    auto scene = load_temp_scene(xml, mode);
    const Sensor &sensor = *scene->sensors().at(0);
    std::vector<merge::Part> parts;
    std::vector<RenderResult> whole_passes;
    for (int i = 0; i < passes; ++i) {
        for (const auto &crop : split_of_pass(i)) {
            RenderOptions opts = options(2);
            opts.pass_index = i;
            opts.pass_count = passes;
            opts.crop = crop;
            RenderResult r = render(*scene, sensor, opts);
            ASSERT_FALSE(r.cancelled);
            parts.push_back(
                part_of(r, sensor, fmt::format("pass {} crop {} {}", i, crop[0], crop[1])));
        }
        RenderOptions opts = options(1);
        opts.pass_index = i;
        opts.pass_count = passes;
        whole_passes.push_back(render(*scene, sensor, opts));
    }
    const merge::Merged merged = merge::merge_parts(parts);

    RenderOptions all = options(3);
    all.pass_index = -1;
    all.pass_count = passes;
    const RenderResult single = render(*scene, sensor, all);
    EXPECT_EQ(single.spp, single.spp_total);
    EXPECT_EQ(merged.metadata.strings.at("facet:spp"), std::to_string(single.spp));
    ASSERT_EQ(merged.image.channels, single.image.channels);
    const size_t exact = differing_values(merged.image, single.image);
    EXPECT_EQ(exact, 0u) << "values of the merge that differ from the render of all the passes";

    // The spp-weighted mean of the developed passes (what merges took before the raw sums).
    Image mean = single.image;
    const size_t values = mean.data.size();
    for (size_t k = 0; k < values; ++k) {
        const int c = int(k % size_t(mean.channels));
        const size_t pixel = k / size_t(mean.channels);
        double sum = 0.0, weight = 0.0;
        for (const RenderResult &r : whole_passes) {
            sum += double(r.spp) * double(r.image.data[pixel * size_t(r.image.channels) + c]);
            weight += double(r.spp);
        }
        mean.data[k] = float(sum / weight);
    }
    RenderOptions one = options(2);
    one.spp = int(single.spp);
    const RenderResult plain = render(*scene, sensor, one);
    std::printf(
        "%s: %d passes, %u spp: the raw-sum merge differs from the one-process render of "
        "the passes in %zu of %zu values; the spp-weighted mean of the passes in %zu (max "
        "relative difference %.3g); the one render of %u spp: the merge in %zu values\n",
        what.c_str(), passes, single.spp, exact, values, differing_values(mean, single.image),
        [&] {
            double m = 0.0;
            for (size_t k = 0; k < values; ++k)
                m = std::max(m, std::abs(double(mean.data[k]) - single.image.data[k]) /
                                    std::max(1e-3, std::abs(double(single.image.data[k]))));
            return m;
        }(),
        plain.spp, differing_values(merged.image, plain.image));
}

} // namespace

TEST(RenderParts, PassesMergeExactlyWithEveryFilter) {
    for (const char *filter : {"", "<rfilter type=\"gaussian\"/>", "<rfilter type=\"box\"/>",
                               "<rfilter type=\"tent\"/>", "<rfilter type=\"lanczos\"/>",
                               "<rfilter type=\"mitchell\"/>", "<rfilter type=\"catmullrom\"/>"}) {
        expect_exact_pass_merge(*filter ? filter : "default filter (gaussian)",
                                scene_xml("independent", 3, filter), 3);
    }
}

TEST(RenderParts, PassesMergeExactlyWithOtherSamplersAndAovs) {
    expect_exact_pass_merge("stratified", scene_xml("stratified", 4, ""), 3);
    expect_exact_pass_merge("ldsampler", scene_xml("ldsampler", 2, ""), 4);
    // AOV channels and alpha: their sums merge like the colour's.
    expect_exact_pass_merge(
        "aov + rgba",
        scene_xml("independent", 2, R"(<string name="pixel_format" value="rgba"/>)", 29, 21,
                  R"(<integrator type="aov"><string name="aovs" value="dd:depth, nn:sh_normal"/>
                     <integrator type="path"><integer name="max_depth" value="4"/></integrator>
                     </integrator>)"),
        2);
}

TEST(RenderParts, SpectralBandPassesMergeExactly) {
    // A film of spectral bands (no R, G, B) with AOVs: the bands' sums merge like colours.
    std::string xml = scene_xml("independent", 2,
                                R"(<spectrum name="short" value="400:0, 450:1, 500:0"/>
           <spectrum name="long" value="550:0, 650:1, 750:0"/><rfilter type="tent"/>)",
                                29, 21,
                                R"(<integrator type="aov"><string name="aovs" value="dd:depth"/>
           <integrator type="path"><integer name="max_depth" value="4"/></integrator>
           </integrator>)");
    const size_t at = xml.find("\"hdrfilm\"");
    ASSERT_NE(at, std::string::npos);
    xml.replace(at, 9, "\"specfilm\"");
    expect_exact_pass_merge("specfilm + aov", xml, 3, "scalar_spectral");
}

TEST(RenderParts, LightTracerPassesMergeExactly) {
    expect_exact_pass_merge(
        "ptracer",
        scene_xml(
            "independent", 2, "", 29, 21,
            R"(<integrator type="ptracer"><integer name="max_depth" value="4"/></integrator>)"),
        3);
}

TEST(RenderParts, PartFilesMergeExactly) {
    // Through EXR files (float16 colour, float32 raw sums): the merge is developed from the raw
    // sums, so it is still the one-process render of the passes, bit for bit.
    auto scene = load_temp_scene(scene_xml("independent", 2, ""));
    const Sensor &sensor = *scene->sensors().at(0);
    std::vector<merge::Part> parts;
    for (int i = 0; i < 2; ++i)
        for (const auto &crop : split_of_pass(i + 1)) {
            RenderOptions opts = options();
            opts.pass_index = i;
            opts.pass_count = 2;
            opts.crop = crop;
            RenderResult r = render(*scene, sensor, opts);
            const std::string path =
                (temp_dir() / fmt::format("part-{}-{}-{}.exr", i, crop[0], crop[1])).string();
            ImageWriteOptions w;
            add_metadata(w, part_of(r, sensor, path).metadata);
            sensor.film().write(r.image, path, w);
            parts.push_back(merge::read_part(path));
            EXPECT_TRUE(parts.back().half);
        }
    const std::vector<std::string> &names = parts[0].image.channel_names;
    // The raw sums, in the order the EXR file lists them.
    ASSERT_EQ(names.size(), 7u);
    std::vector<std::string> sorted = names;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<std::string>{"B", "G", "R", "facet.sum.B", "facet.sum.G",
                                                "facet.sum.R", "facet.weight"}));
    const merge::Merged merged = merge::merge_parts(parts);
    RenderOptions all = options();
    all.pass_index = -1;
    all.pass_count = 2;
    EXPECT_EQ(differing_values(merged.image, render(*scene, sensor, all).image), 0u);
    EXPECT_TRUE(merged.half);

    // Parts without raw sums (developed images only) cannot be merged as passes.
    for (merge::Part &p : parts) {
        std::vector<float> rgb;
        for (size_t k = 0; k < p.image.data.size(); k += 7)
            rgb.insert(rgb.end(), p.image.data.begin() + std::ptrdiff_t(k),
                       p.image.data.begin() + std::ptrdiff_t(k + 3));
        p.image.data = rgb;
        p.image.channels = 3;
        p.image.channel_names.resize(3);
    }
    try {
        merge::merge_parts(parts);
        ADD_FAILURE() << "a part without raw sums was merged";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("no raw channels"), std::string::npos) << e.what();
    }
}

TEST(RenderParts, IndependentPassesMergeToTheWholeRender) {
    expect_parts_merge_to_whole("independent", 3, 4);
}

TEST(RenderParts, StratifiedPassesMergeToTheWholeRender) {
    // 3 parts x 4 = 12 samples become the 16 of a 4 x 4 pattern, split 5 + 5 + 6.
    expect_parts_merge_to_whole("stratified", 4, 3);
}

TEST(RenderParts, PatternSamplerPassesMergeToTheWholeRender) {
    expect_parts_merge_to_whole("ldsampler", 2, 4);
    expect_parts_merge_to_whole("multijitter", 3, 2);
    expect_parts_merge_to_whole("orthogonal", 3, 3);
}

TEST(RenderParts, SampleRangeOfAPart) {
    auto scene = load_temp_scene(scene_xml("stratified", 4, ""));
    const Sensor &sensor = *scene->sensors().at(0);
    RenderOptions opts = options();
    opts.pass_count = 3;
    opts.pass_index = 2;
    SampleRange r = render_sample_range(sensor, opts);
    EXPECT_EQ(r.total, 16u);
    EXPECT_EQ(r.first, 10u);
    EXPECT_EQ(r.count, 6u);
    opts.pass_index = 3;
    EXPECT_THROW(render_sample_range(sensor, opts), Error);
    opts.pass_index = -2; // -1 is every pass
    EXPECT_THROW(render(*scene, sensor, opts), Error);
    opts.pass_index = 0;
    opts.pass_count = 0;
    EXPECT_THROW(render(*scene, sensor, opts), Error);
    // More parts than samples: an empty part is an error, not a black image.
    opts.pass_count = 40;
    opts.spp = 1;
    opts.pass_index = 0;
    auto independent = load_temp_scene(scene_xml("independent", 1, ""));
    EXPECT_NO_THROW(render_sample_range(*independent->sensors().at(0), opts));
    EXPECT_EQ(render_sample_range(*independent->sensors().at(0), opts).count, 1u);
}

TEST(RenderParts, CropIsBitIdenticalToTheFullRender) {
    // The default gaussian filter reaches two pixels across the crop edge, and the crop is not
    // aligned to the 8-pixel blocks.
    auto scene = load_temp_scene(scene_xml("independent", 4, ""));
    const Sensor &sensor = *scene->sensors().at(0);
    RenderResult full = render(*scene, sensor, options());
    EXPECT_EQ(full.image.x, 0);
    EXPECT_EQ(full.image.full_width, 29);
    for (auto crop : {std::array<int, 4>{{5, 3, 18, 17}}, std::array<int, 4>{{0, 0, 1, 1}},
                      std::array<int, 4>{{20, 9, 29, 21}}}) {
        RenderOptions opts = options(1);
        opts.crop = crop;
        RenderResult part = render(*scene, sensor, opts);
        ASSERT_EQ(part.image.width, crop[2] - crop[0]);
        ASSERT_EQ(part.image.height, crop[3] - crop[1]);
        EXPECT_EQ(part.image.x, crop[0]);
        EXPECT_EQ(part.image.y, crop[1]);
        EXPECT_EQ(part.image.full_width, 29);
        EXPECT_EQ(part.image.full_height, 21);
        EXPECT_EQ(part.crop, crop);
        EXPECT_TRUE(same_pixels(part.image, full.image, crop[0], crop[1]));
    }
    // The film's crop window is back to the scene's for a render without a crop.
    RenderResult again = render(*scene, sensor, options());
    EXPECT_EQ(again.image.width, 29);
    EXPECT_EQ(0, std::memcmp(again.image.data.data(), full.image.data.data(),
                             full.image.data.size() * sizeof(float)));
    // A crop outside the film or an empty one is an error naming the film.
    RenderOptions bad = options();
    bad.crop = {{5, 3, 30, 17}};
    try {
        render(*scene, sensor, bad);
        ADD_FAILURE() << "no error for a crop outside the film";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("29x21"), std::string::npos) << e.what();
    }
    bad.crop = {{5, 3, 5, 17}};
    EXPECT_THROW(render(*scene, sensor, bad), Error);
}

TEST(RenderParts, FilmCropWindowWritesTheDataWindow) {
    // hdrfilm's own crop window: the same pixels as the full render, written as an EXR whose
    // data window is the crop inside the full display window.
    auto full_scene = load_temp_scene(scene_xml("independent", 2, ""));
    RenderResult full = render(*full_scene, *full_scene->sensors().at(0), options());
    auto scene = load_temp_scene(scene_xml("independent", 2, R"(
            <integer name="crop_offset_x" value="7"/><integer name="crop_offset_y" value="4"/>
            <integer name="crop_width" value="11"/><integer name="crop_height" value="9"/>)"));
    const Sensor &sensor = *scene->sensors().at(0);
    RenderResult part = render(*scene, sensor, options());
    ASSERT_EQ(part.image.width, 11);
    EXPECT_TRUE(same_pixels(part.image, full.image, 7, 4));

    const std::string path = (temp_dir() / "crop.exr").string();
    sensor.film().write(part.image, path, {});
    auto in = OIIO::ImageInput::open(path);
    ASSERT_TRUE(in);
    const OIIO::ImageSpec &spec = in->spec();
    EXPECT_EQ(spec.x, 7);
    EXPECT_EQ(spec.y, 4);
    EXPECT_EQ(spec.width, 11);
    EXPECT_EQ(spec.height, 9);
    EXPECT_EQ(spec.full_x, 0);
    EXPECT_EQ(spec.full_y, 0);
    EXPECT_EQ(spec.full_width, 29);
    EXPECT_EQ(spec.full_height, 21);
    in->close();
    Image back = read_image(path);
    EXPECT_EQ(back.x, 7);
    EXPECT_EQ(back.y, 4);
    EXPECT_EQ(back.full_width, 29);
    EXPECT_EQ(back.full_height, 21);
    EXPECT_EQ(back.width, 11);
}

TEST(RenderParts, MetadataNamesThePart) {
    auto scene = load_temp_scene(scene_xml("independent", 3, ""));
    RenderOptions opts = options();
    opts.pass_index = 1;
    opts.pass_count = 2;
    opts.crop = {{2, 1, 9, 8}};
    const Sensor &sensor = *scene->sensors().at(0);
    RenderResult r = render(*scene, sensor, opts);
    auto m = render_file_metadata(render_file_info(r, sensor, "", "", 0, "scalar_rgb")).strings;
    EXPECT_EQ(m["facet:spp"], "3");
    EXPECT_EQ(m["facet:spp_total"], "6");
    EXPECT_EQ(m["facet:sample_offset"], "3");
    EXPECT_EQ(m["facet:pass_index"], "1");
    EXPECT_EQ(m["facet:pass_count"], "2");
    EXPECT_EQ(m["facet:crop"], "2 1 9 8");
    EXPECT_EQ(m["facet:film_size"], "29 21");
    EXPECT_EQ(m.count("facet:spp_target"), 0u);

    // The scene identity changes with the file, a parameter or the film size, and only then.
    const std::string a = scene_identity("<scene/>", {{"spp", "4"}}, 29, 21);
    EXPECT_EQ(a.size(), 16u);
    EXPECT_EQ(a, scene_identity("<scene/>", {{"spp", "4"}}, 29, 21));
    EXPECT_NE(a, scene_identity("<scene />", {{"spp", "4"}}, 29, 21));
    EXPECT_NE(a, scene_identity("<scene/>", {{"spp", "5"}}, 29, 21));
    EXPECT_NE(a, scene_identity("<scene/>", {{"spp", "4"}}, 29, 22));
    EXPECT_NE(a, scene_identity("<scene/>", {}, 29, 21));
}
