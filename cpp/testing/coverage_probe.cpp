#include "testing/coverage_probe.h"

namespace softgl::testing {

ProbeResult coverage_probe(const ProbeInput& in, const RasterState& state, ThreadPool& pool) {
    const ProbeGeometry g = set_up_and_bin(in, state);
    ProbeResult r;
    r.width = state.width;
    r.height = state.height;
    r.samples = state.samples;
    const size_t pixels = in.record ? size_t(state.width) * size_t(state.height) : 0;
    r.count.assign(pixels * state.samples, 0);
    r.depth.assign(pixels * state.samples, 0.0);
    r.last.assign(pixels, -1);
    r.front.assign(pixels, 0);
    r.weights.assign(pixels * 3, 0.f);
    r.point_coord.assign(pixels * 2, 0.f);

    r.setup = g.setup;
    r.tiles_skipped = g.bins.tiles_skipped;
    r.seconds_setup = g.seconds_setup;
    r.seconds_bin = g.seconds_bin;

    // Per tile, on the pool: each tile writes only its own pixels, primitives in order.
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<RasterStats> stats(pool.size());
    std::vector<uint64_t> covered(pool.size(), 0);
    std::vector<std::vector<Quad>> quad_buffers(pool.size());
    const int S = state.samples;
    const int32_t W = state.width;
    pool.parallel_for(g.grid.count(), [&](size_t tile, unsigned worker) {
        const TileRect rect = g.grid.rect(tile);
        std::vector<Quad>& quads = quad_buffers[worker];
        for (uint32_t index : g.bins.tile(tile)) {
            const PrimitiveSetup& p = g.prims[index];
            quads.clear();
            rasterize(p, rect, *g.pattern, quads, stats[worker]);
            if (!in.record) {
                for (const Quad& q : quads) covered[worker] += uint64_t(__builtin_popcountll(q.coverage));
                continue;
            }
            for (const Quad& q : quads) {
                covered[worker] += uint64_t(__builtin_popcountll(q.coverage));
                for (int j = 0; j < 4; ++j) {
                    const uint32_t mask = quad_pixel_mask(q, j);
                    if (!mask) continue;
                    const int32_t px = q.x + (j & 1), py = q.y + (j >> 1);
                    const size_t pix = size_t(py) * W + px;
                    const int64_t X = int64_t(px) * kSubPixel, Y = int64_t(py) * kSubPixel;
                    for (int s = 0; s < S; ++s) {
                        if (!(mask >> s & 1)) continue;
                        r.count[pix * S + s] += 1;
                        r.depth[pix * S + s] = p.depth_at(X + g.pattern->x[s], Y + g.pattern->y[s]);
                    }
                    r.last[pix] = int32_t(p.primitive);
                    r.front[pix] = p.front_facing;
                    double w[3];
                    p.weights_at(X + kSubPixel / 2, Y + kSubPixel / 2, w);
                    for (int k = 0; k < 3; ++k) r.weights[pix * 3 + k] = float(w[k]);
                    if (p.kind == PrimitiveKind::Point) p.point_coord(px, py, &r.point_coord[pix * 2]);
                }
            }
        }
    });
    for (const auto& s : stats) r.raster.add(s);
    for (uint64_t c : covered) r.samples_covered += c;
    r.seconds_raster = seconds_since(t0);
    return r;
}

}  // namespace softgl::testing
