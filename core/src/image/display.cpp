// OpenColorIO in libfacet_image: configs (read once), the working space facet's pixels are in,
// display/view transforms and the 8-bit pixels of a display-referred output.
#include "image_module.h"

#include <facet/image.h>
#include <facet/logger.h>
#include <facet/spectrum.h>

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <dlfcn.h>
#include <filesystem>
#include <map>
#include <mutex>
#include <tuple>
#include <utility>

namespace OCIO = OCIO_NAMESPACE;
namespace fs = std::filesystem;

namespace facet {

namespace {

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

} // namespace

namespace detail {

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

} // namespace detail

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
