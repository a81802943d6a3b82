// libfacet_image: libfacet loads this module on first use (image_api.cpp) and calls it through
// this table, the one symbol the module exports (image_library.h).
#include "image_library.h"

#include <facet/image.h>

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <string>

namespace OCIO = OCIO_NAMESPACE;

extern "C" __attribute__((visibility("default"))) const facet::detail::ImageLibrary *
facet_image_library() {
    // Images are read only by the readers of the formats facet documents (open_image()).
    static const bool by_extension_only = OIIO::attribute("try_all_readers", 0);
    (void)by_extension_only;
    static const std::string versions =
        fmt::format("OpenImageIO {}, OpenColorIO {}", OIIO_VERSION_STRING, OCIO::GetVersion());
    static const facet::detail::ImageLibrary table = {
        FACET_IMAGE_LIBRARY_VERSION, &facet::write_image,
        &facet::check_image_path,    &facet::check_image_output,
        &facet::ocio_displays,       &facet::resolve_display_view,
        &facet::read_image,          &facet::read_image_file,
        &facet::ocio_config_path,    [] { return versions.c_str(); },
        &facet::read_image_header,   &facet::read_image_bytes,
    };
    return &table;
}
