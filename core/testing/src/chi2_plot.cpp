// The chi-square heat map: observed, expected and difference panels with axes, colour scales
// and a title, drawn into an Image and written as a PNG. The text uses a 5×8 pixel font drawn
// for this file (printable ASCII), so the picture needs no font files.

#include <facet/chi2.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/math.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace facet {

namespace {

constexpr double kPi = 3.14159265358979323846;

// -- Text -----------------------------------------------------------------------------------------

/// Glyphs of the characters 32 ('  ') to 126 ('~'), 5 pixels wide and 8 high: row r (0 at the top)
/// is bits 39 - 5r .. 35 - 5r, the leftmost pixel in the highest bit. Capitals and digits sit on
/// rows 0-6; row 7 holds the descenders of g, j, p, q, y and the tails of ',' and ';'.
const uint64_t FONT[95] = {
    0x0000000000ULL, 0x2108420080ULL, 0x5280000000ULL, 0x52beafa940ULL, //   ! " #
    0x23e8e2f880ULL, 0xc644444c60ULL, 0x64a88ac9a0ULL, 0x2100000000ULL, // $ % & '
    0x1110841040ULL, 0x4104211100ULL, 0x012aea9000ULL, 0x0109f21000ULL, // ( ) * +
    0x0000001088ULL, 0x0001f00000ULL, 0x0000000080ULL, 0x0044444000ULL, // , - . /
    0x74675cc5c0ULL, 0x23084211c0ULL, 0x74422223e0ULL, 0xf88820c5c0ULL, // 0 1 2 3
    0x11952f8840ULL, 0xfc3c10c5c0ULL, 0x3221e8c5c0ULL, 0xf844442100ULL, // 4 5 6 7
    0x7462e8c5c0ULL, 0x7462f08980ULL, 0x0008001000ULL, 0x0008001088ULL, // 8 9 : ;
    0x1111041040ULL, 0x003e0f8000ULL, 0x4104111100ULL, 0x7442220080ULL, // < = > ?
    0x746f5bc1c0ULL, 0x7463f8c620ULL, 0xf463e8c7c0ULL, 0x74610845c0ULL, // @ A B C
    0xe4a318cb80ULL, 0xfc21e843e0ULL, 0xfc21e84200ULL, 0x746178c5e0ULL, // D E F G
    0x8c63f8c620ULL, 0x71084211c0ULL, 0x3884214980ULL, 0x8ca98a4a20ULL, // H I J K
    0x84210843e0ULL, 0x8eeb58c620ULL, 0x8c7359c620ULL, 0x746318c5c0ULL, // L M N O
    0xf463e84200ULL, 0x74631ac9a0ULL, 0xf463ea4a20ULL, 0x7c20e087c0ULL, // P Q R S
    0xf908421080ULL, 0x8c6318c5c0ULL, 0x8c6318a880ULL, 0x8c635ad540ULL, // T U V W
    0x8c54454620ULL, 0x8c54421080ULL, 0xf8444443e0ULL, 0x72108421c0ULL, // X Y Z [
    0x0410410400ULL, 0x70842109c0ULL, 0x22a2000000ULL, 0x00000003e0ULL, // backslash ] ^ _
    0x4100000000ULL, 0x001c17c5e0ULL, 0x842d98c7c0ULL, 0x001d0845c0ULL, // ` a b c
    0x085b38c5e0ULL, 0x001d1fc1c0ULL, 0x3251c42100ULL, 0x001f18bc2eULL, // d e f g
    0x842d98c620ULL, 0x20184211c0ULL, 0x100c210a4cULL, 0x84254c5240ULL, // h i j k
    0x61084211c0ULL, 0x00355ac620ULL, 0x002d98c620ULL, 0x001d18c5c0ULL, // l m n o
    0x003d18fa10ULL, 0x001f18bc21ULL, 0x002d984200ULL, 0x001f0707c0ULL, // p q r s
    0x42388424c0ULL, 0x002318cda0ULL, 0x002318a880ULL, 0x00231ad540ULL, // t u v w
    0x0022a22a20ULL, 0x002318bc2eULL, 0x003e2223e0ULL, 0x1108821040ULL, // x y z {
    0x2108421080ULL, 0x4108221100ULL, 0x0011510000ULL,                  // | } ~
};

constexpr int GlyphW = 5, GlyphH = 8;
constexpr int TextScale = 2;                    ///< each font pixel is 2 × 2 image pixels
constexpr int CharW = (GlyphW + 1) * TextScale; ///< advance, one pixel of spacing
constexpr int LineH = GlyphH * TextScale;       ///< height of a line of text
constexpr int LineGap = 6;                      ///< between lines of text

bool glyph_pixel(unsigned char c, int x, int y) {
    if (c < 32 || c > 126) c = '?';
    return x >= 0 && x < GlyphW && y >= 0 && y < GlyphH &&
           ((FONT[c - 32] >> (39 - 5 * y - x)) & 1u);
}

/// The characters as the font draws them: bytes outside printable ASCII (UTF-8 sequences count
/// once) become '?'.
std::string printable(const std::string &text) {
    std::string out;
    for (size_t i = 0; i < text.size(); ++i) {
        unsigned char c = (unsigned char)text[i];
        if (c >= 32 && c <= 126) {
            out += char(c);
        } else if (c >= 0xc0) {
            out += '?';
            while (i + 1 < text.size() && ((unsigned char)text[i + 1] & 0xc0) == 0x80) ++i;
        } else if (c < 0x80) {
            out += ' '; // control characters (tabs, newlines)
        }
    }
    return out;
}

int text_width(const std::string &text) { return int(printable(text).size()) * CharW; }

struct Canvas {
    Image img;
    Canvas(int w, int h, const Color3f &background) : img(w, h, 3) {
        img.channel_names = {"R", "G", "B"};
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) set(x, y, background);
    }
    void set(int x, int y, const Color3f &c) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
        for (int k = 0; k < 3; ++k) img.at(x, y, k) = c[k];
    }
    void rect(int x0, int y0, int w, int h, const Color3f &c) {
        for (int y = y0; y < y0 + h; ++y)
            for (int x = x0; x < x0 + w; ++x) set(x, y, c);
    }
    /// The outline of a rectangle, one pixel outside it.
    void frame(int x0, int y0, int w, int h, const Color3f &c) {
        rect(x0 - 1, y0 - 1, w + 2, 1, c);
        rect(x0 - 1, y0 + h, w + 2, 1, c);
        rect(x0 - 1, y0 - 1, 1, h + 2, c);
        rect(x0 + w, y0 - 1, 1, h + 2, c);
    }
    /// Text with its top-left corner at (x, y).
    void text(int x, int y, const std::string &s, const Color3f &c) {
        std::string p = printable(s);
        for (size_t i = 0; i < p.size(); ++i)
            for (int gy = 0; gy < GlyphH; ++gy)
                for (int gx = 0; gx < GlyphW; ++gx)
                    if (glyph_pixel((unsigned char)p[i], gx, gy))
                        rect(x + int(i) * CharW + gx * TextScale, y + gy * TextScale, TextScale,
                             TextScale, c);
    }
    /// Text centred horizontally on x.
    void text_centred(int x, int y, const std::string &s, const Color3f &c) {
        text(x - text_width(s) / 2, y, s, c);
    }
    void text_right(int x, int y, const std::string &s, const Color3f &c) {
        text(x - text_width(s), y, s, c);
    }
    /// Text centred on x but kept within [x0, x1] (labels of ticks at the ends of an axis).
    void text_within(int x, int x0, int x1, int y, const std::string &s, const Color3f &c) {
        int w = text_width(s);
        text(std::clamp(x - w / 2, x0, std::max(x0, x1 - w)), y, s, c);
    }
};

