// softgl._core.testing: the submodule, and the helpers its stages' hooks share (hooks.h).
#include "hooks.h"

#include "softgl/core/simd.h"

namespace softgl::bindings {

void check_rows_inside(const Array<int32_t>& quads, size_t n, uint64_t rows, py::ssize_t height, py::ssize_t width) {
    for (size_t i = 0; i < n; ++i)
        if (rows >> i & 1)
            if (i + 4 > n || quads.at(i, 0) < 0 || quads.at(i, 1) < 0 || quads.at(i, 0) + 8 > width ||
                quads.at(i, 1) + 2 > height)
                throw py::value_error("a row of four outside the image");
}

BlendOp blend_op(bool enabled, const std::array<uint32_t, 6>& fe, const std::array<bool, 4>& mask, bool has_alpha,
                 const std::array<float, 4>& constant) {
    State state;
    state.blend.enabled = enabled;
    state.blend.src_rgb = fe[0]; state.blend.dst_rgb = fe[1];
    state.blend.src_alpha = fe[2]; state.blend.dst_alpha = fe[3];
    state.blend.equation_rgb = fe[4]; state.blend.equation_alpha = fe[5];
    state.blend.color = constant;
    state.color_mask = mask;
    return BlendOp::from_state(state, has_alpha);
}

}  // namespace softgl::bindings

void bind_testing(py::module_& m) {
    auto t = m.def_submodule("testing", "single pipeline stages, for tests");
    bind_testing_draw(t);
    bind_testing_transforms(t);
    bind_testing_fragment_ops(t);
    // The lane kernels' instruction-set levels: 0 scalar, 1 SSE2, 2 AVX2, 3 AVX-512; the best this CPU runs.
    t.def("simd_level", [] { return int(softgl::best_simd_level()); });
    bind_testing_setup(t);
    bind_testing_interpolate(t);
    bind_testing_blend_table(t);
    bind_testing_early_depth(t);
    bind_testing_raster(t);
    bind_testing_clip(t);
    bind_testing_sampler(t);
}
