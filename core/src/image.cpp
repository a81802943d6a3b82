#include "file_output.h"
#include "image_library.h"

#include <facet/checked.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/spectrum.h>

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <utility>

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

/// The parsed config at `config_path`, read once.
OCIO::ConstConfigRcPtr load_ocio_config(const std::string &config_path) {
    static std::mutex mutex;
    static std::map<std::string, OCIO::ConstConfigRcPtr> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(config_path);
    if (it != cache.end()) return it->second;
    try {
        OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(config_path.c_str());
        cache.emplace(config_path, config);
        return config;
    } catch (const OCIO::Exception &e) {
        FACET_THROW("cannot read the OpenColorIO config \"{}\": {}", config_path, e.what());
    }
}

std::string join_names(const std::vector<std::string> &names) {
    if (names.empty()) return "(none)";
    std::string out;
    for (const auto &n : names) out += (out.empty() ? "\"" : ", \"") + n + "\"";
    return out;
}

/// The look names in an OpenColorIO look list ("a, +b, -c", alternatives separated by '|').
std::vector<std::string> look_names(const std::string &looks) {
    std::vector<std::string> names;
    std::string cur;
    auto flush = [&] {
        size_t b = cur.find_first_not_of(" \t+-"), e = cur.find_last_not_of(" \t");
        if (b != std::string::npos && e >= b) names.push_back(cur.substr(b, e - b + 1));
        cur.clear();
    };
    for (char c : looks) {
        if (c == ',' || c == ':' || c == '|')
            flush();
        else
            cur += c;
    }
    flush();
    return names;
}

/// Names and aliases colour-management configs give scene-linear Rec.709 (sRGB primaries, D65
/// white), facet's working space. "linear" alone comes last: Blender's configs mean Rec.709 by
/// it, but the name says nothing about primaries, so a config's interchange roles go first.
const char *const k_rec709_names[] = {"Linear Rec.709 (sRGB)",
                                      "lin_rec709_srgb",
                                      "Linear Rec.709",
                                      "lin_rec709",
                                      "Utility - Linear - sRGB",
                                      "Utility - Linear - Rec.709",
                                      "lin_srgb",
                                      "Linear sRGB",
                                      "srgb_linear",
                                      "sRGB - Linear",
                                      "Linear BT.709"};

/// Scene-linear Rec.709 to CIE XYZ (D65), IEC 61966-2-1.
OCIO::MatrixTransformRcPtr rec709_to_xyz() {
    static const double m[16] = {0.4124564, 0.3575761, 0.1804375, 0,         0.2126729, 0.7151522,
                                 0.0721750, 0,         0.0193339, 0.1191920, 0.9503041, 0,
                                 0,         0,         0,         1};
    OCIO::MatrixTransformRcPtr t = OCIO::MatrixTransform::Create();
    t->setMatrix(m);
    return t;
}

/// The colour space of `config` that facet's pixels are in, and the config to look it up in:
/// a space named (or aliased) as linear Rec.709, else one facet adds to a copy of the config,
/// defined through the config's scene interchange role (ACES2065-1 or CIE XYZ D65), else one
/// named "linear". Throws when the config has none of these.
std::pair<OCIO::ConstConfigRcPtr, std::string> working_space(OCIO::ConstConfigRcPtr config,
                                                             const std::string &path) {
    auto usable = [](const OCIO::ConstColorSpaceRcPtr &cs) {
        return cs && !cs->isData() && cs->getReferenceSpaceType() == OCIO::REFERENCE_SPACE_SCENE;
    };
    for (const char *name : k_rec709_names) {
        OCIO::ConstColorSpaceRcPtr cs = config->getColorSpace(name);
        if (usable(cs)) return {config, cs->getName()};
    }
    // Rec.709 -> the interchange space, then that space's own way to the config's reference.
    auto through = [&](const char *role,
                       OCIO::ConstTransformRcPtr to_interchange) -> OCIO::ConstConfigRcPtr {
        if (!config->hasRole(role)) return nullptr;
        OCIO::ConstColorSpaceRcPtr cs = config->getColorSpace(role);
        if (!usable(cs)) return nullptr;
        OCIO::GroupTransformRcPtr to_reference = OCIO::GroupTransform::Create();
        to_reference->appendTransform(to_interchange->createEditableCopy());
        if (OCIO::ConstTransformRcPtr t = cs->getTransform(OCIO::COLORSPACE_DIR_TO_REFERENCE)) {
            to_reference->appendTransform(t->createEditableCopy());
        } else if (OCIO::ConstTransformRcPtr f =
                       cs->getTransform(OCIO::COLORSPACE_DIR_FROM_REFERENCE)) {
            OCIO::TransformRcPtr inv = f->createEditableCopy();
            inv->setDirection(
                OCIO::CombineTransformDirections(inv->getDirection(), OCIO::TRANSFORM_DIR_INVERSE));
            to_reference->appendTransform(inv);
        }
        OCIO::ColorSpaceRcPtr working = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
        working->setName("facet working space (linear Rec.709)");
        working->setEncoding("scene-linear");
        working->setTransform(to_reference, OCIO::COLORSPACE_DIR_TO_REFERENCE);
        OCIO::ConfigRcPtr copy = config->createEditableCopy();
        copy->addColorSpace(working);
        return copy;
    };
    OCIO::GroupTransformRcPtr to_aces = OCIO::GroupTransform::Create();
    to_aces->appendTransform(rec709_to_xyz());
    OCIO::BuiltinTransformRcPtr xyz_to_aces = OCIO::BuiltinTransform::Create();
    xyz_to_aces->setStyle("UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD");
    xyz_to_aces->setDirection(OCIO::TRANSFORM_DIR_INVERSE);
    to_aces->appendTransform(xyz_to_aces);
    if (auto copy = through("aces_interchange", to_aces))
        return {copy, "facet working space (linear Rec.709)"};
    if (auto copy = through("cie_xyz_d65_interchange", rec709_to_xyz()))
        return {copy, "facet working space (linear Rec.709)"};
    if (OCIO::ConstColorSpaceRcPtr cs = config->getColorSpace("linear"); usable(cs))
        return {config, cs->getName()};
    FACET_THROW("the OpenColorIO config \"{}\" does not say which of its colour spaces is "
                "linear Rec.709 (sRGB primaries), the space facet renders in: name or alias one "
                "\"lin_rec709\", or give the config an aces_interchange or "
                "cie_xyz_d65_interchange role",
                path);
}

