#include "softgl/pipeline/passthrough_shaders.h"

#include <algorithm>
#include <cstring>

namespace softgl {

PassthroughVertexShader::PassthroughVertexShader(int point_size_location)
    : point_size_location_(point_size_location) {
    layout_.words = 4;
    layout_.flat.assign(4, 0);
    layout_.read_by_fragment.assign(4, 1);
}

uint32_t PassthroughVertexShader::used_attributes() const {
    return 3u | (point_size_location_ >= 0 ? 1u << point_size_location_ : 0u);
}

void PassthroughVertexShader::run(const std::array<AttributeStream, kMaxVertexAttribs>& attribs,
                                  size_t count, const uint32_t*, const uint32_t*, const VertexDestination& out) const {
    std::fill_n(out.point_size, count, 1.0f);
    for (size_t v = 0; v < count; ++v)
        for (int c = 0; c < 4; ++c) {
            std::memcpy(&out.position[v * 4 + size_t(c)], &attribs[0].comp[size_t(c)][v], 4);
            out.varyings[v * 4 + size_t(c)] = attribs[1].comp[size_t(c)][v];
        }
    if (point_size_location_ >= 0)
        for (size_t v = 0; v < count; ++v)
            std::memcpy(&out.point_size[v], &attribs[size_t(point_size_location_)].comp[0][v], 4);
}

void ColorFragmentShader::run(const FragmentBatch& b, FragmentResults& out, unsigned) const {
    const size_t L = b.lanes, S = b.stride();
    out.color.resize(4 * L);
    out.outputs = 1;
    for (size_t c = 0; c < 4; ++c) std::memcpy(&out.color[c * L], &b.varyings[c * S], 4 * L);
    out.killed.assign(may_discard() ? L : 0, 0);
    if (may_discard())
        for (size_t lane = 0; lane < L; ++lane) out.killed[lane] = out.color[3 * L + lane] < discard_below_;
    if (depth_from_red_) out.depth.assign(out.color.begin(), out.color.begin() + long(L));
}

}  // namespace softgl
