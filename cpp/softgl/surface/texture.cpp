#include "softgl/surface/texture.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "softgl/surface/formats.h"

namespace softgl {

using namespace gl_ext;

namespace {

// ES 3.0 tables 3.13 / 3.2 and WebGL 1's unsized formats (as pseudo-sized names).
const FormatInfo kFormats[] = {
    {gl::RGBA8, gl::RGBA, Encoding::Unorm, {8, 8, 8, 8}},
    {gl::RGB8, gl::RGB, Encoding::Unorm, {8, 8, 8, 0}},
    {gl::RG8, gl::RG, Encoding::Unorm, {8, 8, 0, 0}},
    {gl::R8, gl::RED, Encoding::Unorm, {8, 0, 0, 0}},
    {gl::RGBA4, gl::RGBA, Encoding::Unorm, {4, 4, 4, 4}},
    {gl::RGB5_A1, gl::RGBA, Encoding::Unorm, {5, 5, 5, 1}},
    {gl::RGB565, gl::RGB, Encoding::Unorm, {5, 6, 5, 0}},
    {gl::RGB10_A2, gl::RGBA, Encoding::Unorm, {10, 10, 10, 2}},
    {gl::SRGB8, gl::RGB, Encoding::Srgb, {8, 8, 8, 0}},
    {gl::SRGB8_ALPHA8, gl::RGBA, Encoding::Srgb, {8, 8, 8, 8}},
    {gl::R8_SNORM, gl::RED, Encoding::Snorm, {8, 0, 0, 0}},
    {gl::RG8_SNORM, gl::RG, Encoding::Snorm, {8, 8, 0, 0}},
    {gl::RGB8_SNORM, gl::RGB, Encoding::Snorm, {8, 8, 8, 0}},
    {gl::RGBA8_SNORM, gl::RGBA, Encoding::Snorm, {8, 8, 8, 8}},
    {gl::R16F, gl::RED, Encoding::Float16, {16, 0, 0, 0}},
    {gl::RG16F, gl::RG, Encoding::Float16, {16, 16, 0, 0}},
    {gl::RGB16F, gl::RGB, Encoding::Float16, {16, 16, 16, 0}},
    {gl::RGBA16F, gl::RGBA, Encoding::Float16, {16, 16, 16, 16}},
    {gl::R32F, gl::RED, Encoding::Float32, {32, 0, 0, 0}},
    {gl::RG32F, gl::RG, Encoding::Float32, {32, 32, 0, 0}},
    {gl::RGB32F, gl::RGB, Encoding::Float32, {32, 32, 32, 0}},
    {gl::RGBA32F, gl::RGBA, Encoding::Float32, {32, 32, 32, 32}},
    {gl::R11F_G11F_B10F, gl::RGB, Encoding::Float11_11_10, {11, 11, 10, 0}},
    {gl::RGB9_E5, gl::RGB, Encoding::Rgb9e5, {9, 9, 9, 0}},
    {gl::R8I, gl::RED_INTEGER, Encoding::Int, {8, 0, 0, 0}},
    {gl::R8UI, gl::RED_INTEGER, Encoding::Uint, {8, 0, 0, 0}},
    {gl::R16I, gl::RED_INTEGER, Encoding::Int, {16, 0, 0, 0}},
    {gl::R16UI, gl::RED_INTEGER, Encoding::Uint, {16, 0, 0, 0}},
    {gl::R32I, gl::RED_INTEGER, Encoding::Int, {32, 0, 0, 0}},
    {gl::R32UI, gl::RED_INTEGER, Encoding::Uint, {32, 0, 0, 0}},
    {gl::RG8I, gl::RG_INTEGER, Encoding::Int, {8, 8, 0, 0}},
    {gl::RG8UI, gl::RG_INTEGER, Encoding::Uint, {8, 8, 0, 0}},
    {gl::RG16I, gl::RG_INTEGER, Encoding::Int, {16, 16, 0, 0}},
    {gl::RG16UI, gl::RG_INTEGER, Encoding::Uint, {16, 16, 0, 0}},
    {gl::RG32I, gl::RG_INTEGER, Encoding::Int, {32, 32, 0, 0}},
    {gl::RG32UI, gl::RG_INTEGER, Encoding::Uint, {32, 32, 0, 0}},
    {gl::RGB8I, gl::RGB_INTEGER, Encoding::Int, {8, 8, 8, 0}},
    {gl::RGB8UI, gl::RGB_INTEGER, Encoding::Uint, {8, 8, 8, 0}},
    {gl::RGB16I, gl::RGB_INTEGER, Encoding::Int, {16, 16, 16, 0}},
    {gl::RGB16UI, gl::RGB_INTEGER, Encoding::Uint, {16, 16, 16, 0}},
    {gl::RGB32I, gl::RGB_INTEGER, Encoding::Int, {32, 32, 32, 0}},
    {gl::RGB32UI, gl::RGB_INTEGER, Encoding::Uint, {32, 32, 32, 0}},
    {gl::RGBA8I, gl::RGBA_INTEGER, Encoding::Int, {8, 8, 8, 8}},
    {gl::RGBA8UI, gl::RGBA_INTEGER, Encoding::Uint, {8, 8, 8, 8}},
    {gl::RGBA16I, gl::RGBA_INTEGER, Encoding::Int, {16, 16, 16, 16}},
    {gl::RGBA16UI, gl::RGBA_INTEGER, Encoding::Uint, {16, 16, 16, 16}},
    {gl::RGBA32I, gl::RGBA_INTEGER, Encoding::Int, {32, 32, 32, 32}},
    {gl::RGBA32UI, gl::RGBA_INTEGER, Encoding::Uint, {32, 32, 32, 32}},
    {gl::RGB10_A2UI, gl::RGBA_INTEGER, Encoding::Uint, {10, 10, 10, 2}},
    {gl::DEPTH_COMPONENT16, gl::DEPTH_COMPONENT, Encoding::Depth16, {0, 0, 0, 0}},
    {gl::DEPTH_COMPONENT24, gl::DEPTH_COMPONENT, Encoding::Depth24, {0, 0, 0, 0}},
    {gl::DEPTH_COMPONENT32F, gl::DEPTH_COMPONENT, Encoding::Depth32F, {0, 0, 0, 0}},
    {gl::DEPTH24_STENCIL8, gl::DEPTH_STENCIL, Encoding::Depth24, {0, 0, 0, 0}, true},
    {gl::DEPTH32F_STENCIL8, gl::DEPTH_STENCIL, Encoding::Depth32F, {0, 0, 0, 0}, true},
    {gl::STENCIL_INDEX8, gl::STENCIL_INDEX8, Encoding::Stencil8, {0, 0, 0, 0}, true},
    {ALPHA8, gl::ALPHA, Encoding::Unorm, {0, 0, 0, 8}},
    {LUMINANCE8, gl::LUMINANCE, Encoding::Unorm, {8, 8, 8, 0}},
    {LUMINANCE8_ALPHA8, gl::LUMINANCE_ALPHA, Encoding::Unorm, {8, 8, 8, 8}},
    {ALPHA16F, gl::ALPHA, Encoding::Float16, {0, 0, 0, 16}},
    {LUMINANCE16F, gl::LUMINANCE, Encoding::Float16, {16, 16, 16, 0}},
    {LUMINANCE_ALPHA16F, gl::LUMINANCE_ALPHA, Encoding::Float16, {16, 16, 16, 16}},
    {ALPHA32F, gl::ALPHA, Encoding::Float32, {0, 0, 0, 32}},
    {LUMINANCE32F, gl::LUMINANCE, Encoding::Float32, {32, 32, 32, 0}},
    {LUMINANCE_ALPHA32F, gl::LUMINANCE_ALPHA, Encoding::Float32, {32, 32, 32, 32}},
};

float unorm(uint32_t k, int bits) { return float(k) / float((uint64_t(1) << bits) - 1); }

// Rounds x >= 0 to an unsigned float with 5 exponent bits and `m` mantissa bits (ES 3.0 §2.1.3,
// 2.1.4), to nearest; too large finite values become the largest finite value.
float round_small_float(float x, int m) {
    if (std::isnan(x)) return x;
    if (!(x > 0.0f)) return 0.0f;
    if (std::isinf(x)) return x;
    const double max_value = (2.0 - std::ldexp(1.0, -m)) * 32768.0;
    if (x >= max_value) return float(max_value);
    int e = std::ilogb(double(x));
    if (e < -14) e = -14;   // denormals share the smallest exponent
    const double step = std::ldexp(1.0, e - m);
    return float(std::min(max_value, std::nearbyint(double(x) / step) * step));
}

// ES 3.0 §3.7.2 (equations 3.2-3.4): RGB9_E5's shared exponent.
void round_rgb9e5(const float in[3], float out[3]) {
    const int N = 9, B = 15, Emax = 31;
    const double max_value = double((1 << N) - 1) / double(1 << N) * std::ldexp(1.0, Emax - B);
    double c[3];
    for (int i = 0; i < 3; ++i) c[i] = std::isnan(in[i]) ? 0.0 : std::clamp(double(in[i]), 0.0, max_value);
    const double maxc = std::max({c[0], c[1], c[2]});
    int exp_p = std::max(-B - 1, maxc > 0 ? int(std::floor(std::log2(maxc))) : -B - 1) + 1 + B;
    const double maxs = std::floor(maxc / std::ldexp(1.0, exp_p - B - N) + 0.5);
    if (maxs == double(1 << N)) exp_p += 1;
    const double scale = std::ldexp(1.0, exp_p - B - N);
    for (int i = 0; i < 3; ++i) out[i] = float(std::floor(c[i] / scale + 0.5) * scale);
}

}  // namespace

SampleKind FormatInfo::kind() const {
    switch (encoding) {
        case Encoding::Int: return SampleKind::Int;
        case Encoding::Uint: return SampleKind::Uint;
        case Encoding::Depth16: case Encoding::Depth24: case Encoding::Depth32F: case Encoding::Stencil8:
            return SampleKind::Depth;
        default: return SampleKind::Float;
    }
}

const FormatInfo* format_info(GLenum internal_format) {
    for (const FormatInfo& f : kFormats)
        if (f.internal_format == internal_format) return &f;
    return nullptr;
}

float srgb_to_linear(float c) {
    const double v = c;
    return float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

float linear_to_srgb(float c) {
    const double v = std::isnan(c) ? 0.0 : std::clamp(double(c), 0.0, 1.0);
    return float(v < 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 0.41666) - 0.055);
}

float half_to_float(uint16_t h) {
    const uint32_t sign = uint32_t(h >> 15) << 31, exp = (h >> 10) & 0x1F, mant = h & 0x3FF;
    float f;
    if (exp == 0) {
        f = std::ldexp(float(mant), -24);
        return sign ? -f : f;
    }
    uint32_t bits;
    if (exp == 31) bits = sign | 0x7F800000u | (mant << 13);
    else bits = sign | ((exp + 112) << 23) | (mant << 13);
    std::memcpy(&f, &bits, 4);
    return f;
}

uint16_t float_to_half(float f) {
    uint32_t x;
    std::memcpy(&x, &f, 4);
    const uint16_t sign = uint16_t((x >> 16) & 0x8000);
    const uint32_t ax = x & 0x7FFFFFFFu;
    if (ax > 0x7F800000u) return uint16_t(sign | 0x7E00);          // NaN
    if (ax >= 0x477FF000u) return uint16_t(sign | 0x7C00);         // rounds to >= 65520: Inf
    if (ax < 0x38800000u) {                                        // below 2^-14: denormal
        const double v = double(std::fabs(f)) * 16777216.0;        // units of 2^-24
        return uint16_t(sign | uint16_t(std::nearbyint(v)));       // ties to even (default mode)
    }
    uint32_t e = (ax >> 23) - 112, m = ax & 0x7FFFFF;
    uint32_t h = (e << 10) | (m >> 13);
    const uint32_t rest = m & 0x1FFF;
    if (rest > 0x1000 || (rest == 0x1000 && (h & 1))) ++h;         // to nearest, ties to even
    return uint16_t(sign | h);
}

void quantize_color(const FormatInfo& f, const float in[4], float out[4]) {
    const bool luminance = f.base_format == gl::LUMINANCE || f.base_format == gl::LUMINANCE_ALPHA;
    for (int c = 0; c < 4; ++c) {
        const int bits = f.bits[size_t(c)];
        if (!bits) { out[c] = c == 3 ? 1.0f : 0.0f; continue; }
        // Luminance formats store L in r, g and b: keep them equal (they come expanded).
        const float v = luminance && c < 3 ? in[0] : in[c];
        switch (f.encoding) {
            case Encoding::Unorm: out[c] = unorm(float_to_unorm(v, bits), bits); break;
            case Encoding::Srgb:
                if (c == 3) out[c] = unorm(float_to_unorm(v, 8), 8);
                else out[c] = srgb_to_linear(unorm(float_to_unorm(linear_to_srgb(v), 8), 8));
                break;
            case Encoding::Snorm: {
                const float x = std::isnan(v) ? 0.0f : std::clamp(v, -1.0f, 1.0f);
                out[c] = std::max(float(std::floor(double(x) * 127.0 + 0.5)) / 127.0f, -1.0f);
                break;
            }
            case Encoding::Float16: out[c] = half_to_float(float_to_half(canonical_nan(v))); break;
            case Encoding::Float11_11_10: out[c] = round_small_float(canonical_nan(v), c == 2 ? 5 : 6); break;
            case Encoding::Rgb9e5: break;   // below, all channels at once
            default: out[c] = canonical_nan(v); break;
        }
    }
    if (f.encoding == Encoding::Rgb9e5) round_rgb9e5(in, out);
}

uint32_t quantize_unorm8(const FormatInfo& f, const float in[4]) {
    const bool luminance = f.base_format == gl::LUMINANCE || f.base_format == gl::LUMINANCE_ALPHA;
    uint32_t packed = 0;
    for (int c = 0; c < 4; ++c) {
        const uint32_t k = !f.bits[size_t(c)] ? (c == 3 ? 255u : 0u) : float_to_unorm(luminance && c < 3 ? in[0] : in[c], 8);
        packed |= k << (8 * c);
    }
    return packed;
}

void quantize_integer(const FormatInfo& f, const uint32_t in[4], uint32_t out[4]) {
    for (int c = 0; c < 4; ++c) {
        const int bits = f.bits[size_t(c)];
        if (!bits) { out[c] = c == 3 ? 1u : 0u; continue; }
        if (bits == 32) { out[c] = in[c]; continue; }
        if (f.encoding == Encoding::Uint) {
            out[c] = std::min<uint32_t>(in[c], uint32_t((uint64_t(1) << bits) - 1));
        } else {
            const int32_t lo = -(1 << (bits - 1)), hi = (1 << (bits - 1)) - 1;
            out[c] = uint32_t(std::clamp(int32_t(in[c]), lo, hi));
        }
    }
}

uint32_t depth_word(Encoding e, double depth) {
    const double d = std::isnan(depth) ? 0.0 : std::clamp(depth, 0.0, 1.0);
    if (e == Encoding::Depth16) return uint32_t(std::floor(d * 65535.0 + 0.5));
    if (e == Encoding::Depth32F) {
        const float f = float(d);
        uint32_t w;
        std::memcpy(&w, &f, 4);
        return w;
    }
    return uint32_t(std::floor(d * 16777215.0 + 0.5));
}

float depth_value(Encoding e, uint32_t w) {
    if (e == Encoding::Depth16) return float(double(w) / 65535.0);
    if (e == Encoding::Depth32F) {
        float f;
        std::memcpy(&f, &w, 4);
        return f;
    }
    return float(double(w) / 16777215.0);
}

uint64_t Image::allocation_bytes(const FormatInfo* fmt, int32_t w, int32_t h, int32_t d, int32_t s, bool encoded) {
    const uint64_t n = uint64_t(w) * uint64_t(h) * uint64_t(d) * uint64_t(s);
    if (stores_bytes(fmt)) return n * 4;                      // RGBA bytes per sample
    if (const int b = narrow_bytes(fmt)) return n * uint64_t(b) + kNarrowPad;   // their channels' bytes
    if (const size_t b = packed_elements(fmt, size_t(n), encoded)) return b;   // encoded at the format's size
    if (fmt->kind() == SampleKind::Float) return color_elements(fmt, n) * 4;   // a float per channel
    if (fmt->kind() != SampleKind::Depth) return n * uint64_t(integer_bytes(fmt));   // the channels' widths
    return n * ((fmt->encoding != Encoding::Stencil8 ? 4 : 0) + (fmt->has_stencil ? 1 : 0));
}

void Image::allocate(const FormatInfo* fmt, int32_t w, int32_t h, int32_t d, int32_t s, bool encoded) {
    clear();
    format = fmt;
    width = w, height = h, depth = d, samples = s;
    const size_t n = texel_count();
    switch (fmt->kind()) {
        case SampleKind::Float:
            // Absent alpha reads as 1 from the start (e.g. RGB8).
            if (stores_bytes(fmt)) rgba8.assign(n, fmt->bits[3] ? 0u : 0xFF000000u);
            else if (stores_narrow(fmt)) narrow.assign(n * size_t(narrow_bytes(fmt)) + kNarrowPad, 0);   // absent channels are implied
            else if (const size_t b = packed_elements(fmt, n, encoded)) {
                packed_size = uint8_t(packed_bytes(fmt));
                packed.assign(b, 0);
                // WebGL 1's LUMINANCE16F / LUMINANCE_ALPHA16F... kept expanded: absent alpha is 1.
                if (packed_size == 8 && !fmt->bits[3])
                    for (size_t i = 0; i < n; ++i) packed[i * 8 + 6] = 0x00, packed[i * 8 + 7] = 0x3C;
            }
            else color.assign(color_elements(fmt, n), 0.0f);
            break;
        case SampleKind::Int: case SampleKind::Uint: integer.assign(n * size_t(integer_bytes(fmt)), 0); break;
        case SampleKind::Depth:
            if (fmt->encoding != Encoding::Stencil8) depth_words.assign(n, 0u);
            if (fmt->has_stencil) stencil.assign(n, 0);
            break;
    }
    // Absent channels read as their defaults from the start (e.g. alpha 1 of RGB8).
    if (color_channels() == 4 && !fmt->bits[3])
        for (size_t i = 0; i < n; ++i) color[i * 4 + 3] = 1.0f;
}

int Image::integer_bytes(const FormatInfo* fmt) {
    if (!fmt || !fmt->is_integer()) return 0;
    if (fmt->bits[0] == 10) return 4;   // RGB10_A2UI: one packed word
    return (fmt->bits[0] + fmt->bits[1] + fmt->bits[2] + fmt->bits[3]) / 8;
}

void Image::read_integer(size_t t, uint32_t out[4]) const {
    const FormatInfo& f = *format;
    out[0] = out[1] = out[2] = 0, out[3] = 1;   // absent channels (ES 3.0 table 3.24)
    const uint8_t* p = integer.data() + t * size_t(integer_bytes(format));
    if (f.bits[0] == 10) {   // RGB10_A2UI
        uint32_t w;
        std::memcpy(&w, p, 4);
        out[0] = w & 1023u, out[1] = (w >> 10) & 1023u, out[2] = (w >> 20) & 1023u, out[3] = w >> 30;
        return;
    }
    const bool sign = f.encoding == Encoding::Int;
    for (int c = 0; c < 4 && f.bits[size_t(c)]; ++c) {
        switch (f.bits[size_t(c)]) {
            case 8: out[c] = sign ? uint32_t(int32_t(int8_t(*p))) : *p; break;
            case 16: { uint16_t v; std::memcpy(&v, p, 2); out[c] = sign ? uint32_t(int32_t(int16_t(v))) : v; break; }
            default: std::memcpy(&out[c], p, 4); break;
        }
        p += f.bits[size_t(c)] / 8;
    }
}

void Image::store_integer(size_t t, const uint32_t in[4], const bool mask[4]) {
    const FormatInfo& f = *format;
    uint8_t* p = integer.data() + t * size_t(integer_bytes(format));
    if (f.bits[0] == 10) {   // RGB10_A2UI
        uint32_t w;
        std::memcpy(&w, p, 4);
        const uint32_t shift[4] = {0, 10, 20, 30}, ones[4] = {1023u, 1023u, 1023u, 3u};
        for (int c = 0; c < 4; ++c)
            if (!mask || mask[c]) w = (w & ~(ones[c] << shift[c])) | ((in[c] & ones[c]) << shift[c]);
        std::memcpy(p, &w, 4);
        return;
    }
    // The low bits of each channel (quantize_integer already clamped them to its range).
    for (int c = 0; c < 4 && f.bits[size_t(c)]; ++c) {
        const size_t w = f.bits[size_t(c)] / 8;
        if (!mask || mask[c]) std::memcpy(p, &in[c], w);   // little-endian: the low bytes
        p += w;
    }
}

namespace {

// Channels of a format kept expanded to floats or halves: the base format's (RED 1, RG 2, RGB 3;
// RGBA and WebGL 1's luminance/alpha formats 4).
int expanded_channels(const FormatInfo& f) {
    const GLenum b = f.base_format;
    return b == gl::RED ? 1 : b == gl::RG ? 2 : b == gl::RGB ? 3 : 4;
}

// RGB565, RGBA4, RGB5_A1, RGB10_A2: unorm channels of other than 8 bits, packed in one word.
bool packed_unorm(const FormatInfo& f) {
    return f.encoding == Encoding::Unorm && !f.has_stencil && f.base_format != gl::DEPTH_COMPONENT && !f.is_unorm8();
}

// The linear value of each sRGB byte (ES 3.0 §3.8.15 eq. 3.24 of k / 255, as srgb_to_linear
// computes it): strictly increasing, so a stored value finds its byte again by search.
const std::array<float, 256>& srgb_decode_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int k = 0; k < 256; ++k) t[size_t(k)] = srgb_to_linear(unorm(uint32_t(k), 8));
        return t;
    }();
    return table;
}

}  // namespace

