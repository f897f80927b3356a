// softgl._core.testing's process-wide speed-path switches, kept apart from the stage hooks: the
// per-context Tuning (core/tuning.h, bound in bindings/tuning.cpp) replaces them.
#include "hooks.h"
#include "softgl/core/simd.h"
#include "softgl/pipeline/draw.h"
#include "softgl/pipeline/early_depth.h"
#include "softgl/pipeline/glsl_stages.h"
#include "softgl/surface/sampler.h"

void bind_testing_tuning_hooks(py::module_& t) {
    // Draws run in batches of this many primitives (all contexts, all threads); 0 = the default.
    // Returns the previous size.
    t.def("set_draw_batch_primitives", &softgl::set_draw_batch_primitives, py::arg("primitives"));
    // Hidden-surface removal: 0 never, 1 where primitives pile up (the default), 2 in every tile
    // with two or more primitives. Returns the previous mode.
    t.def("set_hidden_surface_removal", [](int mode) {
        if (mode < 0 || mode > 2) throw py::value_error("hidden-surface removal: 0, 1 or 2");
        return int(softgl::set_hidden_surface_removal(softgl::HiddenSurfaceRemoval(mode)));
    }, py::arg("mode"));
    // Depth bounds (pipeline/early_depth DepthBounds): 0 off, 1 on (the default), 2 sabotaged (for
    // tests that must catch a wrong bound); simd_level of the block reads (-1: the best). Returns
    // the previous mode.
    t.def("set_depth_bounds", [](int mode, int simd_level) {
        if (mode < 0 || mode > 2) throw py::value_error("depth bounds: 0, 1 or 2");
        if (simd_level < -1 || simd_level > int(softgl::best_simd_level())) throw py::value_error("depth bounds: simd level");
        return softgl::set_depth_bounds(mode, simd_level);
    }, py::arg("mode"), py::arg("simd_level") = -1);
    // Fragment shaders that only copy varyings or constants: true takes the shortcut (the
    // default), false runs them on the executor; returns how many draws took it since the last call.
    t.def("fragment_copies", &softgl::set_fragment_copies, py::arg("enabled"));
}
