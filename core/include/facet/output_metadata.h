#pragma once

#include <facet/fwd.h>
#include <facet/image.h>
#include <facet/transform.h>

#include <optional>

namespace facet {

/// The world-to-NDC matrix of a projective sensor (perspective, thin lens, orthographic), found
/// from the rays the sensor generates: NDC x and y are the position on the full film in [0, 1]
/// (x right, y down, as Sensor::sample_ray takes it; times the film size gives raster
/// coordinates), z is 0 on the near and 1 on the far clipping plane. Row-major, for column
/// vectors (x' = M x, then divide by w). Empty for sensors whose rays are not a projective map of
/// the film (radiance meters, environment cameras).
std::optional<Matrix4f> sensor_world_to_ndc(const Sensor &sensor);

/// Adds the typed EXR attributes pbrt-v4 writes: `samplesPerPixel` (int), `renderTimeSeconds`
/// (float), `worldToCamera` and, for projective sensors, `worldToNDC` (4×4 float matrices,
/// row-major for column vectors, as pbrt-v4 stores them).
void add_render_metadata(ImageWriteOptions &opts, const Sensor &sensor, int spp, double seconds);

} // namespace facet
