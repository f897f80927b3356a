#include "testing/probe.h"

#include <stdexcept>

namespace softgl::testing {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

ProbeGeometry set_up_and_bin(const ProbeInput& in, const RasterState& state) {
    const int per = in.kind == PrimitiveKind::Triangle ? 3 : in.kind == PrimitiveKind::Line ? 2 : 1;
    if (state.width <= 0 || state.height <= 0) throw std::invalid_argument("empty target");
    ProbeGeometry g;
    g.pattern = &sample_pattern(state.samples);
    if (in.indices) {
        for (size_t i = 0; i < in.primitive_count * per; ++i)
            if (in.indices[i] >= in.vertex_count) throw std::invalid_argument("index out of range");
    } else if (in.primitive_count * per > in.vertex_count) {
        throw std::invalid_argument("not enough vertices");
    }

    auto t0 = std::chrono::steady_clock::now();
    g.prims.reserve(in.primitive_count);
    Setup setup(state);
    auto vtx = [&](size_t prim, int k) -> uint32_t {
        return in.indices ? in.indices[prim * per + k] : uint32_t(prim * per + k);
    };
    for (size_t n = 0; n < in.primitive_count; ++n) {
        if (per == 3) {
            const uint32_t i0 = vtx(n, 0), i1 = vtx(n, 1), i2 = vtx(n, 2);
            setup.triangle(in.positions + 4 * i0, in.positions + 4 * i1, in.positions + 4 * i2,
                           i0, i1, i2, uint32_t(n), g.prims);
        } else if (per == 2) {
            const uint32_t i0 = vtx(n, 0), i1 = vtx(n, 1);
            setup.line(in.positions + 4 * i0, in.positions + 4 * i1, i0, i1, uint32_t(n), g.prims);
        } else {
            const uint32_t i0 = vtx(n, 0);
            setup.point(in.positions + 4 * i0, in.point_sizes ? in.point_sizes[i0] : 1.f, i0,
                        uint32_t(n), g.prims);
        }
    }
    g.setup = setup.stats;
    g.seconds_setup = seconds_since(t0);

    t0 = std::chrono::steady_clock::now();
    g.grid = TileGrid(state.width, state.height);
    g.bins.reset(g.grid);
    g.bins.add(g.prims);
    g.seconds_bin = seconds_since(t0);
    return g;
}

}  // namespace softgl::testing
