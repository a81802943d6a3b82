#pragma once

#include <facet/assert.h>
#include <facet/transform.h>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace facet {

/// Interleaved float image.
struct Image {
    int width = 0, height = 0, channels = 0;
    /// Where the pixels lie in a larger image (OpenEXR's data and display windows): this image
    /// is the window at (x, y) of a full_width x full_height one (0: the image itself). A film's
    /// crop window is developed so; EXR files keep both windows.
    int x = 0, y = 0, full_width = 0, full_height = 0;
    std::vector<std::string> channel_names;
    std::vector<float> data;

    Image() = default;
    Image(int w, int h, int c) : width(w), height(h), channels(c), data(size_t(w) * h * c, 0.f) {}
    float &at(int x, int y, int c) {
        FACET_ASSERT(x >= 0 && x < width && y >= 0 && y < height && c >= 0 && c < channels);
        return data[(size_t(y) * width + x) * channels + c];
    }
    float at(int x, int y, int c) const {
        FACET_ASSERT(x >= 0 && x < width && y >= 0 && y < height && c >= 0 && c < channels);
        return data[(size_t(y) * width + x) * channels + c];
    }
};

struct ImageWriteOptions {
    /// EXR: float16 for the colour channels (the leading R, G, B, A, X, Y, Z channels of a
    /// developed film). AOV channels after them always stay float32: a half holds integers
    /// exactly only up to 2048 and overflows to infinity above 65504 (primitive indices, depths).
    bool half = false;
    /// EXR: the channels stored as float16, by name, when not empty (a film whose colour
    /// channels are not R, G, B: specfilm's bands; a merge writes each channel as its parts
    /// have it); `half` is ignored then.
    std::vector<std::string> half_channels;
    /// EXR: the colour channels are Rec.709 (R, G, B, or Y), tagged with its chromaticities (XYZ
    /// pixels and a film's spectral bands are not).
    bool rec709 = true;
    std::string ocio_config; ///< "" = $OCIO, else the installed config
    std::string display;     ///< OpenColorIO display; "" = the config's default display
    std::string view;        ///< view of that display; "" = the display's default view
    /// OpenColorIO looks ("a, +b, -c"); "" = only the view's own. Given, they replace the view's.
    std::string looks;
    std::map<std::string, std::string> metadata; ///< string attributes (every format that has them)
    /// Typed EXR attributes (other formats ignore them): int, float and 4×4 float matrices
    /// (Matrix4f's row-major elements in order, as pbrt-v4 stores its matrices).
    std::map<std::string, int> int_metadata;
    std::map<std::string, float> float_metadata;
    std::map<std::string, Matrix4f> matrix_metadata;
};

/// Writes with OpenEXR (.exr), OpenImageIO (other formats) or facet's own writer (PFM) to a
/// temporary file next to `path`, checks that file (read back; see verify_written in exr.cpp and
/// image/write.cpp), then renames it over `path`: a failed write throws and leaves an existing
/// `path` untouched. .exr/.hdr/.pfm stay scene-linear (an RGB EXR is tagged with the Rec.709
/// chromaticities); 8-bit formats (.png, .jpg, ...) go through the OpenColorIO display/view
/// transform of the chosen config.
void write_image(const std::string &path, const Image &image, const ImageWriteOptions &opts = {});
/// Throws the error write_image() would give for `path` before any pixel exists: a missing folder
/// or an extension no writer knows (.pfm is written by facet itself, the rest by OpenImageIO).
/// Lets a command refuse a bad output name before a long render.
void check_image_path(const std::string &path);
/// Proves that write_image() can replace `path`: it is not a directory (nor another non-regular
/// file), its folder exists, and the temporary file the write goes through can be created there
/// (it is created and removed). Throws "cannot write image" with the reason.
void check_output_file(const std::string &path);
/// check_image_path(), and for 8-bit formats resolve_display_view(): a wrong display, view or
/// look name fails before a long render. Warns when display options meet a linear format.
void check_image_output(const std::string &path, const ImageWriteOptions &opts);

