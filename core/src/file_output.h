#pragma once

// Writing an output file so that it is never left half written: both image writers
// (image/write.cpp, OpenImageIO; exr.cpp, OpenEXR) encode to memory and hand the bytes to
// replace_image_file().

#include <functional>
#include <string>
#include <vector>

namespace facet::detail {

/// Writes `bytes` as the image file `path`: to a temporary file next to it first (every write,
/// the flush to the disk and the close checked), then the file's size and `verify(temporary)`
/// ("" or what is wrong with the file), then a rename over `path`. Throws "cannot write image"
/// with the reason otherwise; an existing `path` is then unchanged and no temporary file is left.
void replace_image_file(const std::string &path, const std::vector<unsigned char> &bytes,
                        const std::function<std::string(const std::string &)> &verify);

/// The temporary file replace_image_file() writes `path` through (".NAME.tmp-PID" next to it,
/// NAME shortened and made unique by a hash where the whole would exceed NAME_MAX).
std::string temp_file_for(const std::string &path);

} // namespace facet::detail
