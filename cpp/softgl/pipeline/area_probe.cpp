#include "softgl/pipeline/area_probe.h"

#include <chrono>
#include <stdexcept>

#include "softgl/pipeline/bin.h"

namespace softgl {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

AreaProbeResult area_probe(const ProbeInput& in, const RasterState& state,
                           const AreaOptions& options, ThreadPool& pool) {
    const int per = in.kind == PrimitiveKind::Triangle ? 3 : in.kind == PrimitiveKind::Line ? 2 : 1;
    if (state.width <= 0 || state.height <= 0) throw std::invalid_argument("empty target");
    const SamplePattern& pattern = sample_pattern(state.samples);
    if (in.indices) {
        for (size_t i = 0; i < in.primitive_count * per; ++i)
            if (in.indices[i] >= in.vertex_count) throw std::invalid_argument("index out of range");
    } else if (in.primitive_count * per > in.vertex_count) {
        throw std::invalid_argument("not enough vertices");
    }
    AreaProbeResult r;
    r.width = state.width;
    r.height = state.height;
    const size_t pixels = in.record ? size_t(state.width) * size_t(state.height) : 0;
    r.coverage.assign(pixels, 0.0);
    r.fragments.assign(pixels, 0);

    auto t0 = std::chrono::steady_clock::now();
    std::vector<PrimitiveSetup> prims;
    prims.reserve(in.primitive_count);
    Setup setup(state);
    auto vtx = [&](size_t prim, int k) -> uint32_t {
        return in.indices ? in.indices[prim * per + k] : uint32_t(prim * per + k);
    };
    for (size_t n = 0; n < in.primitive_count; ++n) {
        if (per == 3) {
            const uint32_t i0 = vtx(n, 0), i1 = vtx(n, 1), i2 = vtx(n, 2);
            setup.triangle(in.positions + 4 * i0, in.positions + 4 * i1, in.positions + 4 * i2,
                           i0, i1, i2, uint32_t(n), prims);
        } else if (per == 2) {
            const uint32_t i0 = vtx(n, 0), i1 = vtx(n, 1);
            setup.line(in.positions + 4 * i0, in.positions + 4 * i1, i0, i1, uint32_t(n), prims);
        } else {
            const uint32_t i0 = vtx(n, 0);
            setup.point(in.positions + 4 * i0, in.point_sizes ? in.point_sizes[i0] : 1.f, i0,
                        uint32_t(n), prims);
        }
    }
    r.setup = setup.stats;
    r.seconds_setup = seconds_since(t0);

    t0 = std::chrono::steady_clock::now();
    const TileGrid grid(state.width, state.height);
    Bins bins;
    bins.reset(grid);
    bins.add(prims);
    r.seconds_bin = seconds_since(t0);

    t0 = std::chrono::steady_clock::now();
    std::vector<RasterStats> stats(pool.size());
    // Per-tile totals, summed in tile order afterwards: the total does not depend on the thread count.
    std::vector<double> tile_total(grid.count(), 0.0);
    std::vector<uint64_t> tile_fragments(grid.count(), 0);
    std::vector<std::vector<Quad>> quad_buffers(pool.size());
    std::vector<std::vector<QuadArea>> area_buffers(pool.size());
    const int32_t W = state.width;
    pool.parallel_for(grid.count(), [&](size_t tile, unsigned worker) {
        const TileRect rect = grid.rect(tile);
        std::vector<Quad>& quads = quad_buffers[worker];
        std::vector<QuadArea>& areas = area_buffers[worker];
        double total = 0;
        uint64_t frags = 0;
        for (uint32_t index : bins.tile(tile)) {
            quads.clear();
            areas.clear();
            rasterize_area(prims[index], rect, pattern, options, quads, areas, stats[worker]);
            for (size_t q = 0; q < quads.size(); ++q) {
                for (int j = 0; j < 4; ++j) {
                    const double f = areas[q].fraction[j];
                    if (!quad_pixel_mask(quads[q], j)) continue;
                    total += f;
                    ++frags;
                    if (!in.record) continue;
                    const size_t pix = size_t(quads[q].y + (j >> 1)) * W + size_t(quads[q].x + (j & 1));
                    r.coverage[pix] += f;
                    r.fragments[pix] += 1;
                }
            }
        }
        tile_total[tile] = total;
        tile_fragments[tile] = frags;
    });
    for (const auto& s : stats) r.raster.add(s);
    for (size_t t = 0; t < grid.count(); ++t) {
        r.total += tile_total[t];
        r.fragment_count += tile_fragments[t];
    }
    r.seconds_raster = seconds_since(t0);
    return r;
}

}  // namespace softgl
