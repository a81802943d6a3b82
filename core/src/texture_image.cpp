#include <facet/checked.h>
#include <facet/logger.h>
#include <facet/math.h>
#include <facet/texture_image.h>

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <unistd.h>
#include <unordered_map>

namespace facet {

namespace {

constexpr double MiB = double(size_t(1) << 20);

size_t default_budget() {
    if (const char *env = std::getenv("FACET_TEXTURE_MEMORY_MB"); env && *env) {
        char *end = nullptr;
        const unsigned long long mb = std::strtoull(env, &end, 10);
        size_t bytes;
        if (end && *end == 0 && mb > 0 && checked_mul(size_t(mb), size_t(1) << 20, bytes))
            return bytes;
        FACET_LOG(Warn, "FACET_TEXTURE_MEMORY_MB=\"{}\" is not a positive number of MiB; ignored",
                  env);
    }
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    size_t bytes;
    if (pages > 0 && page > 0 && checked_mul(size_t(pages) / 4 * 3, size_t(page), bytes))
        return bytes;
    return size_t(8) << 30;
}

std::atomic<size_t> g_budget{0}; ///< set_texture_memory_budget(); 0: the default
std::atomic<size_t> g_used{0};

/// Bytes of the texture memory budget, taken until destroyed.
class Reservation {
public:
    Reservation() = default;
    Reservation(const Reservation &) = delete;
    Reservation &operator=(const Reservation &) = delete;
    Reservation &operator=(Reservation &&other) noexcept {
        std::swap(m_bytes, other.m_bytes);
        return *this;
    }
    ~Reservation() { g_used.fetch_sub(m_bytes); }

    /// Holds `bytes` from now on; more than before must fit in the budget, or a facet::Error
    /// says that `path`'s `what` does not fit.
    void set(size_t bytes, const std::string &path, const std::string &what) {
        if (bytes <= m_bytes) {
            g_used.fetch_sub(m_bytes - bytes);
            m_bytes = bytes;
            return;
        }
        const size_t more = bytes - m_bytes, budget = texture_memory_budget();
        size_t used = g_used.load();
        while (used <= budget && more <= budget - used)
            if (g_used.compare_exchange_weak(used, used + more)) {
                m_bytes = bytes;
                return;
            }
        FACET_THROW("cannot load image \"{}\": its {} need {:.1f} MiB of texture memory, and the "
                    "images loaded hold {:.1f} MiB of the budget of {:.1f} MiB (set "
                    "FACET_TEXTURE_MEMORY_MB to change it)",
                    path, what, double(more) / MiB, double(used) / MiB, double(budget) / MiB);
    }

private:
    size_t m_bytes = 0;
};

/// An image held by the cache's users, with its share of the budget.
template <typename T> struct Held {
    T value;
    Reservation reservation;
};

/// "device:inode:size:mtime" of a regular file, or "" (the reader says what is wrong).
std::string file_identity(const std::string &path) {
    struct stat st;
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return "";
    return fmt::format("{}:{}:{}:{}.{:09}", (unsigned long long)st.st_dev,
                       (unsigned long long)st.st_ino, (long long)st.st_size,
                       (long long)st.st_mtim.tv_sec, (long)st.st_mtim.tv_nsec);
}

/// One key of the cache: the image its users hold, if any; its mutex serialises the loads.
struct Slot {
    std::mutex mutex;
    std::weak_ptr<const void> image;
};

/// The image of `key`: the one a caller holds, or `load()`'s. Loads of one key run one at a
/// time (the second waits for the first and shares its image); loads of others in parallel.
template <typename T, typename Load>
std::shared_ptr<const T> shared(const std::string &key, const Load &load) {
    static std::mutex mutex;
    static std::unordered_map<std::string, std::shared_ptr<Slot>> cache;
    std::shared_ptr<Slot> slot;
    {
        std::lock_guard<std::mutex> lock(mutex);
        auto it = cache.find(key);
        if (it == cache.end()) {
            // Keys whose images died with their users (and that no one is loading) go: the
            // cache does not grow with every scene a process loads.
            for (auto i = cache.begin(); i != cache.end();)
                i = i->second.use_count() == 1 && i->second->image.expired() ? cache.erase(i)
                                                                             : std::next(i);
            it = cache.emplace(key, std::make_shared<Slot>()).first;
        }
        slot = it->second;
    }
    std::lock_guard<std::mutex> lock(slot->mutex);
    if (std::shared_ptr<const void> held = slot->image.lock())
        return std::static_pointer_cast<const T>(held);
    std::shared_ptr<const T> image = load();
    slot->image = image;
    return image;
}

/// "W x H pixels of C channels", for messages.
std::string pixels_of(const Image &image) {
    return fmt::format("{}x{} pixels of {} channel{}", image.width, image.height, image.channels,
                       image.channels == 1 ? "" : "s");
}

/// Bytes of `values` values of `size` bytes (the reader checked their product already).
size_t bytes_of(const Image &image, int channels, size_t size) {
    size_t n = 0;
    if (!checked_mul(size_t(image.width), size_t(image.height), n) ||
        !checked_mul(n, size_t(channels), n) || !checked_mul(n, size, n))
        return std::numeric_limits<size_t>::max();
    return n;
}

/// sRGB electro-optical transfer function (IEC 61966-2-1): encoded value -> linear.
float srgb_to_linear(float v) {
    if (v <= 0.04045f) return v * (1.f / 12.92f);
    return std::pow((v + 0.055f) * (1.f / 1.055f), 2.4f);
}

/// v rounded to the nearest IEEE half-precision value (ties to even; overflow to infinity).
float round_to_half(float v) {
    if (!std::isfinite(v) || v == 0.f) return v;
    float a = std::fabs(v);
    if (a >= 65520.f) return std::copysign(Infinity, v);
    int e;
    std::frexp(a, &e); // a = m 2^e with m in [0.5, 1): 11 significant bits, subnormals below 2^-14
    int spacing = std::max(e - 11, -24);
    return std::copysign(std::ldexp(std::nearbyint(std::ldexp(a, -spacing)), spacing), v);
}

float decode(float v, const TexelDecoding &how) {
    if (how.srgb) v = srgb_to_linear(v);
    if (how.half) v = round_to_half(v);
    return v;
}

/// The texels of `image` (values as floats, or as `bytes` through `values`), their mean and
/// maximum: every texel in order, as the float path always took them.
void decode_texels(const Image &image, const std::vector<uint8_t> &bytes,
                   const std::array<float, 256> &values, const TexelDecoding &how,
                   TexelImage &out) {
    out.width = image.width;
    out.height = image.height;
    out.channels = image.channels <= 2 ? 1 : 3;
    const size_t n = size_t(out.width) * size_t(out.height), in_c = size_t(image.channels);
    const size_t out_c = size_t(out.channels);
    const bool as_bytes = !bytes.empty();
    if (as_bytes) {
        for (size_t b = 0; b < 256; ++b) out.table[b] = decode(values[b], how);
        out.bytes.resize(n * out_c);
    } else {
        out.floats.resize(n * out_c);
    }
    double sum[3] = {0, 0, 0};
    float max = -Infinity;
    for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < out_c; ++c) {
            float v;
            if (as_bytes) {
                const uint8_t b = bytes[i * in_c + c];
                out.bytes[i * out_c + c] = b;
                v = out.table[b];
            } else {
                v = decode(image.data[i * in_c + c], how);
                out.floats[i * out_c + c] = v;
            }
            sum[c] += double(v);
            max = std::max(max, v);
        }
    }
    out.max = max;
    if (out.channels == 1)
        out.mean = Color3f(float(sum[0] / double(n)));
    else
        out.mean = Color3f(float(sum[0] / double(n)), float(sum[1] / double(n)),
                           float(sum[2] / double(n)));
}

} // namespace