int Image::packed_bytes(const FormatInfo* fmt) {
    if (!fmt || fmt->kind() != SampleKind::Float) return 0;
    if (fmt->encoding == Encoding::Float16) return 2 * expanded_channels(*fmt);
    if (fmt->encoding == Encoding::Srgb) return fmt->bits[3] ? 4 : 3;
    if (packed_unorm(*fmt)) return (fmt->bits[0] + fmt->bits[1] + fmt->bits[2] + fmt->bits[3]) / 8;
    return 0;
}

size_t Image::packed_elements(const FormatInfo* fmt, size_t n, bool encoded) {
    const int b = packed_bytes(fmt);
    if (b == 0 || (!encoded && fmt->encoding != Encoding::Float16)) return 0;
    // Textures (sampled: 4-half loads) below 4 channels: the pad after the last texel.
    return n * size_t(b) + (!encoded && b < 8 ? kHalfPad : 0);
}

int Image::color_channels(const FormatInfo* fmt) {
    if (!fmt || fmt->kind() != SampleKind::Float || stores_bytes(fmt) || stores_narrow(fmt)) return 0;
    const GLenum b = fmt->base_format;
    return b == gl::RED ? 1 : b == gl::RG ? 2 : b == gl::RGB ? 3 : 4;
}

void Image::read_color(size_t t, float out[4]) const {
    if (!rgba8.empty()) {
        const uint32_t v = rgba8[t];
        for (int c = 0; c < 4; ++c) out[c] = unorm((v >> (8 * c)) & 255u, 8);
        return;
    }
    if (!narrow.empty()) {
        // The absent channels' defaults (ES 3.0 table 3.24): 0, alpha 1; luminance in r, g and b.
        const GLenum base = format->base_format;
        const size_t n = size_t(narrow_bytes(format));
        const float k0 = unorm(narrow[t * n], 8), k1 = n == 2 ? unorm(narrow[t * n + 1], 8) : 0.0f;
        if (base == gl::ALPHA) out[0] = out[1] = out[2] = 0.0f, out[3] = k0;
        else if (base == gl::LUMINANCE || base == gl::LUMINANCE_ALPHA) out[0] = out[1] = out[2] = k0, out[3] = n == 2 ? k1 : 1.0f;
        else out[0] = k0, out[1] = k1, out[2] = 0.0f, out[3] = 1.0f;
        return;
    }
    // color_channels() floats, the absent channels' defaults (0, alpha 1: ES 3.0 table 3.24).
    out[0] = out[1] = out[2] = 0.0f, out[3] = 1.0f;
    if (!packed.empty()) {
        const FormatInfo& f = *format;
        const size_t nb = packed_size;
        const uint8_t* p = &packed[t * nb];
        if (f.encoding == Encoding::Float16) {
            for (size_t c = 0; c < nb / 2; ++c) {
                uint16_t h;
                std::memcpy(&h, p + 2 * c, 2);
                out[c] = half_to_float(h);
            }
        } else if (f.encoding == Encoding::Srgb) {
            const std::array<float, 256>& linear = srgb_decode_table();
            for (int c = 0; c < 3; ++c) out[c] = linear[p[c]];
            if (nb == 4) out[3] = unorm(p[3], 8);   // alpha is linear (ES 3.0 §3.8.15)
        } else {
            uint32_t w = 0;
            std::memcpy(&w, p, nb);
            for (int c = 0, shift = 0; c < 4 && f.bits[size_t(c)]; shift += f.bits[size_t(c)], ++c)
                out[c] = unorm((w >> shift) & ((1u << f.bits[size_t(c)]) - 1u), f.bits[size_t(c)]);
        }
        return;
    }
    const size_t n = size_t(color_channels());
    for (size_t c = 0; c < n; ++c) out[c] = color[t * n + c];
}

