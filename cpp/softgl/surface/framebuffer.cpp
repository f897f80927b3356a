#include "softgl/surface/framebuffer.h"

#include <algorithm>
#include <cstring>

#include "softgl/core/memory_ledger.h"
#include "softgl/surface/formats.h"
#include "softgl/surface/texture.h"   // float_to_half / half_to_float (IEEE binary16)

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace softgl {

namespace {

template <int S>
size_t resolve_rgba8_at(const uint8_t* in, size_t n, uint8_t* out, uint32_t* ties) {
    size_t i = 0, tie_count = 0;
#if defined(__SSE2__)
    // Four pixels per step: each pixel's samples widened to 16 bits and added into eight lanes
    // (partial sums per channel), the halves of two pixels added into one vector of their four
    // channel sums, then rounded, shifted and packed back to bytes.
    if constexpr (S == 4 || S == 8 || S == 16) {
        constexpr int kShift = S == 4 ? 2 : S == 8 ? 3 : 4;
        const __m128i zero = _mm_setzero_si128(), half = _mm_set1_epi16(S / 2), low = _mm_set1_epi16(S - 1);
        auto partial = [&](const uint8_t* px) {
            __m128i acc = _mm_setzero_si128();
            for (int k = 0; k < S / 4; ++k) {
                const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(px + 16 * k));
                acc = _mm_add_epi16(acc, _mm_add_epi16(_mm_unpacklo_epi8(v, zero), _mm_unpackhi_epi8(v, zero)));
            }
            return acc;
        };
        auto sums_of_two = [&](const uint8_t* px) {
            const __m128i a = partial(px), b = partial(px + 4 * S);
            return _mm_add_epi16(_mm_unpacklo_epi64(a, b), _mm_unpackhi_epi64(a, b));
        };
        for (; i + 4 <= n; i += 4, in += 16 * S, out += 16) {
            const __m128i s01 = sums_of_two(in), s23 = sums_of_two(in + 8 * S);
            _mm_storeu_si128(reinterpret_cast<__m128i*>(out),
                             _mm_packus_epi16(_mm_srli_epi16(_mm_add_epi16(s01, half), kShift),
                                              _mm_srli_epi16(_mm_add_epi16(s23, half), kShift)));
            if (!ties) continue;
            // Bytes 8p .. 8p + 7 of the mask: pixel p's four channels (two bytes each).
            const int t01 = _mm_movemask_epi8(_mm_cmpeq_epi16(_mm_and_si128(s01, low), half));
            const int t23 = _mm_movemask_epi8(_mm_cmpeq_epi16(_mm_and_si128(s23, low), half));
            const uint32_t t = uint32_t(t01) | (uint32_t(t23) << 16);
            if (!t) continue;
            for (uint32_t p = 0; p < 4; ++p)
                if (t & (0xFFu << (8 * p))) ties[tie_count++] = uint32_t(i + p);
        }
    }
#endif
    for (; i < n; ++i, in += 4 * S, out += 4) {
        bool tie = false;
        for (int c = 0; c < 4; ++c) {
            uint32_t sum = 0;
            for (int s = 0; s < S; ++s) sum += in[s * 4 + c];
            out[c] = uint8_t((sum + uint32_t(S) / 2) / uint32_t(S));
            tie = tie || (S > 1 && sum % uint32_t(S) == uint32_t(S) / 2);
        }
        if (ties && tie) ties[tie_count++] = uint32_t(i);
    }
    return tie_count;
}

}  // namespace

size_t resolve_rgba8(const uint8_t* in, int samples, size_t n, uint8_t* out, uint32_t* ties) {
    switch (samples) {
        case 1: std::memcpy(out, in, n * 4); return 0;
        case 2: return resolve_rgba8_at<2>(in, n, out, ties);
        case 4: return resolve_rgba8_at<4>(in, n, out, ties);
        case 8: return resolve_rgba8_at<8>(in, n, out, ties);
        case 16: return resolve_rgba8_at<16>(in, n, out, ties);
    }
    size_t tie_count = 0;   // other counts (none are allocated today)
    const uint32_t S = uint32_t(samples);
    for (size_t i = 0; i < n; ++i, in += 4 * S, out += 4) {
        bool tie = false;
        for (int c = 0; c < 4; ++c) {
            uint32_t sum = 0;
            for (uint32_t s = 0; s < S; ++s) sum += in[s * 4 + uint32_t(c)];
            out[c] = uint8_t((sum + S / 2) / S);
            tie = tie || (S > 1 && sum % S == S / 2);
        }
        if (ties && tie) ties[tie_count++] = uint32_t(i);
    }
    return tie_count;
}

uint64_t memory_budget() { return default_memory_limit(); }

uint64_t DefaultFramebuffer::bytes_needed(const FramebufferConfig& c) {
    const uint64_t samples = uint64_t(c.width) * uint64_t(c.height) * uint64_t(c.samples);
    uint64_t per_sample = c.color_format == ColorFormat::RGBA8 ? 4 : 16;   // float formats: 4 floats
    if (c.depth) per_sample += 4;
    if (c.stencil) per_sample += 1;
    return samples * per_sample;
}

