// libfacet_image (OpenImageIO, OpenColorIO) is loaded the first time an image file other than an
// EXR output or an EXR, PNG or JPEG input is touched, not before: loading a scene, rendering it,
// writing the render to .exr (libfacet_exr, OpenEXR alone) and reading those files
// (libfacet_read) leave it unloaded, and the first image read or write of another format loads
// it. One process per unit executable: this file's tests are its only ones,
// in order.

#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

const char *kScene = R"(<scene version="3.0.0">
    <sensor type="perspective">
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
        </film>
        <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
    </sensor>
    <shape type="sphere"><emitter type="area"/></shape>
    <shape type="rectangle"/>
</scene>)";

fs::path scratch() {
    fs::path dir = fs::temp_directory_path() / ("facet_image_library_" + std::to_string(getpid()));
    fs::create_directories(dir);
    return dir;
}

} // namespace

TEST(ImageLibrary, ARenderToExrNeverLoadsIt) {
    ASSERT_FALSE(image_library_loaded()) << "loaded before anything touched an image";
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(kScene));
    ASSERT_TRUE(scene);
    // An output name of a format facet documents is checked without loading it.
    const fs::path out = scratch() / "out.exr";
    check_image_output(out.string(), {});
    EXPECT_THROW(check_image_path((scratch() / "no-such-folder" / "x.exr").string()), Error);
    RenderOptions opts;
    opts.progress = false;
    RenderResult r = render(*scene, *scene->sensors().front(), opts);
    EXPECT_FALSE(image_library_loaded()) << "loaded by loading or rendering the scene";
    scene->sensors().front()->film().write(r.image, out.string(), {});
    EXPECT_FALSE(image_library_loaded()) << "loaded to write an EXR";
    // EXR, PNG and JPEG files are read by libfacet_read (OpenEXR, libpng, libjpeg).
    Image back = read_image(out.string());
    EXPECT_EQ(back.width, 8);
    EXPECT_EQ(back.height, 8);
    const std::string common = FACET_SOURCE_DIR "/scenes/materials/common/";
    EXPECT_GT(read_image_bytes(common + "hammered_height.png").bytes.size(), 0u);
    EXPECT_FALSE(image_library_loaded()) << "loaded to read an EXR or a PNG";
    // Other formats are read by OpenImageIO.
    EXPECT_GT(read_image(common + "sky.hdr").width, 0);
    EXPECT_TRUE(image_library_loaded());
    fs::remove_all(out.parent_path());
}

TEST(ImageLibrary, IsFoundNextToLibfacet) {
    const fs::path path = image_library_path();
    EXPECT_EQ(path.filename(), "libfacet_image.so");
    EXPECT_TRUE(fs::is_regular_file(path)) << path;
}

TEST(ImageLibrary, AMissingLibraryIsAClearErrorBeforeTheRender) {
    ::setenv("FACET_IMAGE_LIBRARY", "/nonexistent/libfacet_image.so", 1);
    try {
        check_image_path((scratch() / "x.png").string());
        ADD_FAILURE() << "no error for a missing image library";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("image library \"/nonexistent/libfacet_image.so\" "
                                             "(OpenImageIO and OpenColorIO) is missing"),
                  std::string::npos)
            << e.what();
    }
    ::unsetenv("FACET_IMAGE_LIBRARY");
    fs::remove_all(scratch());
}

TEST(ImageLibrary, AMissingExrWriterIsAClearErrorBeforeTheRender) {
    ::setenv("FACET_EXR_LIBRARY", "/nonexistent/libfacet_exr.so", 1);
    try {
        check_image_path((scratch() / "x.exr").string());
        ADD_FAILURE() << "no error for a missing EXR writer";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("EXR writer \"/nonexistent/libfacet_exr.so\" "
                                             "(OpenEXR) is missing"),
                  std::string::npos)
            << e.what();
    }
    ::unsetenv("FACET_EXR_LIBRARY");
    fs::remove_all(scratch());
}