void Image::store_color(size_t t, const float q[4], const bool mask[4]) {
    if (!rgba8.empty()) {
        // q holds k / 255 (quantize_color's output): the byte is k again.
        uint32_t v = rgba8[t];
        for (int c = 0; c < 4; ++c) {
            if (mask && !mask[c]) continue;
            v = (v & ~(255u << (8 * c))) | (float_to_unorm(q[c], 8) << (8 * c));
        }
        rgba8[t] = v;
        return;
    }
    if (!narrow.empty()) {
        // Byte i holds channel `from[i]` of RGBA (q holds k / 255: the byte is k again).
        const GLenum base = format->base_format;
        const size_t n = size_t(narrow_bytes(format));
        const int from[2] = {base == gl::ALPHA ? 3 : 0, base == gl::LUMINANCE_ALPHA ? 3 : 1};
        for (size_t i = 0; i < n; ++i)
            if (!mask || mask[from[i]]) narrow[t * n + i] = uint8_t(float_to_unorm(q[from[i]], 8));
        return;
    }
    if (!packed.empty()) {
        // q holds values of the format (quantize_color's output): each has one encoding.
        const FormatInfo& f = *format;
        const size_t nb = packed_size;
        uint8_t* p = &packed[t * nb];
        if (f.encoding == Encoding::Float16) {
            for (size_t c = 0; c < nb / 2; ++c) {
                if (mask && !mask[c]) continue;
                const uint16_t h = float_to_half(q[c]);
                std::memcpy(p + 2 * c, &h, 2);
            }
        } else if (f.encoding == Encoding::Srgb) {
            const std::array<float, 256>& linear = srgb_decode_table();
            for (int c = 0; c < 3; ++c)
                if (!mask || mask[c]) p[c] = uint8_t(std::lower_bound(linear.begin(), linear.end() - 1, q[c]) - linear.begin());
            if (nb == 4 && (!mask || mask[3])) p[3] = uint8_t(float_to_unorm(q[3], 8));
        } else {
            uint32_t w = 0;
            std::memcpy(&w, p, nb);
            for (int c = 0, shift = 0; c < 4 && f.bits[size_t(c)]; shift += f.bits[size_t(c)], ++c) {
                if (mask && !mask[c]) continue;
                const uint32_t ones = (1u << f.bits[size_t(c)]) - 1u;
                w = (w & ~(ones << shift)) | (float_to_unorm(q[c], f.bits[size_t(c)]) << shift);
            }
            std::memcpy(p, &w, nb);
        }
        return;
    }
    const size_t n = size_t(color_channels());
    for (size_t c = 0; c < n; ++c)
        if (!mask || mask[c]) color[t * n + c] = q[c];
}

