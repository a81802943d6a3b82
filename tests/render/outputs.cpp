// What `facet render` writes, as a user sees it: every output format (PFM included), verified
// writes that never replace a good file by a broken one, typed EXR metadata, and the
// OpenColorIO display, view and look of 8-bit outputs.

#include "test_util.h"

#include <facet/image.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;

namespace {

using facet::test::FACET;

/// A diffuse sphere under a constant sky; `$format` is the film's file_format.
const char *SCENE = R"(<scene version="3.0.0">
    <default name="spp" value="4"/>
    <default name="res" value="24"/>
    <default name="format" value="openexr"/>
    <integrator type="path">
        <integer name="max_depth" value="3"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
            <string name="file_format" value="$format"/>
        </film>
    </sensor>
    <emitter type="constant">
        <rgb name="radiance" value="1, 0.9, 0.8"/>
    </emitter>
    <shape type="sphere">
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.2, 0.5, 0.7"/>
        </bsdf>
    </shape>
</scene>
)";

using Result = facet::test::CommandResult;
using facet::test::read_file;
using facet::test::write_file;

class Outputs : public facet::test::ScratchFolderTest {
protected:
    Outputs() : ScratchFolderTest("outputs", SCENE) {}
};

TEST_F(Outputs, PfmFromTheOptionAndFromTheFilm) {
    Result r = run("render scene.xml -q -o x.pfm");
    ASSERT_EQ(r.code, 0) << r.err;
    facet::Image img = facet::read_image(path("x.pfm"));
    EXPECT_EQ(img.width, 24);
    EXPECT_EQ(img.height, 24);
    EXPECT_EQ(img.channels, 3);
    EXPECT_EQ(read_file(path("x.pfm")).substr(0, 10), "PF\n24 24\n-");

    // The same pixels, in the same places, as the (float16) EXR of the same render.
    r = run("render scene.xml -q -o x.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    facet::Image exr = facet::read_image(path("x.exr"));
    ASSERT_EQ(exr.channels, 3);
    for (size_t i = 0; i < img.data.size(); ++i)
        ASSERT_NEAR(img.data[i], exr.data[i], std::abs(exr.data[i]) / 1024.f) << i;

    // file_format=pfm gives scene.pfm.
    r = run("render scene.xml -q -D format=pfm");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(facet::read_image(path("scene.pfm")).channels, 3);
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "x.pfm", "x.exr", "scene.pfm"}));
}

/// The attribute `name` of the image at `path`, or null (the input stays open in `in`).
const OIIO::ParamValue *attribute(std::unique_ptr<OIIO::ImageInput> &in, const std::string &path,
                                  const std::string &name) {
    in = OIIO::ImageInput::open(path);
    return in ? in->spec().find_attribute(name) : nullptr;
}

TEST_F(Outputs, WriteThatRunsOutOfSpaceFailsAndKeepsTheOldImage) {
    for (const char *name : {"big.png", "big.exr", "big.pfm"}) {
        SCOPED_TRACE(name);
        Result r = run(std::string("render scene.xml -q -D res=8 -o ") + name);
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string before = read_file(path(name));
        ASSERT_FALSE(before.empty());
        // Files may not grow past 2 KiB (writes beyond fail with EFBIG, as on a full disk; the
        // signal that would kill the process is ignored): the 64x64 image does not fit.
        r = run(std::string("render scene.xml -q -D res=64 -o ") + name,
                "trap '' XFSZ; ulimit -f 2;");
        EXPECT_NE(r.code, 0) << "a write that did not fit reported success";
        EXPECT_NE(r.err.find("facet: error: cannot write image"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("unchanged"), std::string::npos) << r.err;
        EXPECT_EQ(read_file(path(name)), before); // the old image, untouched
    }
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "big.png", "big.exr", "big.pfm"}));
}

