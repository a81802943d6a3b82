#pragma once

#include <facet/fwd.h>
#include <facet/image.h>
#include <facet/transform.h>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace facet {

struct RenderResult;

/// The names of the attributes facet writes into the file of a render (`facet render`, Python's
/// facet.write of a rendered image, `facet merge` and facet.merge), the one list all of them use.
namespace attr {
// String attributes. A merge checks and places parts by them (facet/merge.h).
inline constexpr const char *spp = "facet:spp";               ///< samples per pixel taken
inline constexpr const char *spp_target = "facet:spp_target"; ///< asked for, when stopped early
inline constexpr const char *spp_total = "facet:spp_total";   ///< of all the passes
inline constexpr const char *sample_offset = "facet:sample_offset"; ///< first sample index
inline constexpr const char *pass = "facet:pass_index";
inline constexpr const char *passes = "facet:pass_count";
inline constexpr const char *crop = "facet:crop";             ///< "x0 y0 x1 y1" of the film
inline constexpr const char *film_size = "facet:film_size";   ///< "width height"
inline constexpr const char *scene_hash = "facet:scene_hash"; ///< scene_identity()
inline constexpr const char *seed = "facet:seed";
inline constexpr const char *render_time = "facet:render_time"; ///< seconds, "12.345"
inline constexpr const char *scene = "facet:scene";             ///< the scene file, absolute
inline constexpr const char *blocks = "facet:blocks"; ///< "done/total" work units, when stopped
inline constexpr const char *merged_parts = "facet:merged_parts"; ///< parts of a merge
inline constexpr const char *mode = "facet:mode"; ///< the colour mode, "scalar_rgb" (facet/mode.h)
// Typed attributes, as pbrt-v4 writes them (int, float, 4×4 float matrices row-major for
// column vectors).
inline constexpr const char *samples_per_pixel = "samplesPerPixel";
inline constexpr const char *render_time_seconds = "renderTimeSeconds";
inline constexpr const char *world_to_camera = "worldToCamera";
inline constexpr const char *world_to_ndc = "worldToNDC";
} // namespace attr

/// The attributes of an image file, by type (as ImageWriteOptions takes them).
struct FileMetadata {
    std::map<std::string, std::string> strings;
    std::map<std::string, int> ints;
    std::map<std::string, float> floats;
    std::map<std::string, Matrix4f> matrices;
};

/// Adds `metadata` to the attributes `opts` writes (replacing those of the same name).
void add_metadata(ImageWriteOptions &opts, const FileMetadata &metadata);

/// Everything the file of a render, or of the merge of its parts, records about it.
struct RenderFileInfo {
    /// Samples per pixel in the image (of a stopped render: what was reached), and what the
    /// render was to take; facet:spp_target is written only when they differ.
    uint32_t spp = 0, spp_target = 0;
    /// The image's place in the whole render (RenderResult's fields of the same names).
    uint32_t sample_offset = 0, spp_total = 0;
    int pass_index = 0, pass_count = 1;
    std::array<int, 4> crop{{0, 0, 0, 0}};
    int film_width = 0, film_height = 0;
    std::optional<double> seconds; ///< the render time; unknown for a merge of untimed parts
    /// Work units done and in total, for a render stopped before its end (facet:blocks).
    std::optional<std::pair<size_t, size_t>> blocks;
    std::string scene_hash; ///< scene_identity() of the input; empty: not recorded
    std::string scene_path; ///< the scene file, absolute; empty for a scene from a string
    std::optional<uint64_t> seed;
    std::string mode; ///< the colour mode rendered in (facet/mode.h); empty: not recorded
    std::optional<Matrix4f> world_to_camera, world_to_ndc; ///< the sensor's (below)
};

/// The file information of `result`, a render of `sensor` of the scene whose identity is
/// `scene_hash`, loaded from `scene_path` (empty when from a string), with `seed`, in the colour
/// mode `mode` (resolve_mode()'s).
RenderFileInfo render_file_info(const RenderResult &result, const Sensor &sensor,
                                const std::string &scene_hash, const std::string &scene_path,
                                uint64_t seed, const std::string &mode);

/// The attributes of a render's file, the only place they are built: the facet:* strings a
/// merge needs (attr::spp ... attr::blocks), the colour mode (attr::mode) and pbrt-v4's typed
/// samplesPerPixel, renderTimeSeconds, worldToCamera and worldToNDC.
FileMetadata render_file_metadata(const RenderFileInfo &info);

/// Identity of a render's input, for checking that parts belong together: 16 hex digits of a
/// 64-bit FNV-1a hash of `scene_text` (the scene file's bytes), the parameters (key=value, in
/// key order) and the film size. Stored as facet:scene_hash.
std::string scene_identity(const std::string &scene_text,
                           const std::map<std::string, std::string> &params, int film_width,
                           int film_height);

/// The world-to-NDC matrix of a projective sensor (perspective, thin lens, orthographic), found
/// from the rays the sensor generates: NDC x and y are the position on the full film in [0, 1]
/// (x right, y down, as Sensor::sample_ray takes it; times the film size gives raster
/// coordinates), z is 0 on the near and 1 on the far clipping plane. Row-major, for column
/// vectors (x' = M x, then divide by w). Empty for sensors whose rays are not a projective map of
/// the film (radiance meters, environment cameras).
std::optional<Matrix4f> sensor_world_to_ndc(const Sensor &sensor);

} // namespace facet
