// write_image() of every format but EXR (libfacet_exr writes those, exr.cpp), and the checks of
// an output path made before a render.
#include "file_output.h"
#include "image_module.h"

#include <facet/image.h>
#include <facet/logger.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace facet {

using detail::lower_extension;
using detail::to_display_8bit;

namespace {

/// Formats that keep scene-linear floating-point values.
bool is_linear_format(const std::string &ext) {
    return ext == ".exr" || ext == ".hdr" || ext == ".rgbe" || ext == ".pfm";
}

/// The channels written to a file of a format that holds at most `max_channels` colour channels
/// plus alpha: grey (1), grey+alpha (2), RGB (3) or RGBA (4). Extra channels are dropped.
std::vector<int> output_channels(const Image &image, const std::string &path) {
    std::vector<int> ch;
    if (image.channels <= 2) {
        for (int c = 0; c < image.channels; ++c) ch.push_back(c);
        return ch;
    }
    ch = {0, 1, 2};
    if (image.channels >= 4 && image.channel_names.size() > 3 && image.channel_names[3] == "A")
        ch.push_back(3);
    if (int(ch.size()) < image.channels)
        FACET_LOG(Warn,
                  "\"{}\": this format holds only {} channels; the other {} (AOVs) are not written "
                  "(use .exr to keep them)",
                  path, ch.size(), image.channels - int(ch.size()));
    return ch;
}

/// The PFM header encode_pfm() writes.
std::string pfm_header(int width, int height, int channels) {
    return fmt::format("{}\n{} {}\n-1.0\n", channels == 1 ? "Pf" : "PF", width, height);
}

/// Portable float map encoder. OpenImageIO 2.4 reads PFM but has no PFM writer, and the format
/// is a 3-line header plus raw little-endian floats, bottom row first.
std::vector<unsigned char> encode_pfm(const float *pixels, int width, int height, int channels) {
    static_assert(sizeof(float) == 4, "PFM stores 32-bit floats");
    const std::string header = pfm_header(width, height, channels);
    const size_t row = size_t(width) * size_t(channels) * sizeof(float);
    std::vector<unsigned char> bytes(header.begin(), header.end());
    bytes.resize(header.size() + row * size_t(height));
    for (int y = 0; y < height; ++y)
        std::memcpy(bytes.data() + header.size() + row * size_t(height - 1 - y),
                    pixels + size_t(y) * size_t(width) * size_t(channels), row);
    return bytes;
}

/// Checks that the temporary file `file` (of the expected size, see replace_image_file()) really
/// holds the image just encoded, before it replaces anything: OpenImageIO reads it back
/// completely with the expected size and channel count; a PNG's, TIFF's or PFM's pixels must
/// equal the ones written. Returns "" or what is wrong.
std::string verify_written(const std::string &file, const OIIO::ImageSpec &spec,
                           const std::string &ext, const void *pixels) {
    // The temporary file's name has no image extension: the reader is chosen by the output's.
    auto in = ext.size() > 1 ? OIIO::ImageInput::create(ext.substr(1), /*do_open=*/false) : nullptr;
    OIIO::ImageSpec back;
    if (!in) return fmt::format("the written file cannot be read back: {}", OIIO::geterror());
    if (!in->open(file, back))
        return fmt::format("the written file cannot be read back: {}", in->geterror());
    // Formats without alpha (JPEG) drop it.
    const bool dropped_alpha =
        back.nchannels == spec.nchannels - 1 && spec.alpha_channel == spec.nchannels - 1;
    if (back.width != spec.width || back.height != spec.height ||
        (back.nchannels != spec.nchannels && !dropped_alpha))
        return fmt::format("the written file reads back as {}x{} with {} channels", back.width,
                           back.height, back.nchannels);
    // Lossless formats read back the very values written.
    const bool eight_bit = ext == ".png" || ext == ".tif" || ext == ".tiff";
    const bool compare = eight_bit || ext == ".pfm";
    const OIIO::TypeDesc type = eight_bit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
    std::vector<unsigned char> data(back.image_pixels() * size_t(back.nchannels) * type.size());
    bool ok = in->read_image(0, 0, 0, back.nchannels, type, data.data());
    std::string err = ok ? "" : in->geterror();
    in->close();
    if (!ok) return fmt::format("the written file does not read back: {}", err);
    if (compare && std::memcmp(data.data(), pixels, data.size()) != 0)
        return "the pixels read back differ from the ones written";
    return "";
}

} // namespace

