// softgl._core.testing hooks for surface/sampler: one texture lookup of a 2D or 2D array texture
// through TextureUnitSampler on a chosen path (general, fast scalar, AVX2 blocks, best), so that
// tests compare the paths lane by lane on coordinates a draw would rarely produce.
#include <memory>

#include "hooks.h"

#include <pybind11/stl.h>

#include "softgl/core/simd.h"
#include "softgl/surface/sampler.h"
#include "softgl/surface/texture.h"

using namespace softgl;
using softgl::bindings::Array;

namespace {

SamplerPath sampler_path(const std::string& name) {
    if (name == "general") return SamplerPath::General;
    if (name == "scalar") return SamplerPath::Scalar;
    if (name == "avx2") return SamplerPath::Avx2;
    if (name == "best") return SamplerPath::Best;
    throw py::value_error("path: general, scalar, avx2 or best");
}

glsl::TextureLod lod_mode(const std::string& name) {
    if (name == "implicit") return glsl::TextureLod::Implicit;
    if (name == "bias") return glsl::TextureLod::Bias;
    if (name == "explicit") return glsl::TextureLod::Explicit;
    if (name == "gradient") return glsl::TextureLod::Gradient;
    throw py::value_error("lod_mode: implicit, bias, explicit or gradient");
}

// levels: arrays (layers, h, w, 4) float32, level 0 first: texel values (unorm8: the bytes k,
// stored as k / 255 in an RGBA8 texture; else an RGBA32F texture). params: min_filter,
// mag_filter, wrap_s, wrap_t (GL enums), min_lod, max_lod. storage: what the fast path's level
// table holds: "default" (as a draw leaves it: floats, and the byte copy of RGBA8 2D levels),
// "bytes" (bytes only, no floats: every unorm8 level), "floats" (no byte copy).
// coords (3, n): s, t, layer; lod (n): bias or level; ddx, ddy (2, n): derivatives (implicit,
// bias: what the executor computes from the quad; gradient: the shader's); active (n) bools.
// Returns (out (4, n) float32, whether the fast path served the query).
py::tuple sample_texture_hook(const std::string& path, int simd, py::list levels, bool unorm8, py::dict params,
                              Array<float> coords, const std::string& mode,
                              Array<float> lod, Array<float> ddx, Array<float> ddy, Array<uint8_t> active,
                              std::array<int, 2> offset) {
    if (levels.empty() || coords.ndim() != 2 || coords.shape(0) != 3) throw py::value_error("levels, coords (3, n)");
    const py::ssize_t n = coords.shape(1);
    if (lod.size() != n || ddx.ndim() != 2 || ddx.shape(0) != 2 || ddx.shape(1) != n || ddy.ndim() != 2 ||
        ddy.shape(0) != 2 || ddy.shape(1) != n || active.size() != n)
        throw py::value_error("lod (n), ddx and ddy (2, n), active (n)");
    auto tex = std::make_shared<Texture>();
    const Array<float> first = levels[0].cast<Array<float>>();
    if (first.ndim() != 4 || first.shape(3) != 4) throw py::value_error("levels: (layers, h, w, 4)");
    const int32_t layers = int32_t(first.shape(0));
    const bool array = layers > 1;
    tex->target = array ? gl::TEXTURE_2D_ARRAY : gl::TEXTURE_2D;
    const FormatInfo* format = format_info(unorm8 ? gl::RGBA8 : gl::RGBA32F);
    const int32_t count = int32_t(levels.size());
    for (int32_t k = 0; k < count; ++k) {
        const Array<float> a = levels[size_t(k)].cast<Array<float>>();
        if (a.ndim() != 4 || a.shape(0) != layers || a.shape(3) != 4) throw py::value_error("levels: (layers, h, w, 4)");
        Image& img = tex->image(0, k);
        img.allocate(format, int32_t(a.shape(2)), int32_t(a.shape(1)), layers);
        // 8-bit unorm images keep bytes as their only storage (Image::rgba8): the values are bytes k.
        if (unorm8)
            for (size_t i = 0; i < img.rgba8.size(); ++i) {
                uint32_t texel = 0;
                for (int c = 0; c < 4; ++c) texel |= uint32_t(a.data()[i * 4 + size_t(c)]) << (8 * c);
                img.rgba8[i] = texel;
            }
        else
            for (size_t i = 0; i < img.texel_count(); ++i) img.store_color(i, a.data() + i * 4);
    }
    tex->max_level = count - 1;
    SamplerParams& p = tex->sampler;
    p.min_filter = params["min_filter"].cast<GLenum>(), p.mag_filter = params["mag_filter"].cast<GLenum>();
    p.wrap_s = params["wrap_s"].cast<GLenum>(), p.wrap_t = params["wrap_t"].cast<GLenum>();
    if (params.contains("min_lod")) p.min_lod = params["min_lod"].cast<float>();
    if (params.contains("max_lod")) p.max_lod = params["max_lod"].cast<float>();

    TextureUnitSampler sampler;
    BoundTexture& bt = sampler.units[0][array ? 3 : 0];
    bt.texture = tex.get();
    bt.params = p;
    bt.base = 0;
    bt.q = needs_mipmaps(p.min_filter) ? max_sampled_level(*tex) : 0;
    tex->refresh_sampling(bt.base, bt.q);   // the level table, as a draw builds it when it binds the texture
    const uint32_t filled[4] = {array ? 0u : 1u, 0u, 0u, array ? 1u : 0u};
    sampler.plan_units(filled);   // and the unit's sampling plan
    std::vector<glsl::Scalar> unit(static_cast<size_t>(n)), in[8], outs[4];
    std::vector<uint32_t> lanes(static_cast<size_t>(n));
    for (py::ssize_t l = 0; l < n; ++l) lanes[size_t(l)] = active.data()[l] ? ~0u : 0u;
    const float* sources[8] = {coords.data(), coords.data() + n, coords.data() + 2 * n, lod.data(),
                               ddx.data(), ddx.data() + n, ddy.data(), ddy.data() + n};
    for (int k = 0; k < 8; ++k) {
        in[k].resize(size_t(n));
        for (py::ssize_t l = 0; l < n; ++l) in[k][size_t(l)].f = sources[k][l];
    }
    glsl::TextureQuery q;
    q.kind = glsl::TextureKind::Sample;
    q.dim = array ? glsl::SamplerDim::Tex2DArray : glsl::SamplerDim::Tex2D;
    q.result = glsl::BaseType::Float;
    q.lod_mode = lod_mode(mode);
    q.lane_count = int(n);
    q.active = lanes.data();
    q.unit = unit.data();
    q.uniform_unit = true;
    for (int k = 0; k < 3; ++k) q.coord[k] = in[k].data();
    q.lod = in[3].data();
    for (int k = 0; k < 2; ++k) q.ddx[k] = in[4 + k].data(), q.ddy[k] = in[6 + k].data();
    q.offset[0] = offset[0], q.offset[1] = offset[1];
    for (int c = 0; c < 4; ++c) outs[c].assign(size_t(n), glsl::Scalar{}), q.out[c] = outs[c].data();
    q.path = sampler_path(path);
    q.simd = std::min(SimdLevel(simd), best_simd_level());
    uint64_t fast = 0;
    q.fast_queries = &fast;
    sampler.sample(q);
    py::array_t<float> result({py::ssize_t(4), n});
    for (int c = 0; c < 4; ++c)
        for (py::ssize_t l = 0; l < n; ++l) result.mutable_at(c, l) = outs[c][size_t(l)].f;
    return py::make_tuple(result, fast != 0);
}

// lambdas_of_rho2_at: (lambdas float32, how many the vector kernel vouched for).
py::tuple lod_lambdas_hook(int simd, Array<double> rho2) {
    py::array_t<float> out(rho2.size());
    const size_t sure = lambdas_of_rho2_at(SimdLevel(simd), rho2.data(), size_t(rho2.size()), out.mutable_data());
    return py::make_tuple(out, sure);
}

}  // namespace

void bind_testing_sampler(py::module_& t) {
    t.def("sample_texture", &sample_texture_hook, py::arg("path"), py::arg("simd"), py::arg("levels"),
          py::arg("unorm8"), py::arg("params"), py::arg("coords"), py::arg("lod_mode"),
          py::arg("lod"), py::arg("ddx"), py::arg("ddy"), py::arg("active"), py::arg("offset"));
    t.def("lod_lambdas", &lod_lambdas_hook, py::arg("simd"), py::arg("rho2"));
}
