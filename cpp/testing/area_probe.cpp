#include "testing/area_probe.h"

namespace softgl::testing {

AreaProbeResult area_probe(const ProbeInput& in, const RasterState& state,
                           const AreaOptions& options, ThreadPool& pool) {
    const ProbeGeometry g = set_up_and_bin(in, state);
    AreaProbeResult r;
    r.width = state.width;
    r.height = state.height;
    const size_t pixels = in.record ? size_t(state.width) * size_t(state.height) : 0;
    r.coverage.assign(pixels, 0.0);
    r.fragments.assign(pixels, 0);

    r.setup = g.setup;
    r.seconds_setup = g.seconds_setup;
    r.seconds_bin = g.seconds_bin;

    const auto t0 = std::chrono::steady_clock::now();
    std::vector<RasterStats> stats(pool.size());
    // Per-tile totals, summed in tile order afterwards: the total does not depend on the thread count.
    std::vector<double> tile_total(g.grid.count(), 0.0);
    std::vector<uint64_t> tile_fragments(g.grid.count(), 0);
    std::vector<std::vector<Quad>> quad_buffers(pool.size());
    std::vector<std::vector<QuadArea>> area_buffers(pool.size());
    const int32_t W = state.width;
    pool.parallel_for(g.grid.count(), [&](size_t tile, unsigned worker) {
        const TileRect rect = g.grid.rect(tile);
        std::vector<Quad>& quads = quad_buffers[worker];
        std::vector<QuadArea>& areas = area_buffers[worker];
        double total = 0;
        uint64_t frags = 0;
        for (uint32_t index : g.bins.tile(tile)) {
            quads.clear();
            areas.clear();
            rasterize_area(g.prims[index], rect, *g.pattern, options, quads, areas, stats[worker]);
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
    for (size_t t = 0; t < g.grid.count(); ++t) {
        r.total += tile_total[t];
        r.fragment_count += tile_fragments[t];
    }
    r.seconds_raster = seconds_since(t0);
    return r;
}

}  // namespace softgl::testing
