#include <atomic>
#include <dlfcn.h>
#include <utility>

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