void Image::encode_color(size_t t, const float v[4], const bool mask[4]) {
    // What quantize_color rounds to, encoded at once: binary16 of the value (NaN: the one quiet
    // NaN), the sRGB byte of eq. 4.1 (alpha: linear), the unorm integer k.
    const FormatInfo& f = *format;
    const size_t nb = packed_size;
    uint8_t* p = &packed[t * nb];
    if (f.encoding == Encoding::Float16) {
        for (size_t c = 0; c < nb / 2; ++c) {
            if (!mask[c]) continue;
            const uint16_t h = float_to_half(canonical_nan(v[c]));
            std::memcpy(p + 2 * c, &h, 2);
        }
    } else if (f.encoding == Encoding::Srgb) {
        for (int c = 0; c < 3; ++c)
            if (mask[c]) p[c] = uint8_t(float_to_unorm(linear_to_srgb(v[c]), 8));
        if (nb == 4 && mask[3]) p[3] = uint8_t(float_to_unorm(v[3], 8));
    } else {
        uint32_t w = 0;
        std::memcpy(&w, p, nb);
        for (int c = 0, shift = 0; c < 4 && f.bits[size_t(c)]; shift += f.bits[size_t(c)], ++c) {
            if (!mask[c]) continue;
            const uint32_t ones = (1u << f.bits[size_t(c)]) - 1u;
            w = (w & ~(ones << shift)) | (float_to_unorm(v[c], f.bits[size_t(c)]) << shift);
        }
        std::memcpy(p, &w, nb);
    }
}