std::string DefaultFramebuffer::check(const FramebufferConfig& c, uint64_t released, const MemoryAccount* account) {
    if (c.width <= 0 || c.height <= 0)
        return "drawing buffer size must be positive, got " + std::to_string(c.width) + "x" +
               std::to_string(c.height);
    if (c.width > kMaxDrawingBufferSize || c.height > kMaxDrawingBufferSize)
        return "drawing buffer " + std::to_string(c.width) + "x" + std::to_string(c.height) +
               " exceeds the maximum of " + std::to_string(kMaxDrawingBufferSize) + " per side";
    // Refuse what cannot fit in half the physical memory, before allocating anything.
    const uint64_t budget = memory_budget(), need = bytes_needed(c);
    if (need > budget)
        return "drawing buffer needs " + std::to_string(need >> 20) + " MiB, more than half of " +
               "this machine's memory (" + std::to_string(budget >> 20) + " MiB)";
    // With the other objects' memory (the ledger, the process's and the context's), less what
    // the buffer it replaces frees.
    const uint64_t more = need - std::min(need, released);
    if (!memory_fits(account, more))
        return "drawing buffer needs " + std::to_string(need) + " bytes, which " + over_memory_limit(account, more);
    return {};
}

DefaultFramebuffer::DefaultFramebuffer(const FramebufferConfig& config, std::shared_ptr<MemoryAccount> account)
    : config_(config), memory_(std::move(account)) {
    const size_t n = size_t(config.width) * size_t(config.height) * size_t(config.samples);
    memory_.force(bytes_needed(config));   // check() compared it with the limit
    // Initial contents are zero (WebGL clears a new drawing buffer to transparent black, depth 1,
    // stencil 0; ES 3.0 §4.2.3 clear values); without alpha the buffer reads back alpha = 1.
    if (is_float()) {
        color_f_.assign(n * 4, 0.0f);
        if (!config.alpha)
            for (size_t i = 0; i < n; ++i) color_f_[i * 4 + 3] = 1.0f;
    } else {
        color_.assign(n * 4, 0);
        if (!config.alpha)
            for (size_t i = 0; i < n; ++i) color_[i * 4 + 3] = 255;
    }
    if (config.depth) depth_.assign(n, (1u << kDepthBits) - 1);
    if (config.stencil) stencil_.assign(n, 0);
}

Rect DefaultFramebuffer::clip(Rect r) const {
    // Widen to 64 bits: x + width may overflow int32.
    const int64_t x0 = std::max<int64_t>(r.x, 0), y0 = std::max<int64_t>(r.y, 0);
    const int64_t x1 = std::min<int64_t>(int64_t(r.x) + r.width, config_.width);
    const int64_t y1 = std::min<int64_t>(int64_t(r.y) + r.height, config_.height);
    Rect out;
    out.x = int32_t(x0);
    out.y = int32_t(y0);
    out.width = int32_t(std::max<int64_t>(0, x1 - x0));
    out.height = int32_t(std::max<int64_t>(0, y1 - y0));
    return out;
}

void DefaultFramebuffer::clear_color(Rect rect, const std::array<float, 4>& rgba,
                                     const std::array<bool, 4>& mask) {
    const Rect r = clip(rect);
    std::array<bool, 4> write = mask;
    if (!config_.alpha) write[3] = false;  // no alpha channel: alpha stays 1
    const int S = config_.samples;
    if (is_float()) {
        // ES 3.0 §4.2.3: the clear colour is converted to the buffer's format; float buffers
        // take it unclamped (§2.1.1 conversion to binary16 for RGBA16F).
        float value[4];
        for (int c = 0; c < 4; ++c) value[c] = quantize(rgba[c]);
        for (int32_t y = r.y; y < r.y + r.height; ++y) {
            float* p = color_sample_f(r.x, y, 0);
            const size_t count = size_t(r.width) * S;
            for (size_t i = 0; i < count; ++i, p += 4)
                for (int c = 0; c < 4; ++c)
                    if (write[c]) p[c] = value[c];
        }
        return;
    }
    uint8_t value[4];
    for (int c = 0; c < 4; ++c) value[c] = float_to_unorm8(rgba[c]);
    for (int32_t y = r.y; y < r.y + r.height; ++y) {
        uint8_t* p = color_sample(r.x, y, 0);
        const size_t count = size_t(r.width) * S;
        if (write[0] && write[1] && write[2] && write[3]) {
            for (size_t i = 0; i < count; ++i, p += 4) std::copy(value, value + 4, p);
        } else {
            for (size_t i = 0; i < count; ++i, p += 4)
                for (int c = 0; c < 4; ++c)
                    if (write[c]) p[c] = value[c];
        }
    }
}

