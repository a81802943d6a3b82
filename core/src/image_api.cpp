// The functions of facet/image.h in libfacet: they load libfacet_image (image/, every use of
// OpenImageIO and OpenColorIO), libfacet_exr (writing EXR) or libfacet_read (reading EXR, PNG
// and JPEG) the first time one needs it and forward to it. See image_library.h for the
// structure.

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

/// A module of libfacet's, loaded with dlopen() on first use and never unloaded.
struct Module {
    const char *file;  ///< installed next to libfacet
    const char *env;   ///< names another path
    const char *entry; ///< the one symbol it exports: a function returning its table
    int version;       ///< of the table's layout
    const char *what;  ///< for messages
};

const Module ImageModule{"libfacet_image.so", "FACET_IMAGE_LIBRARY", FACET_IMAGE_LIBRARY_ENTRY,
                         FACET_IMAGE_LIBRARY_VERSION,
                         "image library (OpenImageIO and OpenColorIO, needed to read and write "
                         "images)"};
const Module ExrModule{"libfacet_exr.so", "FACET_EXR_LIBRARY", FACET_EXR_LIBRARY_ENTRY,
                       FACET_EXR_LIBRARY_VERSION,
                       "EXR writer (OpenEXR, needed to write .exr images)"};
const Module ReadModule{"libfacet_read.so", "FACET_READ_LIBRARY", FACET_READ_LIBRARY_ENTRY,
                        FACET_READ_LIBRARY_VERSION,
                        "image reader (OpenEXR, libpng and libjpeg, reading those formats)"};

std::string module_path(const Module &module) {
    if (const char *env = std::getenv(module.env); env && *env) return env;
    Dl_info info;
    if (dladdr(reinterpret_cast<void *>(&module_path), &info) && info.dli_fname)
        return (fs::absolute(fs::path(info.dli_fname)).parent_path() / module.file).string();
    return module.file; // the dynamic loader's search
}

template <typename Table>
const Table &load(const Module &module, std::atomic<const Table *> &slot) {
    if (const Table *table = slot.load(std::memory_order_acquire)) return *table;
    static std::mutex mutex;
    std::lock_guard<std::mutex> lock(mutex);
    if (const Table *table = slot.load(std::memory_order_relaxed)) return *table;
    const std::string path = module_path(module);
    // RTLD_LOCAL: the image libraries' symbols stay out of the global scope, which plugins
    // loaded later resolve against.
    void *handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle)
        FACET_THROW("cannot load facet's {}: {}; it is installed next to libfacet, or ${} names it",
                    module.what, dlerror(), module.env);
    using Entry = const Table *(*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, module.entry));
    const Table *table = entry ? entry() : nullptr;
    if (!table || table->version != module.version)
        FACET_THROW("\"{}\" is not the {} of this facet (expected the entry point {} of version "
                    "{}{})",
                    path, module.file, module.entry, module.version,
                    table ? fmt::format(", found version {}", table->version) : "");
    FACET_LOG(Debug, "loaded {} ({})", path, table->versions());
    slot.store(table, std::memory_order_release);
    return *table;
}

std::atomic<const detail::ImageLibrary *> g_library{nullptr};
std::atomic<const detail::ExrLibrary *> g_exr{nullptr};

const detail::ImageLibrary &library() { return load(ImageModule, g_library); }
const detail::ExrLibrary &exr_library() { return load(ExrModule, g_exr); }

/// libfacet_read, or null when it cannot be loaded: libfacet_image then reads every image (the
/// same pixels, and OpenImageIO's memory), and the reason is logged once.
const detail::ReadLibrary *read_library() {
    static std::atomic<const detail::ReadLibrary *> slot{nullptr};
    static const detail::ReadLibrary *const table = []() -> const detail::ReadLibrary * {
        try {
            return &load(ReadModule, slot);
        } catch (const std::exception &e) {
            FACET_LOG(Warn, "{}; images are read by the image library instead", e.what());
            return nullptr;
        }
    }();
    return table;
}

