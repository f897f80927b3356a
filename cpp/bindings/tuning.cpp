// softgl._core.testing.tuning / set_tuning / default_tuning / set_default_tuning: a context's
// speed-path switches (core/tuning.h) as a dict of names, for tests and benchmarks that A/B a path.
#include <pybind11/pybind11.h>

#include <string>

#include "exclusive.h"   // the Context caster every binding file shares
#include "softgl/api/context.h"
#include "softgl/core/tuning.h"

namespace py = pybind11;
using softgl::Tuning;

namespace {

const char* const kHiddenSurfaceRemoval[] = {"off", "where_piles_up", "in_every_tile", "where_boxes_pile_up"};
const char* const kDepthBounds[] = {"off", "on", "sabotaged_for_tests"};
const char* const kSamplerPath[] = {"general", "scalar", "best", "avx2"};

template <size_t N>
uint8_t named(const char* const (&names)[N], const std::string& field, const py::handle value) {
    const std::string name = py::str(value);
    for (size_t k = 0; k < N; ++k)
        if (name == names[k]) return uint8_t(k);
    std::string accepted;
    for (size_t k = 0; k < N; ++k) accepted += (k ? ", '" : "'") + std::string(names[k]) + "'";
    throw py::value_error("set_tuning: " + field + " must be one of " + accepted + ", not '" + name + "'");
}

py::dict as_dict(const Tuning& t) {
    py::dict d;
    d["simd"] = softgl::kSimdLevelNames[int(t.simd)];
    d["batch_primitives"] = t.batch_primitives;
    d["hidden_surface_removal"] = kHiddenSurfaceRemoval[int(t.hidden_surface_removal)];
    d["depth_bounds"] = kDepthBounds[int(t.depth_bounds)];
    d["fragment_copies"] = t.fragment_copies;
    d["sampler_path"] = kSamplerPath[int(t.sampler_path)];
    d["fragment_batches"] = t.fragment_batches;
    d["skip_helper_lanes"] = t.skip_helper_lanes;
    d["hoist_uniform_values"] = t.hoist_uniform_values;
    d["flat_primitives"] = t.flat_primitives;
    d["blit_rows"] = t.blit_rows;
    d["pool_spin_microseconds"] = t.pool_spin_microseconds;
    d["texture_copies"] = t.texture_copies;
    d["texel_words"] = t.texel_words;
    d["linear_words"] = t.linear_words;
    d["lod_free_helper_lanes"] = t.lod_free_helper_lanes;
    d["depth_blocks"] = t.depth_blocks;
    d["blend_in_place"] = t.blend_in_place;
    return d;
}

// Sets the named fields of t; the rest keep their values. Checks everything before changing t.
void update(Tuning& t, const py::kwargs& fields) {
    Tuning next = t;
    for (auto [key, value] : fields) {
        const std::string k = py::str(key);
        if (k == "simd") {
            next.simd = softgl::SimdLevel(named(softgl::kSimdLevelNames, k, value));
            if (next.simd > softgl::best_simd_level())
                throw py::value_error(std::string("set_tuning: simd '") + softgl::kSimdLevelNames[int(next.simd)] +
                                      "' is above this CPU's best, '" +
                                      softgl::kSimdLevelNames[int(softgl::best_simd_level())] + "'");
        } else if (k == "batch_primitives") {
            const long long n = value.cast<long long>();
            if (n < 0 || n > softgl::kDrawBatchPrimitivesMax)
                throw py::value_error("set_tuning: batch_primitives must be 0 (the default) to " +
                                      std::to_string(softgl::kDrawBatchPrimitivesMax));
            next.batch_primitives = n ? uint32_t(n) : softgl::kDrawBatchPrimitivesDefault;
        } else if (k == "hidden_surface_removal") {
            next.hidden_surface_removal = softgl::HiddenSurfaceRemoval(named(kHiddenSurfaceRemoval, k, value));
        } else if (k == "depth_bounds") {
            next.depth_bounds = softgl::DepthBoundsMode(named(kDepthBounds, k, value));
        } else if (k == "fragment_copies") {
            next.fragment_copies = value.cast<bool>();
        } else if (k == "sampler_path") {
            next.sampler_path = softgl::SamplerPath(named(kSamplerPath, k, value));
        } else if (k == "fragment_batches") {
            next.fragment_batches = value.cast<bool>();
        } else if (k == "skip_helper_lanes") {
            next.skip_helper_lanes = value.cast<bool>();
        } else if (k == "hoist_uniform_values") {
            next.hoist_uniform_values = value.cast<bool>();
        } else if (k == "flat_primitives") {
            next.flat_primitives = value.cast<bool>();
        } else if (k == "blit_rows") {
            next.blit_rows = value.cast<bool>();
        } else if (k == "pool_spin_microseconds") {
            const long long us = value.cast<long long>();
            if (us < 0 || us > 1'000'000)
                throw py::value_error("set_tuning: pool_spin_microseconds must be 0 to 1000000");
            next.pool_spin_microseconds = uint32_t(us);
        } else if (k == "texture_copies") {
            next.texture_copies = value.cast<bool>();
        } else if (k == "texel_words") {
            next.texel_words = value.cast<bool>();
        } else if (k == "linear_words") {
            next.linear_words = value.cast<bool>();
        } else if (k == "lod_free_helper_lanes") {
            next.lod_free_helper_lanes = value.cast<bool>();
        } else if (k == "depth_blocks") {
            next.depth_blocks = value.cast<bool>();
        } else if (k == "blend_in_place") {
            next.blend_in_place = value.cast<bool>();
        } else {
            throw py::type_error("set_tuning: no field '" + k + "' (fields: " +
                                 std::string(py::str(as_dict(Tuning{}).attr("keys")())) + ")");
        }
    }
    t = next;
}

}  // namespace

void bind_tuning(py::module_& m) {
    py::module_ t = m.attr("testing");
    t.def("tuning", [](softgl::Context& ctx) { return as_dict(ctx.tuning()); }, py::arg("context"),
          "The context's speed-path switches (core/tuning.h) as a dict.");
    t.def("set_tuning", [](softgl::Context& ctx, const py::kwargs& fields) {
        py::dict before = as_dict(ctx.tuning());
        update(ctx.tuning(), fields);
        return before;
    }, py::arg("context"),
       "Sets the named switches of the context (simd, batch_primitives, hidden_surface_removal, depth_bounds, "
       "fragment_copies, sampler_path, fragment_batches, skip_helper_lanes, hoist_uniform_values, flat_primitives, blit_rows, pool_spin_microseconds, texture_copies, texel_words, linear_words, lod_free_helper_lanes, depth_blocks, blend_in_place); returns the previous ones as a dict, to pass back.");
    t.def("default_tuning", [] { return as_dict(Tuning::process_default()); },
          "The switches new contexts start with.");
    t.def("set_default_tuning", [](const py::kwargs& fields) {
        py::dict before = as_dict(Tuning::process_default());
        update(Tuning::process_default(), fields);
        return before;
    }, "Sets the switches new contexts start with; returns the previous ones as a dict.");
}