void Image::texel(int32_t x, int32_t y, int32_t z, float out[4]) const {
    const size_t i = (size_t(z) * size_t(height) + size_t(y)) * size_t(width) + size_t(x);
    switch (format->kind()) {
        case SampleKind::Float: read_color(i, out); break;
        case SampleKind::Int: case SampleKind::Uint: {
            uint32_t v[4];
            read_integer(i, v);
            for (int c = 0; c < 4; ++c) out[c] = format->kind() == SampleKind::Int ? float(int32_t(v[c])) : float(v[c]);
            break;
        }
        case SampleKind::Depth:
            out[0] = depth_words.empty() ? 0.0f : depth_value(format->encoding, depth_words[i]);
            out[1] = 0, out[2] = 0, out[3] = 1;
            break;
    }
}

// ---------------------------------------------------------------------------- unpacking

namespace {

int format_components(GLenum format) {
    switch (format) {
        case gl::RGBA: case gl::RGBA_INTEGER: return 4;
        case gl::RGB: case gl::RGB_INTEGER: case SRGB_EXT: return 3;
        case gl::RG: case gl::RG_INTEGER: case gl::LUMINANCE_ALPHA: case gl::DEPTH_STENCIL: return 2;
        case gl::RED: case gl::RED_INTEGER: case gl::ALPHA: case gl::LUMINANCE: case gl::DEPTH_COMPONENT: return 1;
        case SRGB_ALPHA_EXT: return 4;
        default: return 0;
    }
}

int type_bytes(GLenum type) {
    switch (type) {
        case gl::UNSIGNED_BYTE: case gl::BYTE: return 1;
        case gl::UNSIGNED_SHORT: case gl::SHORT: case gl::HALF_FLOAT: case HALF_FLOAT_OES: return 2;
        case gl::UNSIGNED_INT: case gl::INT: case gl::FLOAT: return 4;
        default: return 0;
    }
}

int packed_bytes(GLenum type) {
    switch (type) {
        case gl::UNSIGNED_SHORT_5_6_5: case gl::UNSIGNED_SHORT_4_4_4_4: case gl::UNSIGNED_SHORT_5_5_5_1: return 2;
        case gl::UNSIGNED_INT_2_10_10_10_REV: case gl::UNSIGNED_INT_10F_11F_11F_REV:
        case gl::UNSIGNED_INT_5_9_9_9_REV: case gl::UNSIGNED_INT_24_8: return 4;
        case gl::FLOAT_32_UNSIGNED_INT_24_8_REV: return 8;
        default: return 0;
    }
}

template <class T> T load(const uint8_t* p) { T v; std::memcpy(&v, p, sizeof(T)); return v; }

// One decoded source pixel: components as normalized/float values (`f`) and raw integers (`i`).
struct Decoded {
    double f[4] = {0, 0, 0, 0};
    int64_t i[4] = {0, 0, 0, 0};
    double depth = 0;
    uint8_t stencil = 0;
    int n = 0;
};

void decode(const uint8_t* p, GLenum format, GLenum type, Decoded& d) {
    d.n = format_components(format);
    switch (type) {
        case gl::UNSIGNED_SHORT_5_6_5: {
            const uint16_t v = load<uint16_t>(p);
            const uint32_t c[3] = {uint32_t(v >> 11), uint32_t((v >> 5) & 63), uint32_t(v & 31)};
            d.f[0] = unorm(c[0], 5), d.f[1] = unorm(c[1], 6), d.f[2] = unorm(c[2], 5);
            for (int k = 0; k < 3; ++k) d.i[k] = c[k];
            return;
        }
        case gl::UNSIGNED_SHORT_4_4_4_4: {
            const uint16_t v = load<uint16_t>(p);
            for (int k = 0; k < 4; ++k) d.i[k] = (v >> (12 - 4 * k)) & 15, d.f[k] = unorm(uint32_t(d.i[k]), 4);
            return;
        }
        case gl::UNSIGNED_SHORT_5_5_5_1: {
            const uint16_t v = load<uint16_t>(p);
            for (int k = 0; k < 3; ++k) d.i[k] = (v >> (11 - 5 * k)) & 31, d.f[k] = unorm(uint32_t(d.i[k]), 5);
            d.i[3] = v & 1, d.f[3] = double(v & 1);
            return;
        }
        case gl::UNSIGNED_INT_2_10_10_10_REV: {
            const uint32_t v = load<uint32_t>(p);
            for (int k = 0; k < 3; ++k) d.i[k] = (v >> (10 * k)) & 1023, d.f[k] = unorm(uint32_t(d.i[k]), 10);
            d.i[3] = v >> 30, d.f[3] = unorm(v >> 30, 2);
            return;
        }
        case gl::UNSIGNED_INT_10F_11F_11F_REV: {
            // ES 3.0 §2.1.3/2.1.4: unsigned 11- and 10-bit floats with 5-bit exponents.
            const uint32_t v = load<uint32_t>(p);
            const uint32_t parts[3] = {v & 0x7FF, (v >> 11) & 0x7FF, v >> 22};
            const int mbits[3] = {6, 6, 5};
            for (int k = 0; k < 3; ++k) {
                const uint32_t e = parts[k] >> mbits[k], m = parts[k] & ((1u << mbits[k]) - 1);
                if (e == 0) d.f[k] = std::ldexp(double(m), -14 - mbits[k]);
                else if (e == 31) d.f[k] = m ? NAN : INFINITY;
                else d.f[k] = std::ldexp(1.0 + double(m) / double(1 << mbits[k]), int(e) - 15);
            }
            return;
        }
        case gl::UNSIGNED_INT_5_9_9_9_REV: {
            const uint32_t v = load<uint32_t>(p);
            const int e = int(v >> 27);
            for (int k = 0; k < 3; ++k) d.f[k] = double((v >> (9 * k)) & 511) * std::ldexp(1.0, e - 15 - 9);
            return;
        }
        case gl::UNSIGNED_INT_24_8: {
            const uint32_t v = load<uint32_t>(p);
            d.depth = double(v >> 8) / 16777215.0;
            d.stencil = uint8_t(v & 0xFF);
            return;
        }
        case gl::FLOAT_32_UNSIGNED_INT_24_8_REV:
            d.depth = double(load<float>(p));
            d.stencil = uint8_t(load<uint32_t>(p + 4) & 0xFF);
            return;
        default: break;
    }
    const int size = type_bytes(type);
    for (int k = 0; k < d.n; ++k) {
        const uint8_t* q = p + k * size;
        switch (type) {
            case gl::UNSIGNED_BYTE: d.i[k] = q[0]; d.f[k] = unorm(q[0], 8); break;
            case gl::BYTE: {
                const int8_t v = int8_t(q[0]);
                d.i[k] = v;
                d.f[k] = std::max(double(v) / 127.0, -1.0);   // ES 3.0 §2.1.6.2 (snorm)
                break;
            }
            case gl::UNSIGNED_SHORT: { const uint16_t v = load<uint16_t>(q); d.i[k] = v; d.f[k] = double(v) / 65535.0; break; }
            case gl::SHORT: { const int16_t v = load<int16_t>(q); d.i[k] = v; d.f[k] = std::max(double(v) / 32767.0, -1.0); break; }
            case gl::UNSIGNED_INT: { const uint32_t v = load<uint32_t>(q); d.i[k] = v; d.f[k] = double(v) / 4294967295.0; break; }
            case gl::INT: { const int32_t v = load<int32_t>(q); d.i[k] = v; d.f[k] = std::max(double(v) / 2147483647.0, -1.0); break; }
            case gl::FLOAT: d.f[k] = double(load<float>(q)); break;
            case gl::HALF_FLOAT: case HALF_FLOAT_OES: d.f[k] = double(half_to_float(load<uint16_t>(q))); break;
            default: break;
        }
    }
    if (format == gl::DEPTH_COMPONENT) d.depth = type == gl::FLOAT ? d.f[0] : d.f[0];
}

// The RGBA a format's components stand for (ES 3.0 table 3.5 / ES 2.0 table 3.6).
void expand(GLenum format, const double in[4], double out[4]) {
    switch (format) {
        case gl::RGBA: case gl::RGBA_INTEGER: case SRGB_ALPHA_EXT: for (int c = 0; c < 4; ++c) out[c] = in[c]; return;
        case gl::RGB: case gl::RGB_INTEGER: case SRGB_EXT: out[0] = in[0], out[1] = in[1], out[2] = in[2], out[3] = 1; return;
        case gl::RG: case gl::RG_INTEGER: out[0] = in[0], out[1] = in[1], out[2] = 0, out[3] = 1; return;
        case gl::RED: case gl::RED_INTEGER: out[0] = in[0], out[1] = 0, out[2] = 0, out[3] = 1; return;
        case gl::LUMINANCE: out[0] = out[1] = out[2] = in[0], out[3] = 1; return;
        case gl::LUMINANCE_ALPHA: out[0] = out[1] = out[2] = in[0], out[3] = in[1]; return;
        case gl::ALPHA: out[0] = out[1] = out[2] = 0, out[3] = in[0]; return;
        default: for (int c = 0; c < 4; ++c) out[c] = 0; return;
    }
}

bool has_alpha(GLenum format) {
    return format == gl::RGBA || format == gl::LUMINANCE_ALPHA || format == gl::ALPHA || format == SRGB_ALPHA_EXT;
}

}  // namespace