/// What an OpenColorIO config offers 8-bit outputs: its (active) displays in order, each with
/// its views, and its looks.
struct OcioDisplays {
    struct Display {
        std::string name, default_view;
        std::vector<std::string> views;
    };
    std::string config; ///< path of the config
    std::string description, default_display;
    std::vector<Display> displays;
    std::vector<std::string> looks;
};
/// Reads the config ocio_config_path(`config_path`) (parsed once per path).
OcioDisplays ocio_displays(const std::string &config_path = "");

/// The display transform of an 8-bit output.
struct DisplayView {
    std::string config, display, view, looks;
};
/// `opts`'s display, view and looks resolved in its config: the config's default display and
/// that display's default view stand for empty names. A name the config does not have throws an
/// error listing the config's displays, the display's views or the config's looks.
DisplayView resolve_display_view(const ImageWriteOptions &opts);

/// Reads any format OpenImageIO knows; 8-bit images are returned as stored (no decoding).
Image read_image(const std::string &path);

/// What an image file declares, read and checked as read_image() checks it (a size that wraps
/// or exceeds allocation_limit(), the hostile headers it refuses) without reading a pixel: the
/// size of an image is known before any memory is spent on it.
struct ImageHeader {
    Image image;        ///< sizes, windows and channel names; no pixels
    bool bytes = false; ///< read_image_bytes() keeps its values as stored, a byte each
};
ImageHeader read_image_header(const std::string &path);

/// An image read as read_image() reads it, but with its values kept as stored where they are
/// bytes (8-bit files read by scanlines, all channels of one type: ImageHeader::bytes): a
/// quarter of the memory, and the same values through `values`.
struct ByteImage {
    /// Sizes, windows and channel names; its pixels only when `bytes` is empty (a file whose
    /// values are not bytes).
    Image image;
    std::vector<uint8_t> bytes;      ///< the interleaved values as stored
    std::array<float, 256> values{}; ///< the float read_image() gives each byte value
};
ByteImage read_image_bytes(const std::string &path);

/// An image file with what read_image() leaves out: how it stores its channels and its
/// attributes (as `facet merge` reads the parts of a split render).
struct ImageFile {
    Image image;
    bool half = false; ///< the first channel (a film's colour) is stored as float16
    std::vector<std::string> half_channels;        ///< the names of the channels stored as float16
    std::map<std::string, std::string> attributes; ///< every attribute, as text
};
/// read_image(), and the storage and attributes of the file.
ImageFile read_image_file(const std::string &path);

/// The image and colour libraries (OpenImageIO, OpenColorIO) live in libfacet_image, which
/// libfacet loads the first time an image is read or written or a display transform resolved
/// (they are some 260 shared libraries a render needs only to write its result). The path of
/// that library (installed next to libfacet; $FACET_IMAGE_LIBRARY overrides it).
std::string image_library_path();
/// Whether libfacet_image is loaded in this process (nothing loads it but the functions above
/// and preload_image_library()).
bool image_library_loaded();
/// Starts loading libfacet_image on a background thread (once; errors are left to the first
/// real use). `facet render` calls it as the render starts: the ~0.5 CPU-s of loading overlap
/// the render instead of delaying the first sample, and an interrupted render writes its image
/// without waiting for the libraries.
void preload_image_library();
/// Starts loading, on a background thread, the module write_image(`path`) needs: libfacet_exr
/// (OpenEXR only, a few MiB) for .exr, else libfacet_image. A render to .exr thus never loads
/// OpenImageIO and OpenColorIO (unless its scene reads an image).
void preload_image_writer(const std::string &path);
/// Path of the OCIO config facet uses: `explicit_path`, else $OCIO, else the installed one.
std::string ocio_config_path(const std::string &explicit_path = "");

} // namespace facet
