#pragma once

#include <facet/vector.h>

/// Warps from the unit square to other domains, each with the density of what it produces.
namespace facet::warp {

Point2f square_to_uniform_disk_concentric(const Point2f &u);
float square_to_uniform_disk_concentric_pdf(const Point2f &p);
Point2f square_to_uniform_triangle(const Point2f &u); ///< barycentric (b1, b2)
Vector3f square_to_uniform_sphere(const Point2f &u);
float square_to_uniform_sphere_pdf(const Vector3f &v);
Vector3f square_to_uniform_hemisphere(const Point2f &u);
float square_to_uniform_hemisphere_pdf(const Vector3f &v);
Vector3f square_to_cosine_hemisphere(const Point2f &u);
float square_to_cosine_hemisphere_pdf(const Vector3f &v);
/// Uniform direction inside the cone of directions with cos θ >= cos_cutoff around +Z.
Vector3f square_to_uniform_cone(const Point2f &u, float cos_cutoff);
float square_to_uniform_cone_pdf(const Vector3f &v, float cos_cutoff);
/// 1D tent on [-1, 1].
float interval_to_tent(float u);

} // namespace facet::warp
