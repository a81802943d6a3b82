#include <facet/image.h>
#include <facet/logger.h>
#include <facet/spectrum.h>

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <filesystem>
#include <map>
#include <mutex>
#include <tuple>
#include <unistd.h>

namespace OCIO = OCIO_NAMESPACE;
namespace fs = std::filesystem;

namespace facet {

namespace {

std::string lower_extension(const std::string &path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

/// Formats that keep scene-linear floating-point values.
bool is_linear_format(const std::string &ext) {
    return ext == ".exr" || ext == ".hdr" || ext == ".rgbe" || ext == ".pfm";
}

/// CPU processor for (config, display, view), created once per combination.
OCIO::ConstCPUProcessorRcPtr display_processor(const std::string &config_path,
                                               const std::string &display,
                                               const std::string &view) {
    static std::mutex mutex;
    static std::map<std::tuple<std::string, std::string, std::string>, OCIO::ConstCPUProcessorRcPtr>
        cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto key = std::make_tuple(config_path, display, view);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    try {
        OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(config_path.c_str());
        OCIO::ConstProcessorRcPtr proc = config->getProcessor(
            OCIO::ROLE_SCENE_LINEAR, display.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
        OCIO::ConstCPUProcessorRcPtr cpu = proc->getDefaultCPUProcessor();
        cache.emplace(key, cpu);
        return cpu;
    } catch (const OCIO::Exception &e) {
        FACET_THROW(
            "OpenColorIO: cannot build the display transform (display \"{}\", view \"{}\") from "
            "config \"{}\": {}",
            display, view, config_path, e.what());
    }
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

/// Display-referred 8-bit pixels for `image` (first 1-4 channels, see output_channels()).
std::vector<uint8_t> to_display_8bit(const Image &image, const std::vector<int> &ch,
                                     const ImageWriteOptions &opts) {
    const size_t npix = size_t(image.width) * size_t(image.height);
    const int nout = int(ch.size());
    const bool grey = nout <= 2, alpha = nout == 2 || nout == 4;
    // OCIO works on RGB or RGBA; grey values are expanded to RGB and the red channel is kept.
    // Films developed to CIE XYZ (pixel_format xyz) are displayed through linear Rec.709.
    const bool xyz = !grey && image.channel_names.size() >= 3 && image.channel_names[0] == "X" &&
                     image.channel_names[1] == "Y" && image.channel_names[2] == "Z";
    std::vector<float> rgb(npix * 3);
    for (size_t i = 0; i < npix; ++i) {
        const float *src = image.data.data() + i * image.channels;
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = src[grey ? ch[0] : ch[c]];
        if (xyz) {
            Color3f c = xyz_to_srgb(Color3f(rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]));
            rgb[i * 3] = c.r;
            rgb[i * 3 + 1] = c.g;
            rgb[i * 3 + 2] = c.b;
        }
    }
    auto cpu = display_processor(ocio_config_path(opts.ocio_config), opts.display, opts.view);
    OCIO::PackedImageDesc desc(rgb.data(), long(image.width), long(image.height), 3);
    cpu->apply(desc);

    auto quantise = [](float v) -> uint8_t {
        if (!(v > 0.f)) return 0; // NaN too
        return uint8_t(std::lround(std::min(v, 1.f) * 255.f));
    };
    std::vector<uint8_t> out(npix * nout);
    for (size_t i = 0; i < npix; ++i) {
        uint8_t *dst = out.data() + i * nout;
        if (grey) {
            dst[0] = quantise(rgb[i * 3]);
        } else {
            for (int c = 0; c < 3; ++c) dst[c] = quantise(rgb[i * 3 + c]);
        }
        if (alpha) dst[nout - 1] = quantise(image.data[i * image.channels + ch[nout - 1]]);
    }
    return out;
}

std::string temp_path_for(const std::string &path) {
    fs::path p(path);
    fs::path dir = p.parent_path();
    std::string name = "." + p.filename().string() + ".tmp-" + std::to_string(::getpid());
    return dir.empty() ? name : (dir / name).string();
}

/// Removes the temporary file when the write does not complete.
struct TempFileGuard {
    std::string path;
    bool armed = true;
    ~TempFileGuard() {
        if (armed) std::remove(path.c_str());
    }
};

/// Portable float map writer. OpenImageIO 2.4 reads PFM but has no PFM writer, and the format
/// is a 3-line header plus raw little-endian floats, bottom row first.
bool write_pfm(const std::string &file, const float *pixels, int width, int height, int channels,
               std::string &err) {
    std::FILE *f = std::fopen(file.c_str(), "wb");
    if (!f) {
        err = std::strerror(errno);
        return false;
    }
    bool ok = std::fprintf(f, "%s\n%d %d\n-1.0\n", channels == 1 ? "Pf" : "PF", width, height) > 0;
    static_assert(sizeof(float) == 4, "PFM stores 32-bit floats");
    for (int y = height - 1; ok && y >= 0; --y) {
        const size_t n = size_t(width) * size_t(channels);
        ok = std::fwrite(pixels + size_t(y) * n, sizeof(float), n, f) == n;
    }
    if (!ok) err = std::strerror(errno);
    if (std::fclose(f) != 0 && ok) {
        ok = false;
        err = std::strerror(errno);
    }
    return ok;
}

} // namespace

void write_image(const std::string &path, const Image &image, const ImageWriteOptions &opts) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
        image.data.size() != size_t(image.width) * size_t(image.height) * size_t(image.channels))
        FACET_THROW("cannot write image \"{}\": invalid image ({}x{}, {} channels, {} values)",
                    path, image.width, image.height, image.channels, image.data.size());
    fs::path dir = fs::path(path).parent_path();
    if (!dir.empty() && !fs::is_directory(dir))
        FACET_THROW("cannot write image \"{}\": the folder \"{}\" does not exist", path,
                    dir.string());

