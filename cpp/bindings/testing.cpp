#include <cstring>
// softgl._core.testing: direct access to single pipeline stages for tests. Conversions only.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "softgl/api/context.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/draw.h"
#include "softgl/pipeline/passthrough_shaders.h"
#include "softgl/pipeline/blend.h"
#include "softgl/pipeline/depth_stencil.h"

namespace py = pybind11;

namespace {

// A glm::mat4 as a (4, 4) array in math layout (m[row, col]); GLM stores columns.
py::array_t<float> from_glm(const glm::mat4& m) {
    py::array_t<float> out({4, 4});
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) *out.mutable_data(r, c) = m[c][r];
    return out;
}

glm::vec3 vec3(const std::array<float, 3>& v) { return glm::vec3(v[0], v[1], v[2]); }

}  // namespace

void bind_testing(py::module_& m) {
    auto t = m.def_submodule("testing", "single pipeline stages, for tests");
    // A draw through the whole pipeline with the C++ passthrough shaders, using the context's
    // state and drawing buffer: positions (N, 4) and colors (N, 4) float32 as attributes 0 and 1.
    t.def("draw_passthrough",
          [](softgl::Context& ctx, uint32_t mode, py::array_t<float, py::array::c_style | py::array::forcecast> positions,
             py::array_t<float, py::array::c_style | py::array::forcecast> colors, py::object indices,
             float discard_below, bool depth_from_red, uint32_t instances, py::object point_sizes) {
              const size_t n = size_t(positions.shape(0));
              if (positions.ndim() != 2 || positions.shape(1) != 4 || colors.ndim() != 2 ||
                  colors.shape(1) != 4 || size_t(colors.shape(0)) != n)
                  throw py::value_error("positions and colors must be (N, 4)");
              softgl::VertexArray vao;
              auto make_buffer = [](const void* data, size_t bytes) {
                  auto b = std::make_shared<softgl::Buffer>();
                  b->data.assign(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + bytes);
                  return b;
              };
              auto attach = [&](int loc, std::shared_ptr<softgl::Buffer> b, int size) {
                  auto& a = vao.attribs[size_t(loc)];
                  a.enabled = true;
                  a.size = size;
                  a.buffer = std::move(b);
              };
              attach(0, make_buffer(positions.data(), n * 16), 4);
              attach(1, make_buffer(colors.data(), n * 16), 4);
              int point_size_location = -1;
              if (!point_sizes.is_none()) {
                  auto ps = point_sizes.cast<py::array_t<float, py::array::c_style | py::array::forcecast>>();
                  if (size_t(ps.size()) != n) throw py::value_error("point_sizes must have N values");
                  attach(2, make_buffer(ps.data(), n * 4), 1);
                  point_size_location = 2;
              }
              std::vector<uint32_t> index_list;
              softgl::DrawCall call;
              call.mode = mode;
              call.instance_count = instances;
              if (!indices.is_none()) {
                  index_list = indices.cast<std::vector<uint32_t>>();
                  for (uint32_t i : index_list)
                      if (i >= n) throw py::value_error("index out of range");
                  call.indices = index_list.data();
                  call.count = uint32_t(index_list.size());
              } else {
                  call.count = uint32_t(n);
              }
              softgl::PassthroughVertexShader vs(point_size_location);
              softgl::ColorFragmentShader fs(discard_below, depth_from_red);
              softgl::DrawStats stats;
              {
                  py::gil_scoped_release release;
                  softgl::RenderTarget target = softgl::RenderTarget::for_default(ctx.framebuffer());
                  softgl::DrawInputs in{ctx.state(), vao, ctx.current_attribs(), vs, fs, target, ctx.pool()};
                  softgl::draw(in, call, stats);
              }
              py::dict d;
              d["vertices_shaded"] = stats.vertices_shaded;
              d["primitives"] = stats.primitives;
              d["primitives_culled"] = stats.primitives_culled;
              d["quads"] = stats.quads;
              d["fragments_shaded"] = stats.fragments_shaded;
              d["fragments_killed_early"] = stats.fragments_killed_early;
              d["fragments_killed_late"] = stats.fragments_killed_late;
              d["fragments_discarded"] = stats.fragments_discarded;
              d["samples_written"] = stats.samples_written;
              d["samples_blended"] = stats.samples_blended;
              d["draws_skipped_no_output"] = stats.draws_skipped_no_output;
              d["draws_early_depth"] = stats.draws_early_depth;
              d["draws_plain_write"] = stats.draws_plain_write;
              return d;
          },
          py::arg("ctx"), py::arg("mode"), py::arg("positions"), py::arg("colors"), py::arg("indices") = py::none(),
          py::arg("discard_below") = -1.0f, py::arg("depth_from_red") = false, py::arg("instances") = 1,
          py::arg("point_sizes") = py::none());
    t.def("read_depth", [](softgl::Context& ctx) {
        auto& fb = ctx.framebuffer();
        const int S = fb.config().samples;
        py::array_t<uint32_t> out({py::ssize_t(fb.height()), py::ssize_t(fb.width()), py::ssize_t(S)});
        for (int y = 0; y < fb.height(); ++y)
            for (int x = 0; x < fb.width(); ++x)
                for (int s = 0; s < S; ++s) *out.mutable_data(y, x, s) = fb.depth_sample(x, y, s);
        return out;
    });
    t.def("read_stencil", [](softgl::Context& ctx) {
        auto& fb = ctx.framebuffer();
        const int S = fb.config().samples;
        py::array_t<uint8_t> out({py::ssize_t(fb.height()), py::ssize_t(fb.width()), py::ssize_t(S)});
        for (int y = 0; y < fb.height(); ++y)
            for (int x = 0; x < fb.width(); ++x)
                for (int s = 0; s < S; ++s) *out.mutable_data(y, x, s) = fb.stencil_sample(x, y, s);
        return out;
    });
    t.def("assemble", [](uint32_t mode, uint32_t count) {
        std::vector<uint32_t> out;
        softgl::assemble(mode, count, out);
        return out;
    });
    // GLM as the reference for softgl.transforms (the C++ side's math library).
    t.def("glm_perspective", [](float fovy, float aspect, float n, float f) { return from_glm(glm::perspective(fovy, aspect, n, f)); });
    t.def("glm_ortho", [](float l, float r, float b, float tp, float n, float f) { return from_glm(glm::ortho(l, r, b, tp, n, f)); });
    t.def("glm_look_at", [](std::array<float, 3> eye, std::array<float, 3> center, std::array<float, 3> up) {
        return from_glm(glm::lookAt(vec3(eye), vec3(center), vec3(up)));
    });
    t.def("glm_translate", [](std::array<float, 3> v) { return from_glm(glm::translate(glm::mat4(1.0f), vec3(v))); });
    t.def("glm_scale", [](std::array<float, 3> v) { return from_glm(glm::scale(glm::mat4(1.0f), vec3(v))); });
    t.def("glm_rotate", [](float angle, std::array<float, 3> axis) { return from_glm(glm::rotate(glm::mat4(1.0f), angle, vec3(axis))); });
    t.def("glm_inverse_transpose", [](py::array_t<float, py::array::c_style | py::array::forcecast> a) {
        glm::mat4 m;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m[c][r] = *a.data(r, c);
        return from_glm(glm::transpose(glm::inverse(m)));
    });
    // The specialised per-fragment colour kernels (pipeline/fragment_ops.h), for the proof that
    // they equal blend_unorm8: lanes=false runs write_color<K> per pixel, lanes=true the
    // structure-of-arrays (SSE2) kernel the draw uses for single-sampled targets.
    t.def("fragment_ops_write",
          [](const std::array<uint32_t, 6>& fe, const std::array<float, 4>& constant,
             const std::array<bool, 4>& mask, bool has_alpha,
             py::array_t<float, py::array::c_style | py::array::forcecast> src,
             py::array_t<uint8_t, py::array::c_style | py::array::forcecast> dst, bool lanes, int level) {
              softgl::State state;
              state.blend.enabled = true;
              state.blend.src_rgb = fe[0]; state.blend.dst_rgb = fe[1];
              state.blend.src_alpha = fe[2]; state.blend.dst_alpha = fe[3];
              state.blend.equation_rgb = fe[4]; state.blend.equation_alpha = fe[5];
              state.blend.color = constant;
              state.color_mask = mask;
              const softgl::BlendOp op = softgl::BlendOp::from_state(state, has_alpha);
              if (src.ndim() != 2 || src.shape(1) != 4 || dst.ndim() != 2 || dst.shape(1) != 4 ||
                  src.shape(0) != dst.shape(0))
                  throw py::value_error("src must be (N, 4) float32 and dst (N, 4) uint8");
              const size_t n = size_t(src.shape(0));
              py::array_t<uint8_t> out({dst.shape(0), py::ssize_t(4)});
              std::memcpy(out.mutable_data(), dst.data(), size_t(dst.nbytes()));
              if (!lanes) {
                  softgl::write_colors(op, src.data(), out.mutable_data(), n);
              } else {
                  std::vector<float> soa(4 * n);
                  for (size_t i = 0; i < n; ++i)
                      for (size_t c = 0; c < 4; ++c) soa[c * n + i] = src.data()[4 * i + c];
                  std::vector<uint32_t> px(n);
                  std::memcpy(px.data(), out.data(), 4 * n);
                  if (level < 0) softgl::write_color_lanes(softgl::color_kernel(op), op, soa.data(), n, px.data(), n);
                  else softgl::write_color_lanes_at(softgl::SimdLevel(level), softgl::color_kernel(op), op, soa.data(), n, px.data(), n);
                  std::memcpy(out.mutable_data(), px.data(), 4 * n);
              }
              return std::make_pair(out, int(softgl::color_kernel(op)));
          },
          py::arg("funcs_and_equations"), py::arg("constant"), py::arg("mask"), py::arg("has_alpha"), py::arg("src"),
          py::arg("dst"), py::arg("lanes"), py::arg("level") = -1);
    // The lane kernels' instruction-set levels: 0 scalar, 1 SSE2, 2 AVX2; the best this CPU runs.
    t.def("simd_level", [] { return int(softgl::best_simd_level()); });
    // Texture lookups: 0 the general per-lane path, 1 the 2D fast path without SIMD, 2 with the
    // best SIMD (the default); returns how many queries the fast path served since the last call.
    t.def("sampler_path", [](int path) {
        if (path < 0 || path > 2) throw py::value_error("sampler path: 0, 1 or 2");
        return softgl::set_sampler_path(softgl::SamplerPath(path));
    });
    t.def("blend_unorm8",
          [](const std::array<uint32_t, 6>& funcs_and_equations, const std::array<float, 4>& constant,
             const std::array<bool, 4>& mask, bool has_alpha,
             py::array_t<float, py::array::c_style | py::array::forcecast> src,
             py::array_t<uint8_t, py::array::c_style | py::array::forcecast> dst) {
              softgl::State state;
              state.blend.enabled = true;
              state.blend.src_rgb = funcs_and_equations[0];
              state.blend.dst_rgb = funcs_and_equations[1];
              state.blend.src_alpha = funcs_and_equations[2];
              state.blend.dst_alpha = funcs_and_equations[3];
              state.blend.equation_rgb = funcs_and_equations[4];
              state.blend.equation_alpha = funcs_and_equations[5];
              state.blend.color = constant;
              state.color_mask = mask;
              const softgl::BlendOp op = softgl::BlendOp::from_state(state, has_alpha);
              if (src.ndim() != 2 || src.shape(1) != 4 || dst.ndim() != 2 || dst.shape(1) != 4 ||
                  src.shape(0) != dst.shape(0))
                  throw py::value_error("src must be (N, 4) float32 and dst (N, 4) uint8");
              py::array_t<uint8_t> out({dst.shape(0), py::ssize_t(4)});
              std::memcpy(out.mutable_data(), dst.data(), size_t(dst.nbytes()));
              for (py::ssize_t i = 0; i < src.shape(0); ++i)
                  softgl::blend_unorm8(op, src.data(i, 0), out.mutable_data(i, 0));
              return out;
          });
}
