#include "softgl/surface/blend.h"

#include <algorithm>

#include "softgl/surface/formats.h"

namespace softgl {

BlendOp BlendOp::from_state(const State& s, bool has_alpha) {
    BlendOp op;
    op.enabled = s.blend.enabled;
    op.src_rgb = s.blend.src_rgb;
    op.dst_rgb = s.blend.dst_rgb;
    op.src_alpha = s.blend.src_alpha;
    op.dst_alpha = s.blend.dst_alpha;
    op.eq_rgb = s.blend.equation_rgb;
    op.eq_alpha = s.blend.equation_alpha;
    for (int c = 0; c < 4; ++c) op.constant[size_t(c)] = clamp01(s.blend.color[size_t(c)]);
    op.constant_unclamped = s.blend.color;
    op.write = s.color_mask;
    op.has_alpha = has_alpha;
    if (!has_alpha) op.write[3] = false;
    return op;
}

bool BlendOp::is_plain_write() const {
    return !enabled || (src_rgb == gl::ONE && dst_rgb == gl::ZERO && src_alpha == gl::ONE &&
                        dst_alpha == gl::ZERO && eq_rgb == gl::FUNC_ADD && eq_alpha == gl::FUNC_ADD);
}

namespace {


}  // namespace

void blend_unorm8(const BlendOp& op, const float src[4], uint8_t dst[4]) {
    float s[4], d[4], out[4];
    for (int c = 0; c < 4; ++c) s[c] = clamp01(src[c]);
    if (op.is_plain_write()) {
        for (int c = 0; c < 4; ++c) out[c] = s[c];
    } else {
        for (int c = 0; c < 4; ++c) d[c] = float(dst[c]) / 255.0f;
        if (!op.has_alpha) d[3] = 1.0f;
        for (int c = 0; c < 4; ++c) {
            const bool alpha = c == 3;
            const float sf = blend_factor<float>(alpha ? op.src_alpha : op.src_rgb, c, s, d, op.constant.data());
            const float df = blend_factor<float>(alpha ? op.dst_alpha : op.dst_rgb, c, s, d, op.constant.data());
            out[c] = blend_equation<float>(alpha ? op.eq_alpha : op.eq_rgb, s[c], sf, d[c], df);
        }
    }
    for (int c = 0; c < 4; ++c)
        if (op.write[size_t(c)]) dst[c] = float_to_unorm8(out[c]);
}

// Textures and framebuffers (render targets stored as floats).
void blend_float(const BlendOp& op, const float src[4], const float dst[4], bool clamp, float out[4]) {
    float s[4], d[4], k[4], r[4];
    for (int c = 0; c < 4; ++c) {
        s[c] = clamp ? clamp01(src[c]) : src[c];
        d[c] = clamp ? clamp01(dst[c]) : dst[c];
        k[c] = clamp ? op.constant[size_t(c)] : op.constant_unclamped[size_t(c)];   // ES 3.0 §4.1.7
    }
    if (!op.has_alpha) d[3] = 1.0f;
    if (op.is_plain_write()) {
        for (int c = 0; c < 4; ++c) r[c] = s[c];
    } else {
        for (int c = 0; c < 4; ++c) {
            const bool alpha = c == 3;
            const float sf = blend_factor<float>(alpha ? op.src_alpha : op.src_rgb, c, s, d, k);
            const float df = blend_factor<float>(alpha ? op.dst_alpha : op.dst_rgb, c, s, d, k);
            r[c] = blend_equation<float>(alpha ? op.eq_alpha : op.eq_rgb, s[c], sf, d[c], df);
        }
    }
    for (int c = 0; c < 4; ++c) out[c] = op.write[size_t(c)] ? r[c] : dst[c];
}

}  // namespace softgl
