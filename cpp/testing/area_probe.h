// A diagnostic draw for area coverage (SOFTGL_smooth): clip -> setup -> bin -> rasterize_area on the
// thread pool, with a "fragment stage" that only accumulates each pixel's coverage fractions. Used by
// tests and benchmarks (softgl._core.raster_area) and as the reference wiring for smooth draws:
// the lead's fragment loop is coverage_probe's, with rasterize_area in place of rasterize and
// alpha *= fraction per pixel.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/pipeline/coverage.h"
#include "softgl/runtime/thread_pool.h"
#include "testing/probe.h"

namespace softgl::testing {

struct AreaProbeResult {
    int32_t width = 0, height = 0;
    std::vector<double> coverage;     // [y][x] sum of the fractions of all primitives, row 0 = bottom
    std::vector<uint32_t> fragments;  // [y][x] number of fragments emitted (fraction > 0)
    double total = 0;                 // sum of all fractions (also when record = false)
    uint64_t fragment_count = 0;
    SetupStats setup;
    RasterStats raster;
    double seconds_setup = 0, seconds_bin = 0, seconds_raster = 0;
};

// `state` selects the shapes (line_smooth, point_smooth, ...); `options` exact or sampled.
// Throws std::invalid_argument on bad sizes, indices or options.
AreaProbeResult area_probe(const ProbeInput& input, const RasterState& state,
                           const AreaOptions& options, ThreadPool& pool);

}  // namespace softgl::testing