/// CPU processor for (config, display, view, looks), created once per combination.
OCIO::ConstCPUProcessorRcPtr display_processor(const DisplayView &dv) {
    static std::mutex mutex;
    static std::map<std::tuple<std::string, std::string, std::string, std::string>,
                    OCIO::ConstCPUProcessorRcPtr>
        cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto key = std::make_tuple(dv.config, dv.display, dv.view, dv.looks);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    try {
        // facet's pixels are linear Rec.709, whatever the config's scene_linear role is.
        auto [config, source] = working_space(load_ocio_config(dv.config), dv.config);
        OCIO::DisplayViewTransformRcPtr dvt = OCIO::DisplayViewTransform::Create();
        dvt->setSrc(source.c_str());
        dvt->setDisplay(dv.display.c_str());
        dvt->setView(dv.view.c_str());
        OCIO::ConstProcessorRcPtr proc;
        if (dv.looks.empty()) {
            proc = config->getProcessor(dvt);
        } else {
            // The looks replace the view's own looks, as in OCIO's viewing pipeline.
            OCIO::LegacyViewingPipelineRcPtr pipeline = OCIO::LegacyViewingPipeline::Create();
            pipeline->setDisplayViewTransform(dvt);
            pipeline->setLooksOverrideEnabled(true);
            pipeline->setLooksOverride(dv.looks.c_str());
            proc = pipeline->getProcessor(config);
        }
        OCIO::ConstCPUProcessorRcPtr cpu = proc->getDefaultCPUProcessor();
        cache.emplace(key, cpu);
        return cpu;
    } catch (const OCIO::Exception &e) {
        FACET_THROW("OpenColorIO: cannot build the display transform (display \"{}\", view "
                    "\"{}\"{}) from config \"{}\": {}",
                    dv.display, dv.view, dv.looks.empty() ? "" : ", looks \"" + dv.looks + "\"",
                    dv.config, e.what());
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
    auto cpu = display_processor(resolve_display_view(opts));
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

OcioDisplays ocio_displays(const std::string &explicit_path) {
    OcioDisplays out;
    out.config = ocio_config_path(explicit_path);
    OCIO::ConstConfigRcPtr config = load_ocio_config(out.config);
    out.description = config->getDescription() ? config->getDescription() : "";
    const char *def = config->getDefaultDisplay();
    out.default_display = def ? def : "";
    for (int i = 0, n = config->getNumDisplays(); i < n; ++i) {
        OcioDisplays::Display d;
        d.name = config->getDisplay(i);
        const char *dview = config->getDefaultView(d.name.c_str());
        d.default_view = dview ? dview : "";
        for (int j = 0, m = config->getNumViews(d.name.c_str()); j < m; ++j)
            d.views.push_back(config->getView(d.name.c_str(), j));
        out.displays.push_back(std::move(d));
    }
    for (int i = 0, n = config->getNumLooks(); i < n; ++i)
        out.looks.push_back(config->getLookNameByIndex(i));
    return out;
}

DisplayView resolve_display_view(const ImageWriteOptions &opts) {
    const OcioDisplays all = ocio_displays(opts.ocio_config);
    OCIO::ConstConfigRcPtr config = load_ocio_config(all.config);
    DisplayView dv;
    dv.config = all.config;
    dv.display = opts.display.empty() ? all.default_display : opts.display;
    dv.looks = opts.looks;
    std::vector<std::string> display_names;
    for (const auto &d : all.displays) display_names.push_back(d.name);
    const OcioDisplays::Display *display = nullptr;
    for (const auto &d : all.displays)
        if (d.name == dv.display) display = &d;
    // A display the config defines but does not list as active is still valid.
    const bool inactive =
        !display && !dv.display.empty() && config->getDisplayAllByName(dv.display.c_str()) >= 0;
    if (!display && !inactive)
        FACET_THROW("the OpenColorIO config \"{}\" has no display \"{}\"; its displays: {} "
                    "(default \"{}\")",
                    all.config, dv.display, join_names(display_names), all.default_display);
    std::vector<std::string> views;
    std::string default_view;
    if (display) {
        views = display->views;
        default_view = display->default_view;
    } else {
        for (int j = 0, m = config->getNumViews(OCIO::VIEW_DISPLAY_DEFINED, dv.display.c_str());
             j < m; ++j)
            views.push_back(config->getView(OCIO::VIEW_DISPLAY_DEFINED, dv.display.c_str(), j));
        default_view = config->getDefaultView(dv.display.c_str());
    }
    dv.view = opts.view.empty() ? default_view : opts.view;
    if (std::find(views.begin(), views.end(), dv.view) == views.end()) {
        // Inactive views of the display are valid too.
        bool defined = false;
        for (int j = 0, m = config->getNumViews(OCIO::VIEW_DISPLAY_DEFINED, dv.display.c_str());
             j < m; ++j)
            defined |=
                dv.view == config->getView(OCIO::VIEW_DISPLAY_DEFINED, dv.display.c_str(), j);
        for (int j = 0, m = config->getNumViews(OCIO::VIEW_SHARED, dv.display.c_str()); j < m; ++j)
            defined |= dv.view == config->getView(OCIO::VIEW_SHARED, dv.display.c_str(), j);
        if (!defined)
            FACET_THROW("the display \"{}\" of the OpenColorIO config \"{}\" has no view \"{}\"; "
                        "its views: {} (default \"{}\")",
                        dv.display, all.config, dv.view, join_names(views), default_view);
    }
    for (const std::string &look : look_names(dv.looks))
        if (!config->getLook(look.c_str()))
            FACET_THROW("the OpenColorIO config \"{}\" has no look \"{}\"; its looks: {}",
                        all.config, look, join_names(all.looks));
    working_space(config, all.config); // refuses a config that cannot say where Rec.709 is
    return dv;
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
namespace {

/// Bytes OpenEXR (3.1) reads for a value of each fixed-size attribute type, whatever size the
/// file gives it.
int exr_fixed_size(const std::string &type) {
    static const std::map<std::string, int> sizes = {
        {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
        {"compression", 1}, {"double", 8},   {"envmap", 1},
        {"float", 4},       {"int", 4},      {"keycode", 28},
        {"lineOrder", 1},   {"m33f", 36},    {"m44f", 64},
        {"m33d", 72},       {"m44d", 128},   {"rational", 8},
        {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
        {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
        {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
    auto it = sizes.find(type);
    return it == sizes.end() ? -1 : it->second;
}

/// The most raw pixel bytes an EXR compression can store per byte of file, with a factor of two
/// to spare, or 0 where there is no useful bound: none 1, RLE 64 (a run of 128 bytes in 2),
/// ZIP and ZIPS 1032 (deflate's limit), PIZ 409.6 (its Huffman coder sends a run of 256 equal
/// 16-bit values as a code, a run code and an 8-bit count: 10 bits at best), PXR24 4/3 of
/// deflate's (24 of 32 bits kept), B44 32/14 and B44A 32/3 (a flat 4x4 block of halves in 3
/// bytes), DWAA and DWAB 64 x 1032 (channels that are not colour are run-length coded, then
/// deflated; a colour channel's 8x8 block, 128 bytes, leaves 2 bytes of DC and 2 of AC to
/// deflate, 33,024 at best). Measured on constant images of 4096x512 halves: PIZ 397, DWAA
/// 3,791, DWAB 9,511.
double exr_max_ratio(int compression) {
    switch (compression) {
    case 0:
        return 2.0;
    case 1:
        return 128.0;
    case 2:
    case 3:
        return 2 * 1032.0;
    case 4:
        return 2 * 409.6;
    case 5:
        return 2 * 1032.0 * 4.0 / 3.0;
    case 6:
        return 2 * 32.0 / 14.0;
    case 7:
        return 2 * 32.0 / 3.0;
    case 8:
    case 9:
        return 2 * 64.0 * 1032.0;
    default:
        return 0.0;
    }
}

/**
 * OpenEXR (3.1) allocates header attributes at sizes the file gives before reading them, so a
 * 1 KB file whose attribute claims 1.7 GB costs that much memory and a minute. The headers are
 * scanned here first, the way OpenEXR reads them:
 * - every attribute must fit in the rest of the file;
 * - a value OpenEXR reads by its contents (fixed-size types, a channel list, a string vector, a
 *   preview image) must take exactly the bytes its size says: OpenEXR does not skip to the
 *   declared end, so a value read past it or short of it makes OpenEXR read the next attribute
 *   from the middle of a value (a channel list that ran on gave a 1.6 GB "attribute" from a
 *   223-byte file);
 * - the pixels the data window and the channel list declare must pass allocation_bytes(), and
 *   fit in the file at the best ratio the compression can reach (exr_max_ratio());
 * - a tile (allocated whole) must pass allocation_bytes() and be at most 256x256 pixels or 4
 *   times the data window (a 20x12 image in tiles of 8 x 16777224 took 2.2 GB and 4 s).
 * Values checked by their size alone are skipped unread; the rest of the file is not read.
 */
void check_exr_headers(const std::string &path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE *)> file(std::fopen(path.c_str(), "rb"),
                                                          &std::fclose);
    if (!file) return; // OpenImageIO reports it
    std::FILE *f = file.get();
    std::fseek(f, 0, SEEK_END);
    const long size_or_error = std::ftell(f);
    if (size_or_error < 8) return;
    const size_t file_size = size_t(size_or_error);
    std::rewind(f);
    // The file's bytes [0, n), read as far as the scan needs them: values checked by their size
    // alone are skipped unread.
    std::vector<unsigned char> buf;
    size_t n = 0;
    auto have = [&](size_t upto) {
        if (upto <= n) return true;
        if (upto > file_size) return false;
        buf.resize(std::min(file_size, std::max({upto, 2 * n, size_t(1) << 16})));
        n += std::fread(buf.data() + n, 1, buf.size() - n, f);
        buf.resize(n);
        return upto <= n;
    };
    if (!have(8) || buf[0] != 0x76 || buf[1] != 0x2f || buf[2] != 0x31 || buf[3] != 0x01) return;
    const bool multipart = (buf[5] & 0x10) != 0; // version field bit 12
    const bool deep_file = (buf[5] & 0x08) != 0; // bit 11: deep data ("non-image")
    size_t pos = 8;
    auto cstring = [&](size_t &at, size_t limit, std::string &out) {
        out.clear();
        while (at < limit && have(at + 1) && buf[at] != 0 && out.size() < 256)
            out += char(buf[at++]);
        if (at >= limit || !have(at + 1) || buf[at] != 0) return false;
        ++at;
        return true;
    };
    auto int32_at = [&](size_t at) {
        int32_t v;
        std::memcpy(&v, buf.data() + at, 4);
        return v;
    };
    auto fail = [&](const std::string &name, const std::string &type, const std::string &why) {
        FACET_THROW("cannot read image \"{}\": the EXR attribute \"{}\" ({}) {}", path, name, type,
                    why);
    };
    std::string name, type, channel;
    for (int header = 0; have(pos + 1); ++header) {
        if (buf[pos] == 0) break; // an empty header ends the list of a multi-part file
        // OpenEXR reads a header over its default one: a 64x64 data window, ZIP, no channels.
        int64_t width = 64, height = 64, pixel_bytes = -1;
        double sampled_bytes = 0.0; // per pixel, for channels stored at 1/(xs ys) of the pixels
        int compression = 3;        // ZIP
        bool deep = deep_file && !multipart;
        uint64_t tile_pixels = 0; // up to (2^32 - 1)^2
        for (;;) {
            if (!have(pos + 1)) return;
            if (buf[pos] == 0) {
                ++pos;
                break;
            }
            if (!cstring(pos, file_size, name) || !cstring(pos, file_size, type) || !have(pos + 4))
                return;
            const int32_t size = int32_at(pos);
            pos += 4;
            if (size < 0 || int64_t(size) > int64_t(file_size) - int64_t(pos))
                fail(name, type, fmt::format("claims {} bytes, more than the file holds", size));
            const size_t end = pos + size_t(size);
            const int fixed = exr_fixed_size(type);
            const bool read_value = fixed >= 0 || type == "chlist" || type == "stringvector" ||
                                    type == "preview" || (type == "string" && name == "type");
            if (read_value && !have(end)) return; // a read error: OpenImageIO reports it
            if (fixed >= 0 && size != fixed) {
                fail(name, type, fmt::format("has {} bytes instead of {}", size, fixed));
            } else if (type == "chlist") {
                // Channels (a name, then type, pLinear, 3 reserved bytes, x and y sampling),
                // then an empty name. Only the list named "channels" describes the pixels.
                const bool pixels_list = name == "channels";
                if (pixels_list) {
                    pixel_bytes = 0;
                    sampled_bytes = 0.0;
                }
                size_t at = pos;
                for (;;) {
                    if (at < end && buf[at] == 0) {
                        ++at;
                        break;
                    }
                    if (!cstring(at, end, channel) || at + 16 > end)
                        fail(name, type, "runs past its size");
                    const int32_t pixel_type = int32_at(at);
                    const int bytes = pixel_type == 1 ? 2 : 4; // HALF, or UINT and FLOAT
                    const int32_t xs = int32_at(at + 8), ys = int32_at(at + 12);
                    if (pixels_list) {
                        pixel_bytes += bytes;
                        if (xs > 0 && ys > 0) sampled_bytes += bytes / (double(xs) * double(ys));
                    }
                    at += 16;
                }
                if (at != end) fail(name, type, "ends before its size");
            } else if (type == "stringvector") {
                size_t at = pos;
                while (at < end) {
                    const int32_t length = at + 4 <= end ? int32_at(at) : -1;
                    if (length < 0 || int64_t(length) > int64_t(end - at - 4))
                        fail(name, type, "has a string that runs past its size");
                    at += 4 + size_t(length);
                }
            } else if (type == "floatvector") {
                if (size % 4 != 0) fail(name, type, "is not a whole number of floats");
            } else if (type == "preview") {
                const uint32_t w = size >= 8 ? uint32_t(int32_at(pos)) : 0;
                const uint32_t h = size >= 8 ? uint32_t(int32_at(pos + 4)) : 0;
                if (size < 8 || uint64_t(w) * h * 4 != uint64_t(size) - 8)
                    fail(name, type, "declares a size its pixels do not have");
            } else if (type == "idmanifest") {
                if (size < 4) fail(name, type, "is shorter than its 4-byte length");
            }
            if (type == "compression" && name == "compression") compression = buf[pos];
            if (type == "string" && name == "type" && multipart) {
                const std::string value(buf.begin() + long(pos), buf.begin() + long(end));
                deep = value == "deepscanline" || value == "deeptile";
            }
            if (type == "tiledesc" && name == "tiles")
                tile_pixels = uint64_t(uint32_t(int32_at(pos))) * uint32_t(int32_at(pos + 4));
            if (type == "box2i" && name == "dataWindow") {
                width = int64_t(int32_at(pos + 8)) - int32_at(pos) + 1;
                height = int64_t(int32_at(pos + 12)) - int32_at(pos + 4) + 1;
            }
            pos = end;
        }
        // The pixels of this part at full resolution, before OpenEXR sizes its buffers by them.
        size_t pixels = 0;
        if (width > 0 && height > 0 && pixel_bytes > 0) {
            if (!checked_mul(size_t(width), size_t(height), pixels))
                pixels = std::numeric_limits<size_t>::max();
            allocation_bytes(pixels, size_t(pixel_bytes), path, "EXR data window");
            // OpenEXR and OpenImageIO allocate whole tiles; beyond the image they hold padding.
            if (tile_pixels > 0) {
                allocation_bytes(size_t(tile_pixels), size_t(pixel_bytes), path, "EXR tile");
                if (tile_pixels > std::max<uint64_t>(4 * uint64_t(pixels), 65536))
                    FACET_THROW("cannot read image \"{}\": its tiles of {} pixels are larger "
                                "than 256x256 and 4 times its {}x{}-pixel data window",
                                path, tile_pixels, width, height);
            }
            // Pixels that cannot be in the file: more than its compression can pack into its
            // bytes (OpenEXR pads a short chunk without an error).
            const double bound = exr_max_ratio(compression) * double(file_size);
            if (!deep && bound > 0.0 && double(pixels) * sampled_bytes > bound)
                FACET_THROW("cannot read image \"{}\": its data window declares {}x{} pixels "
                            "({:.0f} bytes), more than its compression can hold in {} bytes",
                            path, width, height, double(pixels) * sampled_bytes, file_size);
        }
        if (!multipart) break;
    }
}

/**
 * OpenImageIO (2.4) decodes an RLE-compressed BMP whole as it opens the file, into a buffer of
 * a byte per pixel sized from the header: a 55-byte file declaring 604 million by 3 pixels took
 * 1.9 GB and 2 s before any size could be checked. So the header is read here first: the
 * pixels must pass allocation_bytes() (as floats, as read_image() will hold them), and an RLE
 * image may have at most 256 pixels per byte of the file (a run of 255 pixels takes two bytes;
 * only pixels the file leaves undefined can make an image sparser) and must have the depth of
 * its RLE kind.
 */
void check_bmp_header(const std::string &path) {
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) return; // OpenImageIO reports it
    unsigned char h[34] = {};
    const size_t n = std::fread(h, 1, sizeof h, f);
    std::fseek(f, 0, SEEK_END);
    const long file_size = std::ftell(f);
    std::fclose(f);
    // The magics OpenImageIO's reader takes: BM (Windows), BA, CI, CP, PT (OS/2).
    const std::string magic{char(h[0]), char(h[1])};
    if (n < 26 ||
        (magic != "BM" && magic != "BA" && magic != "CI" && magic != "CP" && magic != "PT"))
        return; // too short: OpenImageIO reports it
    auto u32 = [&](int at) {
        return uint32_t(h[at]) | uint32_t(h[at + 1]) << 8 | uint32_t(h[at + 2]) << 16 |
               uint32_t(h[at + 3]) << 24;
    };
    const uint32_t header_size = u32(14);
    int64_t width, height;
    uint32_t compression = 0;
    if (header_size == 12) { // OS/2 BITMAPCOREHEADER: 16-bit sizes, no compression
        width = int64_t(h[18] | h[19] << 8);
        height = int64_t(h[20] | h[21] << 8);
    } else {
        width = std::abs(int64_t(int32_t(u32(18))));
        height = std::abs(int64_t(int32_t(u32(22)))); // negative: rows stored top down
        if (n >= 34) compression = u32(30);
    }
    size_t pixels = 0;
    if (!checked_mul(size_t(width), size_t(height), pixels))
        pixels = std::numeric_limits<size_t>::max();
    allocation_bytes(pixels, sizeof(float), path, "BMP pixels");
    const bool rle = compression == 1 || compression == 2;
    if (rle && file_size > 0 && pixels / 256 > size_t(file_size))
        FACET_THROW("cannot read image \"{}\": the RLE-compressed BMP declares {}x{} pixels, more "
                    "than 256 per byte of its {}-byte file",
                    path, width, height, file_size);
    // RLE8 codes 8-bit and RLE4 4-bit palette indices: OpenImageIO decodes any other depth with
    // them out of bounds (a 24-bit RLE8 file crashed it).
    const int bits = h[28] | h[29] << 8;
    if (rle && bits != (compression == 1 ? 8 : 4))
        FACET_THROW("cannot read image \"{}\": the BMP is RLE{}-compressed with {} bits per pixel "
                    "instead of {}",
                    path, compression == 1 ? 8 : 4, bits, compression == 1 ? 8 : 4);
}

/**
 * The RowsPerStrip of a TIFF's first image, as libtiff reads it (one value of an integer type;
 * any other entry is ignored, and the strip is the whole image), or 0 when the file has none or
 * is not a TIFF. OpenImageIO (2.4) keeps it in an int and reads a band of whole strips through
 * buffers of width x channels x RowsPerStrip values computed in int, not clamped to the image's
 * rows: values from 2^31 on became a negative strip height and corrupted the heap (a 300x50
 * image, release build), and a 217-byte file made it ask for 5.6e15 bytes.
 */
uint64_t tiff_rows_per_strip(const std::string &path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE *)> file(std::fopen(path.c_str(), "rb"),
                                                          &std::fclose);
    if (!file) return 0;
    std::FILE *f = file.get();
    auto read_at = [&](uint64_t at, unsigned char *out, size_t n) {
        return at <= uint64_t(std::numeric_limits<long>::max()) &&
               std::fseek(f, long(at), SEEK_SET) == 0 && std::fread(out, 1, n, f) == n;
    };
    unsigned char h[16];
    if (!read_at(0, h, 8)) return 0;
    const bool little = h[0] == 'I' && h[1] == 'I';
    if (!little && !(h[0] == 'M' && h[1] == 'M')) return 0;
    auto uint = [&](const unsigned char *b, int n) {
        uint64_t v = 0;
        for (int i = 0; i < n; ++i) v |= uint64_t(b[little ? i : n - 1 - i]) << (8 * i);
        return v;
    };
    const uint64_t version = uint(h + 2, 2);
    const bool big = version == 43; // BigTIFF: 8-byte counts and offsets
    if (version != 42 && !(big && read_at(0, h, 16))) return 0;
    const uint64_t ifd = big ? uint(h + 8, 8) : uint(h + 4, 4);
    const int count_bytes = big ? 8 : 2, entry_bytes = big ? 20 : 12, value_bytes = big ? 8 : 4;
    unsigned char e[20];
    if (!read_at(ifd, e, size_t(count_bytes))) return 0;
    const uint64_t entries = uint(e, count_bytes);
    for (uint64_t i = 0; i < std::min<uint64_t>(entries, 65536); ++i) {
        if (!read_at(ifd + uint64_t(count_bytes) + i * uint64_t(entry_bytes), e,
                     size_t(entry_bytes)))
            return 0;
        if (uint(e, 2) != 278) continue; // RowsPerStrip
        const uint64_t type = uint(e + 2, 2), count = uint(e + 4, big ? 8 : 4);
        const unsigned char *value = e + 4 + (big ? 8 : 4);
        // BYTE, SHORT, LONG, LONG8 and their signed kinds (negative values are ignored).
        const int size = type == 1 || type == 6     ? 1
                         : type == 3 || type == 8   ? 2
                         : type == 4 || type == 9   ? 4
                         : type == 16 || type == 17 ? 8
                                                    : 0;
        if (count != 1 || size == 0 || size > value_bytes) return 0;
        const uint64_t v = uint(value, size);
        const bool is_signed = type == 6 || type == 8 || type == 9 || type == 17;
        if (is_signed && (v >> (8 * size - 1)) != 0) return 0;
        return v <= 0xffffffffu ? v : 0; // libtiff ignores what a uint32 cannot hold
    }
    return 0;
}

/**
 * A TIFF's strips as OpenImageIO will buffer them (tiff_rows_per_strip()): a RowsPerStrip that
 * does not fit its int (2^32 - 1, TIFF's "the whole image", becomes -1, which it handles), a strip
 * whose values overflow its int, and a strip over the allocation limit are refused.
 */
void check_tiff_strips(const std::string &path, const OIIO::ImageSpec &spec) {
    const uint64_t rows = tiff_rows_per_strip(path);
    if (rows == 0 || rows == 0xffffffffu) return;
    constexpr uint64_t int_max = uint64_t(std::numeric_limits<int>::max());
    uint64_t values = 0;
    if (rows > int_max || !checked_mul(uint64_t(spec.width), uint64_t(spec.nchannels), values) ||
        !checked_mul(values, rows, values) || values > int_max)
        FACET_THROW("cannot read image \"{}\": its RowsPerStrip of {} for rows of {} pixels of {} "
                    "channels is more than the TIFF reader can address",
                    path, rows, spec.width, spec.nchannels);
    allocation_bytes(size_t(values), spec.format.size(), path, "a TIFF strip");
}

/// The image formats facet reads: Mitsuba 3's (OpenEXR, PNG, JPEG, Radiance RGBE, PFM and the
/// other PNM formats, Targa, BMP) and TIFF, by OpenImageIO's names for its readers.
constexpr const char *ReadableFormats[] = {"openexr", "png",   "jpeg", "hdr",
                                           "pnm",     "targa", "bmp",  "tiff"};

bool is_readable_format(const std::string &name) {
    return std::any_of(std::begin(ReadableFormats), std::end(ReadableFormats),
                       [&](const char *f) { return name == f; });
}

/// Opens `path` with the reader its extension names, or, when that reader cannot open it, with
/// the first other reader of ReadableFormats that recognises the contents. OpenImageIO's own
/// fallback (try_all_readers, turned off when this library loads: facet_image_library()) would hand
/// a file that is not what its name says to each of its thirty readers, camera raw, DICOM, GDAL,
/// OpenVDB and video among them: more parsers exposed to a downloaded asset, and slow (a malformed
/// .png: 0.8 ms of CPU against 0.01 ms with the one reader; under the address sanitizer, most of
/// the image fuzzer's time).
std::unique_ptr<OIIO::ImageInput> open_image(const std::string &path) {
    // Created from the bare extension, the reader is only made; from a file name OpenImageIO
    // would open the file with it too.
    const std::string ext = lower_extension(path);
    auto in = ext.size() > 1 ? OIIO::ImageInput::create(ext.substr(1), /*do_open=*/false) : nullptr;
    std::string error;
    OIIO::ImageSpec spec;
    // Colour is kept as stored next to an alpha channel (Mitsuba drops alpha, it never
    // multiplies colour by it); left to itself OpenImageIO premultiplies PNG, TIFF and Targa.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    if (in && is_readable_format(in->format_name())) {
        if (in->open(path, spec, config)) return in;
        error = in->geterror();
    } else {
        (void)OIIO::geterror(); // "could not find a format reader", said better below
        error = in ? fmt::format("{} files are not read", in->format_name())
                   : "the extension names no image format";
        error += " (facet reads OpenEXR, PNG, JPEG, RGBE, PFM and PNM, Targa, BMP and TIFF)";
    }
    for (const char *format : ReadableFormats) {
        if (in && in->format_name() == std::string(format)) continue;
        auto other = OIIO::ImageInput::create(format, /*do_open=*/false);
        if (!other || !other->valid_file(path)) continue;
        if (other->open(path, spec, config)) return other;
        // The contents are this format's: its reader's error says what is wrong.
        error = fmt::format("read as {} (by its contents): {}", format, other->geterror());
        break;
    }
    if (error.empty()) error = "read error";
    FACET_THROW("cannot read image \"{}\": {}", path, error);
}

/// How read_pixels() reads: the checked header only, or the pixels; where the values are
/// bytes (8-bit, one type for every channel, scanlines), into `bytes` as stored when given.
struct PixelRead {
    bool header_only = false;
    std::vector<uint8_t> *bytes = nullptr;
    bool keeps_bytes = false; ///< out: the values are (or would be) read into `bytes`
};

Image read_pixels(const std::string &path, PixelRead &how) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        FACET_THROW("cannot read image \"{}\": {}", path,
                    fs::exists(path, ec) ? "not a regular file" : "no such file");
    check_exr_headers(path);
    check_bmp_header(path);
    auto in = open_image(path);
    const OIIO::ImageSpec spec = in->spec();
    // The header's sizes are checked before anything is allocated: positive, a 2D flat image,
    // and a product that neither wraps nor exceeds the allocation limit.
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        FACET_THROW("cannot read image \"{}\": it declares {}x{} pixels of {} channels", path,
                    spec.width, spec.height, spec.nchannels);
    if (spec.depth != 1 || spec.deep)
        FACET_THROW("cannot read image \"{}\": {} images are not supported", path,
                    spec.deep ? "deep" : "volume");
    size_t row = 0, values = 0;
    if (!checked_mul(size_t(spec.width), size_t(spec.nchannels), row) ||
        !checked_mul(row, size_t(spec.height), values))
        values = std::numeric_limits<size_t>::max();
    allocation_bytes(values, sizeof(float), path, "image pixels");
    // OpenImageIO's TIFF reader buffers whole strips (check_tiff_strips(), and the row-by-row
    // reading of MinIsWhite files below).
    const bool tiff_strips = spec.tile_width <= 0 && in->format_name() == std::string("tiff");
    if (tiff_strips) check_tiff_strips(path, spec);
    // A band of whole tiles, converted to float by OpenImageIO in a buffer of its own.
    if (spec.tile_width > 0) {
        size_t tiles_x = 0, tile_values = 0;
        const size_t tw = size_t(spec.tile_width), th = size_t(std::max(spec.tile_height, 1));
        const size_t td = size_t(std::max(spec.tile_depth, 1));
        if (!checked_mul((size_t(spec.width) + tw - 1) / tw, tw, tiles_x) ||
            !checked_mul(tiles_x, th, tile_values) || !checked_mul(tile_values, td, tile_values) ||
            !checked_mul(tile_values, size_t(spec.nchannels), tile_values))
            tile_values = std::numeric_limits<size_t>::max();
        allocation_bytes(tile_values, sizeof(float), path, "a row of image tiles");
    }

    Image img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = spec.nchannels;
    img.channel_names.assign(spec.channelnames.begin(), spec.channelnames.end());
    // The data window (the pixels read) inside the display window (origin 0 in facet's files).
    img.x = spec.x - spec.full_x;
    img.y = spec.y - spec.full_y;
    img.full_width = spec.full_width;
    img.full_height = spec.full_height;
    img.channel_names.resize(size_t(spec.nchannels));
    // Read in bands of rows (whole tile rows for tiled files), growing the buffer as rows
    // arrive: a header that claims gigabytes of pixels in a small, truncated file fails at its
    // first missing row instead of after the whole buffer has been zeroed.
    // OpenImageIO 2.4 inverts a MinIsWhite TIFF strip it decompresses itself (deflate, 8 or 16
    // bits, contiguous channels) over channels x its values, writing past the buffer when there
    // is more than one channel (a valid 16x64 grey + alpha file aborted the process). It reads
    // a single row through libtiff and inverts that row's values only: such files are read row
    // by row.
    const bool miniswhite_strips =
        tiff_strips && spec.nchannels > 1 &&
        spec.get_int_attribute("tiff:PhotometricInterpretation", -1) == 0;
    const int band = spec.tile_width > 0 ? std::max(spec.tile_height, 1)
                     : miniswhite_strips
                         ? 1
                         : int(std::clamp<size_t>((size_t(1) << 22) / row, 1, 4096));
    // Scanlines of one type are read in the file's own layout (all channels of spec.format) and
    // converted here, band by band: asked for any other layout, OpenImageIO converts through a
    // 64 MB buffer it allocates for every read, however small the image.
    const bool native_layout = spec.tile_width <= 0 && spec.channelformats.empty();
    const bool convert_here = native_layout && spec.format != OIIO::TypeDesc::FLOAT;
    // Bytes as stored: the values convert_here would convert, unconverted.
    how.keeps_bytes = convert_here && spec.format == OIIO::TypeDesc::UINT8;
    if (how.header_only) return img;
    std::vector<uint8_t> *bytes = how.keeps_bytes ? how.bytes : nullptr;
    std::vector<unsigned char> native;
    bool ok = true;
    for (int y0 = 0; ok && y0 < spec.height; y0 += band) {
        const int y1 = std::min(spec.height, y0 + std::max(band, 1));
        const size_t values = size_t(y1 - y0) * row;
        if (bytes) {
            bytes->resize(size_t(y1) * row);
            ok = in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                    OIIO::TypeDesc::UNKNOWN, bytes->data() + size_t(y0) * row);
            continue;
        }
        img.data.resize(size_t(y1) * row);
        float *dst = img.data.data() + size_t(y0) * row;
        if (spec.tile_width > 0) {
            ok = in->read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y0, spec.y + y1, spec.z,
                                spec.z + 1, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, dst);
        } else if (convert_here) {
            native.resize(values * spec.format.size());
            ok = in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                    OIIO::TypeDesc::UNKNOWN, native.data()) &&
                 OIIO::convert_pixel_values(spec.format, native.data(), OIIO::TypeDesc::FLOAT, dst,
                                            int(values));
        } else {
            ok = in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                    native_layout ? OIIO::TypeDesc::UNKNOWN : OIIO::TypeDesc::FLOAT,
                                    dst);
        }
    }
    std::string err = ok ? "" : in->geterror();
    in->close();
    if (!ok) FACET_THROW("cannot read image \"{}\": {}", path, err.empty() ? "read error" : err);
    return img;
}

} // namespace

