// softgl._core.testing hooks for pipeline/early_depth.
#include <array>

#include <pybind11/stl.h>

#include "hooks.h"
#include "softgl/pipeline/early_depth.h"

using namespace softgl;
using softgl::bindings::Array;

namespace {

// early_depth_test_at one instruction-set level: the depth plane (a, b, c) + offset with its origin
// (1/256 pixel), the samples' positions in a pixel (1/256 pixel), quads (n, 3) int64 rows (x, y,
// coverage bits), a (h, w, samples) uint32 depth buffer. Returns (survived (n, 4) uint16, killed,
// the buffer after the test).
auto early_depth_test_hook(int level, std::array<double, 3> plane, double offset, int64_t origin_x,
                           int64_t origin_y, std::vector<std::array<int32_t, 2>> samples, uint32_t func, bool write,
                           Array<int64_t> quads, Array<uint32_t> depth) {
    if (quads.ndim() != 2 || quads.shape(1) != 3 || depth.ndim() != 3 || samples.empty() || samples.size() > 16 ||
        depth.shape(2) != py::ssize_t(samples.size()))
        throw py::value_error("quads (n, 3), 1 to 16 samples, depth (h, w, samples)");
    SamplePattern pattern{};
    pattern.count = int(samples.size());
    for (size_t s = 0; s < samples.size(); ++s) pattern.x[s] = samples[s][0], pattern.y[s] = samples[s][1];
    PrimitiveSetup p{};
    p.depth = {plane[0], plane[1], plane[2]};
    p.depth_offset = offset;
    p.origin_x = origin_x, p.origin_y = origin_y;
    const std::vector<Quad> q = bindings::to_quads(quads);
    py::array_t<uint32_t> buffer = bindings::copy_of(depth);
    EarlyDepth test;
    test.prim = &p, test.pattern = &pattern, test.func = func, test.write = write;
    test.depth = buffer.mutable_data(), test.pitch = size_t(depth.shape(1));
    py::array_t<uint16_t> survived({py::ssize_t(q.size()), py::ssize_t(4)});
    const size_t killed = early_depth_test_at(SimdLevel(level), test, q.data(), q.size(), survived.mutable_data());
    return py::make_tuple(survived, killed, buffer);
}

}  // namespace

void bind_testing_early_depth(py::module_& t) {
    t.def("early_depth_test", &early_depth_test_hook);
}
