#pragma once

// Merging the parts of a render split across processes or machines: the library behind
// `facet merge` and facet.merge / facet.distributed in Python.
//
// A part is an image of a rectangle of the full image (its data window inside the display
// window) from one pass of a render split into passes. Parts of one pass must cover the full
// image exactly once. With one pass the merged pixels are the parts' pixels, unchanged. With
// several, every part carries the raw sums of its pixels after its developed channels
// (Film::raw_channel_names: Σ w·value, Σ w, splats): they are added over the passes in pass order
// and developed once (facet::develop_pixel), so the merge is Σ w·L / Σ w over all the samples
// whatever the filter, bit-identical to the render of all the passes in one process
// (RenderOptions::pass_index -1, `facet render --passes N` without --pass).

#include <facet/image.h>
#include <facet/output_metadata.h>

#include <map>
#include <string>
#include <vector>

namespace facet::merge {

struct Part {
    std::string name;                       ///< file name (or "part N") for messages
    int full_width = 0, full_height = 0;    ///< display window
    int x = 0, y = 0;                       ///< data window origin inside the display window
    Image image;                            ///< the data window's pixels
    bool half = false;                      ///< colour stored as float16
    std::vector<std::string> half_channels; ///< the channels stored as float16
    /// The facet:* string attributes and the camera matrices (attr::world_to_camera and
    /// attr::world_to_ndc; read from a file to the 6 digits its text form keeps).
    FileMetadata metadata;
};

/// Reads a part (display and data windows, channels, facet:* attributes, camera matrices).
Part read_part(const std::string &path);

struct Merged {
    Image image; ///< the full image
    bool half = false;
    std::vector<std::string> half_channels; ///< stored as float16 in every part
    /// What all parts agree on, and the attributes of one render of the whole film
    /// (render_file_metadata()) with all the parts' samples and render time.
    FileMetadata metadata;
    int passes = 1;
};

/// Checks the parts (same scene, size, channels and pass count; each pass covered exactly once,
/// no overlaps, no holes) and merges them; a facet::Error names the offending parts otherwise.
Merged merge_parts(const std::vector<Part> &parts);

/// Writes the merged image and its metadata through facet's writer (EXR: float16 when the
/// parts were).
void write_merged(const Merged &merged, const std::string &path);

} // namespace facet::merge
