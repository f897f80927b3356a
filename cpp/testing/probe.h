// What the coverage and area probes share: their input (primitives in clip coordinates) and the
// geometric half of a draw, done once for both: the input checked, every primitive set up
// (serially, in primitive order) and listed in the tiles it may cover. Each probe then runs its
// own "fragment stage" per tile on the thread pool.
#pragma once
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"

namespace softgl::testing {

struct ProbeInput {
    const float* positions = nullptr;   // clip coordinates, 4 floats per vertex
    size_t vertex_count = 0;
    PrimitiveKind kind = PrimitiveKind::Triangle;
    const uint32_t* indices = nullptr;  // vertices_per_primitive per primitive; null: 0, 1, 2, ...
    size_t primitive_count = 0;
    const float* point_sizes = nullptr; // per vertex; null: 1
    bool record = true;                 // false: only count covered samples (benchmarks the
                                        // geometry and coverage alone; images stay empty)
};

struct ProbeGeometry {
    const SamplePattern* pattern = nullptr;
    std::vector<PrimitiveSetup> prims;
    TileGrid grid;
    Bins bins;                           // indices into prims
    SetupStats setup;
    double seconds_setup = 0, seconds_bin = 0;
};

// Throws std::invalid_argument on an empty target, bad sizes or out-of-range indices.
ProbeGeometry set_up_and_bin(const ProbeInput& input, const RasterState& state);

double seconds_since(std::chrono::steady_clock::time_point t0);

}  // namespace softgl::testing
