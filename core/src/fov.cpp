#include <facet/fov.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace facet {

double perspective_x_fov(const Properties &props, double aspect) {
    constexpr double DegToRad = 3.14159265358979323846 / 180.0;
    if (props.has("fov") && props.has("focal_length"))
        FACET_THROW_AT(
            props.location("focal_length"),
            "give either a field of view (fov) or a focal length (focal_length), not both");
    double fov;
    std::string axis;
    if (props.has("fov")) {
        fov = props.get_float("fov");
        if (!(fov > 0.0 && fov < 180.0))
            FACET_THROW_AT(props.location("fov"), "fov must be between 0 and 180 degrees, got {}",
                           fov);
        axis = props.get_string("fov_axis", "x");
        std::transform(axis.begin(), axis.end(), axis.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
    } else {
        std::string text = props.get_string("focal_length", "50mm");
        std::string number = text;
        if (number.size() > 2 && number.compare(number.size() - 2, 2, "mm") == 0)
            number.resize(number.size() - 2);
        char *end = nullptr;
        double f = std::strtod(number.c_str(), &end);
        if (number.empty() || *end != '\0' || !(f > 0.0) || !std::isfinite(f))
            FACET_THROW_AT(props.location("focal_length"),
                           "focal_length must be a positive length in millimetres such as "
                           "\"50mm\", got \"{}\"",
                           text);
        // 35 mm film: 36x24 mm, measured along its diagonal.
        fov = 2.0 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * f)) / DegToRad;
        axis = "diagonal";
    }

    const double half_tan = std::tan(0.5 * fov * DegToRad);
    auto to_deg = [&](double half_tan_x) { return 2.0 * std::atan(half_tan_x) / DegToRad; };
    if (axis == "x") return fov;
    if (axis == "y") return to_deg(half_tan * aspect);
    if (axis == "diagonal") return to_deg(half_tan / std::sqrt(1.0 + 1.0 / (aspect * aspect)));
    if (axis == "smaller") return aspect > 1.0 ? to_deg(half_tan * aspect) : fov;
    if (axis == "larger") return aspect < 1.0 ? to_deg(half_tan * aspect) : fov;
    FACET_THROW_AT(props.location("fov_axis"),
                   "fov_axis must be one of x, y, diagonal, smaller or larger, got \"{}\"", axis);
}

} // namespace facet