namespace {

Image read_pixels_or_throw(const std::string &path, PixelRead &how) {
    // A size that passed every check can still be more than the machine has (a TIFF strip of
    // many more rows than the image, say, which OpenImageIO buffers whole).
    try {
        return read_pixels(path, how);
    } catch (const std::bad_alloc &) {
        FACET_THROW("cannot read image \"{}\": out of memory (a size the file gives is more "
                    "than this machine can allocate)",
                    path);
    }
}

} // namespace

Image read_image(const std::string &path) {
    PixelRead how;
    return read_pixels_or_throw(path, how);
}

ImageHeader read_image_header(const std::string &path) {
    PixelRead how;
    how.header_only = true;
    ImageHeader header;
    header.image = read_pixels_or_throw(path, how);
    header.bytes = how.keeps_bytes;
    return header;
}

ByteImage read_image_bytes(const std::string &path) {
    ByteImage out;
    PixelRead how;
    how.bytes = &out.bytes;
    out.image = read_pixels_or_throw(path, how);
    // Each byte value as the float path converts it (the same conversion, value by value).
    uint8_t all[256];
    for (int i = 0; i < 256; ++i) all[i] = uint8_t(i);
    if (!OIIO::convert_pixel_values(OIIO::TypeDesc::UINT8, all, OIIO::TypeDesc::FLOAT,
                                    out.values.data(), 256))
        FACET_THROW("cannot read image \"{}\": OpenImageIO cannot convert bytes to floats", path);
    return out;
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

// libfacet_image: libfacet loads this file's library on first use (image_api.cpp) and calls it
// through this table, the one symbol the library exports (image_library.h).

namespace facet {

ImageFile read_image_file(const std::string &path) {
    ImageFile file;
    file.image = read_image(path);
    auto in = open_image(path);
    const OIIO::ImageSpec &spec = in->spec();
    // The film's colour comes first; AOVs and raw sums after it may be float32.
    file.half = (spec.channelformats.empty() ? spec.format : spec.channelformats[0]) ==
                OIIO::TypeDesc::HALF;
    for (const OIIO::ParamValue &p : spec.extra_attribs)
        file.attributes[p.name().string()] = p.get_string();
    in->close();
    return file;
}

} // namespace facet

// libpng's own messages. OpenImageIO's PNG reader and writer give libpng an error function that
// records the message and returns; libpng then calls its default one, which prints "libpng
// error: ..." on stderr before it jumps back to OpenImageIO, so a broken PNG printed a line of
// libpng's before facet's error. This library defines png_set_error_fn (exported, see
// core/CMakeLists.txt), to which the dynamic linker binds OpenImageIO's calls ahead of libpng's
// own (this library comes first in the scope of the libraries it loads, unless the program
// itself links libpng): it hands libpng, in place of the caller's error function, one that calls
// it and then jumps back as libpng's default would, without printing; and a silent function in
// place of a missing warning function.
extern "C" {
struct png_struct_def;
using png_struct_ptr = png_struct_def *;
using png_message_fn = void (*)(png_struct_ptr, const char *);
}

namespace {

/// libpng's own png_set_error_fn and png_longjmp (found after this library's).
struct PngFunctions {
    void (*set_error_fn)(png_struct_ptr, void *, png_message_fn, png_message_fn) = nullptr;
    void (*longjmp)(png_struct_ptr, int) = nullptr;
};

const PngFunctions &png_functions() {
    static const PngFunctions functions = [] {
        PngFunctions f;
        f.set_error_fn =
            reinterpret_cast<decltype(f.set_error_fn)>(dlsym(RTLD_NEXT, "png_set_error_fn"));
        f.longjmp = reinterpret_cast<decltype(f.longjmp)>(dlsym(RTLD_NEXT, "png_longjmp"));
        return f;
    }();
    return functions;
}

/// The callers' error functions (OpenImageIO has one for reading, one for writing), each with
/// a quiet_png_error<slot> that calls it.
constexpr int PngErrorSlots = 8;
std::atomic<png_message_fn> g_png_errors[PngErrorSlots];

template <int Slot> void quiet_png_error(png_struct_ptr png, const char *message) {
    g_png_errors[Slot].load()(png, message);
    png_functions().longjmp(png, 1); // what libpng's default does after printing
}

template <int... Slots>
png_message_fn quiet_png_error_fn(png_message_fn fn, std::integer_sequence<int, Slots...>) {
    static constexpr png_message_fn quiet[] = {&quiet_png_error<Slots>...};
    for (int i = 0; i < PngErrorSlots; ++i) {
        png_message_fn expected = nullptr;
        if (g_png_errors[i].compare_exchange_strong(expected, fn) || expected == fn)
            return quiet[i];
    }
    return fn; // more error functions than slots: libpng prints their messages
}

void silent_png_warning(png_struct_ptr, const char *) {}

} // namespace

extern "C" __attribute__((visibility("default"))) void png_set_error_fn(png_struct_ptr png,
                                                                        void *error_ptr,
                                                                        png_message_fn error_fn,
                                                                        png_message_fn warning_fn) {
    const PngFunctions &f = png_functions();
    if (!f.set_error_fn) return; // no libpng: no PNG to handle
    if (error_fn && f.longjmp)
        error_fn = quiet_png_error_fn(error_fn, std::make_integer_sequence<int, PngErrorSlots>());
    f.set_error_fn(png, error_ptr, error_fn, warning_fn ? warning_fn : &silent_png_warning);
}

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