/// Splits `text` into lines of at most `max_chars` characters, breaking after ", " or a space
/// where it can (a word longer than a line is cut).
std::vector<std::string> wrap(const std::string &text, size_t max_chars) {
    std::vector<std::string> lines;
    std::string rest = printable(text);
    max_chars = std::max<size_t>(max_chars, 8);
    while (rest.size() > max_chars) {
        size_t cut = rest.rfind(' ', max_chars);
        if (cut == std::string::npos || cut < max_chars / 2) cut = max_chars;
        lines.push_back(rest.substr(0, cut));
        rest = rest.substr(cut);
        size_t first = rest.find_first_not_of(' ');
        rest = first == std::string::npos ? std::string() : rest.substr(first);
    }
    if (!rest.empty() || lines.empty()) lines.push_back(rest);
    return lines;
}

// -- Colours --------------------------------------------------------------------------------------

/// A blue-white-red diverging map for t in [-1, 1].
Color3f diverging(double t) {
    t = std::clamp(t, -1.0, 1.0);
    if (t < 0) return lerp(float(-t), Color3f(1.f), Color3f(0.1f, 0.25f, 0.9f));
    return lerp(float(t), Color3f(1.f), Color3f(0.9f, 0.1f, 0.1f));
}

/// A dark-to-bright sequential map for t in [0, 1] (black, purple, orange, yellow-white).
Color3f sequential(double t) {
    t = std::clamp(t, 0.0, 1.0);
    const Color3f stops[] = {
        {0.f, 0.f, 0.02f}, {0.35f, 0.05f, 0.45f}, {0.9f, 0.35f, 0.1f}, {1.f, 0.95f, 0.6f}};
    double x = t * 3.0;
    int i = std::min(2, int(x));
    return lerp(float(x - i), stops[i], stops[i + 1]);
}