int pixel_bytes(GLenum format, GLenum type) {
    if (const int packed = packed_bytes(type)) return packed;
    return format_components(format) * type_bytes(type);
}

static uint64_t row_stride(const PixelUnpack& u, int32_t w) {
    const uint64_t row_pixels = u.row_length > 0 ? uint64_t(u.row_length) : uint64_t(w);
    const uint64_t bytes = row_pixels * uint64_t(pixel_bytes(u.format, u.type));
    const uint64_t a = uint64_t(u.alignment);
    return (bytes + a - 1) / a * a;
}

uint64_t unpack_size(const PixelUnpack& u, int32_t w, int32_t h, int32_t d) {
    if (w <= 0 || h <= 0 || d <= 0) return 0;
    const uint64_t stride = row_stride(u, w);
    const uint64_t image = stride * uint64_t(u.image_height > 0 ? u.image_height : h);
    const uint64_t pb = uint64_t(pixel_bytes(u.format, u.type));
    return uint64_t(u.skip_images + d - 1) * image + uint64_t(u.skip_rows + h - 1) * stride +
           uint64_t(u.skip_pixels + w) * pb;
}

void unpack_into(Image& img, int32_t x0, int32_t y0, int32_t z0, int32_t w, int32_t h, int32_t d,
                 const PixelUnpack& u) {
    const FormatInfo& f = *img.format;
    const uint64_t stride = row_stride(u, w);
    const uint64_t image = stride * uint64_t(u.image_height > 0 ? u.image_height : h);
    const uint64_t pb = uint64_t(pixel_bytes(u.format, u.type));
    const SampleKind kind = f.kind();
    const bool premultiply = u.premultiply && has_alpha(u.format) && kind == SampleKind::Float;
    Decoded px;
    for (int32_t z = 0; z < d; ++z)
        for (int32_t row = 0; row < h; ++row) {
            // UNPACK_FLIP_Y_WEBGL (WebGL 1.0 §5.14.8): the last source row is uploaded first.
            const int32_t src_row = u.flip_y ? h - 1 - row : row;
            const uint8_t* src = u.data + uint64_t(u.skip_images + z) * image +
                                 uint64_t(u.skip_rows + src_row) * stride + uint64_t(u.skip_pixels) * pb;
            for (int32_t col = 0; col < w; ++col, src += pb) {
                decode(src, u.format, u.type, px);
                const size_t t = (size_t(z0 + z) * size_t(img.height) + size_t(y0 + row)) * size_t(img.width) + size_t(x0 + col);
                if (kind == SampleKind::Float) {
                    double rgba[4];
                    expand(u.format, px.f, rgba);
                    if (premultiply) for (int c = 0; c < 3; ++c) rgba[c] *= rgba[3];
                    float in[4] = {float(rgba[0]), float(rgba[1]), float(rgba[2]), float(rgba[3])};
                    if (img.bytes()) {
                        img.rgba8[t] = quantize_unorm8(f, in);
                        continue;
                    }
                    if (!img.narrow.empty()) {
                        float q[4];
                        quantize_color(f, in, q);
                        img.store_color(t, q);
                        continue;
                    }
                    if (f.encoding == Encoding::Srgb) {
                        // Client data of sRGB formats is sRGB-encoded: keep the byte, store its
                        // linear value (ES 3.0 §3.8.15 decodes each texel before filtering).
                        float out[4];
                        for (int c = 0; c < 3; ++c) out[c] = srgb_to_linear(unorm(float_to_unorm(in[c], 8), 8));
                        out[3] = f.bits[3] ? unorm(float_to_unorm(in[3], 8), 8) : 1.0f;
                        img.store_color(t, out);
                        continue;
                    }
                    float q[4];
                    quantize_color(f, in, q);
                    img.store_color(t, q);
                } else if (kind == SampleKind::Int || kind == SampleKind::Uint) {
                    double raw[4] = {double(px.i[0]), double(px.i[1]), double(px.i[2]), double(px.i[3])}, rgba[4];
                    expand(u.format, raw, rgba);
                    uint32_t in[4];
                    for (int c = 0; c < 4; ++c) in[c] = uint32_t(int64_t(rgba[c]));
                    uint32_t q[4];
                    quantize_integer(f, in, q);
                    img.store_integer(t, q);
                } else {
                    if (!img.depth_words.empty()) img.depth_words[t] = depth_word(f.encoding, px.depth);
                    if (!img.stencil.empty()) img.stencil[t] = px.stencil;
                }
            }
        }
}

