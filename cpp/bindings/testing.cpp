#include <array>
#include <cstring>
// softgl._core.testing: direct access to single pipeline stages for tests. Conversions only.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "softgl/api/context.h"
#include "exclusive.h"   // the Context caster every binding file shares
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/early_depth.h"
#include "softgl/pipeline/interpolate.h"
#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/draw.h"
#include "softgl/pipeline/glsl_stages.h"
#include "softgl/pipeline/passthrough_shaders.h"
#include "softgl/surface/blend.h"
#include "softgl/pipeline/depth_stencil.h"
#include "softgl/pipeline/clip.h"
#include "softgl/pipeline/setup.h"

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

// The clipper hooks' inputs: a triangle (3, 4) float32 in clip coordinates and a full-target
// viewport of width x height. Fills v and returns the clipper.
using ClipTriangle = py::array_t<float, py::array::c_style | py::array::forcecast>;
softgl::Clipper clip_inputs(const ClipTriangle& tri, int32_t width, int32_t height, softgl::Vec4d v[3]) {
    if (tri.ndim() != 2 || tri.shape(0) != 3 || tri.shape(1) != 4) throw py::value_error("triangle must be (3, 4)");
    softgl::Viewport vp;
    vp.width = width;
    vp.height = height;
    for (int i = 0; i < 3; ++i) v[i] = {tri.at(i, 0), tri.at(i, 1), tri.at(i, 2), tri.at(i, 3)};
    return softgl::Clipper(vp);
}


// The interpolation hooks' inputs: planes (4, 3) float64 rows (a, b, c) of weight[0..2] and inv_w,
// origin in 1/256 pixel, quads (n, 2) int32 lower-left pixels, values (vertices, words) float32,
// the planes' base pixel. Filled in place: vi points into the other members.
using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Int32s = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
struct InterpolationInputs {
    softgl::PrimitiveSetup prim{};
    std::vector<softgl::Quad> quads;
    std::vector<int> words;
    std::vector<float> values;
    softgl::VaryingInterpolation vi;

    InterpolationInputs(const Doubles& planes, int64_t origin_x, int64_t origin_y, const Int32s& q, const Floats& v,
                        int32_t base_x, int32_t base_y) {
        if (planes.ndim() != 2 || planes.shape(0) != 4 || planes.shape(1) != 3 || q.ndim() != 2 || q.shape(1) != 2 ||
            v.ndim() != 2 || (v.shape(0) != 2 && v.shape(0) != 3))
            throw py::value_error("planes (4, 3), quads (n, 2), values (2 or 3, words)");
        softgl::Plane* pl[4] = {&prim.weight[0], &prim.weight[1], &prim.weight[2], &prim.inv_w};
        for (int k = 0; k < 4; ++k) *pl[k] = {planes.at(k, 0), planes.at(k, 1), planes.at(k, 2)};
        prim.origin_x = origin_x, prim.origin_y = origin_y;
        const size_t n = size_t(q.shape(0)), count = size_t(v.shape(1));
        const int vertices = int(v.shape(0));
        quads.resize(n);
        for (size_t i = 0; i < n; ++i) quads[i] = {q.at(i, 0), q.at(i, 1), ~uint64_t(0)};
        words.resize(count);
        values.resize(size_t(vertices) * count);
        for (size_t k = 0; k < count; ++k) words[k] = int(k);
        for (size_t j = 0; j < size_t(vertices); ++j)
            for (size_t k = 0; k < count; ++k) values[j * count + k] = v.at(j, k);
        softgl::prepare_interpolation(prim, vertices, base_x, base_y, words.data(), count, values.data(), vi);
    }
    InterpolationInputs(const InterpolationInputs&) = delete;   // vi points into this object
};

// The colour hooks' blend state: funcs_and_equations (srcRGB, dstRGB, srcA, dstA, eqRGB, eqA).
softgl::BlendOp blend_op(bool enabled, const std::array<uint32_t, 6>& fe, const std::array<bool, 4>& mask,
                         bool has_alpha, const std::array<float, 4>& constant = {0, 0, 0, 0}) {
    softgl::State state;
    state.blend.enabled = enabled;
    state.blend.src_rgb = fe[0]; state.blend.dst_rgb = fe[1];
    state.blend.src_alpha = fe[2]; state.blend.dst_alpha = fe[3];
    state.blend.equation_rgb = fe[4]; state.blend.equation_alpha = fe[5];
    state.blend.color = constant;
    state.color_mask = mask;
    return softgl::BlendOp::from_state(state, has_alpha);
}