size_t texture_memory_budget() {
    if (const size_t set = g_budget.load()) return set;
    static const size_t fallback = default_budget();
    return fallback;
}

void set_texture_memory_budget(size_t bytes) { g_budget.store(bytes); }

size_t texture_memory_used() { return g_used.load(); }

std::shared_ptr<const Image> read_shared_image(const std::string &path) {
    auto load = [&] {
        const ImageHeader header = read_image_header(path);
        auto held = std::make_shared<Held<Image>>();
        const std::string what = pixels_of(header.image);
        held->reservation.set(bytes_of(header.image, header.image.channels, sizeof(float)), path,
                              what);
        held->value = read_image(path);
        // The file may have changed since its header was read.
        held->reservation.set(held->value.data.size() * sizeof(float), path,
                              pixels_of(held->value));
        return std::shared_ptr<const Image>(held, &held->value);
    };
    const std::string id = file_identity(path);
    if (id.empty()) return load(); // not a regular file: the reader says so
    return shared<Image>(id + "|image", load);
}

std::shared_ptr<const TexelImage> load_texels(const std::string &path, const TexelDecoding &how) {
    auto load = [&] {
        const ImageHeader header = read_image_header(path);
        const Image &h = header.image;
        const int channels = h.channels <= 2 ? 1 : 3;
        const size_t value = header.bytes ? 1 : sizeof(float);
        // The file's values and the texels made of them, before either is allocated.
        size_t need = 0;
        if (!checked_add(bytes_of(h, h.channels, value), bytes_of(h, channels, value), need))
            need = std::numeric_limits<size_t>::max();
        auto held = std::make_shared<Held<TexelImage>>();
        held->reservation.set(need, path, pixels_of(h));
        ByteImage read;
        if (header.bytes)
            read = read_image_bytes(path);
        else
            read.image = read_image(path);
        decode_texels(read.image, read.bytes, read.values, how, held->value);
        const std::string what = pixels_of(read.image);
        read = ByteImage();
        held->reservation.set(held->value.memory(), path, what);
        return std::shared_ptr<const TexelImage>(held, &held->value);
    };
    const std::string id = file_identity(path);
    if (id.empty()) return load(); // not a regular file: the reader says so
    return shared<TexelImage>(
        fmt::format("{}|texels srgb={} half={}", id, int(how.srgb), int(how.half)), load);
}

} // namespace facet
