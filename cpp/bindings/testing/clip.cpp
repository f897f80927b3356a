// softgl._core.testing hooks for the clipper alone (pipeline/clip): a triangle (3, 4) float32 in
// clip coordinates and a full-target viewport of width x height.
#include "hooks.h"
#include "softgl/pipeline/clip.h"

using namespace softgl;
using Triangle = softgl::bindings::Array<float>;

namespace {

// Fills v from `tri` and returns the clipper.
Clipper clip_inputs(const Triangle& tri, int32_t width, int32_t height, Vec4d v[3]) {
    if (tri.ndim() != 2 || tri.shape(0) != 3 || tri.shape(1) != 4) throw py::value_error("triangle must be (3, 4)");
    Viewport vp;
    vp.width = width;
    vp.height = height;
    for (int i = 0; i < 3; ++i) v[i] = {tri.at(i, 0), tri.at(i, 1), tri.at(i, 2), tri.at(i, 3)};
    return Clipper(vp);
}

// The clipped polygon's clip positions (n, 4) and weights (n, 3), float64.
auto clip_triangle(Triangle tri, int32_t width, int32_t height) {
    Vec4d v[3];
    const Clipper clipper = clip_inputs(tri, width, height, v);
    ClipVertex out[kMaxClipVertices];
    const int n = clipper.clip_triangle(v, out);
    py::array_t<double> pos({py::ssize_t(n), py::ssize_t(4)}), weights({py::ssize_t(n), py::ssize_t(3)});
    for (int i = 0; i < n; ++i) {
        const Vec4d& p = out[i].position;
        const double c[4] = {p.x, p.y, p.z, p.w};
        for (int k = 0; k < 4; ++k) *pos.mutable_data(i, k) = c[k];
        for (int k = 0; k < 3; ++k) *weights.mutable_data(i, k) = out[i].weight[k];
    }
    return py::make_tuple(pos, weights);
}

// Clipper::accepts (setup's no-clipping fast path).
bool clip_accepts(Triangle tri, int32_t width, int32_t height) {
    Vec4d v[3];
    return clip_inputs(tri, width, height, v).accepts(v);
}

}  // namespace

void bind_testing_clip(py::module_& t) {
    t.def("clip_triangle", &clip_triangle, py::arg("triangle"), py::arg("width"), py::arg("height"));
    t.def("clip_accepts", &clip_accepts, py::arg("triangle"), py::arg("width"), py::arg("height"));
}