const Color3f Background(0.16f), Ink(0.92f), Faint(0.6f), EmptyCell(0.09f),
    ZeroExpectedHit(0.1f, 0.9f, 0.1f);

/// Sample counts as tick labels: "0", "40", "1000", "2.5e4".
std::string count_label(double v) {
    if (v < 1e4) return fmt::format("{:.0f}", v);
    int e = int(std::floor(std::log10(v)));
    double m = v / std::pow(10.0, e);
    std::string ms = fmt::format("{:.1f}", m);
    if (ms.size() > 2 && ms.substr(ms.size() - 2) == ".0") ms = ms.substr(0, ms.size() - 2);
    return fmt::format("{}e{}", ms, e);
}

/// Degrees wrapped to (-180, 180].
double wrap_degrees(double d) {
    d = std::fmod(d, 360.0);
    if (d <= -180.0) d += 360.0;
    if (d > 180.0) d -= 360.0;
    return d;
}

// Margins around the panels, in pixels.
constexpr int MarginLeft = 6 * CharW, MarginRight = 6 * CharW, PanelGap = 3 * CharW;
constexpr int TickLen = 5, Pad = 8, BarH = 14;

} // namespace

Chi2HeatmapLayout chi2_heatmap_layout(const Chi2Result &r) {
    if (r.observed.empty() || r.phi_res <= 0 || r.cos_res <= 0)
        FACET_THROW("write_chi2_heatmap: the result holds no tables");
    Chi2HeatmapLayout l;
    l.cell = std::max(1, 512 / r.phi_res); // panels about 512 pixels wide
    l.panel_width = r.phi_res * l.cell;
    l.panel_height = r.cos_res * l.cell;
    // Display column c shows histogram column c + shift: the panel's centre line (between
    // columns phi_res/2 - 1 and phi_res/2) lies at the cell edge nearest to phi_center.
    double dphi = 2.0 * kPi / r.phi_res;
    long shift = std::lround(r.phi_center / dphi);
    l.column_shift = int(((shift % r.phi_res) + r.phi_res) % r.phi_res);
    l.width = MarginLeft + 3 * l.panel_width + 2 * PanelGap + MarginRight;
    int chars = (l.width - 2 * Pad) / CharW;
    l.title_lines = int(wrap(r.description, size_t(chars)).size()) + 1;
    // Title lines, then the row of panel captions, then the panels.
    l.panel_y = Pad + l.title_lines * (LineH + LineGap) + LineGap + (LineH + LineGap) + TickLen;
    for (int p = 0; p < 3; ++p) l.panel_x[p] = MarginLeft + p * (l.panel_width + PanelGap);
    // Below: φ tick labels and caption, the colour bar with its labels and caption.
    l.bar_y = l.panel_y + l.panel_height + TickLen + 2 * (LineH + LineGap) + Pad;
    l.height = l.bar_y + BarH + TickLen + 3 * (LineH + LineGap) + Pad;
    return l;
}

