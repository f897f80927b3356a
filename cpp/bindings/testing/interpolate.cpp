// softgl._core.testing hooks for pipeline/interpolate.
#include "hooks.h"

using namespace softgl;
using softgl::bindings::Array;
using softgl::bindings::InterpolationInputs;

InterpolationInputs::InterpolationInputs(const Array<double>& planes, int64_t origin_x, int64_t origin_y,
                                         const Array<int32_t>& q, const Array<float>& v, int32_t base_x,
                                         int32_t base_y) {
    if (planes.ndim() != 2 || planes.shape(0) != 4 || planes.shape(1) != 3 || q.ndim() != 2 || q.shape(1) != 2 ||
        v.ndim() != 2 || (v.shape(0) != 2 && v.shape(0) != 3))
        throw py::value_error("planes (4, 3), quads (n, 2), values (2 or 3, words)");
    Plane* pl[4] = {&prim.weight[0], &prim.weight[1], &prim.weight[2], &prim.inv_w};
    for (int k = 0; k < 4; ++k) *pl[k] = {planes.at(k, 0), planes.at(k, 1), planes.at(k, 2)};
    prim.origin_x = origin_x, prim.origin_y = origin_y;
    const size_t count = size_t(v.shape(1));
    const int vertices = int(v.shape(0));
    quads = bindings::to_quads(q, ~uint64_t(0));
    words.resize(count);
    values.resize(size_t(vertices) * count);
    for (size_t k = 0; k < count; ++k) words[k] = int(k);
    for (size_t j = 0; j < size_t(vertices); ++j)
        for (size_t k = 0; k < count; ++k) values[j * count + k] = v.at(j, k);
    prepare_interpolation(prim, vertices, base_x, base_y, words.data(), count, values.data(), vi);
}

namespace {

// interpolate_varyings_at one instruction-set level, inputs as InterpolationInputs. Returns
// (words, 4n) float32, lane 4*i + j = pixel j of quad i.
py::array_t<float> interpolate_varyings_hook(int level, Array<double> planes, int64_t origin_x, int64_t origin_y,
                                             Array<int32_t> quads, Array<float> values, int32_t base_x, int32_t base_y) {
    const InterpolationInputs in(planes, origin_x, origin_y, quads, values, base_x, base_y);
    const size_t n = in.quads.size(), count = in.words.size();
    py::array_t<float> out({py::ssize_t(count), py::ssize_t(4 * n)});
    interpolate_varyings_at(SimdLevel(level), in.vi, in.quads.data(), n, reinterpret_cast<uint32_t*>(out.mutable_data()),
                            4 * n);
    return out;
}

// interpolate_pixels_at one instruction-set level: the same inputs with `pixels` (m, 2) int32 in
// place of quads. Returns (words, m) float32, lane l = pixel l.
py::array_t<float> interpolate_pixels_hook(int level, Array<double> planes, int64_t origin_x, int64_t origin_y,
                                           Array<int32_t> pixels, Array<float> values, int32_t base_x, int32_t base_y) {
    const InterpolationInputs in(planes, origin_x, origin_y, pixels, values, base_x, base_y);
    const size_t m = size_t(pixels.shape(0)), count = in.words.size();
    std::vector<int32_t> xy(2 * m);
    for (size_t l = 0; l < m; ++l) xy[2 * l] = pixels.at(l, 0), xy[2 * l + 1] = pixels.at(l, 1);
    py::array_t<float> out({py::ssize_t(count), py::ssize_t(m)});
    interpolate_pixels_at(SimdLevel(level), in.vi, xy.data(), m, reinterpret_cast<uint32_t*>(out.mutable_data()), m);
    return out;
}

}  // namespace

void bind_testing_interpolate(py::module_& t) {
    t.def("interpolate_pixels", &interpolate_pixels_hook, py::arg("level"), py::arg("planes"), py::arg("origin_x"),
          py::arg("origin_y"), py::arg("pixels"), py::arg("values"), py::arg("base_x") = 0, py::arg("base_y") = 0);
    t.def("interpolate_varyings", &interpolate_varyings_hook, py::arg("level"), py::arg("planes"), py::arg("origin_x"),
          py::arg("origin_y"), py::arg("quads"), py::arg("values"), py::arg("base_x") = 0, py::arg("base_y") = 0);
}
