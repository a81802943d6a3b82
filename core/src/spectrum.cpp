#include "cie_tables.h"

#include <facet/logger.h>
#include <facet/spectrum.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace facet {

namespace {

constexpr double LambdaMin = 360.0, LambdaMax = 830.0;
constexpr int IntegrationSteps = 1000;
/// Integral of the CIE 1931 y-bar curve (Mitsuba's CIE_Y_integral).
constexpr double CieYIntegral = 106.7502593994140625;
/// Quadrature weight of one step for unweighted spectra (as Mitsuba's RGB variants integrate them).
constexpr double StepWeight = (LambdaMax - LambdaMin) / (CieYIntegral * IntegrationSteps);

inline double step_wavelength(int i) {
    return LambdaMin + (LambdaMax - LambdaMin) * double(i) / double(IntegrationSteps - 1);
}

/// Linear interpolation in one of the 5 nm tables; zero outside 360-830 nm.
double table_lookup(const double *table, double lambda) {
    if (!(lambda >= cie::CIE_FIRST_NM && lambda <= cie::CIE_LAST_NM)) return 0.0;
    double t = (lambda - cie::CIE_FIRST_NM) / cie::CIE_STEP_NM;
    int i = std::min(int(t), cie::CIE_SAMPLES - 2);
    double f = t - i;
    return table[i] * (1.0 - f) + table[i + 1] * f;
}

/// Mitsuba's scale of the D65 table (MI_CIE_D65_NORMALIZATION), which makes D65 integrate to a
/// luminance of 1 against the continuous curves. Over the 1000-step quadrature a white
/// reflectance comes to Y = 0.99889 with it; it is kept, so that spectra match Mitsuba's (a
/// conductor's D65-weighted eta and k move its reflectance by up to 6e-4).
double d65_scale() { return 1.0 / 98.99741751876255; }

double parse_number(const std::string &token, const std::string &what) {
    const char *begin = token.c_str();
    char *end = nullptr;
    errno = 0;
    double v = std::strtod(begin, &end);
    while (end && (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r')) ++end;
    if (end == begin || *end != '\0' || errno == ERANGE)
        FACET_THROW("could not parse {} \"{}\" as a number", what, token);
    return v;
}

std::string trim(const std::string &s) {
    size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

void check_ascending(const SpectrumData &s, const std::string &where) {
    for (size_t i = 1; i < s.wavelengths.size(); ++i)
        if (!(s.wavelengths[i] > s.wavelengths[i - 1]))
            FACET_THROW("{}wavelengths must be strictly ascending ({} nm follows {} nm)", where,
                        s.wavelengths[i], s.wavelengths[i - 1]);
}

} // namespace

double SpectrumData::eval(double lambda) const {
    if (uniform) return value;
    if (wavelengths.empty() || lambda < wavelengths.front() || lambda > wavelengths.back())
        return 0.0;
    size_t hi =
        std::upper_bound(wavelengths.begin(), wavelengths.end(), lambda) - wavelengths.begin();
    if (hi >= wavelengths.size()) return values.back();
    size_t lo = hi - 1;
    double t = (lambda - wavelengths[lo]) / (wavelengths[hi] - wavelengths[lo]);
    return values[lo] * (1.0 - t) + values[hi] * t;
}

std::string SpectrumData::to_string() const {
    if (uniform) return fmt::format("{}", value);
    std::string s;
    for (size_t i = 0; i < wavelengths.size(); ++i)
        s += fmt::format("{}{}:{}", i == 0 ? "" : ", ", wavelengths[i], values[i]);
    return s;
}

SpectrumData parse_spectrum_pairs(const std::string &text) {
    std::string t = trim(text);
    if (t.empty()) FACET_THROW("empty spectrum value");
    if (t.find(':') == std::string::npos) {
        if (t.find(',') != std::string::npos)
            FACET_THROW("spectrum \"{}\": expected a single value or wavelength:value pairs", text);
        return SpectrumData::constant(parse_number(t, "spectrum value"));
    }
    SpectrumData s;
    s.uniform = false;
    for (size_t start = 0; start <= t.size();) {
        size_t end = std::min(t.find(',', start), t.size());
        std::string item = trim(t.substr(start, end - start));
        start = end + 1;
        size_t colon = item.find(':');
        if (item.empty() || colon == std::string::npos ||
            item.find(':', colon + 1) != std::string::npos)
            FACET_THROW("spectrum \"{}\": \"{}\" is not a wavelength:value pair", text, item);
        s.wavelengths.push_back(parse_number(trim(item.substr(0, colon)), "wavelength"));
        s.values.push_back(parse_number(trim(item.substr(colon + 1)), "spectrum value"));
    }
    check_ascending(s, fmt::format("spectrum \"{}\": ", text));
    return s;
}

std::vector<double> parse_number_list(const std::string &text, const std::string &what) {
    std::vector<double> values;
    std::string token;
    auto flush = [&] {
        if (!token.empty()) values.push_back(parse_number(token, what));
        token.clear();
    };
    for (char c : text) {
        if (c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r')
            flush();
        else
            token += c;
    }
    flush();
    if (values.empty()) FACET_THROW("{}: expected a list of numbers, found \"{}\"", what, text);
    return values;
}

SpectrumData read_spd_file(const std::string &path) {
    std::ifstream in(path);
    if (!in) FACET_THROW("could not open spectrum file \"{}\"", path);
    SpectrumData s;
    s.uniform = false;
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        size_t hash = line.find('#');
        if (hash != std::string::npos) line.resize(hash);
        std::istringstream ls(line);
        std::string wl, v, extra;
        if (!(ls >> wl)) continue;
        if (!(ls >> v) || (ls >> extra))
            FACET_THROW("spectrum file \"{}\", line {}: expected \"wavelength value\"", path,
                        line_no);
        try {
            s.wavelengths.push_back(parse_number(wl, "wavelength"));
            s.values.push_back(parse_number(v, "value"));
        } catch (const Error &e) {
            FACET_THROW("spectrum file \"{}\", line {}: {}", path, line_no, e.what());
        }
    }
    if (s.wavelengths.empty()) FACET_THROW("spectrum file \"{}\" contains no data", path);
    check_ascending(s, fmt::format("spectrum file \"{}\": ", path));
    return s;
}

Color3f cie1931_xyz(double lambda) {
    return Color3f(float(table_lookup(cie::X_BAR, lambda)), float(table_lookup(cie::Y_BAR, lambda)),
                   float(table_lookup(cie::Z_BAR, lambda)));
}

double cie_d65(double lambda) { return table_lookup(cie::D65, lambda) * d65_scale(); }

Color3f xyz_to_srgb(const Color3f &c) {
    return {3.240479f * c.r - 1.537150f * c.g - 0.498535f * c.b,
            -0.969256f * c.r + 1.875991f * c.g + 0.041556f * c.b,
            0.055648f * c.r - 0.204043f * c.g + 1.057311f * c.b};
}

Color3f srgb_to_xyz(const Color3f &c) {
    // Inverse of the matrix above (Rec.709 primaries, D65 white).
    return {0.412453f * c.r + 0.357580f * c.g + 0.180423f * c.b,
            0.212671f * c.r + 0.715160f * c.g + 0.072169f * c.b,
            0.019334f * c.r + 0.119193f * c.g + 0.950227f * c.b};
}

Color3f spectrum_to_rgb(const SpectrumData &s, SpectrumKind kind) {
    if (s.uniform) {
        float c = float(s.value);
        if (kind == SpectrumKind::Emission) return xyz_to_srgb(Color3f(1.f)) * c;
        return Color3f(c);
    }
    // Emitters' spectra and the measured conductor data are integrated as they are; everything
    // else a scene gives (reflectances, but also eta, k and alpha) is weighted by D65.
    bool weighted = kind == SpectrumKind::Reflectance || kind == SpectrumKind::Unbounded;
    double x = 0.0, y = 0.0, z = 0.0;
    for (int i = 0; i < IntegrationSteps; ++i) {
        double l = step_wavelength(i);
        double v = s.eval(l);
        if (weighted) v *= table_lookup(cie::D65, l);
        x += table_lookup(cie::X_BAR, l) * v;
        y += table_lookup(cie::Y_BAR, l) * v;
        z += table_lookup(cie::Z_BAR, l) * v;
    }
    double w = StepWeight * (weighted ? d65_scale() : 1.0);
    Color3f rgb = xyz_to_srgb(Color3f(float(x * w), float(y * w), float(z * w)));
    float hi = kind == SpectrumKind::Reflectance ? 1.f : Infinity;
    return {clamp(rgb.r, 0.f, hi), clamp(rgb.g, 0.f, hi), clamp(rgb.b, 0.f, hi)};
}

namespace {

/// The wavelength density's shape 1 / cosh²(a (λ - c)) and its integral tanh(a (λ - c)) / a.
/// Float arithmetic: every camera ray draws four (a wavelength is good to 1e-4 nm).
constexpr float WavelengthA = 0.0072f, WavelengthCentre = 538.f;
const float TanhLo = std::tanh(WavelengthA * (SpectralMinNm - WavelengthCentre));
const float TanhHi = std::tanh(WavelengthA * (SpectralMaxNm - WavelengthCentre));
const float PdfScale = WavelengthA / (TanhHi - TanhLo);

float sample_wavelength(float u) {
    const float t = TanhLo + (TanhHi - TanhLo) * u;
    // atanh(t) = ½ log((1 + t) / (1 - t)); |t| < 0.98 on the range.
    const float lambda = WavelengthCentre + 0.5f * std::log((1.f + t) / (1.f - t)) / WavelengthA;
    return std::min(std::max(lambda, SpectralMinNm), SpectralMaxNm);
}

} // namespace

Color3f cie_d65(const Wavelengths &lambda) {
    return map(lambda, [](float l) { return float(cie_d65(double(l))); });
}

float pdf_wavelength(float lambda) {
    if (!(lambda >= SpectralMinNm && lambda <= SpectralMaxNm)) return 0.f;
    // 1 / cosh²(x) = 4 e^{-2|x|} / (1 + e^{-2|x|})².
    const float e = std::exp(-2.f * std::abs(WavelengthA * (lambda - WavelengthCentre)));
    return PdfScale * 4.f * e / ((1.f + e) * (1.f + e));
}

std::pair<Wavelengths, Color3f> sample_wavelengths(float u) {
    Wavelengths lambda;
    Color3f weight;
    for (int i = 0; i < Color3f::Channels; ++i) {
        float ui = u + float(i) * (1.f / float(Color3f::Channels));
        if (ui >= 1.f) ui -= 1.f;
        lambda[i] = sample_wavelength(ui);
        weight[i] = 1.f / pdf_wavelength(lambda[i]);
    }
    return {lambda, weight};
}

Color3f wavelength_weights(const Wavelengths &lambda) {
    return map(lambda, [](float l) {
        const float pdf = pdf_wavelength(l);
        return pdf > 0.f ? 1.f / pdf : 0.f;
    });
}

Color3f spectral_to_xyz(const Color3f &L, const Wavelengths &lambda, const Color3f &weight) {
    Color3f xyz(0.f);
    for (int i = 0; i < Color3f::Channels; ++i) xyz += cie1931_xyz(lambda[i]) * (L[i] * weight[i]);
    return xyz * float(1.0 / (Color3f::Channels * CieYIntegral));
}

Color3f spectral_to_srgb(const Color3f &L, const Wavelengths &lambda, const Color3f &weight) {
    return xyz_to_srgb(spectral_to_xyz(L, lambda, weight));
}

} // namespace facet