void write_chi2_heatmap(const std::string &path, const Chi2Result &r) {
    const Chi2HeatmapLayout l = chi2_heatmap_layout(r);
    Canvas cv(l.width, l.height, Background);

    double peak = 0.0;
    for (size_t k = 0; k < r.observed.size(); ++k)
        peak = std::max({peak, r.observed[k], r.expected[k]});
    if (peak <= 0.0) peak = 1.0;
    // Counts on a logarithmic scale, so that faint lobes next to a peak stay visible.
    auto count_t = [&](double v) { return std::log1p(v) / std::log1p(peak); };

    // ---- Title: what was tested, then the statistic and the verdict ----
    int y = Pad;
    for (const std::string &line : wrap(r.description, size_t((l.width - 2 * Pad) / CharW))) {
        cv.text(Pad, y, line, Ink);
        y += LineH + LineGap;
    }
    cv.text(Pad, y,
            fmt::format("chi2 {:.2f}, dof {}, p-value {:.4g} (level {:.3g}): {}; {} samples "
                        "({} smooth)",
                        r.statistic, r.dof, r.p_value, r.significance,
                        r.passed ? "accepted" : "REJECTED", r.samples, r.smooth),
            r.passed ? Ink : Color3f(1.f, 0.45f, 0.35f));

    // ---- Panels ----
    const char *captions[3] = {"observed", "expected", "(o - e) / sqrt(e)"};
    for (int p = 0; p < 3; ++p)
        cv.text(l.panel_x[p], l.panel_y - TickLen - LineH - LineGap, captions[p], Ink);
    cv.text_right(MarginLeft - TickLen - 2, l.panel_y - TickLen - LineH - LineGap, "theta", Faint);
    cv.text(l.panel_x[2] + l.panel_width + TickLen + 2, l.panel_y - TickLen - LineH - LineGap,
            "cos", Faint);
    for (int jc = 0; jc < r.cos_res; ++jc) {
        for (int c = 0; c < r.phi_res; ++c) {
            int ip = (c + l.column_shift) % r.phi_res;
            size_t k = size_t(jc) * r.phi_res + ip;
            double o = r.observed[k], e = r.expected[k];
            Color3f colours[3] = {sequential(count_t(o)), sequential(count_t(e)), EmptyCell};
            if (e > 0.0)
                colours[2] = diverging((o - e) / std::sqrt(e) / 5.0);
            else if (o > 0.0)
                colours[2] = ZeroExpectedHit;
            // cos θ = +1 (the normal) at the top.
            int y0 = l.panel_y + (r.cos_res - 1 - jc) * l.cell;
            for (int p = 0; p < 3; ++p)
                cv.rect(l.panel_x[p] + c * l.cell, y0, l.cell, l.cell, colours[p]);
        }
    }

    // ---- Axes ----
    const double dphi_deg = 360.0 / r.phi_res;
    const double left_deg = -180.0 + l.column_shift * dphi_deg; // φ at each panel's left edge
    for (int p = 0; p < 3; ++p) {
        int x0 = l.panel_x[p], w = l.panel_width, h = l.panel_height;
        cv.frame(x0, l.panel_y, w, h, Faint);
        // φ: ticks at the multiples of 90° (their true azimuths, wherever the centring put them).
        int label_y = l.panel_y + h + TickLen + 3;
        for (int a = -180; a <= 180; a += 90) {
            double offset = std::fmod(a - left_deg + 720.0, 360.0);
            for (double off : {offset, offset + 360.0}) {
                if (off > 360.0 + 1e-9) continue;
                int x = x0 + int(std::lround(off / 360.0 * w));
                if (x > x0 + w) continue;
                cv.rect(x, l.panel_y + h, 1, TickLen + 1, Faint);
                cv.text_within(x, x0, x0 + w, label_y, fmt::format("{}", int(wrap_degrees(a))),
                               Ink);
            }
        }
        cv.text_centred(x0 + w / 2, label_y + LineH + LineGap,
                        fmt::format("phi (degrees), centre {:.0f}", wrap_degrees(left_deg + 180.0)),
                        Faint);
        // θ: ticks every 45° where cos θ puts them (rows are uniform in cos θ).
        for (int t = 0; t <= 180; t += 45) {
            int yt = l.panel_y + int(std::lround((1.0 - std::cos(t * kPi / 180.0)) / 2.0 * h));
            cv.rect(x0 - TickLen - 1, yt, TickLen, 1, Faint);
            if (p == 0)
                cv.text_right(x0 - TickLen - 3,
                              std::clamp(yt - LineH / 2, l.panel_y - 2, l.panel_y + h - LineH + 2),
                              fmt::format("{}", t), Ink);
        }
    }
    // cos θ on the right of the last panel.
    {
        int x0 = l.panel_x[2] + l.panel_width, h = l.panel_height;
        for (int i = 0; i <= 4; ++i) {
            double cv_value = 1.0 - 0.5 * i;
            int yt = l.panel_y + int(std::lround(i / 4.0 * h));
            cv.rect(x0 + 1, yt, TickLen, 1, Faint);
            cv.text(x0 + TickLen + 3,
                    std::clamp(yt - LineH / 2, l.panel_y - 2, l.panel_y + h - LineH + 2),
                    fmt::format("{:g}", cv_value), Ink);
        }
    }

    // ---- Colour scales ----
    const int bar_y = l.bar_y, w = l.panel_width;
    const int label_y = bar_y + BarH + TickLen + 3;
    for (int p = 0; p < 2; ++p) {
        int x0 = l.panel_x[p];
        for (int x = 0; x < w; ++x) cv.rect(x0 + x, bar_y, 1, BarH, sequential((x + 0.5) / w));
        cv.frame(x0, bar_y, w, BarH, Faint);
        // 0, the powers of ten below the peak and the peak, where their labels do not collide.
        std::vector<double> ticks{0.0};
        for (double v = 1.0; v < peak; v *= 10.0) ticks.push_back(v);
        ticks.push_back(peak);
        int right_of_last = -(1 << 20);
        for (size_t i = 0; i < ticks.size(); ++i) {
            std::string label = count_label(ticks[i]);
            int x = x0 + int(std::lround(count_t(ticks[i]) * w));
            int half = text_width(label) / 2;
            bool last = i + 1 == ticks.size();
            if (!last && (x - half < right_of_last + CharW ||
                          x + half + CharW > x0 + w - text_width(count_label(peak))))
                continue;
            cv.rect(x, bar_y + BarH, 1, TickLen + 1, Faint);
            cv.text_within(x, x0, x0 + w, label_y, label, Ink);
            right_of_last = std::max(x0, x - half) + 2 * half;
        }
        cv.text_centred(x0 + w / 2, label_y + LineH + LineGap, "samples per cell (logarithmic)",
                        Faint);
    }
    {
        int x0 = l.panel_x[2];
        for (int x = 0; x < w; ++x)
            cv.rect(x0 + x, bar_y, 1, BarH, diverging(2.0 * (x + 0.5) / w - 1.0));
        cv.frame(x0, bar_y, w, BarH, Faint);
        for (int v = -5; v <= 5; v += 5) {
            int x = x0 + int(std::lround((v + 5) / 10.0 * w));
            cv.rect(x, bar_y + BarH, 1, TickLen + 1, Faint);
            cv.text_within(x, x0, x0 + w, label_y,
                           v > 0 ? fmt::format("+{}", v) : fmt::format("{}", v), Ink);
        }
        int y1 = label_y + LineH + LineGap, y2 = y1 + LineH + LineGap;
        cv.text_centred(x0 + w / 2, y1, "(o-e)/sqrt(e), clamped at 5", Faint);
        std::string legend = "  samples where none were expected";
        int lx = x0 + w / 2 - (CharW + text_width(legend)) / 2;
        cv.rect(lx, y2, CharW, LineH, ZeroExpectedHit);
        cv.text(lx + CharW, y2, legend, Faint);
    }

    ImageWriteOptions wo;
    wo.view = "Raw"; // the colours above are display values already
    write_image(path, cv.img, wo);
}

} // namespace facet