TEST_F(Outputs, FullFilesystemFailsAndKeepsTheOldImage) {
    // A real full disk: a 256 KiB tmpfs in a private mount namespace of this process tree only.
    if (std::system("unshare -rm true > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "unshare -rm is not permitted here (no user/mount namespaces); the "
                        "ulimit test above covers the same path";
    const std::string script =
        "set -u; d='" + path("tmpfs") +
        "'; mkdir -p \"$d\"; "
        "mount -t tmpfs -o size=256k tmpfs \"$d\" || exit 77; "
        "'" +
        FACET +
        "' render scene.xml -q -D res=16 -o \"$d/out.png\" || exit 78; "
        "cp \"$d/out.png\" before.png; "
        "dd if=/dev/zero of=\"$d/filler\" bs=1k 2> /dev/null; "
        "'" +
        FACET +
        "' render scene.xml -q -D res=256 -o \"$d/out.png\" 2> err.txt; "
        "echo $? > code.txt; cp \"$d/out.png\" after.png; ls -a \"$d\" > listing.txt";
    write_file(m_dir / "full.sh", script);
    Result r;
    {
        std::string cmd = "cd '" + m_dir.string() + "' && unshare -rm sh full.sh";
        int status = std::system(cmd.c_str());
        r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    if (r.code == 77) GTEST_SKIP() << "mounting a tmpfs in a user namespace is not permitted";
    ASSERT_EQ(r.code, 0) << "the test script failed";
    EXPECT_NE(read_file(m_dir / "code.txt"), "0\n") << "a write onto a full disk succeeded";
    EXPECT_NE(read_file(m_dir / "err.txt").find("cannot write image"), std::string::npos)
        << read_file(m_dir / "err.txt");
    EXPECT_EQ(read_file(m_dir / "after.png"), read_file(m_dir / "before.png"));
    EXPECT_EQ(read_file(m_dir / "listing.txt"), ".\n..\nfiller\nout.png\n"); // no temp files
}

TEST_F(Outputs, ExrCarriesTypedMetadataAsPbrtWritesIt) {
    Result r = run("render scene.xml -q -o m.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    std::unique_ptr<OIIO::ImageInput> in;
    const OIIO::ParamValue *p = attribute(in, path("m.exr"), "samplesPerPixel");
    ASSERT_TRUE(p);
    EXPECT_EQ(p->type(), OIIO::TypeInt);
    EXPECT_EQ(p->get_int(), 4);
    p = in->spec().find_attribute("renderTimeSeconds");
    ASSERT_TRUE(p);
    EXPECT_EQ(p->type(), OIIO::TypeFloat);
    EXPECT_GT(p->get_float(), 0.f);
    ASSERT_TRUE(in->spec().find_attribute("chromaticities"));

    // worldToCamera: the camera at (0, 0, 5) looking at the origin down its +z.
    p = in->spec().find_attribute("worldToCamera");
    ASSERT_TRUE(p);
    ASSERT_EQ(p->type(), OIIO::TypeMatrix44);
    float w2c[16];
    std::memcpy(w2c, p->data(), sizeof w2c);
    auto apply = [](const float *m, float x, float y, float z, float out[3]) {
        float h[4];
        for (int i = 0; i < 4; ++i)
            h[i] = m[4 * i] * x + m[4 * i + 1] * y + m[4 * i + 2] * z + m[4 * i + 3];
        for (int i = 0; i < 3; ++i) out[i] = h[i] / h[3];
    };
    float c[3];
    apply(w2c, 0.f, 0.f, 5.f, c);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], 0.f, 1e-5f);
    apply(w2c, 0.f, 0.f, 0.f, c);
    EXPECT_NEAR(c[2], 5.f, 1e-5f);

    // worldToNDC: the film position in [0, 1] (x right, y down). With a 40 degree field of view
    // the point 5 tan(20 deg) to the right of the target sits on the right edge, the one as far
    // up on the top edge; the target is the centre.
    p = in->spec().find_attribute("worldToNDC");
    ASSERT_TRUE(p);
    ASSERT_EQ(p->type(), OIIO::TypeMatrix44);
    float w2n[16];
    std::memcpy(w2n, p->data(), sizeof w2n);
    const float edge = 5.f * std::tan(20.f * 3.14159265f / 180.f);
    apply(w2n, 0.f, 0.f, 0.f, c);
    EXPECT_NEAR(c[0], 0.5f, 1e-4f);
    EXPECT_NEAR(c[1], 0.5f, 1e-4f);
    EXPECT_GT(c[2], 0.f);
    EXPECT_LT(c[2], 1.f);
    apply(w2n, edge, 0.f, 0.f, c);
    EXPECT_NEAR(c[0], 1.f, 1e-4f);
    EXPECT_NEAR(c[1], 0.5f, 1e-4f);
    apply(w2n, 0.f, edge, 0.f, c);
    EXPECT_NEAR(c[0], 0.5f, 1e-4f);
    EXPECT_NEAR(c[1], 0.f, 1e-4f);
    // Depth: 0 on the near plane (0.01 in front of the camera), towards 1 on the far one.
    apply(w2n, 0.f, 0.f, 5.f - 0.01f, c);
    EXPECT_NEAR(c[2], 0.f, 1e-3f);
}

TEST_F(Outputs, IndexAndDepthAovsStayFloat32InAHalfExr) {
    std::string scene = SCENE;
    const std::string from = "<integrator type=\"path\">";
    scene.replace(scene.find(from), from.size(),
                  "<integrator type=\"aov\"><string name=\"aovs\" value=\"dd:depth, "
                  "pi:prim_index\"/><integrator type=\"path\">");
    const std::string end = "</integrator>";
    scene.insert(scene.find(end) + end.size(), "</integrator>");
    // The camera 2000 units away (depth 1999: 2000 as a half) with a narrow field of view.
    const std::string eye = "origin=\"0, 0, 5\"";
    scene.replace(scene.find(eye), eye.size(), "origin=\"0, 0, 2000\"");
    const std::string fov = "value=\"40\"";
    scene.replace(scene.find(fov), fov.size(), "value=\"0.05\"");
    write_file(m_dir / "aov.xml", scene);
    Result r = run("render aov.xml -q -o aov.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path("aov.exr"));
    ASSERT_TRUE(in);
    int dd = -1;
    for (int c = 0; c < in->spec().nchannels; ++c) {
        const std::string &name = in->spec().channelnames[c];
        if (name == "dd") dd = c;
        const bool aov = name == "dd" || name == "pi";
        EXPECT_EQ(in->spec().channelformat(c), aov ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF)
            << name;
    }
    ASSERT_GE(dd, 0);
    const int nc = in->spec().nchannels;
    std::vector<float> row(size_t(in->spec().width) * size_t(nc));
    ASSERT_TRUE(in->read_scanline(12, 0, OIIO::TypeDesc::FLOAT, row.data()));
    // The centre pixel sees the sphere's front at z = 1.
    const float depth = row[size_t(12 * nc + dd)];
    EXPECT_NEAR(depth, 1999.f, 0.01f); // a half would give 2000
}

TEST_F(Outputs, StudioConfigDisplaysViewsAndLooks) {
    const std::string ocio = "OCIO='" FACET_TEST_DATA_DIR "/ocio/studio.config'";
    // The config has no "sRGB" display: its default display and view are used.
    Result r = run("render scene.xml -q -o a.png", ocio);
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("render scene.xml -q -o b.png --view Linear", ocio);
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("render scene.xml -q -o c.png --look push --view Linear", ocio);
    ASSERT_EQ(r.code, 0) << r.err;
    facet::Image a = facet::read_image(path("a.png")), b = facet::read_image(path("b.png")),
                 c = facet::read_image(path("c.png"));
    // The same render seen through gamma 2, linearly, and linearly after doubling: pixel by
    // pixel a = sqrt(b) and c = min(2 b, 1), within 8-bit rounding.
    size_t compared = 0;
    for (size_t i = 0; i < a.data.size(); ++i) {
        if (b.data[i] < 0.05f || b.data[i] > 0.45f) continue;
        EXPECT_NEAR(a.data[i], std::sqrt(b.data[i]), 0.02f) << i;
        EXPECT_NEAR(c.data[i], 2.f * b.data[i], 0.01f) << i;
        ++compared;
    }
    EXPECT_GT(compared, 100u);

    // A wrong name is refused before rendering, with the config's choices.
    r = run("render scene.xml -q -o d.png --display sRGB", ocio);
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("\"Studio Monitor\", \"Projector\""), std::string::npos) << r.err;
    r = run("render scene.xml -q -o d.png --display Projector --view Film", ocio);
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("its views: \"Lin\""), std::string::npos) << r.err;
    r = run("render scene.xml -q -o d.png --look glow", ocio);
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("\"push\", \"dim\""), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("d.png")));

    // `facet colors` lists them; the listing must reach its destination.
    r = run("colors", ocio);
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char *word : {"Studio Monitor *", "Film *", "Linear", "Pushed Film", "Projector",
                             "Lin *", "push", "dim"})
        EXPECT_NE(r.out.find(word), std::string::npos) << word << " in\n" << r.out;
    r = run("colors");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("ACES 1.0 - SDR Video"), std::string::npos) << r.out;
    fs::path full = m_dir / "full.sh";
    write_file(full, "'" + FACET + "' colors > /dev/full");
    const int status = std::system(("sh '" + full.string() + "' 2> /dev/null").c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0)
        << "a listing written to a full disk reported success";
}

} // namespace
