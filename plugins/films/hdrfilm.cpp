static const char *DOC = R"DOC(
# hdrfilm

High dynamic range film: accumulates filtered samples and develops them to scene-linear values
(linear Rec.709 RGB). The output format follows the extension of the output file: `.exr` keeps
everything (float16 or float32, AOV channels, metadata); `.hdr`/`.rgbe`/`.pfm` keep linear RGB;
`.png`/`.jpg` and other 8-bit formats go through the OpenColorIO display transform.

| Parameter | Type | Default | Description |
|---|---|---|---|
| width | integer | 768 | Image width in pixels (width·height at most 2²⁷) |
| height | integer | 576 | Image height in pixels |
| crop_offset_x | integer | 0 | Left column of the crop window (the part that is rendered; an EXR keeps it as its data window inside the full display window) |
| crop_offset_y | integer | 0 | Top row of the crop window |
| crop_width | integer | width - crop_offset_x | Width of the crop window |
| crop_height | integer | height - crop_offset_y | Height of the crop window |
| file_format | string | openexr | openexr (.exr), rgbe (.rgbe) or pfm (.pfm): the default extension |
| pixel_format | string | rgb | rgb, rgba, luminance, luminance_alpha, xyz or xyza |
| component_format | string | float16 | float16 or float32 (EXR sample type) |
| sample_border | boolean | false | Accepted for compatibility; facet always samples the pixels whose filter footprint reaches the crop window, so a crop's pixels equal those of the full image |
| compensate | boolean | false | Accepted for compatibility, no effect: a pixel's sums are float, each pass's added in a fixed order, and the passes of a split render are added in double |
| high_quality_edges | boolean | false | Mitsuba 0.6 name of sample_border; accepted, no effect |
| banner | boolean | false | Mitsuba 0.6 parameter; accepted, no effect |
| attach_log | boolean | false | Mitsuba 0.6 parameter; accepted, no effect |
| (rfilter) | rfilter | gaussian | Nested reconstruction filter |

```xml
<film type="hdrfilm">
    <integer name="width" value="1920"/>
    <integer name="height" value="1080"/>
    <string name="pixel_format" value="rgba"/>
    <rfilter type="tent"/>
</film>
```
)DOC";

#include <facet/film.h>
#include <facet/plugin.h>
#include <facet/spectrum.h>

#include <algorithm>
#include <cctype>

namespace facet {

class HDRFilm final : public Film {
public:
    enum class PixelFormat { RGB, RGBA, Luminance, LuminanceAlpha, XYZ, XYZA };

    explicit HDRFilm(const Properties &props) : Film(props) {
        std::string file_format = lower(props.get_string("file_format", "openexr"));
        if (file_format == "openexr" || file_format == "exr")
            m_extension = ".exr";
        else if (file_format == "rgbe" || file_format == "hdr")
            m_extension = ".rgbe";
        else if (file_format == "pfm")
            m_extension = ".pfm";
        else
            FACET_THROW_AT(props.location("file_format"),
                           "file_format must be openexr, rgbe or pfm, got \"{}\"", file_format);
        m_file_format = file_format;

        std::string pixel_format = lower(props.get_string("pixel_format", "rgb"));
        if (pixel_format == "rgb")
            m_pixel_format = PixelFormat::RGB;
        else if (pixel_format == "rgba")
            m_pixel_format = PixelFormat::RGBA;
        else if (pixel_format == "luminance")
            m_pixel_format = PixelFormat::Luminance;
        else if (pixel_format == "luminance_alpha")
            m_pixel_format = PixelFormat::LuminanceAlpha;
        else if (pixel_format == "xyz")
            m_pixel_format = PixelFormat::XYZ;
        else if (pixel_format == "xyza")
            m_pixel_format = PixelFormat::XYZA;
        else
            FACET_THROW_AT(props.location("pixel_format"),
                           "pixel_format must be rgb, rgba, luminance, luminance_alpha, xyz or "
                           "xyza, got \"{}\"",
                           pixel_format);
        m_pixel_format_name = pixel_format;
        m_alpha = m_pixel_format == PixelFormat::RGBA ||
                  m_pixel_format == PixelFormat::LuminanceAlpha ||
                  m_pixel_format == PixelFormat::XYZA;

        // Compatibility switches without an effect in facet (see the table above).
        props.get_bool("sample_border", false);
        props.get_bool("compensate", false);
        props.get_bool("high_quality_edges", false);
        props.get_bool("banner", false);
        props.get_bool("attach_log", false);
    }

    Image develop(const FilmBuffer &buffer) const override {
        Image rgb = Film::develop(buffer);
        if (m_pixel_format == PixelFormat::RGB || m_pixel_format == PixelFormat::RGBA) return rgb;

        // Colour channels become Y or XYZ; alpha and AOVs follow unchanged.
        const bool lum = m_pixel_format == PixelFormat::Luminance ||
                         m_pixel_format == PixelFormat::LuminanceAlpha;
        const int ncol = lum ? 1 : 3;
        const int rest = rgb.channels - 3;
        Image out(rgb.width, rgb.height, ncol + rest);
        out.x = rgb.x;
        out.y = rgb.y;
        out.full_width = rgb.full_width;
        out.full_height = rgb.full_height;
        out.channel_names =
            lum ? std::vector<std::string>{"Y"} : std::vector<std::string>{"X", "Y", "Z"};
        out.channel_names.insert(out.channel_names.end(), rgb.channel_names.begin() + 3,
                                 rgb.channel_names.end());
        for (size_t i = 0, n = size_t(rgb.width) * rgb.height; i < n; ++i) {
            const float *src = rgb.data.data() + i * rgb.channels;
            float *dst = out.data.data() + i * out.channels;
            Color3f c(src[0], src[1], src[2]);
            if (lum) {
                dst[0] = c.luminance();
            } else {
                Color3f xyz = srgb_to_xyz(c);
                dst[0] = xyz.r;
                dst[1] = xyz.g;
                dst[2] = xyz.b;
            }
            std::copy(src + 3, src + rgb.channels, dst + ncol);
        }
        return out;
    }

    std::string default_extension() const override { return m_extension; }

    std::string to_string() const override {
        return fmt::format("HDRFilm[file_format={}, pixel_format={}, {}]", m_file_format,
                           m_pixel_format_name, Film::to_string());
    }

private:
    static std::string lower(std::string s) {
        std::transform(s.begin(), s.end(), s.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        return s;
    }

    PixelFormat m_pixel_format = PixelFormat::RGB;
    std::string m_file_format, m_pixel_format_name, m_extension = ".exr";
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::HDRFilm, Film, "hdrfilm",
                          "High dynamic range film (OpenEXR and friends)", DOC, ::facet::AllModes)
