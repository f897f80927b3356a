#include "softgl/pipeline/coverage_probe.h"

#include <chrono>
#include <stdexcept>

#include "softgl/pipeline/bin.h"

namespace softgl {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

ProbeResult coverage_probe(const ProbeInput& in, const RasterState& state, ThreadPool& pool) {
    const int per = in.kind == PrimitiveKind::Triangle ? 3 : in.kind == PrimitiveKind::Line ? 2 : 1;
    if (state.width <= 0 || state.height <= 0) throw std::invalid_argument("empty target");
    const SamplePattern& pattern = sample_pattern(state.samples);
    if (in.indices) {
        for (size_t i = 0; i < in.primitive_count * per; ++i)
            if (in.indices[i] >= in.vertex_count) throw std::invalid_argument("index out of range");
    } else if (in.primitive_count * per > in.vertex_count) {
        throw std::invalid_argument("not enough vertices");
    }

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

    // Geometry: serial, in primitive order.
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
    r.tiles_skipped = bins.tiles_skipped;
    r.seconds_bin = seconds_since(t0);

    // Per tile, on the pool: each tile writes only its own pixels, primitives in order.
    t0 = std::chrono::steady_clock::now();
    std::vector<RasterStats> stats(pool.size());
    std::vector<uint64_t> covered(pool.size(), 0);
    std::vector<std::vector<Quad>> quad_buffers(pool.size());
    const int S = state.samples;
    const int32_t W = state.width;
    pool.parallel_for(grid.count(), [&](size_t tile, unsigned worker) {
        const TileRect rect = grid.rect(tile);
        std::vector<Quad>& quads = quad_buffers[worker];
        for (uint32_t index : bins.tile(tile)) {
            const PrimitiveSetup& p = prims[index];
            quads.clear();
            rasterize(p, rect, pattern, quads, stats[worker]);
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
                        r.depth[pix * S + s] = p.depth_at(X + pattern.x[s], Y + pattern.y[s]);
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

}  // namespace softgl