void check_image_path(const std::string &path) {
    fs::path dir = fs::path(path).parent_path();
    if (!dir.empty() && !fs::is_directory(dir))
        FACET_THROW("cannot write image \"{}\": the folder \"{}\" does not exist", path,
                    dir.string());
    const std::string ext = lower_extension(path);
    if (ext == ".pfm") return; // facet's own encoder (encode_pfm)
    if (!OIIO::ImageOutput::create(path)) {
        std::string err = OIIO::geterror(); // clears OpenImageIO's error state
        FACET_THROW("cannot write image \"{}\": no image format for the extension \"{}\" ({})",
                    path, ext, err);
    }
}

/// write_image() of every format but EXR (exr.cpp): the caller has checked the image and the path.
void write_image(const std::string &path, const Image &image, const ImageWriteOptions &opts) {
    const std::string ext = lower_extension(path);
    const bool pfm = ext == ".pfm";
    // The plugin is chosen by the target's extension; the data goes to a temporary file first.
    std::unique_ptr<OIIO::ImageOutput> out = pfm ? nullptr : OIIO::ImageOutput::create(path);
    if (!out && !pfm)
        FACET_THROW("cannot write image \"{}\": no image format for the extension \"{}\" ({})",
                    path, ext, OIIO::geterror());

    std::vector<float> linear_pixels;
    std::vector<uint8_t> display_pixels;
    OIIO::ImageSpec spec;
    const void *pixels = nullptr;
    OIIO::TypeDesc pixel_type;
    std::vector<int> ch = output_channels(image, path);
    const int n = int(ch.size());
    if (is_linear_format(ext)) {
        // RGBE and PFM hold grey or RGB floats only.
        const int nout = n <= 2 ? 1 : 3;
        linear_pixels.resize(size_t(image.width) * image.height * nout);
        for (size_t i = 0, np = size_t(image.width) * image.height; i < np; ++i)
            for (int c = 0; c < nout; ++c)
                linear_pixels[i * nout + c] = image.data[i * image.channels + ch[c]];
        spec = OIIO::ImageSpec(image.width, image.height, nout, OIIO::TypeDesc::FLOAT);
        pixels = linear_pixels.data();
        pixel_type = OIIO::TypeDesc::FLOAT;
    } else {
        display_pixels = to_display_8bit(image, ch, opts);
        spec = OIIO::ImageSpec(image.width, image.height, n, OIIO::TypeDesc::UINT8);
        if (n == 2 || n == 4) spec.alpha_channel = n - 1;
        if (ext == ".jpg" || ext == ".jpeg") spec.attribute("compression", "jpeg:95");
        spec.attribute("oiio:ColorSpace", "sRGB");
        // OpenImageIO's TIFF writer puts Exif data (the colour space above becomes
        // Exif:ColorSpace) in a directory of its own and then reads the main directory back from
        // the output, which it cannot do through an output proxy (its read callback returns
        // nothing): the file lost its main directory ("missing required ImageLength"). An 8-bit
        // TIFF without that tag is read as sRGB anyway.
        if (ext == ".tif" || ext == ".tiff") spec.attribute("tiff:write_exif", 0);
        pixels = display_pixels.data();
        pixel_type = OIIO::TypeDesc::UINT8;
    }
    for (const auto &[key, value] : opts.metadata) spec.attribute(key, value);

    // The encoder writes to memory; facet writes the file itself and checks every step (an
    // image library's own file output may miss a full disk, or even exit the process).
    std::vector<unsigned char> bytes;
    if (pfm) {
        bytes =
            encode_pfm(static_cast<const float *>(pixels), spec.width, spec.height, spec.nchannels);
    } else {
        OIIO::Filesystem::IOVecOutput memory(bytes);
        if (!out->set_ioproxy(&memory) || !out->open(path, spec))
            FACET_THROW("cannot write image \"{}\": {}", path, out->geterror());
        bool ok = out->write_image(pixel_type, pixels);
        std::string err = ok ? "" : out->geterror();
        if (!out->close() && ok) {
            ok = false;
            err = out->geterror();
        }
        out.reset();
        if (!ok) FACET_THROW("cannot write image \"{}\": {}", path, err);
    }
    detail::replace_image_file(path, bytes, [&](const std::string &file) {
        return verify_written(file, spec, ext, pixels);
    });
}

void check_image_output(const std::string &path, const ImageWriteOptions &opts) {
    check_image_path(path);
    const std::string ext = lower_extension(path);
    if (ext == ".exr" || is_linear_format(ext)) {
        if (!opts.display.empty() || !opts.view.empty() || !opts.looks.empty())
            FACET_LOG(Warn,
                      "\"{}\" stays scene-linear: the OpenColorIO display, view and looks apply "
                      "to 8-bit outputs (.png, .jpg) only",
                      path);
        return;
    }
    resolve_display_view(opts);
}

} // namespace facet
