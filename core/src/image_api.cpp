// The functions of facet/image.h in libfacet: they load libfacet_image (image.cpp, every use of
// OpenImageIO and OpenColorIO) the first time one needs it and forward to it. See
// image_library.h for the structure.

#include "image_library.h"

#include <facet/logger.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <dlfcn.h>
#include <filesystem>
#include <mutex>
#include <thread>

namespace fs = std::filesystem;

namespace facet {

namespace {

std::atomic<const detail::ImageLibrary *> g_library{nullptr};

const detail::ImageLibrary &library() {
    if (const detail::ImageLibrary *lib = g_library.load(std::memory_order_acquire)) return *lib;
    static std::mutex mutex;
    std::lock_guard<std::mutex> lock(mutex);
    if (const detail::ImageLibrary *lib = g_library.load(std::memory_order_relaxed)) return *lib;
    const std::string path = image_library_path();
    // RTLD_LOCAL: OpenImageIO's and OpenColorIO's symbols stay out of the global scope, which
    // plugins loaded later resolve against.
    void *handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle)
        FACET_THROW("cannot load facet's image library (OpenImageIO and OpenColorIO, needed to "
                    "read and write images): {}; it is installed next to libfacet, or "
                    "$FACET_IMAGE_LIBRARY names it",
                    dlerror());
    using Entry = const detail::ImageLibrary *(*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, FACET_IMAGE_LIBRARY_ENTRY));
    const detail::ImageLibrary *lib = entry ? entry() : nullptr;
    if (!lib || lib->version != FACET_IMAGE_LIBRARY_VERSION)
        FACET_THROW("\"{}\" is not the image library of this facet (expected the entry point "
                    "{} of version {}{})",
                    path, FACET_IMAGE_LIBRARY_ENTRY, FACET_IMAGE_LIBRARY_VERSION,
                    lib ? fmt::format(", found version {}", lib->version) : "");
    FACET_LOG(Debug, "loaded the image library {} ({})", path, lib->versions());
    g_library.store(lib, std::memory_order_release); // never unloaded
    return *lib;
}

std::string lower_extension(const std::string &path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

} // namespace

std::string image_library_path() {
    if (const char *env = std::getenv("FACET_IMAGE_LIBRARY"); env && *env) return env;
    Dl_info info;
    if (dladdr(reinterpret_cast<void *>(&image_library_path), &info) && info.dli_fname)
        return (fs::absolute(fs::path(info.dli_fname)).parent_path() / "libfacet_image.so")
            .string();
    return "libfacet_image.so"; // the dynamic loader's search
}

bool image_library_loaded() { return g_library.load(std::memory_order_acquire) != nullptr; }

void preload_image_library() {
    // Joined at exit: a process that ends early (a failed render) does not unload the
    // libraries under the loading thread.
    struct Preloader {
        std::thread thread;
        ~Preloader() {
            if (thread.joinable()) thread.join();
        }
    };
    static Preloader preloader{std::thread([] {
        try {
            library();
        } catch (const std::exception &) {
            // Reported by the first function that needs the library.
        }
    })};
}

void write_image(const std::string &path, const Image &image, const ImageWriteOptions &opts) {
    library().write_image(path, image, opts);
}

void check_image_path(const std::string &path) {
    // The formats facet documents are known without loading the image library, so that a
    // render checks its output name before the first pixel without paying for it; only the
    // library's presence is checked. Other extensions ask OpenImageIO.
    const std::string ext = lower_extension(path);
    static const char *const known[] = {".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    if (ext == ".pfm" || std::find(std::begin(known), std::end(known), ext) != std::end(known)) {
        fs::path dir = fs::path(path).parent_path();
        std::error_code ec;
        if (!dir.empty() && !fs::is_directory(dir, ec))
            FACET_THROW("cannot write image \"{}\": the folder \"{}\" does not exist", path,
                        dir.string());
        if (ext == ".pfm") return; // written by facet itself
        const std::string lib = image_library_path();
        if (lib.find('/') != std::string::npos && !fs::is_regular_file(lib, ec))
            FACET_THROW("cannot write image \"{}\": facet's image library \"{}\" (OpenImageIO "
                        "and OpenColorIO) is missing; it is installed next to libfacet, or "
                        "$FACET_IMAGE_LIBRARY names it",
                        path, lib);
        return;
    }
    library().check_image_path(path);
}

void check_image_output(const std::string &path, const ImageWriteOptions &opts) {
    const std::string ext = lower_extension(path);
    if (ext == ".exr" || ext == ".hdr" || ext == ".rgbe" || ext == ".pfm") {
        // Scene-linear: no display transform to resolve, nothing to load yet.
        check_image_path(path);
        if (!opts.display.empty() || !opts.view.empty() || !opts.looks.empty())
            FACET_LOG(Warn,
                      "\"{}\" stays scene-linear: the OpenColorIO display, view and looks apply "
                      "to 8-bit outputs (.png, .jpg) only",
                      path);
        return;
    }
    library().check_image_output(path, opts);
}

OcioDisplays ocio_displays(const std::string &config_path) {
    return library().ocio_displays(config_path);
}

DisplayView resolve_display_view(const ImageWriteOptions &opts) {
    return library().resolve_display_view(opts);
}

Image read_image(const std::string &path) { return library().read_image(path); }

ImageFile read_image_file(const std::string &path) { return library().read_image_file(path); }

std::string ocio_config_path(const std::string &explicit_path) {
    return library().ocio_config_path(explicit_path);
}

} // namespace facet
