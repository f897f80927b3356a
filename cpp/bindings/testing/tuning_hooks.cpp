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
    // Texture lookups: 0 the general per-lane path, 1 the 2D fast path without SIMD, 2 with the
    // best SIMD (the default), 3 with AVX2 at most; returns how many queries the fast path served
    // since the last call.
    t.def("sampler_path", [](int path) {
        if (path < 0 || path > 3) throw py::value_error("sampler path: 0, 1, 2 or 3");
        return softgl::set_sampler_path(softgl::SamplerPath(path));
    });
    // Fragment shaders that only copy varyings or constants: true takes the shortcut (the
    // default), false runs them on the executor; returns how many draws took it since the last call.
    t.def("fragment_copies", &softgl::set_fragment_copies, py::arg("enabled"));
}
