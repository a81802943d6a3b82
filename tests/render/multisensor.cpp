// `facet render -s i` renders sensor i of a scene with several sensors (declaration order), and
// an index out of range is a one-line error.

#include <facet/image.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

const char *SCENE = R"(<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="8"/></film>
    </sensor>
    <sensor type="orthographic">
        <transform name="to_world"><lookat origin="0, 5, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
        <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="12"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="sphere"/>
</scene>)";

int run(const std::string &args, std::string &output) {
    std::string cmd = std::string(FACET_BINARY_DIR) + "/bin/facet " + args + " 2>&1";
    FILE *p = popen(cmd.c_str(), "r");
    char buf[4096];
    output.clear();
    while (size_t n = fread(buf, 1, sizeof(buf), p)) output.append(buf, n);
    return pclose(p);
}

} // namespace

TEST(MultipleSensors, DashSPicksTheSensor) {
    fs::path dir = fs::temp_directory_path() / "facet-multisensor";
    fs::create_directories(dir);
    fs::path scene = dir / "two.xml";
    std::ofstream(scene) << SCENE;
    std::string out;
    for (int index : {0, 1}) {
        fs::path image = dir / ("sensor" + std::to_string(index) + ".exr");
        fs::remove(image);
        ASSERT_EQ(run("render -q " + scene.string() + " -s " + std::to_string(index) + " -o " +
                          image.string(),
                      out),
                  0)
            << out;
        facet::Image img = facet::read_image(image.string());
        EXPECT_EQ(img.width, index == 0 ? 16 : 8);
        EXPECT_EQ(img.height, index == 0 ? 8 : 12);
    }
    EXPECT_NE(run("render -q " + scene.string() + " -s 2 -o " + (dir / "bad.exr").string(), out),
              0);
    EXPECT_NE(out.find("2 sensors"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}
