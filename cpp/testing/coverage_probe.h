// A diagnostic draw through the geometric pipeline (clip -> setup -> bin -> raster on the thread
// pool) whose "fragment stage" only records coverage: per sample, how many primitives covered it and
// the depth of the last one; per pixel, the last primitive and its facing and perspective-correct
// weights at the pixel centre. Used by tests and benchmarks (softgl._core.raster_coverage) and as
// the reference wiring for the real draw: replace the per-quad loop in coverage_probe.cpp with
// fragment shading and per-fragment operations.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/runtime/thread_pool.h"
#include "testing/probe.h"

namespace softgl::testing {

struct ProbeResult {
    int32_t width = 0, height = 0, samples = 1;
    std::vector<uint32_t> count;         // [y][x][sample], row 0 = bottom
    std::vector<double> depth;           // [y][x][sample], depth of the last covering primitive
    std::vector<int32_t> last;           // [y][x] primitive number of the last coverer, -1: none
    std::vector<int8_t> front;           // [y][x] its gl_FrontFacing
    std::vector<float> weights;          // [y][x][3] its perspective-correct weights at the centre
    std::vector<float> point_coord;      // [y][x][2] its gl_PointCoord (points only, else 0)
    uint64_t samples_covered = 0;        // total over all primitives
    SetupStats setup;
    RasterStats raster;
    uint64_t tiles_skipped = 0;
    double seconds_setup = 0, seconds_bin = 0, seconds_raster = 0;
};

// Throws std::invalid_argument on bad sizes or out-of-range indices.
ProbeResult coverage_probe(const ProbeInput& input, const RasterState& state, ThreadPool& pool);

}  // namespace softgl::testing
