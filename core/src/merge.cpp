#include <facet/checked.h>
#include <facet/film.h>
#include <facet/logger.h>
#include <facet/merge.h>
#include <facet/mode.h>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <new>
#include <optional>

namespace fs = std::filesystem;

namespace facet::merge {

namespace {

std::string get(const Part &p, const char *key, const std::string &fallback = "") {
    auto it = p.metadata.strings.find(key);
    return it == p.metadata.strings.end() ? fallback : it->second;
}

long long get_int(const Part &p, const char *key, long long fallback) {
    auto it = p.metadata.strings.find(key);
    if (it == p.metadata.strings.end()) return fallback;
    try {
        size_t used = 0;
        long long v = std::stoll(it->second, &used);
        if (used == it->second.size()) return v;
    } catch (const std::exception &) {}
    FACET_THROW("{}: attribute {} is \"{}\", expected an integer", p.name, key, it->second);
}

std::string rect(long long x0, long long y0, long long x1, long long y1) {
    return fmt::format("[{}, {}) x [{}, {})", x0, x1, y0, y1);
}

std::string rect_of(const Part &p) {
    return rect(p.x, p.y, (long long)p.x + p.image.width, (long long)p.y + p.image.height);
}

std::string join(const std::vector<std::string> &v) {
    std::string s;
    for (const auto &x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

/// Where a part's developed and raw channels (Film::raw_channel_names) are. Found by name: an EXR
/// file may list its channels in another order than they were written in.
struct RawLayout {
    std::vector<int> developed; ///< colours (R, G, B or bands), A?, AOVs (in the part's order)
    int values = 0;             ///< the developed channels but alpha (each has its sum)
    int alpha_at = -1;          ///< A's place among the developed channels (none: -1)
    bool sums = false, splats = false;
    /// The raw channels in develop_pixel's order: Σ w·value for each developed channel but A,
    /// Σ w, then the splats.
    std::vector<int> raw;
    std::vector<std::string> raw_names;
};

/// Index of every channel of `names` in the part `p` (the parts' channel sets agree).
std::vector<int> channel_indices(const Part &p, const std::vector<std::string> &names) {
    std::vector<int> out;
    const std::vector<std::string> &have = p.image.channel_names;
    for (const std::string &n : names) {
        auto it = std::find(have.begin(), have.end(), n);
        if (it == have.end()) FACET_THROW("{} has no channel {}", p.name, n);
        out.push_back(int(it - have.begin()));
    }
    return out;
}

RawLayout raw_layout(const Part &p) {
    const std::vector<std::string> &names = p.image.channel_names;
    const std::string prefix = RawChannelPrefix;
    RawLayout l;
    size_t prefixed = 0;
    for (size_t c = 0; c < names.size(); ++c) {
        if (names[c].rfind(prefix, 0) == 0)
            ++prefixed;
        else
            l.developed.push_back(int(c));
    }
    auto name_of = [&](int c) { return names[size_t(c)]; };
    std::vector<std::string> developed_names;
    for (int c : l.developed) developed_names.push_back(name_of(c));
    if (prefixed == 0)
        FACET_THROW("{} has no raw channels ({}sum.R ..., {}weight): passes merge by their "
                    "sums; render the parts with --pass/--passes of this facet",
                    p.name, prefix, prefix);
    auto find = [&](const std::string &name) {
        auto it = std::find(names.begin(), names.end(), name);
        return it == names.end() ? -1 : int(it - names.begin());
    };
    l.sums = find(prefix + "weight") >= 0;
    l.splats = find(prefix + "splat.R") >= 0;
    // Every developed channel is a sum divided by the weight (the film's colours: R, G, B or
    // its bands, then the AOVs), but the alpha, which has no sum of its own.
    for (size_t d = 0; d < developed_names.size(); ++d)
        if (developed_names[d] == "A" && l.alpha_at < 0 && find(prefix + "sum.A") < 0)
            l.alpha_at = int(d);
    l.values = int(developed_names.size()) - (l.alpha_at >= 0 ? 1 : 0);
    const bool rgb = developed_names.size() >= 3 && developed_names[0] == "R" &&
                     developed_names[1] == "G" && developed_names[2] == "B";
    if (developed_names.empty() || (l.sums && find(prefix + "sum." + developed_names[0]) < 0) ||
        (l.splats && !rgb))
        FACET_THROW("{} has the colour channels {}: passes merge the channels a film sums (R, G, "
                    "B or its spectral bands; render them with the pixel format rgb or rgba)",
                    p.name, join(developed_names));
    std::vector<std::string> expect;
    if (l.sums) {
        for (size_t d = 0; d < developed_names.size(); ++d)
            if (int(d) != l.alpha_at) expect.push_back(prefix + "sum." + developed_names[d]);
        expect.push_back(prefix + "weight");
    }
    if (l.splats)
        for (const char *c : {"R", "G", "B"}) expect.push_back(prefix + "splat." + c);
    for (const std::string &e : expect) l.raw.push_back(find(e));
    l.raw_names = expect;
    if (expect.size() != prefixed || std::count(l.raw.begin(), l.raw.end(), -1) > 0) {
        std::vector<std::string> have;
        for (const std::string &n : names)
            if (n.rfind(prefix, 0) == 0) have.push_back(n);
        FACET_THROW("{}: the raw channels {} are not the {} its developed channels need", p.name,
                    join(have), join(expect));
    }
    return l;
}

/// The first non-finite value of a part (a render that went wrong, or a damaged file: one such
/// value would spread through every pixel its sums reach): a facet::Error names the pixel (in
/// the full image) and the channel.
void check_finite(const Part &p) {
    const Image &img = p.image;
    const size_t n = img.data.size();
    for (size_t i = 0; i < n; ++i) {
        if (std::isfinite(img.data[i])) continue;
        const size_t c = i % size_t(img.channels), pixel = i / size_t(img.channels);
        const long long x = p.x + (long long)(pixel % size_t(img.width));
        const long long y = p.y + (long long)(pixel / size_t(img.width));
        FACET_THROW("{}: pixel ({}, {}) has the value {} in its channel {}: a part must hold "
                    "finite values (render it again)",
                    p.name, x, y, img.data[i],
                    c < img.channel_names.size() ? img.channel_names[c] : std::to_string(c));
    }
}

/// The bounding rectangle {x0, y0, x1, y1} of the pixels of the W x H image that no part of
/// `in_pass` covers (the parts do not overlap). Found band by band between the parts' top and
/// bottom edges, without a buffer of the image's size (the display window is only as big as
/// the parts' headers say).
std::array<int, 4> uncovered(const std::vector<const Part *> &in_pass, int W, int H) {
    std::vector<int> edges = {0, H};
    for (const Part *p : in_pass) {
        edges.push_back(p->y);
        edges.push_back(p->y + p->image.height);
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::array<int, 4> box = {W, H, 0, 0};
    std::vector<std::pair<int, int>> spans;
    for (size_t b = 0; b + 1 < edges.size(); ++b) {
        const int ya = edges[b], yb = edges[b + 1];
        spans.clear();
        for (const Part *p : in_pass)
            if (p->y <= ya && ya < p->y + p->image.height)
                spans.emplace_back(p->x, p->x + p->image.width);
        std::sort(spans.begin(), spans.end());
        auto gap = [&](int a, int e) {
            if (a >= e) return;
            box = {std::min(box[0], a), std::min(box[1], ya), std::max(box[2], e),
                   std::max(box[3], yb)};
        };
        int at = 0;
        for (const auto &[a, e] : spans) {
            gap(at, a);
            at = std::max(at, e);
        }
        gap(at, W);
    }
    return box;
}

/// A 4×4 matrix from its 16 row-major elements as text ("1, 0, 0, ..."), as an image file's
/// attribute reads; empty when the text is not that.
std::optional<Matrix4f> parse_matrix(const std::string &text) {
    float v[16];
    const char *at = text.c_str();
    for (float &x : v) {
        while (*at == ',' || *at == ' ') ++at;
        char *end = nullptr;
        x = std::strtof(at, &end);
        if (end == at) return std::nullopt;
        at = end;
    }
    return Matrix4f::from_rows(v);
}

/// Equal up to the 6 significant digits with which a matrix read from a file was written out
/// (a part from a file and one from memory carry the same camera).
bool same_matrix(const Matrix4f &a, const Matrix4f &b) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            const float x = a.m[i][j], y = b.m[i][j];
            if (!(std::abs(x - y) <= 1e-5f * std::max(std::abs(x), std::abs(y)))) return false;
        }
    return true;
}

/// `count` values of `size` bytes for `what`, checked against the allocation limit; running
/// out of memory is a facet::Error that names them.
template <typename T> void allocate(std::vector<T> &v, size_t count, const std::string &what) {
    const size_t bytes = allocation_bytes(count, sizeof(T), "facet merge", what.c_str());
    try {
        v.assign(count, T(0));
    } catch (const std::bad_alloc &) {
        FACET_THROW("facet merge: out of memory for {} ({:.1f} MiB)", what,
                    double(bytes) / double(1 << 20));
    }
}

/// The merge's metadata: what all parts agree on, and the attributes of one render of the whole
/// W x H film with `spp` samples per pixel (0: unknown, the parts do not say) in the parts'
/// summed render time.
FileMetadata merged_metadata(const std::vector<Part> &parts, int W, int H, long long spp) {
    const Part &first = parts[0];
    FileMetadata out;
    for (const auto &entry : first.metadata.strings) {
        // Not a structured binding: C++17 lambdas cannot capture those (clang rejects it).
        const std::string &key = entry.first, &value = entry.second;
        if (key == attr::spp || key == attr::render_time || key == attr::blocks)
            continue; // the merge's own, below
        bool shared = std::all_of(parts.begin(), parts.end(), [&](const Part &p) {
            auto it = p.metadata.strings.find(key);
            return it != p.metadata.strings.end() && it->second == value;
        });
        if (shared) out.strings[key] = value;
    }
    RenderFileInfo info;
    info.spp = info.spp_target = info.spp_total = uint32_t(spp);
    info.crop = {{0, 0, W, H}};
    info.film_width = W;
    info.film_height = H;
    double seconds = 0.0;
    bool timed = true;
    for (const Part &p : parts) {
        std::string t = get(p, attr::render_time);
        timed = timed && !t.empty();
        seconds += std::atof(t.c_str());
    }
    if (timed) info.seconds = seconds;
    for (const char *key : {attr::world_to_camera, attr::world_to_ndc}) {
        auto a = first.metadata.matrices.find(key);
        if (a == first.metadata.matrices.end()) continue;
        const Matrix4f &m = a->second;
        const bool shared = std::all_of(parts.begin(), parts.end(), [&](const Part &p) {
            auto it = p.metadata.matrices.find(key);
            return it != p.metadata.matrices.end() && same_matrix(it->second, m);
        });
        if (shared)
            (std::strcmp(key, attr::world_to_camera) == 0 ? info.world_to_camera
                                                          : info.world_to_ndc) = m;
    }
    // The shared scene, scene hash and seed stay as the parts wrote them.
    const FileMetadata own = render_file_metadata(info);
    for (const auto &[key, value] : own.strings) out.strings[key] = value;
    out.ints = own.ints;
    out.floats = own.floats;
    out.matrices = own.matrices;
    if (spp <= 0) {
        // Parts without a sample count (not written by facet): none is claimed for the merge.
        for (const char *key : {attr::spp, attr::spp_total}) out.strings.erase(key);
        out.ints.erase(attr::samples_per_pixel);
    }
    out.strings[attr::merged_parts] = std::to_string(parts.size());
    return out;
}

} // namespace

Part read_part(const std::string &path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        FACET_THROW("cannot read part \"{}\": {}", path,
                    fs::exists(path, ec) ? "not a regular file" : "no such file");
    // The header first: a data window outside the display window is refused before any pixel
    // is read.
    const Image header = read_image_header(path).image;
    if (header.full_width <= 0 || header.full_height <= 0 || header.x < 0 || header.y < 0 ||
        (long long)header.x + header.width > header.full_width ||
        (long long)header.y + header.height > header.full_height)
        FACET_THROW("{}: its data window {} is not inside its {}x{} display window", path,
                    rect(header.x, header.y, header.x + header.width, header.y + header.height),
                    header.full_width, header.full_height);
    ImageFile file;
    try {
        file = read_image_file(path);
    } catch (const std::bad_alloc &) {
        FACET_THROW("cannot read part \"{}\": out of memory for its {}x{} pixels of {} channels",
                    path, header.width, header.height, header.channels);
    }
    Part part;
    part.name = path;
    part.full_width = file.image.full_width;
    part.full_height = file.image.full_height;
    part.x = file.image.x;
    part.y = file.image.y;
    part.half = file.half;
    part.half_channels = file.half_channels;
    part.image = std::move(file.image);
    for (auto &[name, value] : file.attributes) {
        if (name.rfind("facet:", 0) == 0) part.metadata.strings[name] = value;
        if (name == attr::world_to_camera || name == attr::world_to_ndc) // typed: by name
            if (auto m = parse_matrix(value)) part.metadata.matrices[name] = *m;
    }
    return part;
}

Merged merge_parts(const std::vector<Part> &parts) {
    if (parts.empty()) FACET_THROW("no parts to merge");
    const Part &first = parts[0];
    const int W = first.full_width, H = first.full_height, C = first.image.channels;
    if (W <= 0 || H <= 0) FACET_THROW("{}: its display window is {}x{} pixels", first.name, W, H);
    const long long passes = get_int(first, attr::passes, 1);
    if (passes < 1)
        FACET_THROW("{}: {} is {}, expected at least 1", first.name, attr::passes, passes);

    // Everything that must agree between parts of one render.
    for (const Part &p : parts) {
        if (p.full_width != W || p.full_height != H)
            FACET_THROW("{} is a part of a {}x{} image, {} of a {}x{} image: parts of different "
                        "renders",
                        p.name, p.full_width, p.full_height, first.name, W, H);
        long long n = get_int(p, attr::passes, 1);
        if (n != passes)
            FACET_THROW("{} is a part of a render in {} pass{}, {} of one in {}", p.name, n,
                        n == 1 ? "" : "es", first.name, passes);
        // The same channels, in any order (EXR files list them in their own order).
        std::vector<std::string> a = p.image.channel_names, b = first.image.channel_names;
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
        if (a != b)
            FACET_THROW("{} has the channels {}, {} has {}: parts of different renders", p.name,
                        join(p.image.channel_names), first.name, join(first.image.channel_names));
        for (const char *key : {attr::scene_hash, attr::seed, attr::spp_total}) {
            const std::map<std::string, std::string> &of_first = first.metadata.strings,
                                                     &of_p = p.metadata.strings;
            auto a = of_first.find(key), b = of_p.find(key);
            bool has_a = a != of_first.end(), has_b = b != of_p.end();
            if (has_a != has_b || (has_a && a->second != b->second))
                FACET_THROW("{} has {} {}, {} has {}: parts of different {}", p.name, key,
                            has_b ? b->second : "(none)", first.name, has_a ? a->second : "(none)",
                            std::strcmp(key, attr::seed) == 0        ? "seeds"
                            : std::strcmp(key, attr::spp_total) == 0 ? "sample counts"
                                                                     : "scenes");
        }
        // A part written before parts recorded their mode was rendered in the default one.
        const auto mode_of = [](const Part &part) {
            auto it = part.metadata.strings.find(attr::mode);
            return it == part.metadata.strings.end() ? default_mode() : it->second;
        };
        if (mode_of(p) != mode_of(first))
            FACET_THROW("{} was rendered in the mode {}, {} in {}: parts of different colour "
                        "modes",
                        p.name, mode_of(p), first.name, mode_of(first));
        if (auto it = p.metadata.strings.find(attr::spp_target); it != p.metadata.strings.end())
            FACET_THROW("{} is incomplete: its render was stopped after {} of {} samples per "
                        "pixel",
                        p.name, get(p, attr::spp, "?"), it->second);
        long long i = get_int(p, attr::pass, 0);
        if (i < 0 || i >= passes)
            FACET_THROW("{}: {} is {}, expected 0..{}", p.name, attr::pass, i, passes - 1);
        if (p.x < 0 || p.y < 0 || (long long)p.x + p.image.width > W ||
            (long long)p.y + p.image.height > H)
            FACET_THROW("{}: its data window {} is not inside the {}x{} image", p.name, rect_of(p),
                        W, H);
        if (p.image.width <= 0 || p.image.height <= 0 || p.image.channels <= 0 ||
            p.image.data.size() !=
                size_t(p.image.width) * size_t(p.image.height) * size_t(p.image.channels))
            FACET_THROW("{} holds {} values for {}x{} pixels of {} channels", p.name,
                        p.image.data.size(), p.image.width, p.image.height, p.image.channels);
        check_finite(p);
        if (passes > 1 && get(p, attr::spp).empty())
            FACET_THROW("{} has no {} attribute: passes are averaged by their sample counts",
                        p.name, attr::spp);
    }

    // Passes merge by their raw sums (the parts' channels agree, so one layout fits all).
    const RawLayout raw = passes > 1 ? raw_layout(first) : RawLayout{};
    const int out_channels = passes > 1 ? int(raw.developed.size()) : C;
    const int nraw = int(raw.raw.size());

    // The parts of each pass, checked to cover the image exactly once before anything of the
    // image's size is allocated: the display window is then no larger than the parts' pixels.
    auto parts_of = [&](long long pass) {
        std::vector<const Part *> in_pass;
        for (const Part &p : parts)
            if (get_int(p, attr::pass, 0) == pass) in_pass.push_back(&p);
        return in_pass;
    };
    auto which = [&](long long pass) {
        return passes > 1 ? fmt::format(" of pass {} (of {})", pass, passes) : std::string();
    };
    for (long long pass = 0; pass < passes; ++pass) {
        const std::vector<const Part *> in_pass = parts_of(pass);
        if (in_pass.empty())
            FACET_THROW("pass {} of {} is missing: no part has {} {}", pass, passes, attr::pass,
                        pass);
        // Overlaps, by rectangle intersection.
        for (size_t i = 0; i < in_pass.size(); ++i)
            for (size_t j = i + 1; j < in_pass.size(); ++j) {
                const Part &a = *in_pass[i], &b = *in_pass[j];
                int x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
                int x1 = std::min(a.x + a.image.width, b.x + b.image.width);
                int y1 = std::min(a.y + a.image.height, b.y + b.image.height);
                if (x0 < x1 && y0 < y1 && a.name == b.name)
                    FACET_THROW("{} is given twice{}", a.name, which(pass));
                if (x0 < x1 && y0 < y1)
                    FACET_THROW("{} ({}) and {} ({}) overlap{} in the pixels {}", a.name,
                                rect_of(a), b.name, rect_of(b), which(pass), rect(x0, y0, x1, y1));
            }
        // Holes: with no overlaps, the pass is complete when the areas add up.
        long long area = 0;
        for (const Part *p : in_pass) area += (long long)p->image.width * p->image.height;
        if (area != (long long)W * H) {
            const std::array<int, 4> box = uncovered(in_pass, W, H);
            FACET_THROW("the parts{} leave {} of the {}x{} pixels uncovered, within {}: a part "
                        "is missing",
                        which(pass), (long long)W * H - area, W, H,
                        rect(box[0], box[1], box[2], box[3]));
        }
    }

    Merged out;
    out.passes = int(passes);
    out.image.width = W;
    out.image.height = H;
    out.image.channels = out_channels;
    allocate(out.image.data, size_t(W) * size_t(H) * size_t(out_channels),
             fmt::format("the merged image ({}x{} pixels of {} channels)", W, H, out_channels));
    if (passes > 1)
        for (int c : raw.developed)
            out.image.channel_names.push_back(first.image.channel_names[size_t(c)]);
    else
        out.image.channel_names = first.image.channel_names;
    // Where each part keeps the channels the merge reads: the output's (one pass) or the raw ones.
    auto channels_read = [&](const Part &p) {
        return channel_indices(p, passes > 1 ? raw.raw_names : out.image.channel_names);
    };
    out.half = std::all_of(parts.begin(), parts.end(), [](const Part &p) { return p.half; });
    for (const std::string &name : out.image.channel_names)
        if (std::all_of(parts.begin(), parts.end(), [&name](const Part &p) {
                return std::find(p.half_channels.begin(), p.half_channels.end(), name) !=
                       p.half_channels.end();
            }))
            out.half_channels.push_back(name);

    // Σ of every raw channel over the passes, in pass order (the order a render of all the
    // passes in one process adds them in).
    std::vector<double> sum;
    if (passes > 1)
        allocate(sum, size_t(W) * size_t(H) * size_t(nraw),
                 fmt::format("the sums of the passes ({}x{} pixels of {} channels)", W, H, nraw));
    long long total_spp = 0;
    bool uniform_spp = true;
    for (long long pass = 0; pass < passes; ++pass) {
        const std::vector<const Part *> in_pass = parts_of(pass);
        long long pass_spp = get_int(*in_pass[0], attr::spp, 0);
        for (const Part *p : in_pass) {
            const long long spp = get_int(*p, attr::spp, 0);
            if (spp != pass_spp) uniform_spp = false;
            const std::vector<int> index = channels_read(*p);
            for (int y = 0; y < p->image.height; ++y) {
                const float *src = p->image.data.data() + size_t(y) * p->image.width * C;
                const size_t row = size_t(p->y + y) * W + p->x;
                for (int x = 0; x < p->image.width; ++x) {
                    const float *px = src + size_t(x) * C;
                    if (passes == 1) {
                        float *dst = out.image.data.data() + (row + x) * size_t(C);
                        for (int c = 0; c < C; ++c) dst[c] = px[index[size_t(c)]];
                        continue;
                    }
                    for (int c = 0; c < nraw; ++c)
                        sum[(row + x) * size_t(nraw) + c] += double(px[index[size_t(c)]]);
                }
            }
        }
        total_spp += pass_spp;
    }
    if (passes > 1) {
        if (!uniform_spp)
            FACET_THROW("the parts of one pass have different sample counts: parts of different "
                        "renders");
        // Developed as the film develops: Σ w·value / Σ w, splats over the light paths per
        // pixel of all the passes.
        const double splat_scale = total_spp > 0 ? 1.0 / double(total_spp) : 1.0;
        for (size_t i = 0; i < size_t(W) * H; ++i) {
            const double *s = sum.data() + i * size_t(nraw);
            develop_pixel(raw.sums ? s : nullptr, raw.values,
                          raw.splats ? s + (raw.sums ? raw.values + 1 : 0) : nullptr, splat_scale,
                          raw.alpha_at, out.image.data.data() + i * size_t(out_channels));
        }
    }

    out.metadata = merged_metadata(parts, W, H, uniform_spp ? total_spp : 0);
    return out;
}

void write_merged(const Merged &merged, const std::string &path) {
    ImageWriteOptions opts;
    opts.half = merged.half;
    // Each channel as the parts store it (a film's bands are float16 like R, G, B), and Rec.709
    // chromaticities where the parts' colour is R, G, B or Y.
    opts.half_channels = merged.half_channels;
    const std::vector<std::string> &names = merged.image.channel_names;
    opts.rec709 = !names.empty() && (names[0] == "R" || names[0] == "Y");
    add_metadata(opts, merged.metadata);
    write_image(path, merged.image, opts);
}

} // namespace facet::merge