void DefaultFramebuffer::clear_depth(Rect rect, float depth) {
    if (depth_.empty()) return;
    const Rect r = clip(rect);
    const uint32_t value = float_to_unorm(depth, kDepthBits);
    const size_t S = config_.samples;
    for (int32_t y = r.y; y < r.y + r.height; ++y) {
        uint32_t* p = &depth_[(size_t(y) * config_.width + r.x) * S];
        std::fill(p, p + size_t(r.width) * S, value);
    }
}

void DefaultFramebuffer::clear_stencil(Rect rect, int32_t value, uint32_t write_mask) {
    if (stencil_.empty()) return;
    const Rect r = clip(rect);
    // ES 3.0 §4.2.3: the clear value is masked to the stencil bits; the write mask applies.
    const uint8_t bits = uint8_t(uint32_t(value) & 0xFFu), mask = uint8_t(write_mask & 0xFFu);
    const size_t S = config_.samples;
    for (int32_t y = r.y; y < r.y + r.height; ++y) {
        uint8_t* p = &stencil_[(size_t(y) * config_.width + r.x) * S];
        for (size_t i = 0; i < size_t(r.width) * S; ++i) p[i] = uint8_t((p[i] & ~mask) | (bits & mask));
    }
}

void DefaultFramebuffer::read_rgba8(int32_t x, int32_t y, int32_t w, int32_t h, uint8_t* dst,
                                    std::ptrdiff_t row_stride) const {
    const Rect r = clip(Rect{x, y, w, h});
    const int S = config_.samples;
    if (is_float()) {   // resolved float, then clamped and rounded like any float -> unorm8
        float px[4];
        for (int32_t py = r.y; py < r.y + r.height; ++py)
            for (int32_t qx = r.x; qx < r.x + r.width; ++qx) {
                read_pixel(qx, py, px);
                uint8_t* out = dst + (py - y) * row_stride + std::ptrdiff_t(qx - x) * 4;
                for (int c = 0; c < 4; ++c) out[c] = float_to_unorm8(px[c]);
            }
        return;
    }
    for (int32_t py = r.y; py < r.y + r.height; ++py) {
        uint8_t* out = dst + (int64_t(py) - y) * row_stride + std::ptrdiff_t(int64_t(r.x) - x) * 4;   // 64-bit: x may be -2^31
        const uint8_t* in = &color_[(size_t(py) * config_.width + r.x) * S * 4];
        resolve_rgba8(in, S, size_t(r.width), out);
    }
}

int DefaultFramebuffer::color_bits() const {
    switch (config_.color_format) {
        case ColorFormat::RGBA16F: return 16;
        case ColorFormat::RGBA32F: return 32;
        default: return 8;
    }
}

float DefaultFramebuffer::quantize(float v) const {
    switch (config_.color_format) {
        case ColorFormat::RGBA16F: return half_to_float(float_to_half(canonical_nan(v)));
        case ColorFormat::RGBA32F: return canonical_nan(v);
        default: return float(float_to_unorm8(v)) / 255.0f;
    }
}

void DefaultFramebuffer::read_sample(int32_t x, int32_t y, int32_t s, float out[4]) const {
    const size_t i = ((size_t(y) * config_.width + x) * config_.samples + size_t(s)) * 4;
    for (int c = 0; c < 4; ++c) out[c] = is_float() ? color_f_[i + size_t(c)] : float(color_[i + size_t(c)]) / 255.0f;
    if (!config_.alpha) out[3] = 1.0f;
}

void DefaultFramebuffer::read_pixel(int32_t x, int32_t y, float out[4]) const {
    const int S = config_.samples;
    if (S == 1) return read_sample(x, y, 0, out);
    // The mean in double: exact for <= 16 samples of binary16 or unorm8, one rounding for 32F.
    double sum[4] = {0, 0, 0, 0};
    float v[4];
    for (int s = 0; s < S; ++s) {
        read_sample(x, y, s, v);
        for (int c = 0; c < 4; ++c) sum[c] += double(v[c]);
    }
    for (int c = 0; c < 4; ++c) {
        const double mean = sum[c] / double(S);
        out[c] = is_float() ? quantize(float(mean)) : float(mean);
    }
}

void DefaultFramebuffer::write_pixel(int32_t x, int32_t y, const float rgba[4], const std::array<bool, 4>& mask) {
    for (int s = 0; s < config_.samples; ++s)
        for (int c = 0; c < 4; ++c) {
            if (!mask[size_t(c)] || (c == 3 && !config_.alpha)) continue;
            if (is_float()) color_sample_f(x, y, s)[c] = quantize(rgba[c]);
            else color_sample(x, y, s)[c] = float_to_unorm8(rgba[c]);
        }
}

void DefaultFramebuffer::read_float(int32_t x, int32_t y, int32_t w, int32_t h, float* dst,
                                    std::ptrdiff_t row_stride) const {
    const Rect r = clip(Rect{x, y, w, h});
    for (int32_t py = r.y; py < r.y + r.height; ++py)
        for (int32_t qx = r.x; qx < r.x + r.width; ++qx)
            read_pixel(qx, py, dst + (py - y) * row_stride + std::ptrdiff_t(qx - x) * 4);
}

}  // namespace softgl
