#pragma once

// Writing an output file so that it is never left half written: the image writers hand their
// bytes to replace_image_file(), encoded in memory (image/write.cpp, OpenImageIO) or as they
// come (exr.cpp, OpenEXR: no second copy of the image at the end of a render, its peak).

#include <cstdint>
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

/// Where a streaming writer puts its bytes: write_at(data, n, offset) writes n bytes at `offset`
/// of the temporary file (a writer may go back, as OpenEXR does for its offset table). A failed
/// write throws Error with the reason.
struct ByteSink {
    std::function<void(const void *data, size_t n, uint64_t offset)> write_at;
};

/// replace_image_file() for bytes that `write(sink)` produces: the file's size is the end of its
/// furthest write.
void replace_image_file(const std::string &path, const std::function<void(const ByteSink &)> &write,
                        const std::function<std::string(const std::string &)> &verify);

/// The temporary file replace_image_file() writes `path` through (".NAME.tmp-PID" next to it,
/// NAME shortened and made unique by a hash where the whole would exceed NAME_MAX).
std::string temp_file_for(const std::string &path);

} // namespace facet::detail
