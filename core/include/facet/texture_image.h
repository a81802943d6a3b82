#pragma once

// The images textures and emitters hold for as long as a scene lives (bitmap, envmap), read
// through one process-wide cache: an image file is decoded once per set of decoding parameters
// and shared by every reference while one holds it (the cache keeps no image alive by itself),
// and the memory these images take is bounded by a budget checked against the file's header
// before anything is decoded.

#include <facet/color.h>
#include <facet/image.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace facet {

/// The most memory, in bytes, the images below may hold at once in this process:
/// $FACET_TEXTURE_MEMORY_MB (mebibytes), else three quarters of the physical memory;
/// set_texture_memory_budget() overrides both (0: back to that default).
size_t texture_memory_budget();
void set_texture_memory_budget(size_t bytes);
/// Bytes the images below hold now (a shared image once), with those being read.
size_t texture_memory_used();

/// read_image() of `path`, shared: while one caller holds the image, reading the same unchanged
/// file (device, inode, size and modification time) again returns it. The values count against
/// the budget, checked from the header before they are read; a facet::Error names the file.
std::shared_ptr<const Image> read_shared_image(const std::string &path);

/// How an image's values become texels.
struct TexelDecoding {
    bool srgb = false; ///< decode sRGB-encoded values to linear (IEC 61966-2-1)
    bool half = false; ///< round to the nearest half-precision value (after decoding)
};

/// The texels of an image: grey (1 channel, from grey and grey + alpha images) or RGB (3, an
/// alpha channel and any further ones dropped), decoded. An 8-bit file's texels stay bytes (a
/// quarter of the memory) and read through `table`, which holds exactly the value the float
/// path would give each byte.
struct TexelImage {
    int width = 0, height = 0, channels = 0;
    std::vector<float> floats;      ///< interleaved texels, unless `bytes` holds them
    std::vector<uint8_t> bytes;     ///< interleaved 8-bit texels: the texel is table[byte]
    std::array<float, 256> table{}; ///< the decoded texel of each byte value
    Color3f mean;                   ///< average texel (grey images: grey)
    float max = 0.f;                ///< largest value of any channel
    size_t memory() const { return floats.size() * sizeof(float) + bytes.size(); }
};

/// The texels of `path` decoded as `how` says, shared as read_shared_image() shares images by
/// every caller with the same file and decoding; the budget is checked before decoding. A
/// facet::Error names the file.
std::shared_ptr<const TexelImage> load_texels(const std::string &path, const TexelDecoding &how);

} // namespace facet