/// `read` filled by libfacet_read when it reads `path`; false leaves the file to libfacet_image.
bool lean_read(const std::string &path, detail::LeanRead &read) {
    const detail::ReadLibrary *lib = read_library();
    return lib && lib->read(path, read);
}

std::string lower_extension(const std::string &path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

} // namespace

std::string image_library_path() { return module_path(ImageModule); }

bool image_library_loaded() { return g_library.load(std::memory_order_acquire) != nullptr; }

namespace {

/// Loads `load()`'s module on a background thread, once per module.
template <typename Load> void preload(Load load) {
    // Joined at exit: a process that ends early (a failed render) does not unload the
    // libraries under the loading thread.
    struct Preloader {
        std::thread thread;
        ~Preloader() {
            if (thread.joinable()) thread.join();
        }
    };
    static Preloader preloader{std::thread([load] {
        try {
            load();
        } catch (const std::exception &) {
            // Reported by the first function that needs the library.
        }
    })};
}

} // namespace

void preload_image_library() {
    preload([] { library(); });
}

void preload_image_writer(const std::string &path) {
    if (lower_extension(path) == ".exr")
        preload([] { exr_library(); });
    else
        preload_image_library();
}

void write_image(const std::string &path, const Image &image, const ImageWriteOptions &opts) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
        image.data.size() != size_t(image.width) * size_t(image.height) * size_t(image.channels))
        FACET_THROW("cannot write image \"{}\": invalid image ({}x{}, {} channels, {} values)",
                    path, image.width, image.height, image.channels, image.data.size());
    check_image_path(path);
    if (lower_extension(path) == ".exr")
        exr_library().write_exr(path, image, opts);
    else
        library().write_image(path, image, opts);
}

void check_image_path(const std::string &path) {
    // The formats facet documents are known without loading the image library, so that a
    // render checks its output name before the first pixel without paying for it; only the
    // presence of the module that writes it is checked. Other extensions ask OpenImageIO.
    const std::string ext = lower_extension(path);
    static const char *const known[] = {".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    if (ext == ".pfm" || std::find(std::begin(known), std::end(known), ext) != std::end(known)) {
        fs::path dir = fs::path(path).parent_path();
        std::error_code ec;
        if (!dir.empty() && !fs::is_directory(dir, ec))
            FACET_THROW("cannot write image \"{}\": the folder \"{}\" does not exist", path,
                        dir.string());
        if (ext == ".pfm") return; // written by facet itself
        const Module &module = ext == ".exr" ? ExrModule : ImageModule;
        const std::string lib = module_path(module);
        if (lib.find('/') != std::string::npos && !fs::is_regular_file(lib, ec))
            FACET_THROW("cannot write image \"{}\": facet's {} \"{}\" ({}) is missing; it is "
                        "installed next to libfacet, or ${} names it",
                        path, ext == ".exr" ? "EXR writer" : "image library", lib,
                        ext == ".exr" ? "OpenEXR" : "OpenImageIO and OpenColorIO", module.env);
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

Image read_image(const std::string &path) {
    detail::LeanRead read;
    if (lean_read(path, read)) return std::move(read.image);
    return library().read_image(path);
}

ImageFile read_image_file(const std::string &path) { return library().read_image_file(path); }

ImageHeader read_image_header(const std::string &path) {
    detail::LeanRead read;
    read.header_only = true;
    if (lean_read(path, read)) return ImageHeader{std::move(read.image), read.keeps_bytes};
    return library().read_image_header(path);
}

ByteImage read_image_bytes(const std::string &path) {
    detail::LeanRead read;
    read.want_bytes = true;
    if (lean_read(path, read))
        return ByteImage{std::move(read.image), std::move(read.bytes), read.values};
    return library().read_image_bytes(path);
}

std::string ocio_config_path(const std::string &explicit_path) {
    return library().ocio_config_path(explicit_path);
}

} // namespace facet
