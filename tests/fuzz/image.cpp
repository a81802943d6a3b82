// libFuzzer target: image reading (facet::read_image through OpenImageIO) and the two plugins
// that read images, the bitmap texture and the envmap emitter. The first byte of an input picks
// the file extension (OpenImageIO chooses its reader by it) and the plugin; the rest is the file.
#include "fuzz_common.h"

#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/texture.h>

namespace {

const char *const Extensions[] = {".exr", ".png", ".hdr", ".pfm", ".jpg", ".tga", ".bmp", ".tif"};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    facet::fuzz::init();
    if (size < 1) return 0;
    const uint8_t selector = data[0];
    const char *ext = Extensions[selector % 8];
    std::string path = facet::fuzz::write_input(data + 1, size - 1, ext);
    try {
        switch ((selector >> 3) % 3) {
        case 0: {
            facet::Image img = facet::read_image(path);
            // Every pixel the header promised is there to read.
            volatile float sink = img.data.empty() ? 0.f : img.data.back();
            (void)sink;
            break;
        }
        case 1: {
            facet::Properties props("bitmap");
            props.set_string("filename", path);
            facet::PluginRegistry::instance().create(facet::ObjectType::Texture, props);
            break;
        }
        default: {
            facet::Properties props("envmap");
            props.set_string("filename", path);
            facet::PluginRegistry::instance().create(facet::ObjectType::Emitter, props);
            break;
        }
        }
    } catch (const facet::Error &) {}
    return 0;
}