// A copy of a (h, w) uint32 image, for hooks that return the image after writing into it.
py::array_t<uint32_t> copy_image(const py::array_t<uint32_t, py::array::c_style | py::array::forcecast>& image) {
    py::array_t<uint32_t> picture({image.shape(0), image.shape(1)});
    std::memcpy(picture.mutable_data(), image.data(), size_t(image.nbytes()));
    return picture;
}

// The blend table of `op` for the constant colour `colour`, as a draw builds it; false (no table)
// when the blend is not per channel.
bool constant_blend_table(const softgl::BlendOp& op, const std::array<float, 4>& colour, softgl::BlendTable& table) {
    if (!softgl::blend_is_per_channel(op)) return false;
    softgl::build_blend_table(softgl::color_kernel(op), op, colour.data(), table);
    return true;
}

// PixelRows' rows of four (bit i: quads i .. i + 3) must lie inside the image: the kernels write
// there unchecked. quads (n, 2) int32 lower-left pixels, image (h, w).
template <class Quads>
void check_rows_inside(const Quads& quads, size_t n, uint64_t rows, py::ssize_t height, py::ssize_t width) {
    for (size_t i = 0; i < n; ++i)
        if (rows >> i & 1)
            if (i + 4 > n || quads.at(i, 0) < 0 || quads.at(i, 1) < 0 || quads.at(i, 0) + 8 > width ||
                quads.at(i, 1) + 2 > height)
                throw py::value_error("a row of four outside the image");
}

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
                  softgl::DrawInputs in{ctx.state(), vao, ctx.current_attribs(), vs, fs, target, ctx.pool(), ctx.tuning()};
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
              d["fragments_hidden"] = stats.fragments_hidden;
              d["samples_written"] = stats.samples_written;
              d["samples_blended"] = stats.samples_blended;
              d["draws_skipped_no_output"] = stats.draws_skipped_no_output;
              d["draws_early_depth"] = stats.draws_early_depth;
              d["draws_plain_write"] = stats.draws_plain_write;
              d["draws_blend_table"] = stats.draws_blend_table;
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
    t.def("primitive_vertex_range", [](uint32_t mode, uint32_t count, uint32_t p0, uint32_t p1) {
        const softgl::VertexRange r = softgl::primitive_vertex_range(mode, count, p0, p1);
        return py::make_tuple(r.begin, r.end, r.and_zero);
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
              const softgl::BlendOp op = blend_op(true, fe, mask, has_alpha, constant);
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
    // The lane kernels' float -> unorm8 conversion against float_to_unorm8 (surface/formats.h) on
    // the float bit patterns first, first + step, ... <= last: runs the Plain kernel at `level` on
    // all four channels of each value and returns how many bytes differ. In C++ so that every
    // float in [0, 1] (about 1.07e9) can be checked in seconds.
    t.def("unorm8_conversion_mismatches",
          [](int level, uint32_t first, uint32_t last, uint32_t step) {
              softgl::State state;   // blending off, every channel written
              const softgl::BlendOp op = softgl::BlendOp::from_state(state, true);
              constexpr size_t block = 4096;
              std::vector<float> src(block);
              std::vector<uint32_t> px(block);
              uint64_t mismatches = 0;
              py::gil_scoped_release release;
              for (uint64_t b = first; b <= last;) {
                  size_t n = 0;
                  for (; n < block && b <= last; ++n, b += step) {
                      const uint32_t bits = uint32_t(b);
                      std::memcpy(&src[n], &bits, 4);
                  }
                  // stride 0: the four channels of lane l all read src[l].
                  softgl::write_color_lanes_at(softgl::SimdLevel(level), softgl::ColorKernel::Plain, op, src.data(), 0,
                                               px.data(), n);
                  for (size_t i = 0; i < n; ++i) {
                      const uint32_t want = softgl::float_to_unorm8(src[i]) * 0x01010101u;
                      if (px[i] != want)
                          for (int c = 0; c < 4; ++c) mismatches += ((px[i] ^ want) >> (8 * c) & 0xFF) != 0;
                  }
              }
              return mismatches;
          },
          py::arg("level"), py::arg("first"), py::arg("last"), py::arg("step") = 1);
    // The lane kernels' instruction-set levels: 0 scalar, 1 SSE2, 2 AVX2, 3 AVX-512; the best this CPU runs.
    t.def("simd_level", [] { return int(softgl::best_simd_level()); });
    // Setup::project_vertices at one instruction-set level: positions (n, 4) float32 clip coordinates,
    // viewport (x, y, width, height) on a width x height target. Returns (XY (n, 2) int64, z_inv_w (n, 2)
    // float64), the WindowPosition fields.
    t.def("project_vertices",
          [](int level, py::array_t<float, py::array::c_style | py::array::forcecast> positions, int32_t width,
             int32_t height, std::array<int32_t, 4> viewport) {
              if (positions.ndim() != 2 || positions.shape(1) != 4) throw py::value_error("positions (n, 4)");
              softgl::RasterState rs = softgl::RasterState::for_target(width, height);
              rs.viewport.x = viewport[0], rs.viewport.y = viewport[1];
              rs.viewport.width = viewport[2], rs.viewport.height = viewport[3];
              const size_t n = size_t(positions.shape(0));
              std::vector<softgl::WindowPosition> out(n);
              softgl::Setup(rs).project_vertices(positions.data(), n, out.data(), softgl::SimdLevel(level));
              py::array_t<int64_t> xy({n, size_t(2)});
              py::array_t<double> zw({n, size_t(2)});
              for (size_t i = 0; i < n; ++i) {
                  xy.mutable_at(i, 0) = out[i].X, xy.mutable_at(i, 1) = out[i].Y;
                  zw.mutable_at(i, 0) = out[i].z, zw.mutable_at(i, 1) = out[i].inv_w;
              }
              return py::make_tuple(xy, zw);
          },
          py::arg("level"), py::arg("positions"), py::arg("width"), py::arg("height"), py::arg("viewport"));
    // pipeline/interpolate at one instruction-set level: planes (4, 3) float64 rows (a, b, c) of
    // weight[0..2] and inv_w, origin in 1/256 pixel, quads (n, 2) int32 lower-left pixels,
    // values (vertices, words) float32, base: the pixel the float planes are based at. Returns
    // (words, 4n) float32, lane 4*i + j = pixel j of quad i.
    t.def("interpolate_varyings",
          [](int level, Doubles planes, int64_t origin_x, int64_t origin_y, Int32s quads, Floats values, int32_t base_x,
             int32_t base_y) {
              const InterpolationInputs in(planes, origin_x, origin_y, quads, values, base_x, base_y);
              const size_t n = in.quads.size(), count = in.words.size();
              py::array_t<float> out({py::ssize_t(count), py::ssize_t(4 * n)});
              softgl::interpolate_varyings_at(softgl::SimdLevel(level), in.vi, in.quads.data(), n,
                                              reinterpret_cast<uint32_t*>(out.mutable_data()), 4 * n);
              return out;
          },
          py::arg("level"), py::arg("planes"), py::arg("origin_x"), py::arg("origin_y"), py::arg("quads"),
          py::arg("values"), py::arg("base_x") = 0, py::arg("base_y") = 0);
    // pipeline/fragment_ops' fused copy kernel (write_interpolated_color_lanes) at one level, or with
    // fused=false the two stages it replaces (interpolate_varyings_at, then write_color_lanes_at):
    // planes, origin, quads, values and base as interpolate_varyings; the colour is words first ..
    // first + 3; blending as fragment_ops_write (enabled when `blend`); dst (4n,) uint32 pixels;
    // rows (fused only): PixelRows' bits, for quads in `image` ((h, w) uint32 pixels).
    // Returns (dst, image) after the call.
    t.def("interpolated_color_lanes",
          [](int level, bool fused, Doubles planes, int64_t origin_x, int64_t origin_y, Int32s quads, Floats values,
             int32_t base_x, int32_t base_y,
             size_t first, bool blend, const std::array<uint32_t, 6>& fe, const std::array<bool, 4>& mask,
             bool has_alpha, py::array_t<uint32_t, py::array::c_style | py::array::forcecast> dst, uint64_t rows,
             py::array_t<uint32_t, py::array::c_style | py::array::forcecast> image) {
              const InterpolationInputs in(planes, origin_x, origin_y, quads, values, base_x, base_y);
              const size_t n = in.quads.size(), count = in.words.size();
              if (first + 4 > count || dst.ndim() != 1 || size_t(dst.shape(0)) != 4 * n || image.ndim() != 2 ||
                  (rows && (!fused || n > 64)))
                  throw py::value_error("values (vertices, words >= first + 4), dst (4n,), image (h, w); rows only "
                                        "fused, with n <= 64");
              check_rows_inside(quads, n, rows, image.shape(0), image.shape(1));
              const softgl::BlendOp op = blend_op(blend, fe, mask, has_alpha);
              const softgl::ColorKernel kernel = softgl::color_kernel(op);
              if (kernel == softgl::ColorKernel::Generic) throw py::value_error("no fused kernel for Generic blending");
              py::array_t<uint32_t> out(py::ssize_t(4 * n));
              std::memcpy(out.mutable_data(), dst.data(), 16 * n);
              const softgl::SimdLevel simd = softgl::SimdLevel(level);
              py::array_t<uint32_t> picture = copy_image(image);
              if (fused) {
                  const softgl::PixelRows pixel_rows{reinterpret_cast<uint8_t*>(picture.mutable_data()), size_t(image.shape(1)), rows};
                  softgl::write_interpolated_color_lanes_at(simd, kernel, op, in.vi, first, in.quads.data(), n, out.mutable_data(), pixel_rows);
              } else {
                  std::vector<uint32_t> varyings(count * 4 * n);
                  softgl::interpolate_varyings_at(simd, in.vi, in.quads.data(), n, varyings.data(), 4 * n);
                  softgl::write_color_lanes_at(simd, kernel, op, reinterpret_cast<const float*>(varyings.data()) + first * 4 * n,
                                               4 * n, out.mutable_data(), 4 * n);
              }
              return std::make_pair(out, picture);
          },
          py::arg("level"), py::arg("fused"), py::arg("planes"), py::arg("origin_x"), py::arg("origin_y"),
          py::arg("quads"), py::arg("values"), py::arg("base_x"), py::arg("base_y"), py::arg("first"),
          py::arg("blend"), py::arg("funcs_and_equations"), py::arg("mask"), py::arg("has_alpha"), py::arg("dst"),
          py::arg("rows"), py::arg("image"));
    // pipeline/fragment_ops' blend table (build_blend_table, apply_blend_table_at at one level) for the
    // constant colour `colour`: blending as fragment_ops_write; quads (n, 2) int32 lower-left
    // pixels, dst (4n,) uint32 their lanes; rows: PixelRows' bits, for quads in `image` ((h, w)
    // uint32 pixels). Returns (per_channel, dst, image) after the call (dst and image unchanged
    // when the blend is not per channel).
    t.def("blend_table_lanes",
          [](int level, const std::array<uint32_t, 6>& fe, const std::array<float, 4>& constant,
             const std::array<bool, 4>& mask, bool has_alpha, const std::array<float, 4>& colour,
             py::array_t<int32_t, py::array::c_style | py::array::forcecast> quads,
             py::array_t<uint32_t, py::array::c_style | py::array::forcecast> dst, uint64_t rows,
             py::array_t<uint32_t, py::array::c_style | py::array::forcecast> image) {
              const size_t n = quads.ndim() == 2 ? size_t(quads.shape(0)) : 0;
              if (quads.ndim() != 2 || quads.shape(1) != 2 || dst.ndim() != 1 || size_t(dst.shape(0)) != 4 * n ||
                  image.ndim() != 2 || n > 64)
                  throw py::value_error("quads (n <= 64, 2), dst (4n,), image (h, w)");
              check_rows_inside(quads, n, rows, image.shape(0), image.shape(1));
              const softgl::BlendOp op = blend_op(true, fe, mask, has_alpha, constant);
              std::vector<softgl::Quad> q(n);
              for (size_t i = 0; i < n; ++i) q[i] = softgl::Quad(quads.at(i, 0), quads.at(i, 1), 0);
              py::array_t<uint32_t> out(py::ssize_t(4 * n));
              std::memcpy(out.mutable_data(), dst.data(), 16 * n);
              py::array_t<uint32_t> picture = copy_image(image);
              softgl::BlendTable table;
              const bool per_channel = constant_blend_table(op, colour, table);
              if (per_channel) {
                  const softgl::PixelRows pixel_rows{reinterpret_cast<uint8_t*>(picture.mutable_data()), size_t(image.shape(1)), rows};
                  softgl::apply_blend_table_at(softgl::SimdLevel(level), table, q.data(), n, out.mutable_data(), pixel_rows);
              }
              return std::make_tuple(per_channel, out, picture);
          },
          py::arg("level"), py::arg("funcs_and_equations"), py::arg("constant"), py::arg("mask"), py::arg("has_alpha"),
          py::arg("colour"), py::arg("quads"), py::arg("dst"), py::arg("rows"), py::arg("image"));
    // apply_blend_table_to_rect_at at one level: the table for `colour` (as blend_table_lanes)
    // applied in place to the pixels [x0, x1) x [y0, y1) of `image` ((h, w) uint32 pixels).
    // Returns (per_channel, image after the call).
    t.def("blend_table_rect",
          [](int level, const std::array<uint32_t, 6>& fe, const std::array<float, 4>& constant,
             const std::array<bool, 4>& mask, bool has_alpha, const std::array<float, 4>& colour,
             const std::array<int32_t, 4>& rect, py::array_t<uint32_t, py::array::c_style | py::array::forcecast> image) {
              if (image.ndim() != 2 || rect[0] < 0 || rect[1] < 0 || rect[0] > rect[2] || rect[1] > rect[3] ||
                  rect[2] > image.shape(1) || rect[3] > image.shape(0))
                  throw py::value_error("image (h, w), rect (x0, y0, x1, y1) inside it");
              const softgl::BlendOp op = blend_op(true, fe, mask, has_alpha, constant);
              py::array_t<uint32_t> picture = copy_image(image);
              softgl::BlendTable table;
              const bool per_channel = constant_blend_table(op, colour, table);
              if (per_channel) {
                  const softgl::PixelRect r{reinterpret_cast<uint8_t*>(picture.mutable_data()), size_t(image.shape(1)),
                                            rect[0], rect[1], rect[2], rect[3]};
                  softgl::apply_blend_table_to_rect_at(softgl::SimdLevel(level), table, r);
              }
              return std::make_tuple(per_channel, picture);
          },
          py::arg("level"), py::arg("funcs_and_equations"), py::arg("constant"), py::arg("mask"), py::arg("has_alpha"),
          py::arg("colour"), py::arg("rect"), py::arg("image"));
    // pipeline/early_depth at one instruction-set level: the depth plane (a, b, c) + offset with its
    // origin (1/256 pixel), the samples' positions in a pixel (1/256 pixel), quads (n, 3) int64 rows
    // (x, y, coverage bits), a (h, w, samples) uint32 depth buffer. Returns (survived (n, 4) uint16,
    // killed, the buffer after the test).
    t.def("early_depth_test",
          [](int level, std::array<double, 3> plane, double offset, int64_t origin_x, int64_t origin_y,
             std::vector<std::array<int32_t, 2>> samples, uint32_t func, bool write,
             py::array_t<int64_t, py::array::c_style | py::array::forcecast> quads,
             py::array_t<uint32_t, py::array::c_style | py::array::forcecast> depth) {
              if (quads.ndim() != 2 || quads.shape(1) != 3 || depth.ndim() != 3 || samples.empty() ||
                  samples.size() > 16 || depth.shape(2) != py::ssize_t(samples.size()))
                  throw py::value_error("quads (n, 3), 1 to 16 samples, depth (h, w, samples)");
              softgl::SamplePattern pattern{};
              pattern.count = int(samples.size());
              for (size_t s = 0; s < samples.size(); ++s) pattern.x[s] = samples[s][0], pattern.y[s] = samples[s][1];
              softgl::PrimitiveSetup p{};
              p.depth = {plane[0], plane[1], plane[2]};
              p.depth_offset = offset;
              p.origin_x = origin_x, p.origin_y = origin_y;
              const size_t n = size_t(quads.shape(0));
              std::vector<softgl::Quad> q(n);
              for (size_t i = 0; i < n; ++i)
                  q[i] = {int32_t(quads.at(i, 0)), int32_t(quads.at(i, 1)), uint64_t(quads.at(i, 2))};
              py::array_t<uint32_t> buffer({depth.shape(0), depth.shape(1), depth.shape(2)});
              std::memcpy(buffer.mutable_data(), depth.data(), size_t(depth.nbytes()));
              softgl::EarlyDepth t;
              t.prim = &p, t.pattern = &pattern, t.func = func, t.write = write;
              t.depth = buffer.mutable_data(), t.pitch = size_t(depth.shape(1));
              py::array_t<uint16_t> survived({py::ssize_t(n), py::ssize_t(4)});
              const size_t killed = softgl::early_depth_test_at(softgl::SimdLevel(level), t, q.data(), n, survived.mutable_data());
              return py::make_tuple(survived, killed, buffer);
          });
    // pipeline/raster at one instruction-set level: edges (n, 3) int64 rows (a, b, c) (n = 2, 3 or 4),
    // bbox and tile (x0, y0, x1, y1) in pixels. Returns (quads (m, 3) uint64 rows (x, y, coverage),
    // (blocks_rejected, blocks_accepted, blocks_partial, quads)).
    t.def("rasterize_edges",
          [](int level, py::array_t<int64_t, py::array::c_style | py::array::forcecast> edges,
             std::array<int32_t, 4> bbox, std::array<int32_t, 4> tile, int samples) {
              if (edges.ndim() != 2 || edges.shape(1) != 3 || edges.shape(0) < 2 || edges.shape(0) > 4)
                  throw py::value_error("edges (2, 3 or 4, 3)");
              softgl::PrimitiveSetup p{};
              p.edge_count = uint8_t(edges.shape(0));
              for (int i = 0; i < p.edge_count; ++i) p.a[i] = edges.at(i, 0), p.b[i] = edges.at(i, 1), p.c[i] = edges.at(i, 2);
              p.x0 = bbox[0], p.y0 = bbox[1], p.x1 = bbox[2], p.y1 = bbox[3];
              std::vector<softgl::Quad> quads;
              softgl::RasterStats stats;
              softgl::rasterize_at(softgl::SimdLevel(level), p, {tile[0], tile[1], tile[2], tile[3]},
                                   softgl::sample_pattern(samples), quads, stats);
              py::array_t<uint64_t> out({py::ssize_t(quads.size()), py::ssize_t(3)});
              for (size_t i = 0; i < quads.size(); ++i) {
                  *out.mutable_data(i, 0) = uint64_t(int64_t(quads[i].x));
                  *out.mutable_data(i, 1) = uint64_t(int64_t(quads[i].y));
                  *out.mutable_data(i, 2) = quads[i].coverage;
              }
              return py::make_tuple(out, py::make_tuple(stats.blocks_rejected, stats.blocks_accepted,
                                                        stats.blocks_partial, stats.quads));
          });
    // Texture lookups: 0 the general per-lane path, 1 the 2D fast path without SIMD, 2 with the
    // best SIMD (the default), 3 with AVX2 at most; returns how many queries the fast path served
    // since the last call.
    t.def("sampler_path", [](int path) {
        if (path < 0 || path > 3) throw py::value_error("sampler path: 0, 1, 2 or 3");
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
    // The clipper alone (pipeline/clip): triangle (3, 4) float32 in clip coordinates, full-target
    // viewport. Returns the clipped polygon's clip positions (n, 4) and weights (n, 3), float64.
    t.def("clip_triangle",
          [](ClipTriangle tri, int32_t width, int32_t height) {
              softgl::Vec4d v[3];
              const softgl::Clipper clipper = clip_inputs(tri, width, height, v);
              softgl::ClipVertex out[softgl::kMaxClipVertices];
              const int n = clipper.clip_triangle(v, out);
              py::array_t<double> pos({py::ssize_t(n), py::ssize_t(4)}), weights({py::ssize_t(n), py::ssize_t(3)});
              for (int i = 0; i < n; ++i) {
                  const softgl::Vec4d& p = out[i].position;
                  const double c[4] = {p.x, p.y, p.z, p.w};
                  for (int k = 0; k < 4; ++k) *pos.mutable_data(i, k) = c[k];
                  for (int k = 0; k < 3; ++k) *weights.mutable_data(i, k) = out[i].weight[k];
              }
              return py::make_tuple(pos, weights);
          },
          py::arg("triangle"), py::arg("width"), py::arg("height"));
    // Clipper::accepts (setup's no-clipping fast path) for the same inputs as clip_triangle.
    t.def("clip_accepts",
          [](ClipTriangle tri, int32_t width, int32_t height) {
              softgl::Vec4d v[3];
              return clip_inputs(tri, width, height, v).accepts(v);
          },
          py::arg("triangle"), py::arg("width"), py::arg("height"));
}
