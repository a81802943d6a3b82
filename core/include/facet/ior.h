#pragma once

#include <facet/fwd.h>

#include <string>
#include <utility>
#include <vector>

/// Indices of refraction of common dielectrics, by the names Mitsuba scenes use.
namespace facet {

/// The named IORs ("vacuum", "air", "bk7", "water", ...) with their values, in table order.
const std::vector<std::pair<std::string, float>> &ior_table();

/// IOR of a named material; case-insensitive ("BK7" works). Throws facet::Error listing the
/// valid names (and the closest one) when the name is unknown.
float lookup_ior(const std::string &name);

/**
 * Reads an IOR parameter that is either a number or a material name, e.g. `int_ior`:
 * absent -> the IOR of `default_name`; zero, negative or unknown values are errors (with the
 * entry's location).
 */
float read_ior(const Properties &props, const std::string &param, const std::string &default_name);

} // namespace facet
