// Every scene shipped in scenes/ loads and renders (tiny, a couple of samples) to a finite image
// that is not black, so the examples in the README keep working as plugins evolve.

#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace facet;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> shipped_scenes() {
    std::vector<std::string> files;
    for (const auto &entry :
         fs::recursive_directory_iterator(fs::path(FACET_SOURCE_DIR) / "scenes")) {
        if (entry.path().extension() != ".xml") continue;
        // Fragments included by the scenes live in folders named "common".
        if (entry.path().parent_path().filename() == "common") continue;
        files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
    return files;
}

} // namespace

TEST(ShippedScenes, EachRendersAFiniteNonBlackImage) {
    auto files = shipped_scenes();
    ASSERT_GE(files.size(), 10u);
    for (const std::string &file : files) {
        SCOPED_TRACE(file);
        LoadOptions opts;
        opts.params = {{"spp", "2"}, {"res", "24"}};
        std::shared_ptr<Scene> scene;
        try {
            scene = load_scene(file, opts);
        } catch (const std::exception &e) {
            ADD_FAILURE() << e.what();
            continue;
        }
        RenderOptions ropts;
        ropts.progress = false;
        RenderResult r = render(*scene, *scene->sensors().at(0), ropts);
        ASSERT_EQ(r.image.width, 24);
        double sum = 0.0;
        bool finite = true;
        for (float v : r.image.data) {
            finite &= std::isfinite(v);
            sum += v;
        }
        EXPECT_TRUE(finite);
        EXPECT_GT(sum, 0.0);
    }
}