    const std::string ext = lower_extension(path);
    const bool pfm = ext == ".pfm";
    // The plugin is chosen by the target's extension; the data goes to a temporary file first.
    std::unique_ptr<OIIO::ImageOutput> out = pfm ? nullptr : OIIO::ImageOutput::create(path);
    if (!out && !pfm)
        FACET_THROW("cannot write image \"{}\": no image format for the extension \"{}\" ({})",
                    path, ext, OIIO::geterror());

    const bool linear = is_linear_format(ext);
    std::vector<float> linear_pixels;
    std::vector<uint8_t> display_pixels;
    OIIO::ImageSpec spec;
    const void *pixels = nullptr;
    OIIO::TypeDesc pixel_type;

    if (ext == ".exr") {
        spec = OIIO::ImageSpec(image.width, image.height, image.channels,
                               opts.half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
        for (int c = 0; c < image.channels; ++c) {
            std::string name = c < int(image.channel_names.size()) ? image.channel_names[c] : "";
            if (name.empty())
                name = image.channels == 1
                           ? "Y"
                           : (c < 4 ? std::string(1, "RGBA"[c]) : fmt::format("channel{}", c));
            spec.channelnames[c] = name;
        }
        spec.alpha_channel = -1;
        for (int c = 0; c < image.channels; ++c)
            if (spec.channelnames[c] == "A") spec.alpha_channel = c;
        spec.attribute("compression", "zip");
        // A crop window: data window at (x, y) inside the full display window.
        spec.x = image.x;
        spec.y = image.y;
        spec.full_x = spec.full_y = 0;
        spec.full_width = image.full_width > 0 ? image.full_width : image.x + image.width;
        spec.full_height = image.full_height > 0 ? image.full_height : image.y + image.height;
        pixels = image.data.data();
        pixel_type = OIIO::TypeDesc::FLOAT;
    } else {
        std::vector<int> ch = output_channels(image, path);
        const int n = int(ch.size());
        if (linear) {
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
            pixels = display_pixels.data();
            pixel_type = OIIO::TypeDesc::UINT8;
        }
    }
    for (const auto &[key, value] : opts.metadata) spec.attribute(key, value);

    const std::string tmp = temp_path_for(path);
    TempFileGuard guard{tmp};
    if (pfm) {
        std::string err;
        if (!write_pfm(tmp, static_cast<const float *>(pixels), spec.width, spec.height,
                       spec.nchannels, err))
            FACET_THROW("cannot write image \"{}\": {}", path, err);
    } else if (!out->open(tmp, spec))
        FACET_THROW("cannot write image \"{}\": {}", path, out->geterror());
    if (out) {
        bool ok = out->write_image(pixel_type, pixels);
        std::string err = ok ? "" : out->geterror();
        if (!out->close() && ok) {
            ok = false;
            err = out->geterror();
        }
        out.reset();
        if (!ok) FACET_THROW("cannot write image \"{}\": {}", path, err);
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
        FACET_THROW("cannot write image \"{}\": renaming the temporary file failed: {}", path,
                    std::strerror(errno));
    guard.armed = false;
}

Image read_image(const std::string &path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        FACET_THROW("cannot read image \"{}\": {}", path,
                    fs::exists(path, ec) ? "not a regular file" : "no such file");
    auto in = OIIO::ImageInput::open(path);
    if (!in) FACET_THROW("cannot read image \"{}\": {}", path, OIIO::geterror());
    const OIIO::ImageSpec &spec = in->spec();
    Image img(spec.width, spec.height, spec.nchannels);
    img.channel_names.assign(spec.channelnames.begin(), spec.channelnames.end());
    // The data window (the pixels read) inside the display window (origin 0 in facet's files).
    img.x = spec.x - spec.full_x;
    img.y = spec.y - spec.full_y;
    img.full_width = spec.full_width;
    img.full_height = spec.full_height;
    bool ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img.data.data());
    std::string err = ok ? "" : in->geterror();
    in->close();
    if (!ok) FACET_THROW("cannot read image \"{}\": {}", path, err);
    return img;
}

std::string ocio_config_path(const std::string &explicit_path) {
    if (!explicit_path.empty()) return explicit_path;
    if (const char *env = std::getenv("OCIO"); env && *env) return env;

    std::vector<fs::path> candidates;
    // Next to libfacet: <prefix>/lib/libfacet.so -> <prefix>/share/facet; a multiarch libdir
    // (lib/<triplet>) is one level deeper.
    Dl_info info;
    if (dladdr(reinterpret_cast<void *>(&ocio_config_path), &info) && info.dli_fname) {
        fs::path libdir = fs::absolute(fs::path(info.dli_fname)).parent_path();
        candidates.push_back(libdir / ".." / "share" / "facet" / "ocio.config");
        candidates.push_back(libdir / ".." / ".." / "share" / "facet" / "ocio.config");
    }
#ifdef FACET_INSTALL_DATA_DIR
    candidates.push_back(fs::path(FACET_INSTALL_DATA_DIR) / "ocio.config");
#endif
#ifdef FACET_BUILD_DATA_DIR
    candidates.push_back(fs::path(FACET_BUILD_DATA_DIR) / "ocio.config");
#endif
    std::string tried;
    for (const auto &c : candidates) {
        std::error_code ec;
        if (fs::is_regular_file(c, ec)) return c.lexically_normal().string();
        tried += "\n  " + c.string();
    }
    FACET_THROW("no OpenColorIO config found: give one with --ocio-config or $OCIO (looked for the "
                "installed one in:{})",
                tried);
}

} // namespace facet
