// libfacet_exr: facet's EXR writer, on OpenEXR directly. A render's output is an EXR by default,
// and writing one needs neither OpenImageIO nor OpenColorIO: this module and OpenEXR take about
// 3 MiB of memory, where loading OpenImageIO alone takes some 120 MiB (its dependencies'
// code and their static initialisers). libfacet loads it with dlopen() for every .exr it writes
// (image_api.cpp; the interface is image_library.h); every read still goes through
// libfacet_image.

#include "file_output.h"
#include "image_library.h"

#include <facet/image.h>
#include <facet/logger.h>

#include <Imath/ImathBox.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/OpenEXRConfig.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <exception>
#include <set>
#include <thread>

namespace facet {

namespace {

/// OpenEXR's output, straight into the file replace_image_file() writes and checks. The first
/// failed write is kept: OpenEXR writes the table of block offsets from its output file's
/// destructor and swallows what that throws.
class SinkStream : public Imf::OStream {
public:
    explicit SinkStream(const detail::ByteSink &sink) : Imf::OStream("file"), m_sink(sink) {}
    void write(const char c[], int n) override {
        if (n <= 0) return;
        try {
            m_sink.write_at(c, size_t(n), m_pos);
        } catch (const std::exception &e) {
            if (m_failure.empty()) m_failure = e.what();
            throw;
        }
        m_pos += uint64_t(n);
    }
    uint64_t tellp() override { return m_pos; }
    void seekp(uint64_t pos) override { m_pos = pos; }
    const std::string &failure() const { return m_failure; }

private:
    const detail::ByteSink &m_sink;
    uint64_t m_pos = 0;
    std::string m_failure;
};

/// The channels of a developed film's colour (and alpha), as opposed to AOV channels.
bool is_colour_channel(const std::string &name) {
    return name == "R" || name == "G" || name == "B" || name == "A" || name == "X" || name == "Y" ||
           name == "Z";
}

/// The name of channel `c`: the image's, else Y for a single channel, R, G, B, A, channel4, ...
std::string channel_name(const Image &image, int c) {
    if (c < int(image.channel_names.size()) && !image.channel_names[c].empty())
        return image.channel_names[c];
    if (image.channels == 1) return "Y";
    return c < 4 ? std::string(1, "RGBA"[c]) : fmt::format("channel{}", c);
}

/// The header: windows, ZIP compression, the channels (half for the leading colour channels
/// when `opts.half`; AOVs after them always float32, see ImageWriteOptions::half), the
/// caller's attributes, the date and, for Rec.709 pixels (opts.rec709, not XYZ), the
/// chromaticities of linear Rec.709.
Imf::Header exr_header(const Image &image, const std::vector<std::string> &names,
                       const std::vector<Imf::PixelType> &types, const ImageWriteOptions &opts) {
    // A crop window: the data window at (x, y) inside the full display window.
    const int full_width = image.full_width > 0 ? image.full_width : image.x + image.width;
    const int full_height = image.full_height > 0 ? image.full_height : image.y + image.height;
    const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(full_width - 1, full_height - 1));
    const Imath::Box2i data(Imath::V2i(image.x, image.y),
                            Imath::V2i(image.x + image.width - 1, image.y + image.height - 1));
    Imf::Header header(display, data, 1.f, Imath::V2f(0.f, 0.f), 1.f, Imf::INCREASING_Y,
                       Imf::ZIP_COMPRESSION);
    for (size_t c = 0; c < names.size(); ++c)
        header.channels().insert(names[c], Imf::Channel(types[c]));
    for (const auto &[key, value] : opts.metadata) header.insert(key, Imf::StringAttribute(value));
    for (const auto &[key, value] : opts.int_metadata) header.insert(key, Imf::IntAttribute(value));
    for (const auto &[key, value] : opts.float_metadata)
        header.insert(key, Imf::FloatAttribute(value));
    for (const auto &[key, m] : opts.matrix_metadata) {
        // Matrix4f's row-major elements in order, as pbrt-v4 stores its matrices.
        const Imath::M44f value(m.m[0][0], m.m[0][1], m.m[0][2], m.m[0][3], m.m[1][0], m.m[1][1],
                                m.m[1][2], m.m[1][3], m.m[2][0], m.m[2][1], m.m[2][2], m.m[2][3],
                                m.m[3][0], m.m[3][1], m.m[3][2], m.m[3][3]);
        header.insert(key, Imf::M44fAttribute(value));
    }
    // When it was written, as OpenImageIO writes it ("YYYY:MM:DD hh:mm:ss", local time).
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    char date[32];
    if (localtime_r(&now, &local) && std::strftime(date, sizeof date, "%Y:%m:%d %H:%M:%S", &local))
        Imf::addCapDate(header, date);
    const bool xyz = names.size() >= 3 && names[0] == "X" && names[1] == "Y" && names[2] == "Z";
    if (opts.rec709 &&
        !xyz) // red, green, blue and white (D65) xy of Rec.709, the space facet renders in
        Imf::addChromaticities(
            header, Imf::Chromaticities(Imath::V2f(0.64f, 0.33f), Imath::V2f(0.30f, 0.60f),
                                        Imath::V2f(0.15f, 0.06f), Imath::V2f(0.3127f, 0.3290f)));
    return header;
}

/// Slices of the interleaved float pixels at `pixels`, rows `first_row`.. of the data window.
Imf::FrameBuffer frame_buffer(const Image &image, const std::vector<std::string> &names,
                              const float *pixels, int first_row, int rows) {
    Imf::FrameBuffer fb;
    const size_t xstride = sizeof(float) * size_t(image.channels);
    const size_t ystride = xstride * size_t(image.width);
    for (int c = 0; c < image.channels; ++c)
        fb.insert(names[size_t(c)],
                  Imf::Slice::Make(Imf::FLOAT, pixels + c, Imath::V2i(image.x, first_row),
                                   image.width, rows, xstride, ystride));
    return fb;
}

/// Reads the written file `file` back completely and compares it with what was written: the
/// same windows and channels, and every value (as stored: rounded to half where a channel is
/// half). Returns "" or what is wrong.
std::string verify_written(const std::string &file, const Image &image,
                           const std::vector<std::string> &names,
                           const std::vector<Imf::PixelType> &types) {
    try {
        Imf::InputFile in(file.c_str(), 1);
        const Imath::Box2i dw = in.header().dataWindow();
        if (dw.min.x != image.x || dw.min.y != image.y || dw.size().x + 1 != image.width ||
            dw.size().y + 1 != image.height)
            return fmt::format("the written file reads back as {}x{}", dw.size().x + 1,
                               dw.size().y + 1);
        int nchannels = 0;
        for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it)
            ++nchannels;
        if (nchannels != image.channels)
            return fmt::format("the written file reads back with {} channels", nchannels);
        if (!in.isComplete()) return "the written file is incomplete";
        // In bands of rows (about 64 KiB, at least the 16 rows a ZIP block holds), so that the
        // check holds no second copy of the image: the end of a render is its peak of memory.
        const int band =
            std::max(16, int((size_t(1) << 14) / (size_t(image.width) * size_t(image.channels))));
        std::vector<float> back(size_t(std::min(band, image.height)) * image.width *
                                image.channels);
        for (int row = 0; row < image.height; row += band) {
            const int rows = std::min(band, image.height - row);
            in.setFrameBuffer(frame_buffer(image, names, back.data(), image.y + row, rows));
            in.readPixels(image.y + row, image.y + row + rows - 1);
            const float *expected = image.data.data() + size_t(row) * image.width * image.channels;
            for (size_t i = 0, n = size_t(rows) * image.width * image.channels; i < n; ++i) {
                const float want = types[i % size_t(image.channels)] == Imf::HALF
                                       ? float(Imath::half(expected[i]))
                                       : expected[i];
                if (!(back[i] == want || (std::isnan(back[i]) && std::isnan(want))))
                    return "the pixels read back differ from the ones written";
            }
        }
    } catch (const std::exception &e) {
        return fmt::format("the written file does not read back: {}", e.what());
    }
    return "";
}

