#include "softgl/surface/render_target.h"

#include <algorithm>
#include <cstring>

#include "softgl/surface/formats.h"

namespace softgl {

RenderTarget RenderTarget::for_default(DefaultFramebuffer& fb) {
    RenderTarget t;
    t.config_ = fb.config();
    t.default_ = &fb;
    if (!fb.is_float()) t.rgba8_ = fb.color_sample(0, 0, 0);
    return t;
}

RenderTarget RenderTarget::for_images(int32_t width, int32_t height, int32_t samples,
                                      const std::array<Color, kMaxColors>& colors, Image* depth, size_t depth_offset,
                                      Image* stencil, size_t stencil_offset) {
    RenderTarget t;
    t.config_.width = width;
    t.config_.height = height;
    t.config_.samples = samples;
    t.config_.alpha = true;
    t.config_.depth = depth != nullptr && !depth->depth_words.empty();
    t.config_.stencil = stencil != nullptr && !stencil->stencil.empty();
    t.colors_ = colors;
    t.depth_ = t.config_.depth ? depth : nullptr;
    t.stencil_ = t.config_.stencil ? stencil : nullptr;
    t.depth_offset_ = depth_offset;
    t.stencil_offset_ = stencil_offset;
    Image* const c0 = colors[0].image;
    bool one_color = c0 != nullptr;
    for (int o = 1; o < kMaxColors; ++o) one_color = one_color && colors[size_t(o)].image == nullptr;
    if (one_color && c0->format->internal_format == gl::RGBA8 && c0->bytes() && c0->width == width &&
        c0->samples == samples && !c0->rgba8.empty())
        t.rgba8_ = reinterpret_cast<uint8_t*>(c0->rgba8.data() + colors[0].offset);
    return t;
}

int RenderTarget::depth_bits() const {
    if (default_) return DefaultFramebuffer::kDepthBits;
    return depth_ ? depth_->format->depth_bits() : 0;
}

uint32_t RenderTarget::depth_word(double z) const {
    return softgl::depth_word(depth_ ? depth_->format->encoding : Encoding::Depth24, z);
}

uint32_t* RenderTarget::depth_samples(int32_t x, int32_t y) {
    if (default_) return default_->depth_samples(x, y);
    if (!depth_) return nullptr;
    return &depth_->depth_words[depth_offset_ + (size_t(y) * size_t(depth_->width) + size_t(x)) * size_t(depth_->samples)];
}

uint8_t* RenderTarget::stencil_samples(int32_t x, int32_t y) {
    if (default_) return default_->stencil_samples(x, y);
    if (!stencil_) return nullptr;
    return &stencil_->stencil[stencil_offset_ + (size_t(y) * size_t(stencil_->width) + size_t(x)) * size_t(stencil_->samples)];
}

namespace {

bool is_rgba8(const FormatInfo& f) {
    return f.encoding == Encoding::Unorm && f.bits[0] == 8 && f.bits[1] == 8 && f.bits[2] == 8 && f.bits[3] == 8;
}

}  // namespace

void write_image_color(Image& img, size_t offset, const BlendOp& op, const float src[4], int32_t x, int32_t y, int s) {
    const FormatInfo& f = *img.format;
    const size_t t = offset + (size_t(y) * size_t(img.width) + size_t(x)) * size_t(img.samples) + size_t(s);
    if (f.is_integer()) {
        // ES 3.0 §4.1.7: no blending for integer buffers; the shader's integer bits are written.
        uint32_t in[4], out[4];
        std::memcpy(in, src, 16);
        quantize_integer(f, in, out);
        const bool mask[4] = {op.write[0], op.write[1], op.write[2], op.write[3]};
        img.store_integer(t, out, mask);
        return;
    }
    if (img.bytes()) {
        uint8_t* const px = reinterpret_cast<uint8_t*>(&img.rgba8[t]);
        if (is_rgba8(f)) {
            // The drawing buffer's rule: blend_float with clamping then quantize_color to 8 bits
            // gives these bytes (surface/blend.cpp), without the float round trip.
            BlendOp o = op;
            o.has_alpha = true;
            blend_unorm8(o, src, px);
            return;
        }
        float dst[4], blended[4];
        img.read_color(t, dst);
        BlendOp o = op;
        o.has_alpha = true;
        blend_float(o, src, dst, true, blended);
        const uint32_t stored = quantize_unorm8(f, blended);
        for (int c = 0; c < 4; ++c)
            if (op.write[size_t(c)]) px[c] = uint8_t(stored >> (8 * c));
        return;
    }
    if (!img.narrow.empty()) {
        // One or two bytes per texel (Image::narrow): through the floats, clamped as unorm.
        float dst[4], blended[4], stored[4];
        img.read_color(t, dst);
        BlendOp o = op;
        o.has_alpha = true;
        blend_float(o, src, dst, true, blended);
        quantize_color(f, blended, stored);
        const bool mask[4] = {op.write[0], op.write[1], op.write[2], op.write[3]};
        img.store_color(t, stored, mask);
        return;
    }
    if (!img.packed.empty()) {
        // Encoded formats (Image::packed: 16F, sRGB, RGB565, ...): through the floats, clamped
        // unless float (ES 3.0 §4.1.7), then encoded (quantize_color's value).
        float dst[4], blended[4];
        img.read_color(t, dst);
        BlendOp o = op;
        o.has_alpha = true;
        blend_float(o, src, dst, !f.is_float(), blended);
        const bool mask[4] = {op.write[0], op.write[1], op.write[2], op.write[3]};
        img.encode_color(t, blended, mask);
        return;
    }
    const size_t n = size_t(img.color_channels());
    float* dst = &img.color[t * n];
    float blended[4], stored[4];
    BlendOp o = op;
    o.has_alpha = true;
    if (n == 4) {
        blend_float(o, src, dst, !f.is_float(), blended);
    } else {
        float full[4];   // the stored channels and the absent ones' defaults (Image::read_color)
        img.read_color(t, full);
        blend_float(o, src, full, !f.is_float(), blended);
    }
    quantize_color(f, blended, stored);
    for (size_t c = 0; c < n; ++c)
        if (op.write[c]) dst[c] = stored[c];
}

namespace {

// The rows of `r`: f(first element, element count) per row, `per_texel` elements per sample.
template <class F>
void for_rows(const Image& img, size_t offset, Rect r, size_t per_texel, F&& f) {
    const size_t S = size_t(img.samples), W = size_t(img.width);
    if (r.width <= 0 || r.height <= 0) return;
    if (r.x == 0 && size_t(r.width) == W) {   // whole rows: one run
        f((offset + size_t(r.y) * W * S) * per_texel, size_t(r.height) * W * S * per_texel);
        return;
    }
    for (int32_t y = r.y; y < r.y + r.height; ++y)
        f((offset + (size_t(y) * W + size_t(r.x)) * S) * per_texel, size_t(r.width) * S * per_texel);
}

// Copies the channels of `mask` of the 4-element texel `first` over the run [at, at + n).
template <class T>
void fill_texels(std::vector<T>& data, size_t at, size_t n, const T first[4], const std::array<bool, 4>& mask,
                 size_t channels = 4) {
    T* p = data.data() + at;
    if (mask[0] && mask[1] && mask[2] && mask[3]) {
        for (size_t i = 0; i < n; i += channels) std::memcpy(p + i, first, channels * sizeof(T));
        return;
    }
    for (size_t i = 0; i < n; i += channels)
        for (size_t c = 0; c < channels; ++c)
            if (mask[c]) p[i + c] = first[c];
}

}  // namespace

void clear_image_color(Image& img, size_t offset, Rect r, const float src[4], const std::array<bool, 4>& mask) {
    if (r.width <= 0 || r.height <= 0) return;
    BlendOp op;
    op.write = mask;
    write_image_color(img, offset, op, src, r.x, r.y, 0);
    const size_t first = offset + (size_t(r.y) * size_t(img.width) + size_t(r.x)) * size_t(img.samples);
    if (img.bytes()) {
        // One 4-byte texel, copied with the written bytes' mask.
        const uint32_t texel = img.rgba8[first];
        uint32_t keep = 0;
        for (int c = 0; c < 4; ++c)
            if (!mask[size_t(c)]) keep |= 255u << (8 * c);
        for_rows(img, offset, r, 1, [&](size_t at, size_t n) {
            uint32_t* p = img.rgba8.data() + at;
            if (!keep) return void(std::fill_n(p, n, texel));
            for (size_t i = 0; i < n; ++i) p[i] = (p[i] & keep) | (texel & ~keep);
        });
    } else if (!img.narrow.empty()) {
        // The first texel's bytes (all of them: a masked channel kept its value there, so each
        // texel keeps its own masked bytes below), copied with the mask of the channels written.
        const size_t n = size_t(Image::narrow_bytes(img.format));
        const GLenum base = img.format->base_format;
        const int from[2] = {base == gl::ALPHA ? 3 : 0, base == gl::LUMINANCE_ALPHA ? 3 : 1};
        uint8_t texel[2] = {img.narrow[first * n], n == 2 ? img.narrow[first * n + 1] : uint8_t(0)};
        for_rows(img, offset, r, 1, [&](size_t at, size_t count) {
            for (size_t i = 0; i < count; ++i)
                for (size_t b = 0; b < n; ++b)
                    if (mask[size_t(from[b])]) img.narrow[(at + i) * n + b] = texel[b];
        });
    } else if (!img.packed.empty()) {
        // The first texel's encoding, copied whole; with a mask, its values stored channel by
        // channel (a masked channel keeps each texel's own value).
        const size_t nb = img.packed_size;
        uint8_t bytes[8];
        std::memcpy(bytes, &img.packed[first * nb], nb);
        float texel[4];
        img.read_color(first, texel);
        const bool all = mask[0] && mask[1] && mask[2] && mask[3];
        const bool m[4] = {mask[0], mask[1], mask[2], mask[3]};
        for_rows(img, offset, r, 1, [&](size_t at, size_t n) {
            for (size_t i = 0; i < n; ++i) {
                if (all) std::memcpy(&img.packed[(at + i) * nb], bytes, nb);
                else img.store_color(at + i, texel, m);
            }
        });
    } else if (img.format->is_integer()) {
        // The first texel's bytes (a masked channel kept its value there, so each texel keeps
        // its own below): copied whole, or channel by channel through store_integer.
        const size_t nb = size_t(Image::integer_bytes(img.format));
        uint8_t bytes[16];
        std::memcpy(bytes, &img.integer[first * nb], nb);
        uint32_t texel[4];
        img.read_integer(first, texel);
        const bool all = mask[0] && mask[1] && mask[2] && mask[3];
        const bool m[4] = {mask[0], mask[1], mask[2], mask[3]};
        for_rows(img, offset, r, 1, [&](size_t at, size_t n) {
            for (size_t i = 0; i < n; ++i) {
                if (all) std::memcpy(&img.integer[(at + i) * nb], bytes, nb);
                else img.store_integer(at + i, texel, m);
            }
        });
    } else {
        const size_t channels = size_t(img.color_channels());   // floats per texel
        float texel[4];
        std::memcpy(texel, &img.color[first * channels], channels * sizeof(float));
        for_rows(img, offset, r, channels, [&](size_t at, size_t n) { fill_texels(img.color, at, n, texel, mask, channels); });
    }
}

void clear_image_depth(Image& img, size_t offset, Rect r, uint32_t word) {
    for_rows(img, offset, r, 1, [&](size_t at, size_t n) { std::fill_n(img.depth_words.data() + at, n, word); });
}

void clear_image_stencil(Image& img, size_t offset, Rect r, uint8_t value, uint8_t write_mask) {
    for_rows(img, offset, r, 1, [&](size_t at, size_t n) {
        uint8_t* p = img.stencil.data() + at;
        if (write_mask == 0xFF) return void(std::fill_n(p, n, value));
        for (size_t i = 0; i < n; ++i) p[i] = uint8_t((p[i] & ~write_mask) | (value & write_mask));
    });
}

void RenderTarget::write_color(const BlendOp& op, const float src[4], int32_t x, int32_t y, int s, int output) {
    if (default_) {
        if (output != 0) return;   // the drawing buffer has one colour buffer (BACK)
        if (default_->is_float()) {
            // softgl color_format rgba16f / rgba32f: blend unclamped in float (ES 3.0 §4.1.7),
            // then round to the format (binary16 ties to even for 16F).
            float* dst = default_->color_sample_f(x, y, s);
            float blended[4];
            blend_float(op, src, dst, false, blended);
            for (int c = 0; c < 4; ++c)
                if (op.write[size_t(c)]) dst[c] = default_->quantize(blended[c]);
            return;
        }
        blend_unorm8(op, src, default_->color_sample(x, y, s));
        return;
    }
    if (output < 0 || output >= kMaxColors) return;
    const Color& c = colors_[size_t(output)];
    if (c.image) write_image_color(*c.image, c.offset, op, src, x, y, s);
}

}  // namespace softgl