// ---------------------------------------------------------------------------- textures

Image& Texture::image(int face, int level) {
    if (images.size() < size_t(faces())) images.resize(size_t(faces()));
    auto& levels = images[size_t(face)];
    if (levels.size() <= size_t(level)) levels.resize(size_t(level) + 1);
    return levels[size_t(level)];
}

const Image* Texture::find(int face, int level) const {
    if (face < 0 || size_t(face) >= images.size() || level < 0) return nullptr;
    const auto& levels = images[size_t(face)];
    if (size_t(level) >= levels.size() || !levels[size_t(level)].defined()) return nullptr;
    return &levels[size_t(level)];
}

size_t Texture::storage_bytes() const {
    size_t total = 0;
    for (const auto& face : images)
        for (const Image& img : face) total += img.storage_bytes();
    return total;
}

void Texture::release_storage() {
    std::vector<std::vector<Image>>().swap(images);
    std::vector<SampledLevel>().swap(sampled_levels);
    sampled_count = 0;
    memory.release();
    ++generation;
}

void Texture::refresh_sampling(int32_t base, int32_t q) {
    // Every level a sampler could use, so that units that bind this texture with other filters
    // (another q) in the same draw find theirs too.
    sampled_base = base;
    sampled_count = std::max(0, std::max(q, max_sampled_level(*this)) - base + 1);
    sampled_levels.assign(size_t(faces()) * size_t(sampled_count), SampledLevel{});
    for (int face = 0; face < faces(); ++face)
        for (int32_t k = 0; k < sampled_count; ++k) {
            const Image* img = find(face, base + k);
            if (!img || img->samples != 1) continue;
            SampledLevel& s = sampled_levels[size_t(face) * size_t(sampled_count) + size_t(k)];
            if (img->bytes() && img->rgba8.size() == img->texel_count()) {
                s.rgba8 = img->rgba8.data();
                s.unorm8 = true;
            } else if (const int nb = Image::narrow_bytes(img->format);
                       nb && img->narrow.size() == img->texel_count() * size_t(nb) + Image::kNarrowPad) {
                s.narrow = img->narrow.data();
                s.narrow_bytes = uint8_t(nb);
                s.narrow_base = img->format->base_format;
                s.unorm8 = true;
                // Channel c of RGBA from the texel's byte src[c] (-1: none; ES 3.0 table 3.24).
                const GLenum b = s.narrow_base;
                const int red[4] = {0, -1, -1, -1}, rg[4] = {0, 1, -1, -1}, lum[4] = {0, 0, 0, -1},
                          alpha[4] = {-1, -1, -1, 0}, lum_alpha[4] = {0, 0, 0, 1};
                const int* src = b == gl::RG ? rg : b == gl::LUMINANCE ? lum : b == gl::ALPHA ? alpha
                               : b == gl::LUMINANCE_ALPHA ? lum_alpha : red;
                for (int j = 0; j < 4; ++j)
                    for (int c = 0; c < 4; ++c)
                        s.narrow_shuffle[4 * j + c] = src[c] < 0 ? uint8_t(0x80) : uint8_t(4 * j + src[c]);
                s.narrow_fill = b == gl::ALPHA || b == gl::LUMINANCE_ALPHA ? 0u : 0xFF000000u;
            } else if (const int nc = img->color_channels();
                       nc && img->color.size() == Image::color_elements(img->format, img->texel_count())) {
                s.color = img->color.data();
                s.color_channels = uint8_t(nc);
            } else if (img->format->encoding == Encoding::Float16 && !img->packed.empty() &&
                       img->packed.size() == Image::packed_elements(img->format, img->texel_count(), false)) {
                s.half = reinterpret_cast<const uint16_t*>(img->packed.data());
                s.color_channels = uint8_t(img->packed_size / 2);
            } else if (img->format->is_depth() && img->depth_words.size() == img->texel_count()) {
                s.depth = img->depth_words.data();
                s.depth_encoding = img->format->encoding;
            } else {
                continue;
            }
            s.width = img->width, s.height = img->height, s.layers = img->depth;
            s.width_pot = is_power_of_two(img->width), s.height_pot = is_power_of_two(img->height);
        }
}

bool needs_mipmaps(GLenum min_filter) { return min_filter != gl::NEAREST && min_filter != gl::LINEAR; }

bool is_power_of_two(int32_t v) { return v > 0 && (v & (v - 1)) == 0; }

static int32_t effective_base(const Texture& t) {
    // ES 3.0 §3.8.10.4: an immutable texture's base level is clamped to its levels.
    return t.immutable ? std::clamp(t.base_level, 0, t.immutable_levels - 1) : t.base_level;
}