void write_exr(const std::string &path, const Image &image, const ImageWriteOptions &opts) {
    std::vector<std::string> names;
    std::set<std::string> seen;
    for (int c = 0; c < image.channels; ++c) {
        names.push_back(channel_name(image, c));
        if (!seen.insert(names.back()).second)
            FACET_THROW("cannot write image \"{}\": two channels are named \"{}\"", path,
                        names.back());
    }
    std::vector<Imf::PixelType> types(names.size(), Imf::FLOAT);
    if (!opts.half_channels.empty()) {
        for (size_t c = 0; c < names.size(); ++c)
            if (std::find(opts.half_channels.begin(), opts.half_channels.end(), names[c]) !=
                opts.half_channels.end())
                types[c] = Imf::HALF;
    } else {
        for (size_t c = 0; opts.half && c < names.size() && is_colour_channel(names[c]); ++c)
            types[c] = Imf::HALF;
    }

    // OpenEXR compresses blocks of 16 rows: large images on all cores, as OpenImageIO did; a
    // small one (a render's typical preview or test) on this thread, without starting a pool
    // of threads (each with its own heap: 0.3 MiB at the end of a render, its peak of memory).
    int threads = 0;
    if (size_t(image.width) * size_t(image.height) >= (size_t(1) << 20)) {
        static const int pool = [] {
            Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
            return Imf::globalThreadCount();
        }();
        threads = pool;
    }
    const auto encode = [&](const detail::ByteSink &sink) {
        try {
            // OpenEXR writes slices of the channel's own type: the half channels are rounded
            // here, interleaved like the image, a band of rows at a time (whole ZIP blocks of
            // 16 rows, about 256 KiB, so that the threads still compress several blocks at
            // once), not as a second copy of the image at the end of a render, its peak.
            std::vector<size_t> half_of; // the image channel of each half one
            for (size_t c = 0; c < types.size(); ++c)
                if (types[c] == Imf::HALF) half_of.push_back(c);
            const size_t nhalf = half_of.size(), row_halves = size_t(image.width) * nhalf;
            const int band =
                nhalf == 0 ? image.height
                           : std::max(16, int((size_t(1) << 17) / std::max<size_t>(row_halves, 1)) /
                                              16 * 16);
            std::vector<Imath::half> halves(size_t(std::min(band, image.height)) * row_halves);
            SinkStream stream(sink);
            {
                Imf::OutputFile out(stream, exr_header(image, names, types, opts), threads);
                for (int row = 0; row < image.height; row += band) {
                    const int rows = std::min(band, image.height - row);
                    const float *in =
                        image.data.data() + size_t(row) * image.width * image.channels;
                    for (size_t i = 0, n = size_t(rows) * image.width; i < n; ++i)
                        for (size_t h = 0; h < nhalf; ++h)
                            halves[i * nhalf + h] =
                                Imath::half(in[i * size_t(image.channels) + half_of[h]]);
                    Imf::FrameBuffer fb =
                        frame_buffer(image, names, image.data.data(), image.y, image.height);
                    for (size_t h = 0; h < nhalf; ++h)
                        fb.insert(names[half_of[h]],
                                  Imf::Slice::Make(Imf::HALF, halves.data() + h,
                                                   Imath::V2i(image.x, image.y + row), image.width,
                                                   rows, sizeof(Imath::half) * nhalf,
                                                   sizeof(Imath::half) * row_halves));
                    out.setFrameBuffer(fb);
                    out.writePixels(rows);
                }
            } // OpenEXR writes the table of block offsets here, and keeps its failure to itself
            if (!stream.failure().empty()) FACET_THROW("{}", stream.failure());
        } catch (const Error &) {
            throw; // the file's own write failed: its reason
        } catch (const std::exception &e) {
            FACET_THROW("{}", e.what());
        }
    };
    detail::replace_image_file(path, encode, [&](const std::string &file) {
        return verify_written(file, image, names, types);
    });
}

} // namespace

} // namespace facet

extern "C" __attribute__((visibility("default"))) const facet::detail::ExrLibrary *
facet_exr_library() {
    static const facet::detail::ExrLibrary table = {
        FACET_EXR_LIBRARY_VERSION,
        &facet::write_exr,
        [] { return "OpenEXR " OPENEXR_VERSION_STRING; },
    };
    return &table;
}