int32_t max_sampled_level(const Texture& t) {
    const int32_t base = effective_base(t);
    const Image* img = t.find(0, base);
    if (!img) return base;
    int32_t size = std::max(img->width, img->height);
    if (t.target == gl::TEXTURE_3D) size = std::max(size, img->depth);
    int32_t p = base;
    while (size > 1) size >>= 1, ++p;   // p = floor(log2(size)) + base
    int32_t q = std::min(p, t.max_level);
    if (t.immutable) q = std::clamp(q, base, t.immutable_levels - 1);
    return q;
}

std::string incompleteness(const Texture& t, const SamplerParams& params, const CompletenessRules& rules) {
    const int32_t base = effective_base(t);
    if (!t.immutable && t.base_level > t.max_level) return "TEXTURE_BASE_LEVEL exceeds TEXTURE_MAX_LEVEL";
    const Image* b = t.find(0, base);
    if (!b || b->width == 0 || b->height == 0 || b->depth == 0) return "the base level has no image";
    const bool mipmapped = needs_mipmaps(params.min_filter);
    const int32_t q = mipmapped ? max_sampled_level(t) : base;
    for (int face = 0; face < t.faces(); ++face) {
        for (int32_t level = base; level <= q; ++level) {
            const Image* img = t.find(face, level);
            const int32_t k = level - base;
            const int32_t w = std::max(1, b->width >> k), h = std::max(1, b->height >> k);
            const int32_t d = t.target == gl::TEXTURE_3D ? std::max(1, b->depth >> k) : b->depth;
            if (!img) return "level " + std::to_string(level) + (t.faces() > 1 ? " of face " + std::to_string(face) : "") + " is missing";
            if (img->width != w || img->height != h || img->depth != d)
                return "level " + std::to_string(level) + " has the wrong size for a mipmap chain";
            if (img->format != b->format) return "level " + std::to_string(level) + " has another internal format";
        }
    }
    if (t.target == gl::TEXTURE_CUBE_MAP && b->width != b->height) return "the cube map faces are not square";
    const FormatInfo& f = *b->format;
    // Non-filterable formats need NEAREST filters (ES 3.0 §3.8.14).
    bool filterable = true;
    if (f.is_integer()) filterable = false;
    if (f.encoding == Encoding::Float32 && !rules.float_linear) filterable = false;
    if (f.encoding == Encoding::Float16 && !rules.half_float_linear) filterable = false;
    if (f.is_depth() && !rules.webgl1 && params.compare_mode == gl::NONE) filterable = false;
    if (f.kind() == SampleKind::Depth && f.encoding == Encoding::Stencil8) filterable = false;
    const bool nearest_only = params.mag_filter == gl::NEAREST &&
                              (params.min_filter == gl::NEAREST || params.min_filter == gl::NEAREST_MIPMAP_NEAREST);
    if (!filterable && !nearest_only) return "the format is not filterable with these filters";
    if (rules.webgl1) {
        // WebGL 1.0 §5.13.8 (ES 2.0 §3.8.2): NPOT textures need CLAMP_TO_EDGE and no mipmapping.
        const bool npot = !is_power_of_two(b->width) || !is_power_of_two(b->height);
        if (npot && (mipmapped || params.wrap_s != gl::CLAMP_TO_EDGE || params.wrap_t != gl::CLAMP_TO_EDGE))
            return "a non-power-of-two texture needs CLAMP_TO_EDGE wrapping and a non-mipmap filter in WebGL 1";
    }
    return {};
}

// The last level generate_mipmaps writes (base: its base level, the image b).
static int32_t last_generated_level(const Texture& t, int32_t base, const Image& b) {
    const bool is3d = t.target == gl::TEXTURE_3D;
    int32_t last = base;
    int32_t size = std::max({b.width, b.height, is3d ? b.depth : 1});
    while (size > 1) size >>= 1, ++last;
    last = std::min(last, t.max_level);
    if (t.immutable) last = std::min(last, t.immutable_levels - 1);
    return last;
}

uint64_t storage_bytes_after_mipmaps(const Texture& t) {
    const int32_t base = effective_base(t);
    const Image* b = t.find(0, base);
    uint64_t total = t.storage_bytes();
    if (!b) return total;
    const bool is3d = t.target == gl::TEXTURE_3D;
    const int32_t last = last_generated_level(t, base, *b);
    for (int face = 0; face < t.faces(); ++face) {
        int32_t w = b->width, h = b->height, d = b->depth;
        for (int32_t level = base + 1; level <= last; ++level) {
            w = std::max(1, w / 2), h = std::max(1, h / 2), d = is3d ? std::max(1, d / 2) : d;
            if (const Image* old = t.find(face, level)) total -= old->storage_bytes();
            total += Image::allocation_bytes(b->format, w, h, d, 1);
        }
    }
    return total;
}

void generate_mipmaps(Texture& t) {
    const int32_t base = effective_base(t);
    const Image* b = t.find(0, base);
    if (!b) return;
    const bool is3d = t.target == gl::TEXTURE_3D;
    const int32_t last = last_generated_level(t, base, *b);
    for (int face = 0; face < t.faces(); ++face) {
        for (int32_t level = base + 1; level <= last; ++level) {
            const Image src = t.image(face, level - 1);   // a copy: image() may reallocate
            const int32_t nw = std::max(1, src.width / 2), nh = std::max(1, src.height / 2);
            const int32_t nd = is3d ? std::max(1, src.depth / 2) : src.depth;
            Image& dst = t.image(face, level);
            dst.allocate(src.format, nw, nh, nd);
            // A box filter over the 2x2(x2) texels each new texel covers; odd sizes clamp the last
            // source texel (ES 3.0 §3.8.11 leaves the filter to the implementation).
            for (int32_t z = 0; z < nd; ++z)
                for (int32_t y = 0; y < nh; ++y)
                    for (int32_t x = 0; x < nw; ++x) {
                        double sum[4] = {0, 0, 0, 0};
                        int count = 0;
                        for (int dz = 0; dz < (is3d ? 2 : 1); ++dz)
                            for (int dy = 0; dy < 2; ++dy)
                                for (int dx = 0; dx < 2; ++dx) {
                                    const int32_t sx = std::min(2 * x + dx, src.width - 1);
                                    const int32_t sy = std::min(2 * y + dy, src.height - 1);
                                    const int32_t sz = is3d ? std::min(2 * z + dz, src.depth - 1) : z;
                                    float p[4];
                                    src.read_color((size_t(sz) * size_t(src.height) + size_t(sy)) * size_t(src.width) + size_t(sx), p);
                                    for (int c = 0; c < 4; ++c) sum[c] += double(p[c]);
                                    ++count;
                                }
                        float avg[4], q[4];
                        for (int c = 0; c < 4; ++c) avg[c] = float(sum[c] / count);
                        const size_t at = (size_t(z) * size_t(nh) + size_t(y)) * size_t(nw) + size_t(x);
                        if (dst.bytes()) {
                            dst.rgba8[at] = quantize_unorm8(*src.format, avg);
                            continue;
                        }
                        quantize_color(*src.format, avg, q);
                        dst.store_color(at, q);
                    }
        }
    }
    ++t.generation;
}

}  // namespace softgl
