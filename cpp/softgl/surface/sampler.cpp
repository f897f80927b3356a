#include "softgl/surface/sampler.h"

#include "softgl/core/simd.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace softgl {

using glsl::BaseType;
using glsl::SamplerDim;
using glsl::TextureKind;
using glsl::TextureLod;

int cube_face(float rx, float ry, float rz, float& sc, float& tc, float& ma) {
    const float ax = std::fabs(rx), ay = std::fabs(ry), az = std::fabs(rz);
    // Ties go to x, then y (as SwiftShader and ANGLE do).
    if (ax >= ay && ax >= az) {
        ma = ax;
        if (rx >= 0) { sc = -rz; tc = -ry; return 0; }
        sc = rz; tc = -ry; return 1;
    }
    if (ay >= az) {
        ma = ay;
        if (ry >= 0) { sc = rx; tc = rz; return 2; }
        sc = rx; tc = -rz; return 3;
    }
    ma = az;
    if (rz >= 0) { sc = rx; tc = -ry; return 4; }
    sc = -rx; tc = -ry; return 5;
}

namespace {

// The direction of face coordinates (sc, tc) on `face` at |ma| = 1 (inverse of table 3.21).
void cube_direction(int face, float sc, float tc, float r[3]) {
    switch (face) {
        case 0: r[0] = 1, r[1] = -tc, r[2] = -sc; break;
        case 1: r[0] = -1, r[1] = -tc, r[2] = sc; break;
        case 2: r[0] = sc, r[1] = 1, r[2] = tc; break;
        case 3: r[0] = sc, r[1] = -1, r[2] = -tc; break;
        case 4: r[0] = sc, r[1] = -tc, r[2] = 1; break;
        default: r[0] = -sc, r[1] = -tc, r[2] = -1; break;
    }
}

// ES 3.0 §3.8.10 eq. 3.18: the face a cube-map direction (s, t, r) selects, with s, t replaced
// by the face coordinates in [0, 1] and the derivatives dx, dy by theirs (quotient rule; the
// third component 0). Both paths call this, so that they agree to the bit.
int cube_coords(float& s, float& t, float r, float dx[3], float dy[3]) {
    float sc, tc, ma;
    const int face = cube_face(s, t, r, sc, tc, ma);
    const int major = face / 2;
    const float sign = (face % 2) ? -1.0f : 1.0f;
    float dsc[2], dtc[2], dma[2];
    const float* d2[2] = {dx, dy};
    for (int n = 0; n < 2; ++n) {
        const float* d = d2[n];
        switch (face) {
            case 0: dsc[n] = -d[2]; dtc[n] = -d[1]; break;
            case 1: dsc[n] = d[2]; dtc[n] = -d[1]; break;
            case 2: dsc[n] = d[0]; dtc[n] = d[2]; break;
            case 3: dsc[n] = d[0]; dtc[n] = -d[2]; break;
            case 4: dsc[n] = d[0]; dtc[n] = -d[1]; break;
            default: dsc[n] = -d[0]; dtc[n] = -d[1]; break;
        }
        dma[n] = sign * d[major];
    }
    const float inv = ma > 0 ? 1.0f / ma : 0.0f;
    s = 0.5f * (sc * inv + 1.0f);
    t = 0.5f * (tc * inv + 1.0f);
    for (int n = 0; n < 2; ++n) {
        float* d = n ? dy : dx;
        d[0] = 0.5f * (dsc[n] * ma - sc * dma[n]) * inv * inv;
        d[1] = 0.5f * (dtc[n] * ma - tc * dma[n]) * inv * inv;
        d[2] = 0.0f;
    }
    return face;
}

// ES 3.0 table 3.19 applied to integer texel coordinates.
int32_t wrap(GLenum mode, int32_t i, int32_t size) {
    switch (mode) {
        case gl::REPEAT: {
            const int32_t m = i % size;
            return m < 0 ? m + size : m;
        }
        case gl::MIRRORED_REPEAT: {
            const int64_t period = 2 * int64_t(size);
            const int64_t m = ((int64_t(i) % period) + period) % period;
            const int64_t a = m - size;
            const int64_t mirror = a >= 0 ? a : -(1 + a);
            return int32_t(size - 1 - mirror);
        }
        default: return std::clamp(i, 0, size - 1);   // CLAMP_TO_EDGE
    }
}

// floor(u) as an int, saturated so that huge or NaN coordinates stay defined.
int32_t ifloor(float u) {
    if (!(u == u)) return 0;
    return int32_t(std::clamp(std::floor(double(u)), -1073741824.0, 1073741823.0));
}

bool compare_passes(GLenum func, float ref, float d) {
    // ES 3.0 table 3.22: the reference is compared with the texel's depth.
    switch (func) {
        case gl::LEQUAL: return ref <= d;
        case gl::GEQUAL: return ref >= d;
        case gl::LESS: return ref < d;
        case gl::GREATER: return ref > d;
        case gl::EQUAL: return ref == d;
        case gl::NOTEQUAL: return ref != d;
        case gl::ALWAYS: return true;
        default: return false;   // NEVER
    }
}

// ---- LINEAR filtering of 8-bit unorm textures (README "Choices"): a fixed-point rule.
// The fractions a, b of eq. 3.20 become 8-bit weights A = round(256 a), B = round(256 b)
// (nearest, ties to even; a NaN fraction gives 0), as GPUs quantize them (8 bits of sub-texel
// precision), and with texels k (the bytes, value k / 255) the value is
//   ((256 - A)(256 - B) k00 + A (256 - B) k10 + (256 - A) B k01 + A B k11) / (255 * 65536),
// the integer sum (at most 255 * 65536 < 2^24) divided in float32, correctly rounded. Every
// product and partial sum is an integer below 2^24, exact in float32, so any order, SIMD width
// or FMA gives the same bits. Levels (mipmaps, 3D slices) still blend in float as before.
inline float weight8(float frac) {
    const float w = std::nearbyint(frac * 256.0f);
    return w > 0.0f ? std::min(w, 256.0f) : 0.0f;   // NaN -> 0, as SIMD max(w, 0) then min(., 256)
}
constexpr float kUnorm8Divisor = 255.0f * 65536.0f;

// The four weights of the rule for fractions a, b: w[0] for t00, w[1] t10, w[2] t01, w[3] t11.
inline void weights8(float a, float b, float w[4]) {
    const float A = weight8(a), B = weight8(b);
    w[0] = (256.0f - A) * (256.0f - B), w[1] = A * (256.0f - B), w[2] = (256.0f - A) * B, w[3] = A * B;
}

// Filtering one level of one bound texture.
struct Level {
    const BoundTexture* bt;
    const Texture* tex;
    int level;
    int face;              // cube maps: the selected face
    const Image* img;      // the face's image at this level
    bool cube, is3d;
    bool compare;
    float ref;

    // The texel at (i, j, k); i, j may be outside the image (wrapped here, or on a cube map,
    // taken from the adjacent face when filtering is seamless).
    void texel(int32_t i, int32_t j, int32_t k, float out[4]) const {
        const int32_t w = img->width, h = img->height;
        if (cube) {
            const bool out_i = i < 0 || i >= w, out_j = j < 0 || j >= h;
            if ((out_i || out_j) && bt->seamless_cube) {
                if (out_i && out_j) {
                    // ES 3.0 §3.8.9.1: at a corner, average the three texels that meet there.
                    float a[4], b[4], c[4];
                    fetch(face, std::clamp(i, 0, w - 1), std::clamp(j, 0, h - 1), 0, a);
                    neighbour(i, std::clamp(j, 0, h - 1), b);
                    neighbour(std::clamp(i, 0, w - 1), j, c);
                    for (int n = 0; n < 4; ++n) out[n] = (a[n] + b[n] + c[n]) / 3.0f;
                    return;
                }
                neighbour(i, j, out);
                return;
            }
            fetch(face, std::clamp(i, 0, w - 1), std::clamp(j, 0, h - 1), 0, out);
            return;
        }
        const SamplerParams& p = bt->params;
        i = wrap(p.wrap_s, i, w);
        j = wrap(p.wrap_t, j, h);
        if (is3d) k = wrap(p.wrap_r, k, img->depth);
        fetch(face, i, j, k, out);
    }

    // A texel just outside `face`: the texel of the adjacent face at the same direction.
    void neighbour(int32_t i, int32_t j, float out[4]) const {
        const int32_t n = img->width;
        const float sc = 2.0f * (float(i) + 0.5f) / float(n) - 1.0f, tc = 2.0f * (float(j) + 0.5f) / float(n) - 1.0f;
        float r[3];
        cube_direction(face, sc, tc, r);
        float s2, t2, ma;
        const int f2 = cube_face(r[0], r[1], r[2], s2, t2, ma);
        const Image* other = tex->find(f2, level);
        const int32_t x = std::clamp(ifloor(0.5f * (s2 / ma + 1.0f) * float(n)), 0, n - 1);
        const int32_t y = std::clamp(ifloor(0.5f * (t2 / ma + 1.0f) * float(n)), 0, n - 1);
        fetch_image(other ? other : img, x, y, 0, out);
    }

    void fetch(int f, int32_t i, int32_t j, int32_t k, float out[4]) const {
        fetch_image(f == face ? img : tex->find(f, level), i, j, k, out);
    }

    void fetch_image(const Image* im, int32_t i, int32_t j, int32_t k, float out[4]) const {
        if (!im->integer.empty()) {
            // Integer texels travel as their bit patterns (only NEAREST filters reach them).
            const size_t n = (size_t(k) * size_t(im->height) + size_t(j)) * size_t(im->width) + size_t(i);
            uint32_t bits[4];
            im->read_integer(n, bits);
            std::memcpy(out, bits, 16);
            return;
        }
        im->texel(i, j, k, out);
        if (im->format->kind() == SampleKind::Depth) {
            if (compare) {
                // ES 3.0 §3.8.16: fixed-point depth compares with the reference clamped to [0, 1].
                const float r = im->format->encoding == Encoding::Depth32F ? ref : std::clamp(ref, 0.0f, 1.0f);
                out[0] = compare_passes(bt->params.compare_func, r, out[0]) ? 1.0f : 0.0f;
            }
            if (bt->depth_as_luminance || compare) out[1] = out[2] = out[0];
        }
    }

    // One filtered value at normalized (s, t, r) of this level (r: 3D coordinate, or the array layer).
    void filter(bool linear, float s, float t, float r, const int off[3], float out[4]) const {
        const int32_t w = img->width, h = img->height;
        const float u = s * float(w) + float(off[0]), v = t * float(h) + float(off[1]);
        int32_t layer = 0;
        float wz = 0.0f;
        if (is3d) wz = r * float(img->depth) + float(off[2]);
        else if (!cube) layer = std::clamp(ifloor(r + 0.5f), 0, img->depth - 1);   // ES 3.0 §3.8.10: layer
        if (!linear) {
            texel(ifloor(u), ifloor(v), is3d ? ifloor(wz) : layer, out);
            return;
        }
        // ES 3.0 §3.8.11, eq. 3.20: i0 = floor(u - 1/2), weights from the fractional parts.
        const float u0 = u - 0.5f, v0 = v - 0.5f;
        const int32_t i0 = ifloor(u0), j0 = ifloor(v0);
        const float a = u0 - std::floor(u0), b = v0 - std::floor(v0);
        float t00[4], t10[4], t01[4], t11[4];
        // 8-bit unorm: the fixed-point rule above (texels k = 255 v: exact for v = k / 255).
        const bool unorm8 = img->format->is_unorm8();
        float w8[4] = {0, 0, 0, 0};
        if (unorm8) weights8(a, b, w8);
        const auto bilinear = [&](float dst[4]) {
            if (unorm8) {
                for (int c = 0; c < 4; ++c)
                    dst[c] = (w8[0] * (t00[c] * 255.0f) + w8[1] * (t10[c] * 255.0f) + w8[2] * (t01[c] * 255.0f) +
                              w8[3] * (t11[c] * 255.0f)) / kUnorm8Divisor;
                return;
            }
            for (int c = 0; c < 4; ++c)
                dst[c] = (1 - a) * (1 - b) * t00[c] + a * (1 - b) * t10[c] + (1 - a) * b * t01[c] + a * b * t11[c];
        };
        if (!is3d) {
            texel(i0, j0, layer, t00);
            texel(i0 + 1, j0, layer, t10);
            texel(i0, j0 + 1, layer, t01);
            texel(i0 + 1, j0 + 1, layer, t11);
            bilinear(out);
            return;
        }
        const float w0 = wz - 0.5f;
        const int32_t k0 = ifloor(w0);
        const float g = w0 - std::floor(w0);
        float lo[4], hi[4];
        for (int plane = 0; plane < 2; ++plane) {
            float* dst = plane ? hi : lo;
            texel(i0, j0, k0 + plane, t00);
            texel(i0 + 1, j0, k0 + plane, t10);
            texel(i0, j0 + 1, k0 + plane, t01);
            texel(i0 + 1, j0 + 1, k0 + plane, t11);
            bilinear(dst);
        }
        for (int c = 0; c < 4; ++c) out[c] = (1 - g) * lo[c] + g * hi[c];
    }
};

void incomplete_result(const glsl::TextureQuery& q, int l) {
    for (int c = 0; c < 4; ++c) {
        if (!q.out[c]) continue;
        glsl::Scalar v{};
        if (q.kind == TextureKind::Size) v.i = 0;
        else if (q.result == BaseType::Float) v.f = c == 3 ? 1.0f : 0.0f;
        else v.i = c == 3 ? 1 : 0;
        q.out[c][l] = v;
    }
}

}  // namespace

void TextureUnitSampler::sample_lanes(const glsl::TextureQuery& q) const {
    for (int l = 0; l < q.lane_count; ++l) sample_lane(q, l);
}

void TextureUnitSampler::sample_lane(const glsl::TextureQuery& q, int l) const {
    const int dim = dim_index(q.dim);
    const bool cube = q.dim == SamplerDim::Cube, is3d = q.dim == SamplerDim::Tex3D;
    {
        const int32_t unit = q.unit[l].i;
        const BoundTexture* bt = unit >= 0 && unit < kSamplerUnits ? &units[size_t(unit)][size_t(dim)] : nullptr;
        if (!bt || !bt->texture || (q.active && !q.active[l])) {
            incomplete_result(q, l);
            return;
        }
        const Texture& tex = *bt->texture;

        if (q.kind == TextureKind::Size) {
            // ES 3.00 §8.8: the size of level base + lod (lod outside the levels: undefined, 0 here).
            const int32_t level = bt->base + q.lod[l].i;
            const Image* img = tex.find(0, level);
            const bool ok = img && q.lod[l].i >= 0;
            const int32_t size[3] = {ok ? img->width : 0, ok ? img->height : 0, ok ? img->depth : 0};
            for (int c = 0; c < 3; ++c)
                if (q.out[c]) q.out[c][l].i = size[c];
            return;
        }

        if (q.kind == TextureKind::Fetch) {
            // texelFetch: no filtering or wrapping; out-of-range coordinates give zeros
            // (undefined in ES 3.0 §3.8.? and WebGL 2 §5.? leaves it so; zero is what ANGLE gives).
            const int32_t level = bt->base + q.lod[l].i;
            const Image* img = tex.find(0, level);
            int32_t c3[3] = {0, 0, 0};
            for (int k = 0; k < 3; ++k)
                if (q.coord[k]) c3[k] = q.coord[k][l].i + q.offset[k];
            const bool inside = img && q.lod[l].i >= 0 && level <= bt->q && c3[0] >= 0 && c3[1] >= 0 && c3[2] >= 0 &&
                                c3[0] < img->width && c3[1] < img->height && c3[2] < img->depth;
            if (!inside) {
                for (int c = 0; c < 4; ++c) if (q.out[c]) q.out[c][l].u = 0;
                return;
            }
            const size_t t = (size_t(c3[2]) * size_t(img->height) + size_t(c3[1])) * size_t(img->width) + size_t(c3[0]);
            if (q.result != BaseType::Float) {
                uint32_t bits[4] = {0, 0, 0, 0};
                if (!img->integer.empty()) img->read_integer(t, bits);
                for (int c = 0; c < 4; ++c)
                    if (q.out[c]) q.out[c][l].u = bits[c];
            } else {
                float texel[4];
                img->texel(c3[0], c3[1], c3[2], texel);
                if (img->format->kind() == SampleKind::Depth && bt->depth_as_luminance) texel[1] = texel[2] = texel[0];
                for (int c = 0; c < 4; ++c) if (q.out[c]) q.out[c][l].f = texel[c];
            }
            return;
        }

        // ---- a filtered lookup ----
        float s = q.coord[0] ? q.coord[0][l].f : 0.0f, t = q.coord[1] ? q.coord[1][l].f : 0.0f;
        float r = q.coord[2] ? q.coord[2][l].f : 0.0f;
        float dx[3] = {0, 0, 0}, dy[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k) {
            if (q.ddx[k]) dx[k] = q.ddx[k][l].f;
            if (q.ddy[k]) dy[k] = q.ddy[k][l].f;
        }
        const int face = cube ? cube_coords(s, t, r, dx, dy) : 0;
        const Image* base_img = tex.find(face, bt->base);
        if (!base_img) { incomplete_result(q, l); return; }

        // ES 3.0 §3.8.10.1-2: the level of detail.
        float lambda;
        if (q.lod_mode == TextureLod::Explicit) {
            lambda = q.lod ? q.lod[l].f : 0.0f;
        } else {
            const float w = float(base_img->width), h = float(base_img->height), d = is3d ? float(base_img->depth) : 0.0f;
            const double lx = std::sqrt(double(dx[0] * w) * (dx[0] * w) + double(dx[1] * h) * (dx[1] * h) + double(dx[2] * d) * (dx[2] * d));
            const double ly = std::sqrt(double(dy[0] * w) * (dy[0] * w) + double(dy[1] * h) * (dy[1] * h) + double(dy[2] * d) * (dy[2] * d));
            const double rho = std::max(lx, ly);
            lambda = rho > 0 ? float(std::log2(rho)) : -INFINITY;
            if (q.lod_mode == TextureLod::Bias && q.lod) lambda += q.lod[l].f;
        }
        const SamplerParams& p = bt->params;
        lambda = std::clamp(lambda, p.min_lod, p.max_lod);   // NaN stays NaN: treated as magnification

        Level lv{bt, &tex, bt->base, face, base_img, cube, is3d, false, 0.0f};
        if (q.shadow && p.compare_mode == gl::COMPARE_REF_TO_TEXTURE) {
            lv.compare = true;
            lv.ref = q.compare ? q.compare[l].f : 0.0f;
        }
        float result[4] = {0, 0, 0, 1};
        // ES 3.0 §3.8.11: lambda <= c (c = 0) magnifies.
        if (!(lambda > 0.0f)) {
            lv.filter(p.mag_filter == gl::LINEAR, s, t, r, q.offset, result);
        } else {
            const GLenum f = p.min_filter;
            const bool linear = f == gl::LINEAR || f == gl::LINEAR_MIPMAP_NEAREST || f == gl::LINEAR_MIPMAP_LINEAR;
            const int32_t base = bt->base, top = bt->q;
            if (f == gl::NEAREST || f == gl::LINEAR || top == base) {
                lv.filter(linear, s, t, r, q.offset, result);
            } else if (f == gl::NEAREST_MIPMAP_NEAREST || f == gl::LINEAR_MIPMAP_NEAREST) {
                // ES 3.0 eq. 3.21: the nearest level.
                int32_t level;
                if (lambda <= 0.5f) level = base;
                else if (float(base) + lambda <= float(top) + 0.5f) level = int32_t(std::ceil(float(base) + lambda + 0.5f)) - 1;
                else level = top;
                lv.level = level;
                lv.img = tex.find(face, level);
                lv.filter(linear, s, t, r, q.offset, result);
            } else {
                // ES 3.0 §3.8.11.2: the two nearest levels, blended by the fraction of lambda.
                int32_t d1, d2;
                if (lambda >= float(top - base)) d1 = d2 = top;
                else d1 = base + int32_t(std::floor(lambda)), d2 = d1 + 1;
                const float frac = lambda - std::floor(lambda);
                float a[4], b[4];
                lv.level = d1;
                lv.img = tex.find(face, d1);
                lv.filter(linear, s, t, r, q.offset, a);
                if (d2 == d1) {
                    std::copy(a, a + 4, result);
                } else {
                    lv.level = d2;
                    lv.img = tex.find(face, d2);
                    lv.filter(linear, s, t, r, q.offset, b);
                    for (int c = 0; c < 4; ++c) result[c] = (1 - frac) * a[c] + frac * b[c];
                }
            }
        }
        if (q.result == BaseType::Float) {
            for (int c = 0; c < 4; ++c) if (q.out[c]) q.out[c][l].f = result[c];
        } else {
            // Integer textures are only complete with NEAREST filters: the texel is exact.
            for (int c = 0; c < 4; ++c)
                if (q.out[c]) {
                    std::memcpy(&q.out[c][l].u, &result[c], 4);
                }
        }
    }
}

// ---------------------------------------------------------------------------- the fast path
//
// The same formulas as sample_lanes in the same order (so the same bits), with what does not
// change across a query resolved once: the texture, its levels (the draw's table,
// Texture::sampled_levels), the filters and wraps. Texels are read straight from the float
// storage, the byte copy of 8-bit unorm levels, or the depth words. With AVX2, blocks of 8
// lanes compute their LOD, texel addresses and weights 8 at a time (the same float operations,
// lane by lane; no FMA); with AVX-512, colour lookups go in blocks of 16. A block whose lanes
// use up to 3 levels filters each once for all its lanes and takes each lane's from its own.

namespace {

// One level of a 2D / 2D array texture or of a cube-map face (texture.h).
using Plane = SampledLevel;

// The colour block loops a plan can name (SamplingPlan::colour_shape; kColourBlocks8).
constexpr int kColourShapes = 19;

// Texel n of an 8-bit unorm plane as its RGBA bytes R | G << 8 | B << 16 | A << 24 (Image::rgba8's
// word): read, or made from a narrow texel (Image::narrow) with the absent channels' defaults of
// ES 3.0 table 3.24 (0, alpha 255; luminance in r, g and b), as Image::read_color gives them.
inline uint32_t narrow_rgba8(const Plane& p, size_t n) {
    const uint8_t* b = p.narrow + n * p.narrow_bytes;
    const uint32_t k0 = b[0], k1 = p.narrow_bytes == 2 ? b[1] : 0u;
    switch (p.narrow_base) {
        case gl::ALPHA: return k0 << 24;
        case gl::LUMINANCE: return k0 | k0 << 8 | k0 << 16 | 0xFF000000u;
        case gl::LUMINANCE_ALPHA: return k0 | k0 << 8 | k0 << 16 | k1 << 24;
        default: return k0 | k1 << 8 | 0xFF000000u;   // RED, RG
    }
}
inline uint32_t unorm8_texel(const Plane& p, size_t n) { return p.rgba8 ? p.rgba8[n] : narrow_rgba8(p, n); }

// The binary16 at h (SampledLevel::half) as a float: exact. Stored halves are never signalling
// NaNs (quantize_color's NaN is 0x7E00), so this and F16C's conversion give the same bits.
inline float half_at(const uint16_t* h) {
    uint16_t v;
    std::memcpy(&v, h, 2);
    return half_to_float(v);
}

// wrap() of a texel coordinate and of its right/upper neighbour, as LINEAR uses them (REPEAT of
// a power of two masks: the same as the modulo for any int in two's complement).
inline void wrap_pair(GLenum mode, int32_t i, int32_t size, bool pot, int32_t& a, int32_t& b) {
    switch (mode) {
        case gl::REPEAT:
            a = pot ? i & (size - 1) : wrap(mode, i, size);
            b = a + 1 == size ? 0 : a + 1;
            return;
        case gl::CLAMP_TO_EDGE:
            a = std::clamp(i, 0, size - 1);
            b = std::clamp(i + 1, 0, size - 1);
            return;
        default:
            a = wrap(mode, i, size);
            b = wrap(mode, i + 1, size);
            return;
    }
}

inline int32_t wrap_one(GLenum mode, int32_t i, int32_t size, bool pot) {
    return mode == gl::REPEAT && pot ? i & (size - 1) : wrap(mode, i, size);
}

// The level(s) a lambda selects (ES 3.0 §3.8.11, as in sample_lanes): planes[first], blended
// with planes[second] by frac when second >= 0.
struct LevelChoice {
    int32_t first = 0, second = -1;
    bool linear = false;
    float frac = 0.0f;
    bool same_levels(const LevelChoice& o) const { return first == o.first && second == o.second && linear == o.linear; }
};

struct Fast2D {
    const Plane* planes;   // levels base .. top of face 0; face f's at planes + f * face_stride
    int32_t face_stride;
    GLenum wrap_s, wrap_t;
    int off_s, off_t;
    int32_t base, top;
    GLenum min_filter;
    bool mag_linear, min_linear, mipmapped;
    float min_lod, max_lod;
    // Depth textures: the comparison (ES 3.0 §3.8.16) and WEBGL_depth_texture's (d, d, d, 1).
    bool compare = false, luminance = false;
    GLenum compare_func = gl::LEQUAL;

    LevelChoice choose(float lambda) const {
        lambda = std::clamp(lambda, min_lod, max_lod);   // NaN stays NaN: magnification
        if (!(lambda > 0.0f)) return {0, -1, mag_linear, 0.0f};
        if (!mipmapped) return {0, -1, min_linear, 0.0f};
        if (min_filter == gl::NEAREST_MIPMAP_NEAREST || min_filter == gl::LINEAR_MIPMAP_NEAREST) {
            int32_t level;
            if (lambda <= 0.5f) level = base;
            else if (float(base) + lambda <= float(top) + 0.5f) level = int32_t(std::ceil(float(base) + lambda + 0.5f)) - 1;
            else level = top;
            return {level - base, -1, min_linear, 0.0f};
        }
        int32_t d1, d2;
        if (lambda >= float(top - base)) d1 = d2 = top;
        else d1 = base + int32_t(std::floor(lambda)), d2 = d1 + 1;
        if (d1 == d2) return {d1 - base, -1, min_linear, 0.0f};
        return {d1 - base, d2 - base, min_linear, lambda - std::floor(lambda)};
    }

    // Texel n of plane p as Level::fetch_image gives it (ref: the lane's depth reference).
    void texel(const Plane& p, size_t n, float ref, float out[4]) const {
        if (p.rgba8 || p.narrow) {
            // 8-bit unorm storage: k / 255 is unorm(k, 8).
            const uint32_t v = unorm8_texel(p, n);
            for (int c = 0; c < 4; ++c) out[c] = float((v >> (8 * c)) & 255u) / 255.0f;
            return;
        }
        if (p.color) {
            // color_channels floats, then the absent channels' values (SampledLevel::color_fill).
            const size_t nc = p.color_channels;
            for (size_t c = 0; c < 4; ++c) out[c] = c < nc ? p.color[n * nc + c] : p.color_fill[c];
            return;
        }
        if (p.half) {
            // color_channels halves, decoded exactly (the vector paths' F16C gives the same bits).
            const size_t nc = p.color_channels;
            for (size_t c = 0; c < 4; ++c) out[c] = c < nc ? half_at(p.half + n * nc + c) : p.color_fill[c];
            return;
        }
        float d = depth_value(p.depth_encoding, p.depth[n]);
        if (compare) {
            // ES 3.0 §3.8.16: fixed-point depth compares with the reference clamped to [0, 1].
            const float r = p.depth_encoding == Encoding::Depth32F ? ref : std::clamp(ref, 0.0f, 1.0f);
            d = compare_passes(compare_func, r, d) ? 1.0f : 0.0f;
        }
        out[0] = d;
        out[1] = out[2] = compare || luminance ? d : 0.0f;
        out[3] = 1.0f;
    }

    // Level::filter of one plane.
    void filter(const Plane& p, bool linear, float s, float t, float r, float ref, float out[4]) const {
        const float u = s * float(p.width) + float(off_s), v = t * float(p.height) + float(off_t);
        const int32_t layer = p.layers == 1 ? 0 : std::clamp(ifloor(r + 0.5f), 0, p.layers - 1);
        const size_t plane = size_t(layer) * size_t(p.height) * size_t(p.width);
        if (!linear) {
            const int32_t i = wrap_one(wrap_s, ifloor(u), p.width, p.width_pot);
            const int32_t j = wrap_one(wrap_t, ifloor(v), p.height, p.height_pot);
            texel(p, plane + size_t(j) * size_t(p.width) + size_t(i), ref, out);
            return;
        }
        const float u0 = u - 0.5f, v0 = v - 0.5f;
        int32_t i0, i1, j0, j1;
        wrap_pair(wrap_s, ifloor(u0), p.width, p.width_pot, i0, i1);
        wrap_pair(wrap_t, ifloor(v0), p.height, p.height_pot, j0, j1);
        const float a = u0 - std::floor(u0), b = v0 - std::floor(v0);
        const size_t row0 = plane + size_t(j0) * size_t(p.width), row1 = plane + size_t(j1) * size_t(p.width);
        if (p.unorm8) {
            // The fixed-point rule (Level::filter), from the bytes.
            float w8[4], k[4][4];
            weights8(a, b, w8);
            const size_t at[4] = {row0 + size_t(i0), row0 + size_t(i1), row1 + size_t(i0), row1 + size_t(i1)};
            for (int n = 0; n < 4; ++n)
                for (int c = 0; c < 4; ++c)
                    k[n][c] = float((unorm8_texel(p, at[n]) >> (8 * c)) & 255u);
            for (int c = 0; c < 4; ++c)
                out[c] = (w8[0] * k[0][c] + w8[1] * k[1][c] + w8[2] * k[2][c] + w8[3] * k[3][c]) / kUnorm8Divisor;
            return;
        }
        float t00[4], t10[4], t01[4], t11[4];
        texel(p, row0 + size_t(i0), ref, t00);
        texel(p, row0 + size_t(i1), ref, t10);
        texel(p, row1 + size_t(i0), ref, t01);
        texel(p, row1 + size_t(i1), ref, t11);
        const float w00 = (1 - a) * (1 - b), w10 = a * (1 - b), w01 = (1 - a) * b, w11 = a * b;
        for (int c = 0; c < 4; ++c) out[c] = w00 * t00[c] + w10 * t10[c] + w01 * t01[c] + w11 * t11[c];
    }

    void filter(const LevelChoice& ch, int face, float s, float t, float r, float ref, float out[4]) const {
        const Plane* levels = planes + size_t(face) * size_t(face_stride);
        filter(levels[ch.first], ch.linear, s, t, r, ref, out);
        if (ch.second < 0) return;
        float b[4];
        filter(levels[ch.second], ch.linear, s, t, r, ref, b);
        for (int c = 0; c < 4; ++c) out[c] = (1 - ch.frac) * out[c] + ch.frac * b[c];
    }

    // Whether the texels Level::filter reads for (s, t) on plane p all lie inside the face
    // (cube maps: texels beyond an edge come from the adjacent face when filtering is seamless).
    bool inside(const Plane& p, bool linear, float s, float t) const {
        const float u = s * float(p.width), v = t * float(p.height);
        if (!linear) {
            const int32_t i = ifloor(u), j = ifloor(v);
            return i >= 0 && i < p.width && j >= 0 && j < p.height;
        }
        const int32_t i0 = ifloor(u - 0.5f), j0 = ifloor(v - 0.5f);
        return i0 >= 0 && i0 < p.width - 1 && j0 >= 0 && j0 < p.height - 1;
    }
    bool inside(const LevelChoice& ch, int face, float s, float t) const {
        const Plane* levels = planes + size_t(face) * size_t(face_stride);
        return inside(levels[ch.first], ch.linear, s, t) && (ch.second < 0 || inside(levels[ch.second], ch.linear, s, t));
    }
};

// lambda = log2(rho) with rho = sqrt(rho2), as float (ES 3.0 eq. 3.17-3.19). A pure function of
// rho2, memoized per thread: log2 is dear, and lanes of neighbouring quads share derivatives.
class LambdaMemo {
public:
    float operator()(double rho2) {
        uint64_t bits;
        std::memcpy(&bits, &rho2, 8);
        // The last value asked first, inline: under affine coordinates every block of a draw
        // asks the same rho2.
        if (bits == last_bits_) return last_lambda_;
        last_bits_ = bits;
        return last_lambda_ = lookup(rho2, bits);
    }
    static LambdaMemo& of_this_thread() {
        thread_local LambdaMemo memo;
        return memo;
    }

private:
    float lookup(double rho2, uint64_t bits) {
        if (!(rho2 == rho2)) return -INFINITY;   // NaN: rho > 0 fails, as in sample_lanes
        Entry& e = entries_[(bits ^ (bits >> 20) ^ (bits >> 40)) % kEntries];
        if (e.not_key == ~bits) return e.lambda;
        const double rho = std::sqrt(rho2);
        const float lambda = rho > 0 ? float(std::log2(rho)) : -INFINITY;
        e = {~bits, lambda};
        return lambda;
    }
    static constexpr size_t kEntries = 256;
    struct Entry { uint64_t not_key; float lambda; };   // ~bits of rho2 (zero: never a non-NaN)
    Entry entries_[kEntries] = {};
    uint64_t last_bits_ = 0x7FF8000000000000ull;   // a NaN's bits, whose lambda is -inf
    float last_lambda_ = -INFINITY;
};

// Whether every texel number of p fits an int32 (gathers take int32 indices; narrow planes: their
// byte offsets, narrow_words8); larger 2D arrays are filtered lane by lane (filter8_lanes).
inline bool int32_indices(const Plane& p) {
    return uint64_t(p.width) * uint64_t(p.height) * uint64_t(p.layers) * uint64_t(p.narrow ? p.narrow_bytes : 1) <=
           uint64_t(INT32_MAX);
}

#if defined(__x86_64__) || defined(__i386__)
#define SOFTGL_SAMPLER_AVX2 1

// ifloor of values that are already integral (or NaN, or infinite): NaN -> 0, saturated.
__attribute__((target("avx2,f16c"))) inline __m256i ifloor_floored8(__m256 fl) {
    const __m256 lo = _mm256_set1_ps(-1073741824.0f), hi = _mm256_set1_ps(1073741824.0f);
    __m256i i = _mm256_cvttps_epi32(_mm256_min_ps(_mm256_max_ps(fl, lo), hi));   // NaN -> lo here
    i = _mm256_min_epi32(i, _mm256_set1_epi32(1073741823));
    return _mm256_and_si256(i, _mm256_castps_si256(_mm256_cmp_ps(fl, fl, _CMP_ORD_Q)));
}

// narrow_rgba8 of 8 lanes: each texel's 4 bytes read at byte narrow_bytes * index (the channels'
// bytes first; Image::kNarrowPad keeps the last texel's read inside the storage), then moved to
// their RGBA places and the absent channels filled (SampledLevel::narrow_shuffle, narrow_fill).
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i narrow_words8(const Plane& p, __m256i index) {
    const __m256i at = _mm256_sll_epi32(index, _mm_cvtsi32_si128(p.narrow_bytes - 1));
    const __m256i w = _mm256_i32gather_epi32(reinterpret_cast<const int*>(p.narrow), at, 1);
    const __m256i order = _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p.narrow_shuffle)));
    return _mm256_or_si256(_mm256_shuffle_epi8(w, order), _mm256_set1_epi32(int(p.narrow_fill)));
}

// The RGBA bytes (Image::rgba8's words) of the texels numbered `index` of an 8-bit unorm plane
// (rgba8 or narrow) for 8 lanes: one gather.
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i unorm8_words8(const Plane& p, __m256i index) {
    if (p.rgba8) return _mm256_i32gather_epi32(reinterpret_cast<const int*>(p.rgba8), index, 4);
    return narrow_words8(p, index);
}

// unorm8_words8 of a storage known from the block loop's shape (kBytes: 1 rgba8, 2 narrow).
template <int kBytes>
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i shaped_words8(const Plane& p, __m256i index) {
    if constexpr (kBytes == 2) return narrow_words8(p, index);
    else return _mm256_i32gather_epi32(reinterpret_cast<const int*>(p.rgba8), index, 4);
}

// wrap_pair / wrap_one of 8 lanes: REPEAT of a power of two and CLAMP_TO_EDGE here, the rest
// lane by lane.
__attribute__((target("avx2,f16c"))) inline void wrap8(GLenum mode, __m256i i, int32_t size, bool pot, bool pair,
                                                  int32_t a[8], int32_t b[8]) {
    const __m256i last = _mm256_set1_epi32(size - 1), one = _mm256_set1_epi32(1);
    if (mode == gl::REPEAT && pot) {
        _mm256_store_si256(reinterpret_cast<__m256i*>(a), _mm256_and_si256(i, last));
        if (pair) _mm256_store_si256(reinterpret_cast<__m256i*>(b), _mm256_and_si256(_mm256_add_epi32(i, one), last));
    } else if (mode == gl::CLAMP_TO_EDGE) {
        const __m256i zero = _mm256_setzero_si256();
        _mm256_store_si256(reinterpret_cast<__m256i*>(a), _mm256_max_epi32(_mm256_min_epi32(i, last), zero));
        if (pair)
            _mm256_store_si256(reinterpret_cast<__m256i*>(b),
                               _mm256_max_epi32(_mm256_min_epi32(_mm256_add_epi32(i, one), last), zero));
    } else {
        alignas(32) int32_t raw[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(raw), i);
        for (int l = 0; l < 8; ++l) {
            if (pair) wrap_pair(mode, raw[l], size, pot, a[l], b[l]);
            else a[l] = wrap_one(mode, raw[l], size, pot);
        }
    }
}

static_assert(sizeof(glsl::Scalar) == sizeof(float), "8 lanes of coordinates load as 8 floats");

// weight8 of 8 lanes: round to nearest even, then max(w, 0) (NaN -> 0) and min(w, 256).
__attribute__((target("avx2,f16c"))) inline __m256 weight8x8(__m256 frac) {
    const __m256 w = _mm256_round_ps(_mm256_mul_ps(frac, _mm256_set1_ps(256.0f)), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    return _mm256_min_ps(_mm256_max_ps(w, _mm256_setzero_ps()), _mm256_set1_ps(256.0f));
}

// w00 t00 + w10 t10 + w01 t01 + w11 t11 of 8 lanes, in Fast2D::filter's order.
__attribute__((target("avx2,f16c"))) inline __m256 weighted_sum8(__m256 w00, __m256 w10, __m256 w01, __m256 w11, __m256 t00,
                                                            __m256 t10, __m256 t01, __m256 t11) {
    __m256 sum = _mm256_mul_ps(w00, t00);
    sum = _mm256_add_ps(sum, _mm256_mul_ps(w10, t10));
    sum = _mm256_add_ps(sum, _mm256_mul_ps(w01, t01));
    return _mm256_add_ps(sum, _mm256_mul_ps(w11, t11));
}

// ---- Depth texels of 8 lanes: Fast2D::texel's first channel (the depth, or the comparison's
// 1 / 0), the same bits. Fixed-point words convert to double exactly, w / (2^n - 1) is correctly
// rounded in double and rounded to float, as depth_value does; the comparisons are
// compare_passes' (ordered, NOTEQUAL unordered: NaN fails all but NOTEQUAL).

// Unsigned 32-bit words as doubles, exactly: the bits of 2^52 + w, less 2^52.
__attribute__((target("avx2,f16c"))) inline __m256d words_as_double4(__m128i w) {
    const __m256i bits = _mm256_or_si256(_mm256_cvtepu32_epi64(w), _mm256_set1_epi64x(0x4330000000000000LL));
    return _mm256_sub_pd(_mm256_castsi256_pd(bits), _mm256_set1_pd(4503599627370496.0));
}

// depth_value of 8 words, by the double reciprocal of 2^n - 1 rather than the division: the
// same float. The product is within 2^-52 (relative) of the quotient w / (2^n - 1), and the
// quotient is never within 2^-49 of a float rounding midpoint (their difference is an integer
// over (2^n - 1) 2^k, and it is never 0: 2^n - 1 is odd, so w / (2^n - 1) is dyadic only when
// it is an integer), so both round to the same float (all 2^16 and 2^24 words:
// tests/textures/test_depth_values.py).
__attribute__((target("avx2,f16c"))) inline __m256 depth_values8(Encoding e, __m256i words) {
    if (e == Encoding::Depth32F) return _mm256_castsi256_ps(words);
    const __m256d reciprocal = _mm256_set1_pd(e == Encoding::Depth16 ? 1.0 / 65535.0 : 1.0 / 16777215.0);
    const __m128 lo = _mm256_cvtpd_ps(_mm256_mul_pd(words_as_double4(_mm256_castsi256_si128(words)), reciprocal));
    const __m128 hi = _mm256_cvtpd_ps(_mm256_mul_pd(words_as_double4(_mm256_extracti128_si256(words, 1)), reciprocal));
    return _mm256_set_m128(hi, lo);
}

// compare_passes(func, ref, d) of 8 lanes as 1.0f / 0.0f.
__attribute__((target("avx2,f16c"))) inline __m256 compare8(GLenum func, __m256 ref, __m256 d) {
    __m256 pass;
    switch (func) {
        case gl::LEQUAL: pass = _mm256_cmp_ps(ref, d, _CMP_LE_OQ); break;
        case gl::GEQUAL: pass = _mm256_cmp_ps(ref, d, _CMP_GE_OQ); break;
        case gl::LESS: pass = _mm256_cmp_ps(ref, d, _CMP_LT_OQ); break;
        case gl::GREATER: pass = _mm256_cmp_ps(ref, d, _CMP_GT_OQ); break;
        case gl::EQUAL: pass = _mm256_cmp_ps(ref, d, _CMP_EQ_OQ); break;
        case gl::NOTEQUAL: pass = _mm256_cmp_ps(ref, d, _CMP_NEQ_UQ); break;
        case gl::ALWAYS: return _mm256_set1_ps(1.0f);
        default: return _mm256_setzero_ps();   // NEVER
    }
    return _mm256_and_ps(pass, _mm256_set1_ps(1.0f));
}

// The texels (i, j) of 8 lanes of a depth plane (each lane in its layer, layer_at) as
// Fast2D::texel's first channel for the lanes' references.
struct DepthTexels8 {
    const Fast2D& f;
    const Plane& p;
    const size_t* layer_at;
    bool indexable;   // every texel index of the plane fits an int32: one gather
    __m256i base;     // layer_at as int32 (indexable)
    __m256 ref;       // the references, clamped to [0, 1] for fixed-point formats (ES 3.0 §3.8.16)

    // layer_at null: every lane in layer 0.
    __attribute__((target("avx2,f16c"))) DepthTexels8(const Fast2D& f_, const Plane& p_, const size_t layer_at_[8], const float* refs)
        : f(f_), p(p_), layer_at(layer_at_) {
        indexable = uint64_t(p.width) * uint64_t(p.height) * uint64_t(p.layers) <= uint64_t(INT32_MAX);
        base = _mm256_setzero_si256();
        if (layer_at && indexable) {
            alignas(32) int32_t b[8];
            for (int l = 0; l < 8; ++l) b[l] = int32_t(layer_at[l]);
            base = _mm256_load_si256(reinterpret_cast<const __m256i*>(b));
        }
        ref = refs ? _mm256_loadu_ps(refs) : _mm256_setzero_ps();
        if (f.compare && p.depth_encoding != Encoding::Depth32F) {
            // std::clamp(ref, 0, 1) = ref < 0 ? 0 : 1 < ref ? 1 : ref (NaN and -0 stay).
            const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
            ref = _mm256_blendv_ps(_mm256_blendv_ps(ref, one, _mm256_cmp_ps(one, ref, _CMP_LT_OQ)), zero,
                                   _mm256_cmp_ps(ref, zero, _CMP_LT_OQ));
        }
    }
    __attribute__((target("avx2,f16c"))) __m256 operator()(const int32_t i[8], const int32_t j[8]) const {
        __m256i words;
        if (indexable) {
            const __m256i at = _mm256_add_epi32(
                _mm256_add_epi32(base, _mm256_mullo_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(j)),
                                                          _mm256_set1_epi32(p.width))),
                _mm256_load_si256(reinterpret_cast<const __m256i*>(i)));
            words = _mm256_i32gather_epi32(reinterpret_cast<const int*>(p.depth), at, 4);
        } else {
            alignas(32) uint32_t w[8];
            for (int l = 0; l < 8; ++l) w[l] = p.depth[(layer_at ? layer_at[l] : 0) + size_t(j[l]) * size_t(p.width) + size_t(i[l])];
            words = _mm256_load_si256(reinterpret_cast<const __m256i*>(w));
        }
        const __m256 d = depth_values8(p.depth_encoding, words);
        return f.compare ? compare8(f.compare_func, ref, d) : d;
    }
    // operator() of indexable planes with the texels' rows (j * width) and columns as vectors.
    __attribute__((target("avx2,f16c"))) __m256 at(__m256i row, __m256i i) const {
        const __m256i words = _mm256_i32gather_epi32(reinterpret_cast<const int*>(p.depth), _mm256_add_epi32(_mm256_add_epi32(base, row), i), 4);
        const __m256 d = depth_values8(p.depth_encoding, words);
        return f.compare ? compare8(f.compare_func, ref, d) : d;
    }
};

// The 8 bytes at h (4 halves) as one integer.
inline long long load_u64(const uint16_t* h) {
    long long v;
    std::memcpy(&v, h, 8);
    return v;
}

// 4 halves at h as floats (F16C: exact, as half_at).
__attribute__((target("avx2,f16c"), always_inline)) inline __m128 halves4(const uint16_t* h) {
    return _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(h)));
}
// 8 halves at h (two texels of 4 channels) as floats.
__attribute__((target("avx2,f16c"), always_inline)) inline __m256 halves8(const uint16_t* h) {
    return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h)));
}

// The texel whose first channel is element e of plane p's colour storage as RGBA: a 4-float (or
// 4-half) load (Image::kColorPad, kHalfPad keep it inside the storage), the channels the plane
// lacks replaced by their values (SampledLevel::color_fill), as Fast2D::texel reads it.
__attribute__((target("avx2,f16c"), always_inline)) inline __m128 color_texel4(const Plane& p, size_t e) {
    const __m128 x = p.half ? halves4(p.half + e) : _mm_loadu_ps(p.color + e);
    if (p.color_channels == 4) return x;
    const __m128 absent = _mm_castsi128_ps(_mm_cmpgt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(p.color_channels - 1)));
    return _mm_blendv_ps(x, _mm_loadu_ps(p.color_fill), absent);
}

// Fast2D::filter of one plane for 8 lanes (r: the layers of a 2D array, else null).
// Depth planes (ref: the lanes' references, or null) read their texels through DepthTexels8.
__attribute__((target("avx2,f16c"))) void filter8(const Fast2D& f, const Plane& p, bool linear, const float* s,
                                             const float* t, const float* r, float out[8][4], const float* ref = nullptr) {
    size_t layer_at[8] = {};   // the first texel of each lane's layer
    if (r)
        for (int l = 0; l < 8; ++l)
            layer_at[l] = size_t(std::clamp(ifloor(r[l] + 0.5f), 0, p.layers - 1)) * size_t(p.height) * size_t(p.width);
    size_t layer[8] = {};   // colour planes: the element where each lane's layer starts
    if (p.color || p.half)
        for (int l = 0; l < 8; ++l) layer[l] = layer_at[l] * p.color_channels;
    const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(s), _mm256_set1_ps(float(p.width))), _mm256_set1_ps(float(f.off_s)));
    const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(t), _mm256_set1_ps(float(p.height))), _mm256_set1_ps(float(f.off_t)));
    alignas(32) int32_t i0[8], i1[8], j0[8], j1[8];
    if (!linear) {
        wrap8(f.wrap_s, ifloor_floored8(_mm256_floor_ps(u)), p.width, p.width_pot, false, i0, i1);
        wrap8(f.wrap_t, ifloor_floored8(_mm256_floor_ps(v)), p.height, p.height_pot, false, j0, j1);
        if (p.depth) {
            alignas(32) float d[8];
            _mm256_store_ps(d, DepthTexels8(f, p, layer_at, ref)(i0, j0));
            const bool grey = f.compare || f.luminance;   // Fast2D::texel: (d, d or 0, d or 0, 1)
            for (int l = 0; l < 8; ++l) out[l][0] = d[l], out[l][1] = out[l][2] = grey ? d[l] : 0.0f, out[l][3] = 1.0f;
            return;
        }
        if (p.rgba8 || p.narrow) {   // 8-bit unorm storage (Fast2D::texel)
            for (int l = 0; l < 8; ++l)
                f.texel(p, layer_at[l] + size_t(j0[l]) * size_t(p.width) + size_t(i0[l]), 0.0f, out[l]);
            return;
        }
        for (int l = 0; l < 8; ++l)
            _mm_storeu_ps(out[l], color_texel4(p, layer[l] + (size_t(j0[l]) * size_t(p.width) + size_t(i0[l])) * p.color_channels));
        return;
    }
    const __m256 half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.0f);
    const __m256 u0 = _mm256_sub_ps(u, half), v0 = _mm256_sub_ps(v, half);
    const __m256 fu = _mm256_floor_ps(u0), fv = _mm256_floor_ps(v0);
    wrap8(f.wrap_s, ifloor_floored8(fu), p.width, p.width_pot, true, i0, i1);
    wrap8(f.wrap_t, ifloor_floored8(fv), p.height, p.height_pot, true, j0, j1);
    const __m256 a = _mm256_sub_ps(u0, fu), b = _mm256_sub_ps(v0, fv);
    if (p.unorm8) {
        // The fixed-point rule (Level::filter): 8-bit weights, texels as bytes k, exact sums.
        const __m256 k256 = _mm256_set1_ps(256.0f), A = weight8x8(a), B = weight8x8(b);
        const __m256 nA = _mm256_sub_ps(k256, A), nB = _mm256_sub_ps(k256, B);
        const __m256 w[4] = {_mm256_mul_ps(nA, nB), _mm256_mul_ps(A, nB), _mm256_mul_ps(nA, B), _mm256_mul_ps(A, B)};
        __m256 sum[4];   // channel c of the 8 lanes' integer sums
        if ((p.rgba8 || p.narrow) && !r) {
            // The bytes of each of the 4 texels of 8 lanes by one gather (2D: no layers).
            const __m256i width = _mm256_set1_epi32(p.width);
            const __m256i row0 = _mm256_mullo_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(j0)), width);
            const __m256i row1 = _mm256_mullo_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(j1)), width);
            const __m256i c0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(i0));
            const __m256i c1 = _mm256_load_si256(reinterpret_cast<const __m256i*>(i1));
            const __m256i at[4] = {_mm256_add_epi32(row0, c0), _mm256_add_epi32(row0, c1), _mm256_add_epi32(row1, c0),
                                   _mm256_add_epi32(row1, c1)};
            const __m256i byte = _mm256_set1_epi32(255);
            for (int n = 0; n < 4; ++n) {
                const __m256i t = unorm8_words8(p, at[n]);
                for (int c = 0; c < 4; ++c) {
                    const __m256 k = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(t, 8 * c), byte));
                    sum[c] = n ? _mm256_add_ps(sum[c], _mm256_mul_ps(w[n], k)) : _mm256_mul_ps(w[n], k);
                }
            }
        } else {
            // Layers (2D arrays): the bytes k per lane, sums lane by lane (exact integers).
            alignas(32) float wl[4][8], lanes[4][8];
            for (int n = 0; n < 4; ++n) _mm256_store_ps(wl[n], w[n]);
            for (int l = 0; l < 8; ++l) {
                const size_t row0 = layer_at[l] + size_t(j0[l]) * size_t(p.width), row1 = layer_at[l] + size_t(j1[l]) * size_t(p.width);
                const size_t at[4] = {row0 + size_t(i0[l]), row0 + size_t(i1[l]), row1 + size_t(i0[l]), row1 + size_t(i1[l])};
                __m128 lane = _mm_setzero_ps();
                for (int n = 0; n < 4; ++n) {
                    const __m128i k = _mm_cvtepu8_epi32(_mm_cvtsi32_si128(int(unorm8_texel(p, at[n]))));
                    lane = _mm_add_ps(lane, _mm_mul_ps(_mm_set1_ps(wl[n][l]), _mm_cvtepi32_ps(k)));
                }
                alignas(16) float v[4];
                _mm_store_ps(v, lane);
                for (int c = 0; c < 4; ++c) lanes[c][l] = v[c];
            }
            for (int c = 0; c < 4; ++c) sum[c] = _mm256_load_ps(lanes[c]);
        }
        // One correctly rounded division per channel, then the 8 lanes back to out[l][c].
        const __m256 divisor = _mm256_set1_ps(kUnorm8Divisor);
        for (int c = 0; c < 4; ++c) sum[c] = _mm256_div_ps(sum[c], divisor);
        for (int h = 0; h < 2; ++h) {
            __m128 r0 = h ? _mm256_extractf128_ps(sum[0], 1) : _mm256_castps256_ps128(sum[0]);
            __m128 r1 = h ? _mm256_extractf128_ps(sum[1], 1) : _mm256_castps256_ps128(sum[1]);
            __m128 r2 = h ? _mm256_extractf128_ps(sum[2], 1) : _mm256_castps256_ps128(sum[2]);
            __m128 r3 = h ? _mm256_extractf128_ps(sum[3], 1) : _mm256_castps256_ps128(sum[3]);
            _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
            _mm_storeu_ps(out[4 * h + 0], r0);
            _mm_storeu_ps(out[4 * h + 1], r1);
            _mm_storeu_ps(out[4 * h + 2], r2);
            _mm_storeu_ps(out[4 * h + 3], r3);
        }
        return;
    }
    const __m256 na = _mm256_sub_ps(one, a), nb = _mm256_sub_ps(one, b);
    alignas(32) float w00[8], w10[8], w01[8], w11[8];
    _mm256_store_ps(w00, _mm256_mul_ps(na, nb));
    _mm256_store_ps(w10, _mm256_mul_ps(a, nb));
    _mm256_store_ps(w01, _mm256_mul_ps(na, b));
    _mm256_store_ps(w11, _mm256_mul_ps(a, b));
    if (p.depth) {
        // The four texels' first channel of 8 lanes (DepthTexels8), then the weighted sums of all
        // 8 lanes at once: per lane the same products and sums, in the same order, as
        // Fast2D::filter, so the same bits.
        const DepthTexels8 texels(f, p, layer_at, ref);
        const __m256 t00 = texels(i0, j0), t10 = texels(i1, j0), t01 = texels(i0, j1), t11 = texels(i1, j1);
        const __m256 a00 = _mm256_load_ps(w00), a10 = _mm256_load_ps(w10), a01 = _mm256_load_ps(w01), a11 = _mm256_load_ps(w11);
        const auto weighted = [&](__m256 t00, __m256 t10, __m256 t01, __m256 t11) __attribute__((target("avx2,f16c"))) {
            return weighted_sum8(a00, a10, a01, a11, t00, t10, t01, t11);
        };
        alignas(32) float c0[8], c1[8], c3[8];
        _mm256_store_ps(c0, weighted(t00, t10, t01, t11));
        const bool grey = f.compare || f.luminance;   // channels 1 and 2 repeat the depth, else 0
        const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
        if (grey) std::memcpy(c1, c0, sizeof c1);
        else _mm256_store_ps(c1, weighted(zero, zero, zero, zero));
        _mm256_store_ps(c3, weighted(one, one, one, one));
        for (int l = 0; l < 8; ++l) out[l][0] = c0[l], out[l][1] = out[l][2] = c1[l], out[l][3] = c3[l];
        return;
    }
    for (int l = 0; l < 8; ++l) {
        const size_t nc = p.color_channels;
        const size_t row0 = layer[l] + size_t(j0[l]) * size_t(p.width) * nc;
        const size_t row1 = layer[l] + size_t(j1[l]) * size_t(p.width) * nc;
        __m128 sum = _mm_mul_ps(_mm_set1_ps(w00[l]), color_texel4(p, row0 + size_t(i0[l]) * nc));
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(w10[l]), color_texel4(p, row0 + size_t(i1[l]) * nc)));
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(w01[l]), color_texel4(p, row1 + size_t(i0[l]) * nc)));
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(w11[l]), color_texel4(p, row1 + size_t(i1[l]) * nc)));
        _mm_storeu_ps(out[l], sum);
    }
}

// result[k][c] of 8 lanes into out[c][l + k] (two 4x4 transposes).
inline void store_lanes8(const float result[8][4], glsl::Scalar* const out[4], int l) {
    for (int half = 0; half < 2; ++half) {
        const float* row = result[4 * half];
        __m128 r0 = _mm_loadu_ps(row), r1 = _mm_loadu_ps(row + 4), r2 = _mm_loadu_ps(row + 8), r3 = _mm_loadu_ps(row + 12);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        if (out[0]) _mm_storeu_ps(&out[0][l + 4 * half].f, r0);
        if (out[1]) _mm_storeu_ps(&out[1][l + 4 * half].f, r1);
        if (out[2]) _mm_storeu_ps(&out[2][l + 4 * half].f, r2);
        if (out[3]) _mm_storeu_ps(&out[3][l + 4 * half].f, r3);
    }
}

__attribute__((target("avx2,f16c"))) inline __m256 load8(const glsl::Scalar* p, int l) {
    return p ? _mm256_loadu_ps(&p[l].f) : _mm256_setzero_ps();
}

// (double) v² of lanes 4 * half .. 4 * half + 3.
__attribute__((target("avx2,f16c"))) inline __m256d square_wide(__m256 v, int half) {
    const __m256d d = _mm256_cvtps_pd(half ? _mm256_extractf128_ps(v, 1) : _mm256_castps256_ps128(v));
    return _mm256_mul_pd(d, d);
}

// Half of log2(x) of 4 positive normal doubles (x = rho²: log2 rho without the square root),
// within 2^-49 |log2 x| / 2: x = 2^e m with m in [sqrt(1/2), sqrt(2)), and
// log2 m = (2 / ln 2) atanh(z), z = (m - 1) / (m + 1), |z| < 0.172, as z * sum z^2k / (2k + 1)
// to k = 8 (the next term is below 2^-49.9 of the sum), the sum by Estrin's scheme (short
// dependency chains: the terms' order does not matter to lambda_exact4's rounding test).
// 1 / (2k + 1) + y / (2k + 3): two terms of the series.
__attribute__((target("avx2,f16c"))) inline __m256d series_pair4(__m256d y, int k) {
    return _mm256_add_pd(_mm256_set1_pd(1.0 / double(2 * k + 1)), _mm256_mul_pd(y, _mm256_set1_pd(1.0 / double(2 * k + 3))));
}

__attribute__((target("avx2,f16c"))) inline __m256d half_log2_approx4(__m256d x) {
    const __m256i bits = _mm256_castpd_si256(x);
    // The exponent field as a double: 2^52 + field, less 2^52 + 1023.
    const __m256d field = _mm256_castsi256_pd(_mm256_or_si256(_mm256_srli_epi64(bits, 52), _mm256_set1_epi64x(0x4330000000000000LL)));
    __m256d e = _mm256_sub_pd(field, _mm256_set1_pd(4503599627371519.0));
    __m256d m = _mm256_castsi256_pd(_mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi64x(0x000FFFFFFFFFFFFFLL)),
                                                    _mm256_set1_epi64x(0x3FF0000000000000LL)));
    const __m256d big = _mm256_cmp_pd(m, _mm256_set1_pd(1.4142135623730951), _CMP_GT_OQ);
    m = _mm256_blendv_pd(m, _mm256_mul_pd(m, _mm256_set1_pd(0.5)), big);
    e = _mm256_add_pd(e, _mm256_and_pd(big, _mm256_set1_pd(1.0)));
    const __m256d one = _mm256_set1_pd(1.0);
    const __m256d z = _mm256_div_pd(_mm256_sub_pd(m, one), _mm256_add_pd(m, one));
    const __m256d y = _mm256_mul_pd(z, z), y2 = _mm256_mul_pd(y, y), y4 = _mm256_mul_pd(y2, y2);
    const __m256d p03 = _mm256_add_pd(series_pair4(y, 0), _mm256_mul_pd(y2, series_pair4(y, 2)));
    const __m256d p47 = _mm256_add_pd(series_pair4(y, 4), _mm256_mul_pd(y2, series_pair4(y, 6)));
    const __m256d p = _mm256_add_pd(_mm256_add_pd(p03, _mm256_mul_pd(y4, p47)),
                                    _mm256_mul_pd(_mm256_mul_pd(y4, y4), _mm256_set1_pd(1.0 / 17.0)));
    // (e + (2 / ln 2) z p) / 2
    return _mm256_mul_pd(_mm256_add_pd(e, _mm256_mul_pd(_mm256_mul_pd(z, p), _mm256_set1_pd(2.0 / 0.69314718055994530942))),
                         _mm256_set1_pd(0.5));
}

// LambdaMemo's float(log2(sqrt(rho2))) of 4 lanes, to the bit: bit k of the result is set when
// lane k is sure. A lane is sure when rho2 is normal and finite and float() rounds the whole
// interval L ± (2^-45 |L| + 2^-50) around the approximation L to one float: the true
// log2(sqrt(rho2)) with sqrt rounded to double (within 2^-52.4 of log2(rho2) / 2), within
// 2^-49 |L| + 2^-52.4 of L, and libm's (within an ulp of it) both lie inside it, so rounding
// either gives that float. The rest (about one lane in 2^20) are left to LambdaMemo.
__attribute__((target("avx2,f16c"))) inline int lambda_exact4(__m256d rho2, __m128& lambda) {
    const __m256d L = half_log2_approx4(rho2);
    const __m256d margin = _mm256_add_pd(_mm256_mul_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), L), _mm256_set1_pd(0x1p-45)),
                                         _mm256_set1_pd(0x1p-50));
    lambda = _mm256_cvtpd_ps(L);
    const __m128 lo = _mm256_cvtpd_ps(_mm256_sub_pd(L, margin)), hi = _mm256_cvtpd_ps(_mm256_add_pd(L, margin));
    // (Subnormal rho2, which float squares never give, to LambdaMemo too: the split assumes normal.)
    const __m256d finite = _mm256_and_pd(_mm256_cmp_pd(rho2, _mm256_set1_pd(0x1p-1022), _CMP_GE_OQ),
                                         _mm256_cmp_pd(rho2, _mm256_set1_pd(INFINITY), _CMP_LT_OQ));
    const int same = _mm_movemask_ps(_mm_and_ps(_mm_cmpeq_ps(lo, lambda), _mm_cmpeq_ps(hi, lambda)));
    return same & _mm256_movemask_pd(finite);
}

// The lambdas of lanes l..l+7 from their rho² (max of the squared lengths along x and y, in
// double), as lambda_at: float(log2(sqrt(rho²))) plus the lanes' bias.
__attribute__((target("avx2,f16c"))) void lambdas_of_rho2_8(const glsl::TextureQuery& q, int l, const double rho2[8],
                                                       LambdaMemo& lambda_of, float out[8]) {
    // Each half of the block with one rho² in all its lanes (derivatives that differ in bits
    // that do not reach rho²): one LambdaMemo lookup per half.
    const __m256d lo2 = _mm256_load_pd(rho2), hi2 = _mm256_load_pd(rho2 + 4);
    if ((_mm256_movemask_pd(_mm256_cmp_pd(lo2, _mm256_set1_pd(rho2[0]), _CMP_EQ_OQ)) &
         _mm256_movemask_pd(_mm256_cmp_pd(hi2, _mm256_set1_pd(rho2[4]), _CMP_EQ_OQ))) == 0xF) {
        const float a = lambda_of(rho2[0]), b = rho2[4] == rho2[0] ? a : lambda_of(rho2[4]);
        __m256 lambda = _mm256_set_m128(_mm_set1_ps(b), _mm_set1_ps(a));
        if (q.lod_mode == TextureLod::Bias && q.lod) lambda = _mm256_add_ps(lambda, _mm256_loadu_ps(&q.lod[l].f));
        _mm256_storeu_ps(out, lambda);
        return;
    }
    // Otherwise lambda = float(log2(sqrt(rho²))) 4 lanes at a time (lambda_exact4); the lanes it
    // cannot vouch for (and 0, infinite or NaN rho²) from LambdaMemo, as the scalar path.
    for (int half = 0; half < 2; ++half) {
        const __m256d r2 = _mm256_load_pd(rho2 + 4 * half);
        __m128 lambda;
        int sure = lambda_exact4(r2, lambda);
        if (q.lod_mode == TextureLod::Bias && q.lod) lambda = _mm_add_ps(lambda, _mm_loadu_ps(&q.lod[l + 4 * half].f));
        _mm_storeu_ps(out + 4 * half, lambda);
        for (int k = 0; sure != 0xF && k < 4; ++k) {
            if (sure & (1 << k)) continue;
            out[4 * half + k] = lambda_of(rho2[4 * half + k]);
            if (q.lod_mode == TextureLod::Bias && q.lod) out[4 * half + k] += q.lod[l + 4 * half + k].f;
        }
    }
}

__attribute__((target("avx2,f16c"))) int lambdas_exact4_at(const double* rho2, LambdaMemo& lambda_of, float* out) {
    __m128 lambda;
    const int sure = lambda_exact4(_mm256_loadu_pd(rho2), lambda);
    _mm_storeu_ps(out, lambda);
    for (int k = 0; k < 4; ++k)
        if (!(sure >> k & 1)) out[k] = lambda_of(rho2[k]);
    return __builtin_popcount(unsigned(sure));
}

// lambda8 (below) of a block whose derivatives differ between lanes: out of line, the longer case.
__attribute__((target("avx2,f16c"), noinline)) void lambda8_lanes(const glsl::TextureQuery& q, int l, float w, float h,
                                                            LambdaMemo& lambda_of, __m256 dx0, __m256 dx1, __m256 dy0,
                                                            __m256 dy1, float out[8]) {
    const __m256 ws = _mm256_set1_ps(w), hs = _mm256_set1_ps(h), zero = _mm256_setzero_ps();
    const __m256 x0 = _mm256_mul_ps(dx0, ws), x1 = _mm256_mul_ps(dx1, hs);
    const __m256 y0 = _mm256_mul_ps(dy0, ws), y1 = _mm256_mul_ps(dy1, hs);
    const __m256 x2 = _mm256_mul_ps(load8(q.ddx[2], l), zero), y2 = _mm256_mul_ps(load8(q.ddy[2], l), zero);
    alignas(32) double rho2[8];
    for (int half = 0; half < 2; ++half) {
        __m256d lx2 = _mm256_add_pd(square_wide(x0, half), square_wide(x1, half));
        __m256d ly2 = _mm256_add_pd(square_wide(y0, half), square_wide(y1, half));
        if (q.ddx[2]) lx2 = _mm256_add_pd(lx2, square_wide(x2, half));
        if (q.ddy[2]) ly2 = _mm256_add_pd(ly2, square_wide(y2, half));
        _mm256_store_pd(rho2 + 4 * half, _mm256_max_pd(ly2, lx2));   // = std::max(lx2, ly2), NaN included
    }
    lambdas_of_rho2_8(q, l, rho2, lambda_of, out);
}

// The lambdas of lanes l..l+7 (Implicit, Bias, Gradient), as lambda_at in sample_2d computes them:
// rho² 8 at a time (float products, widened, squared and summed in double). Inline: a block whose
// lanes share their derivatives (affine coordinates) costs one LambdaMemo lookup and no call.
__attribute__((target("avx2,f16c"), always_inline)) inline void lambda8(const glsl::TextureQuery& q, int l, float w, float h,
                                                                  LambdaMemo& lambda_of, float out[8]) {
    const __m256 dx0 = load8(q.ddx[0], l), dx1 = load8(q.ddx[1], l), dy0 = load8(q.ddy[0], l), dy1 = load8(q.ddy[1], l);
    if (!q.ddx[2] && !q.ddy[2]) {
        // Under affine coordinates the 8 lanes' derivatives are equal: lane 0's rho², computed as
        // lambda_at does (equal floats, -0 = +0 included, give equal squares), one LambdaMemo lookup.
        const __m256i first = _mm256_setzero_si256();
        const __m256 same = _mm256_and_ps(
            _mm256_and_ps(_mm256_cmp_ps(dx0, _mm256_permutevar8x32_ps(dx0, first), _CMP_EQ_OQ),
                          _mm256_cmp_ps(dx1, _mm256_permutevar8x32_ps(dx1, first), _CMP_EQ_OQ)),
            _mm256_and_ps(_mm256_cmp_ps(dy0, _mm256_permutevar8x32_ps(dy0, first), _CMP_EQ_OQ),
                          _mm256_cmp_ps(dy1, _mm256_permutevar8x32_ps(dy1, first), _CMP_EQ_OQ)));
        if (_mm256_movemask_ps(same) == 0xFF) {
            const float x0 = _mm256_cvtss_f32(dx0) * w, x1 = _mm256_cvtss_f32(dx1) * h;
            const float y0 = _mm256_cvtss_f32(dy0) * w, y1 = _mm256_cvtss_f32(dy1) * h;
            const double lx2 = double(x0) * x0 + double(x1) * x1, ly2 = double(y0) * y0 + double(y1) * y1;
            __m256 lambda = _mm256_set1_ps(lambda_of(std::max(lx2, ly2)));
            if (q.lod_mode == TextureLod::Bias && q.lod) lambda = _mm256_add_ps(lambda, _mm256_loadu_ps(&q.lod[l].f));
            _mm256_storeu_ps(out, lambda);
            return;
        }
    }
    lambda8_lanes(q, l, w, h, lambda_of, dx0, dx1, dy0, dy1, out);
}


// lambda_at's explicit level of lanes l..l+7: the lanes' own (0 without one), no bias.
__attribute__((target("avx2,f16c"))) inline void explicit_lambdas8(const glsl::TextureQuery& q, int l, float out[8]) {
    _mm256_store_ps(out, q.lod ? _mm256_loadu_ps(&q.lod[l].f) : _mm256_setzero_ps());
}

// The lambdas of lanes l..l+7 of a 2D query, as lambda_at: explicit, or from the derivatives.
__attribute__((target("avx2,f16c"))) inline void query_lambdas8(const glsl::TextureQuery& q, int l, float w, float h,
                                                           LambdaMemo& lambda_of, float out[8]) {
    if (q.lod_mode == TextureLod::Explicit) explicit_lambdas8(q, l, out);
    else lambda8(q, l, w, h, lambda_of, out);
}

// The block's lambdas with its inactive lanes taking the first active lane's, so that they add
// no level to the block's choice (active != 0).
__attribute__((target("avx2,f16c"))) inline __m256 active_lambdas8(const float lambda[8], uint32_t active) {
    const __m256 v = _mm256_load_ps(lambda);
    if (active == 0xFFu) return v;
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256 off = _mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(active)), bit), _mm256_setzero_si256()));
    return _mm256_blendv_ps(v, _mm256_set1_ps(lambda[__builtin_ctz(active)]), off);
}

// The levels every lane of a block of 8 takes (Fast2D::choose), when they are the same for all:
// planes[first], blended with planes[second] by the lanes' own frac when second >= 0.
struct BlockChoice {
    int32_t first = 0, second = -1;
    bool linear = false;
    __m256 frac;
};

// Fast2D::choose of 8 lanes when they all magnify, all minify without mipmaps, or all blend the
// same two levels (*_MIPMAP_LINEAR) or take the last one: the common cases, as lambda varies
// little inside a block. False (bc unspecified) otherwise.
__attribute__((target("avx2,f16c"), always_inline)) inline bool choose_block8(const Fast2D& f, __m256 v, BlockChoice& bc) {
    const __m256 lo = _mm256_set1_ps(f.min_lod), hi = _mm256_set1_ps(f.max_lod);
    // std::clamp(v, lo, hi) = v < lo ? lo : hi < v ? hi : v (NaN stays NaN).
    v = _mm256_blendv_ps(_mm256_blendv_ps(v, hi, _mm256_cmp_ps(hi, v, _CMP_LT_OQ)), lo, _mm256_cmp_ps(v, lo, _CMP_LT_OQ));
    const int minified = _mm256_movemask_ps(_mm256_cmp_ps(v, _mm256_setzero_ps(), _CMP_GT_OQ));
    if (minified == 0) return bc.first = 0, bc.second = -1, bc.linear = f.mag_linear, true;
    if (minified != 0xFF) return false;
    bc.linear = f.min_linear;
    if (!f.mipmapped) return bc.first = 0, bc.second = -1, true;
    if (f.min_filter != gl::NEAREST_MIPMAP_LINEAR && f.min_filter != gl::LINEAR_MIPMAP_LINEAR) return false;
    const int32_t last = f.top - f.base;
    const int below_last = _mm256_movemask_ps(_mm256_cmp_ps(v, _mm256_set1_ps(float(last)), _CMP_LT_OQ));
    if (below_last == 0) return bc.first = last, bc.second = -1, true;
    const __m256 whole = _mm256_floor_ps(v);
    const __m256 same = _mm256_cmp_ps(whole, _mm256_permutevar8x32_ps(whole, _mm256_setzero_si256()), _CMP_EQ_OQ);
    if (below_last != 0xFF || _mm256_movemask_ps(same) != 0xFF) return false;
    bc.first = int32_t(_mm256_cvtss_f32(whole));
    bc.second = bc.first + 1;
    bc.frac = _mm256_sub_ps(v, whole);
    return true;
}

// choose_block8 as per-lane LevelChoices.
__attribute__((target("avx2,f16c"))) bool choose8(const Fast2D& f, const float lambda[8], LevelChoice ch[8]) {
    BlockChoice bc;
    if (!choose_block8(f, _mm256_loadu_ps(lambda), bc)) return false;
    alignas(32) float frac[8] = {};
    if (bc.second >= 0) _mm256_store_ps(frac, bc.frac);
    for (int k = 0; k < 8; ++k) ch[k] = {bc.first, bc.second, bc.linear, frac[k]};
    return true;
}

// Fast2D::filter(LevelChoice) of 8 lanes that share the levels (frac per lane).
__attribute__((target("avx2,f16c"))) void filter8(const Fast2D& f, const LevelChoice ch[8], const float* s, const float* t,
                                             const float* r, const float* ref, float out[8][4]) {
    filter8(f, f.planes[size_t(ch[0].first)], ch[0].linear, s, t, r, out, ref);
    if (ch[0].second < 0) return;
    float b[8][4];
    filter8(f, f.planes[size_t(ch[0].second)], ch[0].linear, s, t, r, b, ref);
    for (int l = 0; l < 8; ++l) {
        const __m128 x = _mm_mul_ps(_mm_set1_ps(1 - ch[l].frac), _mm_loadu_ps(out[l]));
        _mm_storeu_ps(out[l], _mm_add_ps(x, _mm_mul_ps(_mm_set1_ps(ch[l].frac), _mm_loadu_ps(b[l]))));
    }
}

// filter8(LevelChoice) of 8 lanes whose levels differ: each of the `count` distinct levels
// filtered for all 8 lanes, each lane's result taken from (or blended between) its own.
__attribute__((target("avx2,f16c"))) void filter8(const Fast2D& f, const LevelChoice ch[8], const int32_t levels[3], int count,
                                             const float* s, const float* t, const float* r, const float* ref, float out[8][4]) {
    float by_level[3][8][4];
    for (int i = 0; i < count; ++i) filter8(f, f.planes[size_t(levels[i])], ch[0].linear, s, t, r, by_level[i], ref);
    const auto at = [&](int32_t level) { return int(std::find(levels, levels + count, level) - levels); };
    for (int l = 0; l < 8; ++l) {
        const float* a = by_level[at(ch[l].first)][l];
        if (ch[l].second < 0) {
            _mm_storeu_ps(out[l], _mm_loadu_ps(a));
            continue;
        }
        const float* b = by_level[at(ch[l].second)][l];
        const __m128 x = _mm_mul_ps(_mm_set1_ps(1 - ch[l].frac), _mm_loadu_ps(a));
        _mm_storeu_ps(out[l], _mm_add_ps(x, _mm_mul_ps(_mm_set1_ps(ch[l].frac), _mm_loadu_ps(b))));
    }
}

// cube_face and cube_coords' s, t of 8 lanes (without derivatives): the same comparisons
// (ordered: a NaN fails them, as in cube_face), so the same face for ties on edges and corners
// and for NaN, and the same float operations in the same order, so the same s, t bits.
// With ddx, ddy (each component may be null: 0), also cube_coords' derivatives of s and t:
// ds[0], dt[0] along x, ds[1], dt[1] along y.
__attribute__((target("avx2,f16c"))) inline void cube_coords8(const float* x, const float* y, const float* z, int32_t face[8],
                                                         float s[8], float t[8], const float* const* ddx = nullptr,
                                                         const float* const* ddy = nullptr, float ds[2][8] = nullptr,
                                                         float dt[2][8] = nullptr) {
    const __m256 sign = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps();
    const __m256 rx = _mm256_loadu_ps(x), ry = _mm256_loadu_ps(y), rz = _mm256_loadu_ps(z);
    const __m256 ax = _mm256_andnot_ps(sign, rx), ay = _mm256_andnot_ps(sign, ry), az = _mm256_andnot_ps(sign, rz);
    const __m256 is_x = _mm256_and_ps(_mm256_cmp_ps(ax, ay, _CMP_GE_OQ), _mm256_cmp_ps(ax, az, _CMP_GE_OQ));
    const __m256 is_y = _mm256_andnot_ps(is_x, _mm256_cmp_ps(ay, az, _CMP_GE_OQ));
    // The negative face: not (r >= 0) on the major axis (a NaN rz gives face 5, as cube_face).
    const __m256 neg = _mm256_blendv_ps(_mm256_blendv_ps(_mm256_cmp_ps(rz, zero, _CMP_NGE_UQ), _mm256_cmp_ps(ry, zero, _CMP_NGE_UQ), is_y),
                                        _mm256_cmp_ps(rx, zero, _CMP_NGE_UQ), is_x);
    const __m256 ma = _mm256_blendv_ps(_mm256_blendv_ps(az, ay, is_y), ax, is_x);
    // Table 3.21: sc = -rz, rz, rx, rx, rx, -rx and tc = -ry, -ry, rz, -rz, -ry, -ry for faces 0..5.
    const __m256 nx = _mm256_xor_ps(rx, sign), ny = _mm256_xor_ps(ry, sign), nz = _mm256_xor_ps(rz, sign);
    const __m256 sc = _mm256_blendv_ps(_mm256_blendv_ps(_mm256_blendv_ps(rx, nx, neg), rx, is_y), _mm256_blendv_ps(nz, rz, neg), is_x);
    const __m256 tc = _mm256_blendv_ps(ny, _mm256_blendv_ps(rz, nz, neg), is_y);
    // face = 2 axis + negative, with the masks as -1: 2 axis = 4 + 4 is_x + 2 is_y.
    const __m256i two_axis = _mm256_add_epi32(_mm256_set1_epi32(4),
        _mm256_add_epi32(_mm256_slli_epi32(_mm256_castps_si256(is_x), 2), _mm256_slli_epi32(_mm256_castps_si256(is_y), 1)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(face), _mm256_sub_epi32(two_axis, _mm256_castps_si256(neg)));
    // cube_coords: inv = ma > 0 ? 1 / ma : 0, then s = 0.5 (sc inv + 1), t = 0.5 (tc inv + 1).
    const __m256 inv = _mm256_and_ps(_mm256_cmp_ps(ma, zero, _CMP_GT_OQ), _mm256_div_ps(_mm256_set1_ps(1.0f), ma));
    const __m256 half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.0f);
    _mm256_storeu_ps(s, _mm256_mul_ps(half, _mm256_add_ps(_mm256_mul_ps(sc, inv), one)));
    _mm256_storeu_ps(t, _mm256_mul_ps(half, _mm256_add_ps(_mm256_mul_ps(tc, inv), one)));
    if (!ddx) return;
    // The quotient rule as cube_coords: dsc, dtc by the same table, dma = sign * d[major], then
    // 0.5 (dsc ma - sc dma) inv inv (and the same for t).
    const __m256 major_sign = _mm256_blendv_ps(one, _mm256_set1_ps(-1.0f), neg);
    for (int n = 0; n < 2; ++n) {
        const float* const* d = n ? ddy : ddx;
        const __m256 d0 = d[0] ? _mm256_loadu_ps(d[0]) : zero, d1 = d[1] ? _mm256_loadu_ps(d[1]) : zero;
        const __m256 d2 = d[2] ? _mm256_loadu_ps(d[2]) : zero;
        const __m256 n0 = _mm256_xor_ps(d0, sign), n1 = _mm256_xor_ps(d1, sign), n2 = _mm256_xor_ps(d2, sign);
        const __m256 dsc = _mm256_blendv_ps(_mm256_blendv_ps(_mm256_blendv_ps(d0, n0, neg), d0, is_y), _mm256_blendv_ps(n2, d2, neg), is_x);
        const __m256 dtc = _mm256_blendv_ps(n1, _mm256_blendv_ps(d2, n2, neg), is_y);
        const __m256 dma = _mm256_mul_ps(major_sign, _mm256_blendv_ps(_mm256_blendv_ps(d2, d1, is_y), d0, is_x));
        _mm256_storeu_ps(ds[n], _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(half, _mm256_sub_ps(_mm256_mul_ps(dsc, ma), _mm256_mul_ps(sc, dma))), inv), inv));
        _mm256_storeu_ps(dt[n], _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(half, _mm256_sub_ps(_mm256_mul_ps(dtc, ma), _mm256_mul_ps(tc, dma))), inv), inv));
    }
}

// Fast2D::inside of one plane for 8 lanes: bit k set when lane k's texels lie inside the face.
__attribute__((target("avx2,f16c"))) inline uint32_t inside8(const Plane& p, bool linear, const float* s, const float* t) {
    __m256 u = _mm256_mul_ps(_mm256_loadu_ps(s), _mm256_set1_ps(float(p.width)));
    __m256 v = _mm256_mul_ps(_mm256_loadu_ps(t), _mm256_set1_ps(float(p.height)));
    int32_t w = p.width, h = p.height;
    if (linear) {
        const __m256 half = _mm256_set1_ps(0.5f);
        u = _mm256_sub_ps(u, half), v = _mm256_sub_ps(v, half);
        --w, --h;
    }
    const __m256i i = ifloor_floored8(_mm256_floor_ps(u)), j = ifloor_floored8(_mm256_floor_ps(v));
    const __m256i minus_one = _mm256_set1_epi32(-1);
    const __m256i ok = _mm256_and_si256(
        _mm256_and_si256(_mm256_cmpgt_epi32(i, minus_one), _mm256_cmpgt_epi32(_mm256_set1_epi32(w), i)),
        _mm256_and_si256(_mm256_cmpgt_epi32(j, minus_one), _mm256_cmpgt_epi32(_mm256_set1_epi32(h), j)));
    return uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(ok)));
}

// ---- Colour lookups in blocks of 8 (AVX2), channel-major: out[c] holds channel c of the
// block's 8 lanes (vector lane k: query lane l + k), the layout of the executor's registers, so
// results go straight there (no per-lane results, no transposes). Per lane the same operations
// in the same order as Fast2D::filter (no FMA), so the same bits.


// What filter8_color reads of one plane, broadcast once per plane and query.
struct Plane8 {
    const Plane* p;
    __m256 width_f, height_f, off_s, off_t;
    __m256i width, last_i, last_j, last_layer, layer_texels;
    bool fits;   // int32_indices
};

__attribute__((target("avx2,f16c"))) inline Plane8 plane8(const Fast2D& f, const Plane& p) {
    const bool fits = int32_indices(p);
    return {&p,
            _mm256_set1_ps(float(p.width)), _mm256_set1_ps(float(p.height)),
            _mm256_set1_ps(float(f.off_s)), _mm256_set1_ps(float(f.off_t)),
            _mm256_set1_epi32(p.width), _mm256_set1_epi32(p.width - 1), _mm256_set1_epi32(p.height - 1),
            _mm256_set1_epi32(p.layers - 1), _mm256_set1_epi32(fits ? p.width * p.height : 0), fits};
}

// wrap_pair / wrap_one of 8 lanes as vectors (last = size - 1): REPEAT of a power of two and
// CLAMP_TO_EDGE here, the rest lane by lane.
__attribute__((target("avx2,f16c"), always_inline)) inline void wrap8v(GLenum mode, __m256i i, __m256i last, int32_t size,
                                                                  bool pot, bool pair, __m256i& a, __m256i& b) {
    const __m256i one = _mm256_set1_epi32(1);
    if (mode == gl::REPEAT && pot) {
        a = _mm256_and_si256(i, last);
        if (pair) b = _mm256_and_si256(_mm256_add_epi32(i, one), last);
    } else if (mode == gl::CLAMP_TO_EDGE) {
        const __m256i zero = _mm256_setzero_si256();
        a = _mm256_max_epi32(_mm256_min_epi32(i, last), zero);
        if (pair) b = _mm256_max_epi32(_mm256_min_epi32(_mm256_add_epi32(i, one), last), zero);
    } else {
        alignas(32) int32_t raw[8], wa[8], wb[8] = {};
        _mm256_store_si256(reinterpret_cast<__m256i*>(raw), i);
        for (int k = 0; k < 8; ++k) {
            if (pair) wrap_pair(mode, raw[k], size, pot, wa[k], wb[k]);
            else wa[k] = wrap_one(mode, raw[k], size, pot);
        }
        a = _mm256_load_si256(reinterpret_cast<const __m256i*>(wa));
        b = _mm256_load_si256(reinterpret_cast<const __m256i*>(wb));
    }
}

// The first texel of each lane's layer (Fast2D::filter: clamp(ifloor(r + 1/2), 0, layers - 1)).
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i layer_start8(const Plane8& P, const float* r) {
    if (!r || P.p->layers == 1) return _mm256_setzero_si256();
    const __m256 fl = _mm256_floor_ps(_mm256_add_ps(_mm256_loadu_ps(r), _mm256_set1_ps(0.5f)));
    const __m256i layer = _mm256_max_epi32(_mm256_min_epi32(ifloor_floored8(fl), P.last_layer), _mm256_setzero_si256());
    return _mm256_mullo_epi32(layer, P.layer_texels);
}

// The channels of 8 packed texels: k (bytes) or k / 255, unorm(k, 8) as the float storage holds
// it (a correctly rounded division: the same float).
__attribute__((target("avx2,f16c"), always_inline)) inline void unpack8(__m256i t, __m256 out[4], bool bytes) {
    const __m256i byte = _mm256_set1_epi32(255);
    const __m256 k255 = _mm256_set1_ps(255.0f);
    for (int c = 0; c < 4; ++c) {
        const __m256i k = c == 3 ? _mm256_srli_epi32(t, 24) : _mm256_and_si256(c ? _mm256_srli_epi32(t, 8 * c) : t, byte);
        const __m256 kf = _mm256_cvtepi32_ps(k);
        out[c] = bytes ? kf : _mm256_div_ps(kf, k255);
    }
}

// The halves of 8 texels whose first channels are the elements e (texel number times channels)
// of a 16-bit float plane as channel vectors: two gathers of 4 texels' 8 bytes (lanes 0, 2, 4, 6
// and 1, 3, 5, 7), a transpose in 16 bits that leaves each channel's 8 halves in lane order, one
// exact conversion per channel. Channels the plane lacks hold the next texel's (or the pad).
__attribute__((target("avx2,f16c"), always_inline)) inline void half_texels8(const uint16_t* h, __m256i e, __m256 out[4]) {
    const __m256i split = _mm256_permutevar8x32_epi32(e, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    const long long* base = reinterpret_cast<const long long*>(h);
    const __m256i a = _mm256_i32gather_epi64(base, _mm256_castsi256_si128(split), 2);        // t0 t2 | t4 t6
    const __m256i b = _mm256_i32gather_epi64(base, _mm256_extracti128_si256(split, 1), 2);   // t1 t3 | t5 t7
    const __m256i x = _mm256_unpacklo_epi16(a, b), y = _mm256_unpackhi_epi16(a, b);         // t0 t1, t2 t3 | t4 t5, t6 t7
    // r0-3 g0-3 | r4-7 g4-7 and b0-3 a0-3 | b4-7 a4-7, then the 64-bit quarters in channel order.
    const __m256i rg = _mm256_permute4x64_epi64(_mm256_unpacklo_epi32(x, y), _MM_SHUFFLE(3, 1, 2, 0));
    const __m256i ba = _mm256_permute4x64_epi64(_mm256_unpackhi_epi32(x, y), _MM_SHUFFLE(3, 1, 2, 0));
    out[0] = _mm256_cvtph_ps(_mm256_castsi256_si128(rg));
    out[1] = _mm256_cvtph_ps(_mm256_extracti128_si256(rg, 1));
    out[2] = _mm256_cvtph_ps(_mm256_castsi256_si128(ba));
    out[3] = _mm256_cvtph_ps(_mm256_extracti128_si256(ba, 1));
}

// The float texels (4 per texel) numbered `index` of 8 lanes as channel vectors: 8 loads and a
// 4x4 transpose in each half (halves: half_texels8).
__attribute__((target("avx2,f16c"), always_inline)) inline void float_texels8(const Plane& p, __m256i index, __m256 out[4]) {
    alignas(32) int32_t at[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(at), index);
    // Register k: lane k's texel in the low half, lane k + 4's in the high half.
    __m256 r[4];
    const size_t nc = p.color_channels;
    if (p.half) {   // element numbers in int32: nc * index < 4 * 2^28 (kMaxTextureSize is 16384)
        half_texels8(p.half, _mm256_mullo_epi32(index, _mm256_set1_epi32(int(nc))), out);
        for (size_t c = nc; c < 4; ++c) out[c] = _mm256_set1_ps(p.color_fill[c]);
        return;
    }
    for (int k = 0; k < 4; ++k)
        r[k] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p.color + size_t(at[k]) * nc)),
                                    _mm_loadu_ps(p.color + size_t(at[k + 4]) * nc), 1);
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    out[0] = _mm256_shuffle_ps(t0, t2, 0x44);
    out[1] = _mm256_shuffle_ps(t0, t2, 0xEE);
    out[2] = _mm256_shuffle_ps(t1, t3, 0x44);
    out[3] = _mm256_shuffle_ps(t1, t3, 0xEE);
    // Channels the plane lacks (the loads read past the texel into the next one or the pad).
    for (size_t c = nc; c < 4; ++c) out[c] = _mm256_set1_ps(p.color_fill[c]);
}

// The texels numbered `index` of 8 lanes as channel vectors: from the bytes by one gather, or
// from the floats. bytes: as k = 255 v (exact for the unorm8 fixed-point rule), else as the floats v.
__attribute__((target("avx2,f16c"), always_inline)) inline void texels8(const Plane& p, __m256i index, bool bytes, __m256 out[4]) {
    if (p.rgba8 || p.narrow) {
        unpack8(unorm8_words8(p, index), out, bytes);
        return;
    }
    float_texels8(p, index, out);
    if (bytes)
        for (int c = 0; c < 4; ++c) out[c] = _mm256_mul_ps(out[c], _mm256_set1_ps(255.0f));
}

// Fast2D::filter lane by lane, as channel vectors (planes whose texel numbers exceed int32).
__attribute__((target("avx2,f16c"), noinline)) void filter8_lanes(const Fast2D& f, const Plane& p, bool linear, const float* s,
                                                             const float* t, const float* r, __m256 out[4]) {
    alignas(32) float lanes[4][8];
    for (int k = 0; k < 8; ++k) {
        float v[4];
        f.filter(p, linear, s[k], t[k], r ? r[k] : 0.0f, 0.0f, v);
        for (int c = 0; c < 4; ++c) lanes[c][k] = v[c];
    }
    for (int c = 0; c < 4; ++c) out[c] = _mm256_load_ps(lanes[c]);
}

// Fast2D::filter of one colour plane (p.rgba8 when set, else p.color) for 8 lanes (r: the
// layers of a 2D array, else null).
__attribute__((target("avx2,f16c"), always_inline)) inline void filter8_color(const Fast2D& f, const Plane8& P, bool linear,
                                                                         const float* s, const float* t, const float* r,
                                                                         __m256 out[4]) {
    const Plane& p = *P.p;
    if (!P.fits) return filter8_lanes(f, p, linear, s, t, r, out);
    const __m256i layer = layer_start8(P, r);
    const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(s), P.width_f), P.off_s);
    const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(t), P.height_f), P.off_t);
    __m256i i0, i1, j0, j1;
    if (!linear) {
        wrap8v(f.wrap_s, ifloor_floored8(_mm256_floor_ps(u)), P.last_i, p.width, p.width_pot, false, i0, i1);
        wrap8v(f.wrap_t, ifloor_floored8(_mm256_floor_ps(v)), P.last_j, p.height, p.height_pot, false, j0, j1);
        texels8(p, _mm256_add_epi32(_mm256_add_epi32(layer, _mm256_mullo_epi32(j0, P.width)), i0), false, out);
        return;
    }
    const __m256 half = _mm256_set1_ps(0.5f);
    const __m256 u0 = _mm256_sub_ps(u, half), v0 = _mm256_sub_ps(v, half);
    const __m256 fu = _mm256_floor_ps(u0), fv = _mm256_floor_ps(v0);
    wrap8v(f.wrap_s, ifloor_floored8(fu), P.last_i, p.width, p.width_pot, true, i0, i1);
    wrap8v(f.wrap_t, ifloor_floored8(fv), P.last_j, p.height, p.height_pot, true, j0, j1);
    const __m256 a = _mm256_sub_ps(u0, fu), b = _mm256_sub_ps(v0, fv);
    const __m256i row0 = _mm256_add_epi32(layer, _mm256_mullo_epi32(j0, P.width));
    const __m256i row1 = _mm256_add_epi32(layer, _mm256_mullo_epi32(j1, P.width));
    const __m256i at[4] = {_mm256_add_epi32(row0, i0), _mm256_add_epi32(row0, i1), _mm256_add_epi32(row1, i0),
                           _mm256_add_epi32(row1, i1)};
    __m256 w[4];
    if (p.unorm8) {
        // The fixed-point rule (Level::filter): 8-bit weights, texels as bytes k, exact integer
        // sums (any order), one correctly rounded division.
        const __m256 k256 = _mm256_set1_ps(256.0f), A = weight8x8(a), B = weight8x8(b);
        const __m256 nA = _mm256_sub_ps(k256, A), nB = _mm256_sub_ps(k256, B);
        w[0] = _mm256_mul_ps(nA, nB), w[1] = _mm256_mul_ps(A, nB), w[2] = _mm256_mul_ps(nA, B), w[3] = _mm256_mul_ps(A, B);
    } else {
        const __m256 one = _mm256_set1_ps(1.0f), na = _mm256_sub_ps(one, a), nb = _mm256_sub_ps(one, b);
        w[0] = _mm256_mul_ps(na, nb), w[1] = _mm256_mul_ps(a, nb), w[2] = _mm256_mul_ps(na, b), w[3] = _mm256_mul_ps(a, b);
    }
    // w00 t00 + w10 t10 + w01 t01 + w11 t11, left to right as Fast2D::filter.
    for (int n = 0; n < 4; ++n) {
        __m256 texel[4];
        texels8(p, at[n], p.unorm8, texel);
        for (int c = 0; c < 4; ++c) out[c] = n ? _mm256_add_ps(out[c], _mm256_mul_ps(w[n], texel[c])) : _mm256_mul_ps(w[n], texel[c]);
    }
    if (p.unorm8) {
        const __m256 divisor = _mm256_set1_ps(kUnorm8Divisor);
        for (int c = 0; c < 4; ++c) out[c] = _mm256_div_ps(out[c], divisor);
    }
}

// The lanes' fractions between their two levels (LevelChoice::frac).
__attribute__((target("avx2,f16c"), always_inline)) inline __m256 fractions8(const LevelChoice ch[8]) {
    alignas(32) float frac[8];
    for (int k = 0; k < 8; ++k) frac[k] = ch[k].frac;
    return _mm256_load_ps(frac);
}

// Fast2D::filter(LevelChoice) of 8 lanes that share the levels (frac per lane):
// (1 - frac) a + frac b per channel.
__attribute__((target("avx2,f16c"))) void filter8_color(const Fast2D& f, const LevelChoice ch[8], const float* s, const float* t,
                                                   const float* r, __m256 out[4]) {
    filter8_color(f, plane8(f, f.planes[size_t(ch[0].first)]), ch[0].linear, s, t, r, out);
    if (ch[0].second < 0) return;
    __m256 b[4];
    filter8_color(f, plane8(f, f.planes[size_t(ch[0].second)]), ch[0].linear, s, t, r, b);
    const __m256 g = fractions8(ch), ng = _mm256_sub_ps(_mm256_set1_ps(1.0f), g);
    for (int c = 0; c < 4; ++c) out[c] = _mm256_add_ps(_mm256_mul_ps(ng, out[c]), _mm256_mul_ps(g, b[c]));
}

// filter8_color(LevelChoice) of 8 lanes whose levels differ: each of the `count` distinct levels
// filtered for all 8 lanes, each lane's result taken from (or blended between) its own.
__attribute__((target("avx2,f16c"))) void filter8_color(const Fast2D& f, const LevelChoice ch[8], const int32_t levels[3],
                                                   int count, const float* s, const float* t, const float* r,
                                                   __m256 out[4]) {
    __m256 by_level[3][4];
    for (int i = 0; i < count; ++i) filter8_color(f, plane8(f, f.planes[size_t(levels[i])]), ch[0].linear, s, t, r, by_level[i]);
    // Per level, the lanes whose first / second level it is (all ones per lane).
    alignas(32) int32_t first[3][8] = {}, second[3][8] = {}, blended[8] = {};
    for (int k = 0; k < 8; ++k) {
        for (int i = 0; i < count; ++i) {
            if (ch[k].first == levels[i]) first[i][k] = -1;
            if (ch[k].second == levels[i]) second[i][k] = -1;
        }
        blended[k] = ch[k].second >= 0 ? -1 : 0;
    }
    const __m256 g = fractions8(ch), ng = _mm256_sub_ps(_mm256_set1_ps(1.0f), g);
    for (int c = 0; c < 4; ++c) {
        __m256 a = by_level[0][c], b = by_level[0][c];
        for (int i = 1; i < count; ++i) {
            a = _mm256_blendv_ps(a, by_level[i][c], _mm256_load_ps(reinterpret_cast<const float*>(first[i])));
            b = _mm256_blendv_ps(b, by_level[i][c], _mm256_load_ps(reinterpret_cast<const float*>(second[i])));
        }
        out[c] = _mm256_blendv_ps(a, _mm256_add_ps(_mm256_mul_ps(ng, a), _mm256_mul_ps(g, b)),
                                  _mm256_load_ps(reinterpret_cast<const float*>(blended)));
    }
}

// Channel vectors of lanes l .. l + 7 into the outputs (null: not needed); inactive lanes
// (bit k of `inactive`) get (0, 0, 0, 1), as sample_lanes gives them.
__attribute__((target("avx2,f16c"), always_inline)) inline void store8(const __m256 v[4], glsl::Scalar* const out[4], int l,
                                                                  uint32_t inactive) {
    if (!inactive) {
        for (int c = 0; c < 4; ++c)
            if (out[c]) _mm256_storeu_ps(&out[c][l].f, v[c]);
        return;
    }
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256 off = _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(inactive)), bit), bit));
    for (int c = 0; c < 4; ++c)
        if (out[c]) _mm256_storeu_ps(&out[c][l].f, _mm256_blendv_ps(v[c], _mm256_set1_ps(c == 3 ? 1.0f : 0.0f), off));
}

// Bit k: lane l + k (k < 8) is active.
__attribute__((target("avx2,f16c"), always_inline)) inline uint32_t active8(const glsl::TextureQuery& q, int l) {
    if (!q.active) return 0xFFu;
    const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(q.active + l));
    return ~uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(a, _mm256_setzero_si256())))) & 0xFFu;
}

// What the block loops (colour, and depth planes) share across a query (sample_2d resolves it once).
struct ColourQuery {
    const Fast2D* f;
    const glsl::TextureQuery* q;
    const float* r;          // the layers of a 2D array, else null
    bool needs_lambda;       // else every lane takes `fixed`
    LevelChoice fixed;
    float w, h;              // the base level's size (lambda)
    LambdaMemo* memo;
};

// The distinct levels of ch[0 .. n) (at most 3, all with one filter) in levels, or 0 if more.
inline int distinct_levels(const LevelChoice* ch, int n, int32_t levels[3]) {
    int count = 0;
    for (int k = 0; k < n; ++k) {
        if (ch[k].linear != ch[0].linear) return 0;
        for (const int32_t level : {ch[k].first, ch[k].second}) {
            if (level < 0 || std::find(levels, levels + count, level) != levels + count) continue;
            if (count == 3) return 0;
            levels[count++] = level;
        }
    }
    return count;
}

inline bool same_levels(const LevelChoice* ch, int n) {
    for (int k = 1; k < n; ++k)
        if (!ch[k].same_levels(ch[0])) return false;
    return true;
}

// The levels of lanes l .. l + n - 1 (n = 8 or 16) in ch; inactive lanes take those of the first
// active lane, so that they add no level.
__attribute__((target("avx2,f16c"))) inline void choose_lanes(const ColourQuery& cq, int l, int n, uint32_t active, LevelChoice* ch) {
    const glsl::TextureQuery& q = *cq.q;
    for (int part = 0; part < n; part += 8) {
        alignas(32) float lambda[8];
        query_lambdas8(q, l + part, cq.w, cq.h, *cq.memo, lambda);
        if (!choose8(*cq.f, lambda, ch + part))
            for (int k = 0; k < 8; ++k) ch[part + k] = cq.f->choose(lambda[k]);
    }
    const uint32_t all = n == 16 ? 0xFFFFu : 0xFFu;
    if (active != all)
        for (int k = 0; k < n; ++k)
            if (!(active >> k & 1)) ch[k] = ch[__builtin_ctz(active)];
}

// filter8 of one depth plane as channel vectors (out[c]: channel c of the 8 lanes, the layout
// of the executor's registers, so no transposes): the same texels (DepthTexels8), weights and
// sums in the same order, so the same bits.
// kEncoding: the plane's depth_encoding; kFunc: the comparison (f.compare_func), 0 without one,
// fixed at compile time so that no texel branches on them (filter8_depth picks the instance).
template <Encoding kEncoding, GLenum kFunc>
__attribute__((target("avx2,f16c"))) void filter8_depth_as(const Fast2D& f, const Plane& p, bool linear, const float* s,
                                                      const float* t, const float* r, const float* ref, __m256 out[4]) {
    size_t layer_at[8];   // the first texel of each lane's layer (r: a 2D array's layers)
    if (r)
        for (int l = 0; l < 8; ++l)
            layer_at[l] = size_t(std::clamp(ifloor(r[l] + 0.5f), 0, p.layers - 1)) * size_t(p.height) * size_t(p.width);
    const DepthTexels8 texels(f, p, r ? layer_at : nullptr, ref);
    const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(s), _mm256_set1_ps(float(p.width))), _mm256_set1_ps(float(f.off_s)));
    const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(t), _mm256_set1_ps(float(p.height))), _mm256_set1_ps(float(f.off_t)));
    const bool grey = f.compare || f.luminance;   // Fast2D::texel: (d, d or 0, d or 0, 1)
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    const __m256i last_i = _mm256_set1_epi32(p.width - 1), last_j = _mm256_set1_epi32(p.height - 1);
    const __m256i width = _mm256_set1_epi32(p.width);
    __m256i i0, i1, j0, j1;
    // The texels (i, j) of the 8 lanes: by vectors when every index fits an int32, else lane by lane.
    const auto texel = [&texels, width](__m256i i, __m256i j) __attribute__((target("avx2,f16c"))) {
        if (texels.indexable) {
            // DepthTexels8::at with the encoding and the comparison known.
            const __m256i at = _mm256_add_epi32(_mm256_add_epi32(texels.base, _mm256_mullo_epi32(j, width)), i);
            const __m256 d = depth_values8(kEncoding, _mm256_i32gather_epi32(reinterpret_cast<const int*>(texels.p.depth), at, 4));
            if constexpr (kFunc == 0) return d;
            else return compare8(kFunc, texels.ref, d);
        }
        alignas(32) int32_t ii[8], jj[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(ii), i), _mm256_store_si256(reinterpret_cast<__m256i*>(jj), j);
        return texels(ii, jj);
    };
    if (!linear) {
        wrap8v(f.wrap_s, ifloor_floored8(_mm256_floor_ps(u)), last_i, p.width, p.width_pot, false, i0, i1);
        wrap8v(f.wrap_t, ifloor_floored8(_mm256_floor_ps(v)), last_j, p.height, p.height_pot, false, j0, j1);
        out[0] = texel(i0, j0);
        out[1] = out[2] = grey ? out[0] : zero;
        out[3] = one;
        return;
    }
    const __m256 half = _mm256_set1_ps(0.5f);
    const __m256 u0 = _mm256_sub_ps(u, half), v0 = _mm256_sub_ps(v, half);
    const __m256 fu = _mm256_floor_ps(u0), fv = _mm256_floor_ps(v0);
    wrap8v(f.wrap_s, ifloor_floored8(fu), last_i, p.width, p.width_pot, true, i0, i1);
    wrap8v(f.wrap_t, ifloor_floored8(fv), last_j, p.height, p.height_pot, true, j0, j1);
    const __m256 a = _mm256_sub_ps(u0, fu), b = _mm256_sub_ps(v0, fv);
    const __m256 na = _mm256_sub_ps(one, a), nb = _mm256_sub_ps(one, b);
    const __m256 w00 = _mm256_mul_ps(na, nb), w10 = _mm256_mul_ps(a, nb), w01 = _mm256_mul_ps(na, b), w11 = _mm256_mul_ps(a, b);
    out[0] = weighted_sum8(w00, w10, w01, w11, texel(i0, j0), texel(i1, j0), texel(i0, j1), texel(i1, j1));
    // Channels 1 and 2 repeat the depth, else are the weighted zeros; alpha the weighted ones.
    out[1] = out[2] = grey ? out[0] : weighted_sum8(w00, w10, w01, w11, zero, zero, zero, zero);
    out[3] = weighted_sum8(w00, w10, w01, w11, one, one, one, one);
}

template <Encoding kEncoding>
__attribute__((target("avx2,f16c"))) void filter8_depth_of(const Fast2D& f, const Plane& p, bool linear, const float* s,
                                                      const float* t, const float* r, const float* ref, __m256 out[4]) {
    switch (f.compare ? f.compare_func : 0) {
        case 0: return filter8_depth_as<kEncoding, 0>(f, p, linear, s, t, r, ref, out);
        case gl::LEQUAL: return filter8_depth_as<kEncoding, gl::LEQUAL>(f, p, linear, s, t, r, ref, out);
        case gl::GEQUAL: return filter8_depth_as<kEncoding, gl::GEQUAL>(f, p, linear, s, t, r, ref, out);
        case gl::LESS: return filter8_depth_as<kEncoding, gl::LESS>(f, p, linear, s, t, r, ref, out);
        case gl::GREATER: return filter8_depth_as<kEncoding, gl::GREATER>(f, p, linear, s, t, r, ref, out);
        case gl::EQUAL: return filter8_depth_as<kEncoding, gl::EQUAL>(f, p, linear, s, t, r, ref, out);
        case gl::NOTEQUAL: return filter8_depth_as<kEncoding, gl::NOTEQUAL>(f, p, linear, s, t, r, ref, out);
        case gl::ALWAYS: return filter8_depth_as<kEncoding, gl::ALWAYS>(f, p, linear, s, t, r, ref, out);
        default: return filter8_depth_as<kEncoding, gl::NEVER>(f, p, linear, s, t, r, ref, out);   // as compare8
    }
}

__attribute__((target("avx2,f16c"))) void filter8_depth(const Fast2D& f, const Plane& p, bool linear, const float* s,
                                                   const float* t, const float* r, const float* ref, __m256 out[4]) {
    switch (p.depth_encoding) {
        case Encoding::Depth16: return filter8_depth_of<Encoding::Depth16>(f, p, linear, s, t, r, ref, out);
        case Encoding::Depth32F: return filter8_depth_of<Encoding::Depth32F>(f, p, linear, s, t, r, ref, out);
        default: return filter8_depth_of<Encoding::Depth24>(f, p, linear, s, t, r, ref, out);   // as depth_values8
    }
}

// The depth lookups (with or without the comparison) of the block of lanes l .. l + 7 whose lanes
// share their levels, channel-major straight into the outputs (filter8_depth; inactive lanes
// (0, 0, 0, 1)): false (nothing written) when their levels differ.
__attribute__((target("avx2,f16c"))) bool depth_block8(const ColourQuery& cq, int l) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    const uint32_t active = active8(q, l);
    __m256 result[4] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
    if (!active) return store8(result, out, l, 0xFFu), true;
    const float* s = &q.coord[0][l].f;
    const float* t = &q.coord[1][l].f;
    const float* r = cq.r ? cq.r + l : nullptr;
    const float* ref = q.compare ? &q.compare[l].f : nullptr;
    BlockChoice bc;
    if (!cq.needs_lambda) {
        bc.first = cq.fixed.first, bc.linear = cq.fixed.linear;
    } else {
        alignas(32) float lambda[8];
        query_lambdas8(q, l, cq.w, cq.h, *cq.memo, lambda);
        __m256 v = active_lambdas8(lambda, active);
        if (!choose_block8(f, v, bc)) return false;
    }
    filter8_depth(f, f.planes[size_t(bc.first)], bc.linear, s, t, r, ref, result);
    if (bc.second >= 0) {
        __m256 b[4];
        filter8_depth(f, f.planes[size_t(bc.second)], bc.linear, s, t, r, ref, b);
        // (1 - frac) a + frac b per channel, as Fast2D::filter(LevelChoice).
        const __m256 ng = _mm256_sub_ps(_mm256_set1_ps(1.0f), bc.frac);
        for (int c = 0; c < 4; ++c) result[c] = _mm256_add_ps(_mm256_mul_ps(ng, result[c]), _mm256_mul_ps(bc.frac, b[c]));
    }
    store8(result, out, l, ~active & 0xFFu);
    return true;
}

// The colour lookups of lanes [l, end) in blocks of 8: returns where it stopped, at the first
// block whose lanes need more than 3 levels or two filters (the caller takes it lane by lane),
// or at the last block that fits.
__attribute__((target("avx2,f16c"))) int colour_blocks8(const ColourQuery& cq, int l, int end) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    const Plane8 fixed = plane8(f, f.planes[size_t(cq.fixed.first)]);
    LevelChoice ch[8];
    int32_t levels[3];
    for (; l + 8 <= end; l += 8) {
        const uint32_t active = active8(q, l);
        const float* s = &q.coord[0][l].f;
        const float* t = &q.coord[1][l].f;
        const float* r = cq.r ? cq.r + l : nullptr;
        __m256 result[4] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
        if (!active) {
            // Nothing to compute: every lane gets (0, 0, 0, 1) below.
        } else if (!cq.needs_lambda) {
            filter8_color(f, fixed, cq.fixed.linear, s, t, r, result);
        } else {
            choose_lanes(cq, l, 8, active, ch);
            if (same_levels(ch, 8)) filter8_color(f, ch, s, t, r, result);
            else if (const int count = distinct_levels(ch, 8, levels)) filter8_color(f, ch, levels, count, s, t, r, result);
            else return l;
        }
        store8(result, out, l, ~active & 0xFFu);
    }
    return l;
}

// ---- Colour block loops specialised by the query's shape (kColourBlocks8, chosen once per draw
// for each unit by plan_units): the storage (bytes or floats), the wrap modes (REPEAT of powers of two, or
// CLAMP_TO_EDGE, on both axes and at every level the query can use) and the level choice (one
// fixed filter, or the levels chosen per block), so that the block loop branches on none of them.
// Per lane the same operations in the same order as filter8_color (whose branches on the wrap
// modes and the storage they fix at compile time), so the same bits. Other queries (2D arrays,
// MIRRORED_REPEAT, REPEAT of other sizes, mixed wraps) take colour_blocks8.

enum class WrapKind : uint8_t { RepeatPot, Clamp };
enum class LevelMode : uint8_t { FixedNearest, FixedLinear, PerBlock };

// wrap_one (kPair: false) or wrap_pair (kPair: true) of 8 lanes, i the floored coordinate.
template <WrapKind kWrap, bool kPair>
__attribute__((target("avx2,f16c"), always_inline)) inline void wrap_shaped8(__m256i i, __m256i last, __m256i& a, __m256i& b) {
    const __m256i one = _mm256_set1_epi32(1);
    if constexpr (kWrap == WrapKind::RepeatPot) {
        a = _mm256_and_si256(i, last);
        if constexpr (kPair) b = _mm256_and_si256(_mm256_add_epi32(i, one), last);
    } else {
        const __m256i zero = _mm256_setzero_si256();
        a = _mm256_max_epi32(_mm256_min_epi32(i, last), zero);
        if constexpr (kPair) b = _mm256_max_epi32(_mm256_min_epi32(_mm256_add_epi32(i, one), last), zero);
    }
}

// texels8 of one storage (kBytes: 1 p.rgba8, 2 p.narrow, 0 p.color).
template <int kBytes>
__attribute__((target("avx2,f16c"), always_inline)) inline void texels_shaped8(const Plane& p, __m256i index, bool bytes, __m256 out[4]) {
    if constexpr (kBytes) {
        unpack8(shaped_words8<kBytes>(p, index), out, bytes);
    } else {
        float_texels8(p, index, out);
    }
}

// One row of unorm8_rows8: the horizontal blends of 8 lanes' left and right texels as channel vectors.
__attribute__((target("avx2,f16c"), always_inline)) inline void unorm8_row8(__m256i left, __m256i right, __m256i wa, __m256i nwa,
                                                                       __m256 h[4]) {
    const __m256i bytes = _mm256_set1_epi32(0x00FF00FF), low = _mm256_set1_epi32(0xFFFF);
    const __m256i even = _mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(left, bytes), nwa),
                                          _mm256_mullo_epi16(_mm256_and_si256(right, bytes), wa));
    const __m256i odd = _mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(_mm256_srli_epi32(left, 8), bytes), nwa),
                                         _mm256_mullo_epi16(_mm256_and_si256(_mm256_srli_epi32(right, 8), bytes), wa));
    h[0] = _mm256_cvtepi32_ps(_mm256_and_si256(even, low));
    h[1] = _mm256_cvtepi32_ps(_mm256_and_si256(odd, low));
    h[2] = _mm256_cvtepi32_ps(_mm256_srli_epi32(even, 16));
    h[3] = _mm256_cvtepi32_ps(_mm256_srli_epi32(odd, 16));
}

// The fixed-point rule's sums (filter8_color: ((256 - A)(256 - B) k00 + A (256 - B) k10 +
// (256 - A) B k01 + A B k11) of 8 lanes, by rows: per row the horizontal blend
// H = (256 - A) k0 + A k1 of every channel in 16-bit integers (at most 256 * 255: exact), two
// channels per 32-bit lane (r, b and g, a), then (256 - B) H0 + B H1 in float (integers below
// 2^24: exact). The same integer sums as the four products, so the same bits after the division.
__attribute__((target("avx2,f16c"), always_inline)) inline void unorm8_rows8(__m256i t00, __m256i t10, __m256i t01, __m256i t11,
                                                                        __m256 A, __m256 B, __m256 out[4]) {
    const __m256i ai = _mm256_cvttps_epi32(A), nai = _mm256_sub_epi32(_mm256_set1_epi32(256), ai);
    const __m256i wa = _mm256_or_si256(ai, _mm256_slli_epi32(ai, 16)), nwa = _mm256_or_si256(nai, _mm256_slli_epi32(nai, 16));
    __m256 h0[4], h1[4];
    unorm8_row8(t00, t10, wa, nwa, h0);
    unorm8_row8(t01, t11, wa, nwa, h1);
    const __m256 nB = _mm256_sub_ps(_mm256_set1_ps(256.0f), B), divisor = _mm256_set1_ps(kUnorm8Divisor);
    for (int c = 0; c < 4; ++c)
        out[c] = _mm256_div_ps(_mm256_add_ps(_mm256_mul_ps(nB, h0[c]), _mm256_mul_ps(B, h1[c])), divisor);
}

// filter8_color of one plane of one layer (kBytes: 8-bit unorm bytes, 1 rgba8 or 2 narrow, and the fixed-point rule,
// else floats). face: another plane of P's size to read (a cube map's other faces), else P's own.
// inside (CLAMP_TO_EDGE only): all ones in the lanes whose texels lie inside the plane, no clamp
// applied (Fast2D::inside, as inside8: for LINEAR, i1 - i0 = 1 exactly when ifloor(u - 1/2) is in
// [0, width - 2]; for NEAREST the clamp leaves i unchanged exactly when it is in [0, width - 1]).
template <int kBytes, bool kLinear, WrapKind kWrap>
__attribute__((target("avx2,f16c"), always_inline)) inline void filter8_shaped(const Plane8& P, const float* s, const float* t,
                                                                          __m256 out[4], const Plane* face = nullptr,
                                                                          __m256i* inside = nullptr) {
    const Plane& p = face ? *face : *P.p;
    const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(s), P.width_f), P.off_s);
    const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(t), P.height_f), P.off_t);
    __m256i i0, i1, j0, j1;
    if constexpr (!kLinear) {
        const __m256i i = ifloor_floored8(_mm256_floor_ps(u)), j = ifloor_floored8(_mm256_floor_ps(v));
        wrap_shaped8<kWrap, false>(i, P.last_i, i0, i1);
        wrap_shaped8<kWrap, false>(j, P.last_j, j0, j1);
        if constexpr (kWrap == WrapKind::Clamp)
            if (inside) *inside = _mm256_and_si256(_mm256_cmpeq_epi32(i, i0), _mm256_cmpeq_epi32(j, j0));
        texels_shaped8<kBytes>(p, _mm256_add_epi32(_mm256_mullo_epi32(j0, P.width), i0), false, out);
    } else {
        const __m256 half = _mm256_set1_ps(0.5f);
        const __m256 u0 = _mm256_sub_ps(u, half), v0 = _mm256_sub_ps(v, half);
        const __m256 fu = _mm256_floor_ps(u0), fv = _mm256_floor_ps(v0);
        wrap_shaped8<kWrap, true>(ifloor_floored8(fu), P.last_i, i0, i1);
        wrap_shaped8<kWrap, true>(ifloor_floored8(fv), P.last_j, j0, j1);
        if constexpr (kWrap == WrapKind::Clamp)
            if (inside) {
                const __m256i one = _mm256_set1_epi32(1);
                *inside = _mm256_and_si256(_mm256_cmpeq_epi32(_mm256_sub_epi32(i1, i0), one),
                                           _mm256_cmpeq_epi32(_mm256_sub_epi32(j1, j0), one));
            }
        const __m256 a = _mm256_sub_ps(u0, fu), b = _mm256_sub_ps(v0, fv);
        const __m256i row0 = _mm256_mullo_epi32(j0, P.width), row1 = _mm256_mullo_epi32(j1, P.width);
        const __m256i at[4] = {_mm256_add_epi32(row0, i0), _mm256_add_epi32(row0, i1), _mm256_add_epi32(row1, i0),
                               _mm256_add_epi32(row1, i1)};
        __m256 w[4];
        if constexpr (kBytes) {
            unorm8_rows8(shaped_words8<kBytes>(p, at[0]), shaped_words8<kBytes>(p, at[1]), shaped_words8<kBytes>(p, at[2]),
                         shaped_words8<kBytes>(p, at[3]),
                         weight8x8(a), weight8x8(b), out);
            return;
        } else {
            const __m256 one = _mm256_set1_ps(1.0f), na = _mm256_sub_ps(one, a), nb = _mm256_sub_ps(one, b);
            w[0] = _mm256_mul_ps(na, nb), w[1] = _mm256_mul_ps(a, nb), w[2] = _mm256_mul_ps(na, b), w[3] = _mm256_mul_ps(a, b);
        }
        for (int n = 0; n < 4; ++n) {
            __m256 texel[4];
            texels_shaped8<kBytes>(p, at[n], false, texel);
            for (int c = 0; c < 4; ++c)
                out[c] = n ? _mm256_add_ps(out[c], _mm256_mul_ps(w[n], texel[c])) : _mm256_mul_ps(w[n], texel[c]);
        }
    }
}

// plane8 of each level of a query, made when a block first needs it.
struct Planes8 {
    explicit Planes8(const Fast2D& f_) : f(f_) {}
    const Fast2D& f;
    Plane8 at[16];
    uint32_t made = 0;
    __attribute__((target("avx2,f16c"), always_inline)) const Plane8& operator[](int32_t level) {
        if (!(made >> level & 1)) at[level] = plane8(f, f.planes[size_t(level)]), made |= 1u << level;
        return at[level];
    }
};

// The colour lookups of lanes [l, end) in blocks of 8 of one query shape (as colour_blocks8).
template <int kBytes, WrapKind kWrap, LevelMode kMode>
__attribute__((target("avx2,f16c"))) int colour_blocks8_shaped(const ColourQuery& cq, int l, int end) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    Planes8 planes(f);
    const Plane8& fixed = planes[cq.fixed.first];
    LevelChoice ch[8];
    int32_t levels[3];
    for (; l + 8 <= end; l += 8) {
        const uint32_t active = active8(q, l);
        const float* s = &q.coord[0][l].f;
        const float* t = &q.coord[1][l].f;
        __m256 result[4] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
        if (!active) {
            // Nothing to compute: every lane gets (0, 0, 0, 1) below.
        } else if constexpr (kMode == LevelMode::FixedNearest) {
            filter8_shaped<kBytes, false, kWrap>(fixed, s, t, result);
        } else if constexpr (kMode == LevelMode::FixedLinear) {
            filter8_shaped<kBytes, true, kWrap>(fixed, s, t, result);
        } else {
            alignas(32) float lambda[8];
            query_lambdas8(q, l, cq.w, cq.h, *cq.memo, lambda);
            __m256 v = active_lambdas8(lambda, active);
            BlockChoice bc;
            if (choose_block8(f, v, bc)) {
                const Plane8& first = planes[bc.first];
                if (bc.linear) filter8_shaped<kBytes, true, kWrap>(first, s, t, result);
                else filter8_shaped<kBytes, false, kWrap>(first, s, t, result);
                if (bc.second >= 0) {
                    __m256 b[4];
                    const Plane8& second = planes[bc.second];
                    if (bc.linear) filter8_shaped<kBytes, true, kWrap>(second, s, t, b);
                    else filter8_shaped<kBytes, false, kWrap>(second, s, t, b);
                    // (1 - frac) a + frac b per channel, as filter8_color.
                    const __m256 ng = _mm256_sub_ps(_mm256_set1_ps(1.0f), bc.frac);
                    for (int c = 0; c < 4; ++c)
                        result[c] = _mm256_add_ps(_mm256_mul_ps(ng, result[c]), _mm256_mul_ps(bc.frac, b[c]));
                }
            } else {
                // Lanes on different levels: chosen lane by lane (as choose_lanes), filtered by
                // the general block code.
                _mm256_store_ps(lambda, v);
                for (int k = 0; k < 8; ++k) ch[k] = f.choose(lambda[k]);
                if (same_levels(ch, 8)) filter8_color(f, ch, s, t, nullptr, result);
                else if (const int count = distinct_levels(ch, 8, levels)) filter8_color(f, ch, levels, count, s, t, nullptr, result);
                else return l;
            }
        }
        store8(result, out, l, ~active & 0xFFu);
    }
    return l;
}

using Blocks8 = int (*)(const ColourQuery&, int, int);

// The colour block loops by SamplingPlan::colour_shape (colour_shape below): 0 colour_blocks8,
// then 1 + (storage * 2 + wrap) * 3 + mode with storage 0 rgba8 bytes, 1 narrow bytes, 2 floats
// (kBytes 1, 2, 0), wrap 0 REPEAT of powers of two, 1 CLAMP_TO_EDGE, and mode FixedNearest,
// FixedLinear, PerBlock.
#define SOFTGL_SHAPES(LOOP, B)                                                                       \
    LOOP<B, WrapKind::RepeatPot, LevelMode::FixedNearest>, LOOP<B, WrapKind::RepeatPot, LevelMode::FixedLinear>, \
    LOOP<B, WrapKind::RepeatPot, LevelMode::PerBlock>, LOOP<B, WrapKind::Clamp, LevelMode::FixedNearest>,   \
    LOOP<B, WrapKind::Clamp, LevelMode::FixedLinear>, LOOP<B, WrapKind::Clamp, LevelMode::PerBlock>
constexpr Blocks8 kColourBlocks8[kColourShapes] = {colour_blocks8, SOFTGL_SHAPES(colour_blocks8_shaped, 1),
                                                   SOFTGL_SHAPES(colour_blocks8_shaped, 2),
                                                   SOFTGL_SHAPES(colour_blocks8_shaped, 0)};

// ---- Cube maps in blocks of 8 (AVX2), channel-major as the shaped colour blocks: faces, face
// coordinates and (for a level choice) their derivatives of 8 lanes at once (cube_coords8), one
// level choice for the block (choose_block8 on lambdas computed 8 at a time, as one_lane computes
// them lane by lane), then each face the block's lanes select filtered for all 8 lanes by the
// shaped filter of the query's storage (bytes: the fixed-point rule by rows) and each lane taking
// its own face's result. Per lane the same operations in the same order as one_lane, so the same
// bits. Every face of a cube level has one size, so face 0's Plane8 serves all six.

struct CubeQuery {
    const Fast2D* f;
    const glsl::TextureQuery* q;
    float w, h;          // the base level's size (lambda)
    LambdaMemo* memo;
    bool seamless;       // lanes whose footprint leaves the face go to sample_lane
    // With seamless filtering, lane `lane` of q sampled again lane by lane (sample_lane).
    void (*again)(void* context, int lane);
    void* context;
};

// One face of a cube map filtered for 8 lanes at the block's levels: planes[level]'s sizes, the
// face's texels. inside: the lanes whose texels lie inside the face at every level read (the
// same for all faces).
template <int kBytes, LevelMode kMode>
__attribute__((target("avx2,f16c"), always_inline)) inline void cube_face8(const Fast2D& f, Planes8& planes, const BlockChoice& bc,
                                                                      int face, const float* s8, const float* t8,
                                                                      __m256 dst[4], __m256i& inside) {
    const Plane* levels = f.planes + size_t(face) * size_t(f.face_stride);
    if (bc.linear) filter8_shaped<kBytes, true, WrapKind::Clamp>(planes[bc.first], s8, t8, dst, &levels[bc.first], &inside);
    else filter8_shaped<kBytes, false, WrapKind::Clamp>(planes[bc.first], s8, t8, dst, &levels[bc.first], &inside);
    if (kMode != LevelMode::PerBlock || bc.second < 0) return;
    __m256 b[4];
    __m256i inside_second;
    if (bc.linear) filter8_shaped<kBytes, true, WrapKind::Clamp>(planes[bc.second], s8, t8, b, &levels[bc.second], &inside_second);
    else filter8_shaped<kBytes, false, WrapKind::Clamp>(planes[bc.second], s8, t8, b, &levels[bc.second], &inside_second);
    inside = _mm256_and_si256(inside, inside_second);
    // (1 - frac) a + frac b per channel, as Fast2D::filter(LevelChoice).
    const __m256 ng = _mm256_sub_ps(_mm256_set1_ps(1.0f), bc.frac);
    for (int c = 0; c < 4; ++c) dst[c] = _mm256_add_ps(_mm256_mul_ps(ng, dst[c]), _mm256_mul_ps(bc.frac, b[c]));
}

// The block's lanes on up to 3 distinct levels (ch: each lane's choice, one filter for all; inactive
// lanes take an active lane's): each face the active lanes select, each level filtered for all 8
// lanes, each lane taking (or blending, as Fast2D::filter(LevelChoice)) its own levels' results
// on its own face, as filter8_color(levels) does for one plane. inside: per lane, whether its
// texels lie inside the face at each level it reads.
template <int kBytes, bool kLinear>
__attribute__((target("avx2,f16c"))) void cube_levels8(const Fast2D& f, Planes8& planes, const LevelChoice ch[8],
                                                  const int32_t levels[3], int count, uint32_t active,
                                                  const int32_t face8[8], const float* s8, const float* t8,
                                                  __m256 result[4], __m256i& inside) {
    if (count < 1 || count > 3) __builtin_unreachable();   // the caller's 1-3 levels: by_level is filled
    // Per level, the lanes whose first / second level it is (all ones per lane).
    alignas(32) int32_t first[3][8] = {}, second[3][8] = {}, blended[8] = {};
    for (int k = 0; k < 8; ++k) {
        for (int i = 0; i < count; ++i) {
            if (ch[k].first == levels[i]) first[i][k] = -1;
            if (ch[k].second == levels[i]) second[i][k] = -1;
        }
        blended[k] = ch[k].second >= 0 ? -1 : 0;
    }
    const __m256 g = fractions8(ch), ng = _mm256_sub_ps(_mm256_set1_ps(1.0f), g);
    const __m256 blend = _mm256_load_ps(reinterpret_cast<const float*>(blended));
    const __m256i face_v = _mm256_load_si256(reinterpret_cast<const __m256i*>(face8));
    uint32_t faces = 0;
    for (uint32_t left = active; left; left &= left - 1) faces |= 1u << face8[__builtin_ctz(left)];
    __m256i in_level[3];
    for (uint32_t left = faces; left; left &= left - 1) {
        const int face = __builtin_ctz(left);
        const Plane* face_levels = f.planes + size_t(face) * size_t(f.face_stride);
        __m256 by_level[3][4];
        for (int i = 0; i < count; ++i)
            filter8_shaped<kBytes, kLinear, WrapKind::Clamp>(planes[levels[i]], s8, t8, by_level[i], &face_levels[levels[i]],
                                                             &in_level[i]);
        const __m256 mine = _mm256_castsi256_ps(_mm256_cmpeq_epi32(face_v, _mm256_set1_epi32(face)));
        for (int c = 0; c < 4; ++c) {
            __m256 a = by_level[0][c], b = by_level[0][c];
            for (int i = 1; i < count; ++i) {
                a = _mm256_blendv_ps(a, by_level[i][c], _mm256_load_ps(reinterpret_cast<const float*>(first[i])));
                b = _mm256_blendv_ps(b, by_level[i][c], _mm256_load_ps(reinterpret_cast<const float*>(second[i])));
            }
            const __m256 part = _mm256_blendv_ps(a, _mm256_add_ps(_mm256_mul_ps(ng, a), _mm256_mul_ps(g, b)), blend);
            result[c] = _mm256_blendv_ps(result[c], part, mine);
        }
    }
    // A lane is inside when it is inside at every level it reads (the same at every face: one size).
    inside = _mm256_set1_epi32(-1);
    for (int i = 0; i < count; ++i) {
        const __m256i reads = _mm256_or_si256(_mm256_load_si256(reinterpret_cast<const __m256i*>(first[i])),
                                              _mm256_load_si256(reinterpret_cast<const __m256i*>(second[i])));
        inside = _mm256_and_si256(inside, _mm256_or_si256(in_level[i], _mm256_xor_si256(reads, _mm256_set1_epi32(-1))));
    }
}

// The last 1-7 lanes of a query (lanes l ..) as one block of 8 over copies of their operands,
// the lanes beyond them inactive (their results are dropped): a block's lanes give one_lane's
// bits whatever the other lanes hold, so a tail costs one block, not 1-7 lanes one by one.
struct PaddedTail8 {
    alignas(32) glsl::Scalar coord[3][8] = {}, ddx[3][8] = {}, ddy[3][8] = {}, lod[8] = {}, result[4][8];
    alignas(32) uint32_t active[8] = {};
    glsl::TextureQuery query;   // points into this struct: not copyable
    PaddedTail8(const glsl::TextureQuery& q, int l) : query(q) {
        const int n = q.lane_count - l;
        query.lane_count = 8;
        const auto lanes_of = [&](const glsl::Scalar* src, glsl::Scalar* dst) -> const glsl::Scalar* {
            if (!src) return nullptr;
            std::copy_n(src + l, n, dst);
            return dst;
        };
        for (int k = 0; k < 3; ++k) {
            query.coord[k] = lanes_of(q.coord[k], coord[k]);
            query.ddx[k] = lanes_of(q.ddx[k], ddx[k]);
            query.ddy[k] = lanes_of(q.ddy[k], ddy[k]);
        }
        query.lod = lanes_of(q.lod, lod);
        for (int k = 0; k < n; ++k) active[k] = q.active ? q.active[l + k] : ~0u;
        query.active = active;
        for (int c = 0; c < 4; ++c) query.out[c] = q.out[c] ? result[c] : nullptr;
    }
    PaddedTail8(const PaddedTail8&) = delete;
    PaddedTail8& operator=(const PaddedTail8&) = delete;
    void copy_results(const glsl::TextureQuery& q, int l) const {
        for (int c = 0; c < 4; ++c)
            if (q.out[c]) std::copy_n(result[c], q.lane_count - l, q.out[c] + l);
    }
};

// One block of lanes l .. l + 7: false (nothing written) when its lanes do not share their levels
// (the caller takes the block by the general code); else the results are stored and `outside`
// holds the active lanes whose texels cross a face edge under seamless filtering, which the
// caller samples again by sample_lane (ES 3.0 §3.8.9.1), as one_lane does.
template <int kBytes, LevelMode kMode>
__attribute__((target("avx2,f16c"), always_inline)) inline bool cube_block8(const CubeQuery& cq, Planes8& planes, int l,
                                                                            uint32_t& outside) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    outside = 0;
    const uint32_t active = active8(q, l);
    __m256 result[4] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
    if (!active) return store8(result, out, l, 0xFFu), true;
    alignas(32) int32_t face8[8];
    alignas(32) float s8[8], t8[8];
    BlockChoice bc;
    if constexpr (kMode != LevelMode::PerBlock) {
        cube_coords8(&q.coord[0][l].f, &q.coord[1][l].f, &q.coord[2][l].f, face8, s8, t8);
        bc.linear = kMode == LevelMode::FixedLinear;
    } else {
        alignas(32) float ds[2][8], dt[2][8], lambda[8];
        const float* ddx[3], *ddy[3];
        for (int k = 0; k < 3; ++k) ddx[k] = q.ddx[k] ? &q.ddx[k][l].f : nullptr, ddy[k] = q.ddy[k] ? &q.ddy[k][l].f : nullptr;
        cube_coords8(&q.coord[0][l].f, &q.coord[1][l].f, &q.coord[2][l].f, face8, s8, t8, ddx, ddy, ds, dt);
        if (q.lod_mode == TextureLod::Explicit) {
            explicit_lambdas8(q, l, lambda);
        } else {
            // lambda_of_derivatives of the face derivatives (dx = ds[0], dt[0]; dy = ds[1], dt[1]):
            // float products by the size, squared and summed in double, the larger of x and y.
            // (Its third terms add +0 to a sum of squares, which changes nothing.)
            const __m256 ws = _mm256_set1_ps(cq.w), hs = _mm256_set1_ps(cq.h);
            const __m256 x0 = _mm256_mul_ps(_mm256_load_ps(ds[0]), ws), x1 = _mm256_mul_ps(_mm256_load_ps(dt[0]), hs);
            const __m256 y0 = _mm256_mul_ps(_mm256_load_ps(ds[1]), ws), y1 = _mm256_mul_ps(_mm256_load_ps(dt[1]), hs);
            alignas(32) double rho2[8];
            for (int half = 0; half < 2; ++half) {
                const __m256d lx2 = _mm256_add_pd(square_wide(x0, half), square_wide(x1, half));
                const __m256d ly2 = _mm256_add_pd(square_wide(y0, half), square_wide(y1, half));
                _mm256_store_pd(rho2 + 4 * half, _mm256_max_pd(ly2, lx2));   // = std::max(lx2, ly2)
            }
            lambdas_of_rho2_8(q, l, rho2, *cq.memo, lambda);
        }
        __m256 v = active_lambdas8(lambda, active);
        if (!choose_block8(f, v, bc)) {
            // Lanes on different levels: chosen lane by lane (as choose_lanes), at most 3 levels
            // with one filter filtered for the block, else the general code.
            _mm256_store_ps(lambda, v);
            LevelChoice ch[8];
            for (int k = 0; k < 8; ++k) ch[k] = f.choose(lambda[k]);
            int32_t levels[3];
            const int count = distinct_levels(ch, 8, levels);
            if (!count) return false;
            __m256i inside;
            if (ch[0].linear) cube_levels8<kBytes, true>(f, planes, ch, levels, count, active, face8, s8, t8, result, inside);
            else cube_levels8<kBytes, false>(f, planes, ch, levels, count, active, face8, s8, t8, result, inside);
            store8(result, out, l, ~active & 0xFFu);
            if (cq.seamless) outside = ~uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(inside))) & active;
            return true;
        }
    }
    // The faces of the active lanes: usually one (the first active lane's).
    const __m256i face_v = _mm256_load_si256(reinterpret_cast<const __m256i*>(face8));
    const int first_face = face8[__builtin_ctz(active)];
    const uint32_t on_first =
        uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(face_v, _mm256_set1_epi32(first_face)))));
    uint32_t faces = 1u << first_face;
    for (uint32_t left = active & ~on_first; left; left &= left - 1) faces |= 1u << face8[__builtin_ctz(left)];
    __m256i inside;
    if (faces == 1u << first_face) {
        cube_face8<kBytes, kMode>(f, planes, bc, first_face, s8, t8, result, inside);
    } else {
        for (uint32_t left = faces; left; left &= left - 1) {
            const int face = __builtin_ctz(left);
            __m256 part[4];
            cube_face8<kBytes, kMode>(f, planes, bc, face, s8, t8, part, inside);
            const __m256 mine = _mm256_castsi256_ps(_mm256_cmpeq_epi32(face_v, _mm256_set1_epi32(face)));
            for (int c = 0; c < 4; ++c) result[c] = _mm256_blendv_ps(result[c], part[c], mine);
        }
    }
    store8(result, out, l, ~active & 0xFFu);
    if (cq.seamless) outside = ~uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(inside))) & active;
    return true;
}

// The blocks of 8 of lanes [l, end) by cube_block8 in one loop (the query's constants loaded
// once), each block's lanes that leave the face sampled again by cq.again: the first lane of
// the first block cube_block8 declines (the caller takes it), else the lanes' end.
template <int kBytes, LevelMode kMode>
__attribute__((target("avx2,f16c"))) int cube_run8(const CubeQuery& cq, Planes8& planes, int l, int end) {
    for (; l + 8 <= end; l += 8) {
        uint32_t outside;
        if (!cube_block8<kBytes, kMode>(cq, planes, l, outside)) return l;
        for (; outside; outside &= outside - 1) cq.again(cq.context, l + __builtin_ctz(outside));
    }
    return l;
}

using CubeBlock8 = int (*)(const CubeQuery&, Planes8&, int, int);

// The cube block for a query's storage and level mode, or null (levels of mixed storage, or
// texel numbers beyond int32: the general code).
inline CubeBlock8 cube_blocks8(const Fast2D& f, bool one_storage, LevelMode mode) {
    if (!one_storage) return nullptr;
#define SOFTGL_CUBE(B)                                                                         \
    switch (mode) {                                                                            \
        case LevelMode::FixedNearest: return cube_run8<B, LevelMode::FixedNearest>;           \
        case LevelMode::FixedLinear: return cube_run8<B, LevelMode::FixedLinear>;             \
        default: return cube_run8<B, LevelMode::PerBlock>;                                    \
    }
    if (f.planes[0].rgba8) SOFTGL_CUBE(1)
    if (f.planes[0].narrow) SOFTGL_CUBE(2)   // Image::narrow: shaped_words8 decodes the texels
    SOFTGL_CUBE(0)
#undef SOFTGL_CUBE
}

// ---- AVX-512: blocks of 16 lanes, results straight into the structure-of-arrays outputs.
#define SOFTGL_SAMPLER_AVX512 "avx512f,avx512bw,avx512dq,avx512vl,f16c"
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_*(), which -W(maybe-)uninitialized
// reports once they are inlined here (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

// ---- The LOD of 16 lanes (AVX-512): lambda8's rho² and lambdas_of_rho2_8's rounding test with
// 8 doubles per vector, the same float operations per lane up to rho² (so the same rho²), and
// each lambda either vouched for by the rounding test or taken from LambdaMemo: the same bits.

__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512d series_pair8(__m512d y, int k) {
    return _mm512_add_pd(_mm512_set1_pd(1.0 / double(2 * k + 1)), _mm512_mul_pd(y, _mm512_set1_pd(1.0 / double(2 * k + 3))));
}

// half_log2_approx4 of 8 lanes: the same steps, the same error bound.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512d half_log2_approx8(__m512d x) {
    const __m512i bits = _mm512_castpd_si512(x);
    const __m512d field = _mm512_castsi512_pd(_mm512_or_si512(_mm512_srli_epi64(bits, 52), _mm512_set1_epi64(0x4330000000000000LL)));
    __m512d e = _mm512_sub_pd(field, _mm512_set1_pd(4503599627371519.0));
    __m512d m = _mm512_castsi512_pd(_mm512_or_si512(_mm512_and_si512(bits, _mm512_set1_epi64(0x000FFFFFFFFFFFFFLL)),
                                                    _mm512_set1_epi64(0x3FF0000000000000LL)));
    const __mmask8 big = _mm512_cmp_pd_mask(m, _mm512_set1_pd(1.4142135623730951), _CMP_GT_OQ);
    m = _mm512_mask_mul_pd(m, big, m, _mm512_set1_pd(0.5));
    e = _mm512_mask_add_pd(e, big, e, _mm512_set1_pd(1.0));
    const __m512d one = _mm512_set1_pd(1.0);
    const __m512d z = _mm512_div_pd(_mm512_sub_pd(m, one), _mm512_add_pd(m, one));
    const __m512d y = _mm512_mul_pd(z, z), y2 = _mm512_mul_pd(y, y), y4 = _mm512_mul_pd(y2, y2);
    const __m512d p03 = _mm512_add_pd(series_pair8(y, 0), _mm512_mul_pd(y2, series_pair8(y, 2)));
    const __m512d p47 = _mm512_add_pd(series_pair8(y, 4), _mm512_mul_pd(y2, series_pair8(y, 6)));
    const __m512d p = _mm512_add_pd(_mm512_add_pd(p03, _mm512_mul_pd(y4, p47)),
                                    _mm512_mul_pd(_mm512_mul_pd(y4, y4), _mm512_set1_pd(1.0 / 17.0)));
    return _mm512_mul_pd(_mm512_add_pd(e, _mm512_mul_pd(_mm512_mul_pd(z, p), _mm512_set1_pd(2.0 / 0.69314718055994530942))),
                         _mm512_set1_pd(0.5));
}

// lambda_exact4 of 8 lanes (bit k: lane k sure).
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __mmask8 lambda_exact8(__m512d rho2, __m256& lambda) {
    const __m512d L = half_log2_approx8(rho2);
    const __m512d margin = _mm512_add_pd(_mm512_mul_pd(_mm512_abs_pd(L), _mm512_set1_pd(0x1p-45)), _mm512_set1_pd(0x1p-50));
    lambda = _mm512_cvtpd_ps(L);
    const __m256 lo = _mm512_cvtpd_ps(_mm512_sub_pd(L, margin)), hi = _mm512_cvtpd_ps(_mm512_add_pd(L, margin));
    const __mmask8 finite = _mm512_cmp_pd_mask(rho2, _mm512_set1_pd(0x1p-1022), _CMP_GE_OQ) &
                            _mm512_cmp_pd_mask(rho2, _mm512_set1_pd(INFINITY), _CMP_LT_OQ);
    const __mmask8 same = _mm256_cmp_ps_mask(lo, lambda, _CMP_EQ_OQ) & _mm256_cmp_ps_mask(hi, lambda, _CMP_EQ_OQ);
    return same & finite;
}

// float(log2(sqrt(rho²))) of 8 lanes plus the lanes' bias (l: the first lane), as
// lambdas_of_rho2_8: one LambdaMemo lookup when the 8 share their rho².
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m256 lambdas_of_rho2_8x(const glsl::TextureQuery& q, int l, __m512d rho2,
                                                                                LambdaMemo& lambda_of) {
    const double first = _mm512_cvtsd_f64(rho2);
    __m256 lambda;
    if (_mm512_cmp_pd_mask(rho2, _mm512_set1_pd(first), _CMP_EQ_OQ) == 0xFF) {
        lambda = _mm256_set1_ps(lambda_of(first));
    } else if (const __mmask8 sure = lambda_exact8(rho2, lambda); sure != 0xFF) {
        alignas(64) double r2[8];
        alignas(32) float out[8];
        _mm512_store_pd(r2, rho2);
        _mm256_store_ps(out, lambda);
        for (int k = 0; k < 8; ++k)
            if (!(sure >> k & 1)) out[k] = lambda_of(r2[k]);
        lambda = _mm256_load_ps(out);
    }
    if (q.lod_mode == TextureLod::Bias && q.lod) lambda = _mm256_add_ps(lambda, _mm256_loadu_ps(&q.lod[l].f));
    return lambda;
}

__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512 load16(const glsl::Scalar* p, int l) {
    return p ? _mm512_loadu_ps(&p[l].f) : _mm512_setzero_ps();
}

// (double) v² of lanes 8 * half .. 8 * half + 7.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512d square_wide16(__m512 v, int half) {
    const __m512d d = _mm512_cvtps_pd(half ? _mm512_extractf32x8_ps(v, 1) : _mm512_castps512_ps256(v));
    return _mm512_mul_pd(d, d);
}

// Bits k: lane k equals lane 0.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __mmask16 same_as_first16(__m512 v) {
    return _mm512_cmp_ps_mask(v, _mm512_broadcastss_ps(_mm512_castps512_ps128(v)), _CMP_EQ_OQ);
}

// lambda16 (below) of a block whose derivatives differ between lanes: lambda8_lanes' rho² (float
// products, widened, squared and summed in double) 8 lanes per vector.
__attribute__((target(SOFTGL_SAMPLER_AVX512), noinline)) void lambda16_lanes(const glsl::TextureQuery& q, int l, float w, float h,
                                                                             LambdaMemo& lambda_of, __m512 dx0, __m512 dx1,
                                                                             __m512 dy0, __m512 dy1, float out[16]) {
    const __m512 ws = _mm512_set1_ps(w), hs = _mm512_set1_ps(h), zero = _mm512_setzero_ps();
    const __m512 x0 = _mm512_mul_ps(dx0, ws), x1 = _mm512_mul_ps(dx1, hs);
    const __m512 y0 = _mm512_mul_ps(dy0, ws), y1 = _mm512_mul_ps(dy1, hs);
    const __m512 x2 = _mm512_mul_ps(load16(q.ddx[2], l), zero), y2 = _mm512_mul_ps(load16(q.ddy[2], l), zero);
    for (int half = 0; half < 2; ++half) {
        __m512d lx2 = _mm512_add_pd(square_wide16(x0, half), square_wide16(x1, half));
        __m512d ly2 = _mm512_add_pd(square_wide16(y0, half), square_wide16(y1, half));
        if (q.ddx[2]) lx2 = _mm512_add_pd(lx2, square_wide16(x2, half));
        if (q.ddy[2]) ly2 = _mm512_add_pd(ly2, square_wide16(y2, half));
        // _mm512_max_pd(a, b) is b when unordered: std::max(lx2, ly2), NaN included.
        _mm256_store_ps(out + 8 * half, lambdas_of_rho2_8x(q, l + 8 * half, _mm512_max_pd(ly2, lx2), lambda_of));
    }
}

// lambda8 of lanes l..l+15 (Implicit, Bias, Gradient): one LambdaMemo lookup when all 16 share
// their derivatives (affine coordinates), else lambda16_lanes.
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline void lambda16(const glsl::TextureQuery& q, int l, float w,
                                                                                   float h, LambdaMemo& lambda_of, float out[16]) {
    const __m512 dx0 = load16(q.ddx[0], l), dx1 = load16(q.ddx[1], l), dy0 = load16(q.ddy[0], l), dy1 = load16(q.ddy[1], l);
    if (!q.ddx[2] && !q.ddy[2]) {
        if ((same_as_first16(dx0) & same_as_first16(dx1) & same_as_first16(dy0) & same_as_first16(dy1)) == 0xFFFF) {
            // As lambda8: lane 0's rho², computed as lambda_at does.
            const float x0 = _mm512_cvtss_f32(dx0) * w, x1 = _mm512_cvtss_f32(dx1) * h;
            const float y0 = _mm512_cvtss_f32(dy0) * w, y1 = _mm512_cvtss_f32(dy1) * h;
            const double lx2 = double(x0) * x0 + double(x1) * x1, ly2 = double(y0) * y0 + double(y1) * y1;
            __m512 lambda = _mm512_set1_ps(lambda_of(std::max(lx2, ly2)));
            if (q.lod_mode == TextureLod::Bias && q.lod) lambda = _mm512_add_ps(lambda, _mm512_loadu_ps(&q.lod[l].f));
            _mm512_storeu_ps(out, lambda);
            return;
        }
    }
    lambda16_lanes(q, l, w, h, lambda_of, dx0, dx1, dy0, dy1, out);
}


// ifloor_floored8 of 16 lanes.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512i ifloor_floored16(__m512 fl) {
    const __m512 lo = _mm512_set1_ps(-1073741824.0f), hi = _mm512_set1_ps(1073741824.0f);
    const __m512i i = _mm512_min_epi32(_mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(fl, lo), hi)),
                                       _mm512_set1_epi32(1073741823));
    return _mm512_maskz_mov_epi32(_mm512_cmp_ps_mask(fl, fl, _CMP_ORD_Q), i);
}

// wrap_one (pair: false) or the second coordinate of wrap_pair (pair: true) of 16 lanes, i the
// floored coordinate; REPEAT of a power of two and CLAMP_TO_EDGE here, the rest lane by lane.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline void wrap16(GLenum mode, __m512i i, int32_t size, bool pot,
                                                                  bool pair, __m512i& a, __m512i& b) {
    const __m512i last = _mm512_set1_epi32(size - 1), one = _mm512_set1_epi32(1);
    if (mode == gl::REPEAT && pot) {
        a = _mm512_and_si512(i, last);
        if (pair) b = _mm512_and_si512(_mm512_add_epi32(i, one), last);
    } else if (mode == gl::CLAMP_TO_EDGE) {
        const __m512i zero = _mm512_setzero_si512();
        a = _mm512_max_epi32(_mm512_min_epi32(i, last), zero);
        if (pair) b = _mm512_max_epi32(_mm512_min_epi32(_mm512_add_epi32(i, one), last), zero);
    } else {
        alignas(64) int32_t raw[16], wa[16], wb[16] = {};
        _mm512_store_si512(raw, i);
        for (int l = 0; l < 16; ++l) {
            if (pair) wrap_pair(mode, raw[l], size, pot, wa[l], wb[l]);
            else wa[l] = wrap_one(mode, raw[l], size, pot);
        }
        a = _mm512_load_si512(wa);
        b = _mm512_load_si512(wb);
    }
}

// Where the texels of lane l's layer start: one plane for all lanes, or (2D arrays, kLayered)
// each lane's own layer.
template <bool kLayered>
struct Layers16 {
    const float* plane;
    const uint16_t* half;   // 16-bit float planes (SampledLevel::half; plane null)
    size_t lane[kLayered ? 16 : 1];   // the element where lane l's layer starts
    // Floats (halves) per texel and the absent channels' values (SampledLevel::color_channels, color_fill).
    int32_t channels;
    const float* fill;
    size_t at(int l) const { return kLayered ? lane[l] : 0; }
};

// The texels of 16 lanes (at(l) + 4 * index[l]) as four channel vectors: out[c] lane l =
// texel l's channel c. Four texels per register (lanes k, k + 4, k + 8, k + 12), then a 4x4
// transpose in every 128-bit slot.
template <bool kLayered>
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline void texels16(const Layers16<kLayered>& layers, __m512i index,
                                                                    __m512 out[4]) {
    alignas(64) int32_t at[16];
    _mm512_store_si512(at, _mm512_mullo_epi32(index, _mm512_set1_epi32(layers.channels)));
    __m512 r[4];
    if (!kLayered && layers.half) {   // one plane: half_texels8 of each 8 lanes
        const __m512i e = _mm512_mullo_epi32(index, _mm512_set1_epi32(layers.channels));
        __m256 lo[4], hi[4];
        half_texels8(layers.half, _mm512_castsi512_si256(e), lo);
        half_texels8(layers.half, _mm512_extracti64x4_epi64(e, 1), hi);
        for (int c = 0; c < 4; ++c)
            out[c] = c < layers.channels ? _mm512_insertf32x8(_mm512_castps256_ps512(lo[c]), hi[c], 1) : _mm512_set1_ps(layers.fill[c]);
        return;
    }
    if (layers.half) {
        // 4 texels' halves (lanes k, k + 4, k + 8, k + 12) in one 256-bit register, converted at once.
        const uint16_t* h = layers.half;
        for (int k = 0; k < 4; ++k) {
            const __m256i x = _mm256_setr_epi64x(load_u64(h + layers.at(k) + at[k]), load_u64(h + layers.at(k + 4) + at[k + 4]),
                                                 load_u64(h + layers.at(k + 8) + at[k + 8]),
                                                 load_u64(h + layers.at(k + 12) + at[k + 12]));
            r[k] = _mm512_cvtph_ps(x);
        }
    } else {
        for (int k = 0; k < 4; ++k) {
            r[k] = _mm512_castps128_ps512(_mm_loadu_ps(layers.plane + layers.at(k) + at[k]));
            for (int m = 1; m < 4; ++m)
                r[k] = _mm512_insertf32x4(r[k], _mm_loadu_ps(layers.plane + layers.at(k + 4 * m) + at[k + 4 * m]), m);
        }
    }
    const __m512d t0 = _mm512_castps_pd(_mm512_unpacklo_ps(r[0], r[1])), t1 = _mm512_castps_pd(_mm512_unpackhi_ps(r[0], r[1]));
    const __m512d t2 = _mm512_castps_pd(_mm512_unpacklo_ps(r[2], r[3])), t3 = _mm512_castps_pd(_mm512_unpackhi_ps(r[2], r[3]));
    out[0] = _mm512_castpd_ps(_mm512_unpacklo_pd(t0, t2));
    out[1] = _mm512_castpd_ps(_mm512_unpackhi_pd(t0, t2));
    out[2] = _mm512_castpd_ps(_mm512_unpacklo_pd(t1, t3));
    out[3] = _mm512_castpd_ps(_mm512_unpackhi_pd(t1, t3));
    for (int c = layers.channels; c < 4; ++c) out[c] = _mm512_set1_ps(layers.fill[c]);   // absent channels
}

// k / 255 of 16 lanes (0 <= k <= 255), correctly rounded as unorm()'s division, without one: q =
// k * (1/255) is off by at most an ulp, the residual k - 255 q is exact in one FMA, and q + r / 255
// in one more rounds to the quotient (checked for all 256 k by test_rgba8_copy_every_byte_value).
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) inline __m512 unorm8_16(__m512i k) {
    const __m512 kf = _mm512_cvtepi32_ps(k), inv = _mm512_set1_ps(1.0f / 255.0f);
    const __m512 q = _mm512_mul_ps(kf, inv);
    const __m512 r = _mm512_fnmadd_ps(q, _mm512_set1_ps(255.0f), kf);
    return _mm512_fmadd_ps(r, inv, q);
}

// weight8 of 16 lanes (as weight8x8).
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512 weight8x16(__m512 frac) {
    const __m512 k256 = _mm512_set1_ps(256.0f);
    const __m512 w = _mm512_roundscale_ps(_mm512_mul_ps(frac, k256), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    return _mm512_min_ps(_mm512_max_ps(w, _mm512_setzero_ps()), k256);
}

// The four channels of 16 packed texels as k / 255, the floats the storage holds, or (bytes:
// true) as k, for the fixed-point rule.
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) inline void unpack16(__m512i t, __m512 out[4], bool bytes) {
    const __m512i byte = _mm512_set1_epi32(255);
    for (int c = 0; c < 4; ++c) {
        const __m512i k = _mm512_and_si512(_mm512_srli_epi32(t, 8 * c), byte);
        out[c] = bytes ? _mm512_cvtepi32_ps(k) : unorm8_16(k);
    }
}

// narrow_words8 of 16 lanes.
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline __m512i narrow_words16(const Plane& p, __m512i index) {
    const __m512i at = _mm512_sll_epi32(index, _mm_cvtsi32_si128(p.narrow_bytes - 1));
    const __m512i w = _mm512_i32gather_epi32(at, p.narrow, 1);
    const __m512i order = _mm512_broadcast_i32x4(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p.narrow_shuffle)));
    return _mm512_or_si512(_mm512_shuffle_epi8(w, order), _mm512_set1_epi32(int(p.narrow_fill)));
}

// unorm8_words8 of 16 lanes.
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline __m512i unorm8_words16(const Plane& p, __m512i index) {
    if (p.rgba8) return _mm512_i32gather_epi32(index, p.rgba8, 4);
    return narrow_words16(p, index);
}

// shaped_words8 of 16 lanes.
template <int kBytes>
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline __m512i shaped_words16(const Plane& p, __m512i index) {
    if constexpr (kBytes == 2) return narrow_words16(p, index);
    else return _mm512_i32gather_epi32(index, p.rgba8, 4);
}

// texels16 from 8-bit unorm storage (Image::rgba8 or Image::narrow): one gather.
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) inline void texels16(const Plane& p, __m512i index, __m512 out[4],
                                                                          bool bytes = false) {
    unpack16(unorm8_words16(p, index), out, bytes);
}

// texel_pairs16 from a byte copy: two gathers of 8-byte pairs.
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) inline void texel_pairs16(const uint32_t* rgba8, __m512i index,
                                                                               __m512 left[4], __m512 right[4],
                                                                               bool bytes = false) {
    const __m512i p0 = _mm512_i32gather_epi64(_mm512_castsi512_si256(index), rgba8, 4);
    const __m512i p1 = _mm512_i32gather_epi64(_mm512_extracti64x4_epi64(index, 1), rgba8, 4);
    // The low halves are the left texels, the high halves the right ones.
    unpack16(_mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(p0)), _mm512_cvtepi64_epi32(p1), 1), left, bytes);
    unpack16(_mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(_mm512_srli_epi64(p0, 32))),
                                _mm512_cvtepi64_epi32(_mm512_srli_epi64(p1, 32)), 1), right, bytes);
}

// texels16 of two horizontally adjacent texels per lane (index[l] and index[l] + 1 in one row),
// read as one 8-float load each: left[c] and right[c] are their channel vectors. Register m holds
// lanes m and m + 4 (m < 4) or m + 4 and m + 8, so that after an 8x8 transpose in each 256-bit
// half the 128-bit slots of lanes 0-3, 4-7, 8-11, 12-15 sit two per register.
template <bool kLayered>
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline void texel_pairs16(const Layers16<kLayered>& layers,
                                                                         __m512i index, __m512 left[4], __m512 right[4]) {
    alignas(64) int32_t at[16];
    _mm512_store_si512(at, _mm512_slli_epi32(index, 2));
    __m512 x[8];
    for (int m = 0; m < 8; ++m) {
        const int l = m < 4 ? m : m + 4;
        if (layers.half)   // two texels' 8 halves per load, converted at once
            x[m] = _mm512_insertf32x8(_mm512_castps256_ps512(halves8(layers.half + layers.at(l) + at[l])),
                                      halves8(layers.half + layers.at(l + 4) + at[l + 4]), 1);
        else
            x[m] = _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_loadu_ps(layers.plane + layers.at(l) + at[l])),
                                      _mm256_loadu_ps(layers.plane + layers.at(l + 4) + at[l + 4]), 1);
    }
    // s[4 * h + c]: channel c of lanes 8h .. 8h + 3 (left texel in slot 0, right in slot 1) and
    // of lanes 8h + 4 .. 8h + 7 (slots 2 and 3).
    __m512 s[8];
    for (int h = 0; h < 2; ++h) {
        const __m512* y = x + 4 * h;
        const __m512 t0 = _mm512_unpacklo_ps(y[0], y[1]), t1 = _mm512_unpackhi_ps(y[0], y[1]);
        const __m512 t2 = _mm512_unpacklo_ps(y[2], y[3]), t3 = _mm512_unpackhi_ps(y[2], y[3]);
        s[4 * h + 0] = _mm512_shuffle_ps(t0, t2, 0x44);
        s[4 * h + 1] = _mm512_shuffle_ps(t0, t2, 0xEE);
        s[4 * h + 2] = _mm512_shuffle_ps(t1, t3, 0x44);
        s[4 * h + 3] = _mm512_shuffle_ps(t1, t3, 0xEE);
    }
    for (int c = 0; c < 4; ++c) {
        left[c] = _mm512_shuffle_f32x4(s[c], s[4 + c], _MM_SHUFFLE(2, 0, 2, 0));
        right[c] = _mm512_shuffle_f32x4(s[c], s[4 + c], _MM_SHUFFLE(3, 1, 3, 1));
    }
}

// filter8 of one plane for 16 lanes, out[c] = channel c of the 16 results.
template <bool kLayered>
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) void filter16(const Fast2D& f, const Plane& p, bool linear,
                                                             const float* s, const float* t, const float* r,
                                                             __m512 out[4]) {
    Layers16<kLayered> layers{p.color, p.half, {}, p.color_channels, p.color_fill};
    // Byte planes: each lane's first texel of its layer, added to the gathers' indices (int32:
    // filter16 below takes planes whose texel numbers fit).
    alignas(64) int32_t layer_start[16] = {};
    if constexpr (kLayered)
        for (int l = 0; l < 16; ++l) {
            const size_t start = size_t(std::clamp(ifloor(r[l] + 0.5f), 0, p.layers - 1)) * size_t(p.height) * size_t(p.width);
            if (p.rgba8 || p.narrow) layer_start[l] = int32_t(start);
            else layers.lane[l] = start * p.color_channels;
        }
    const __m512i layer0 = _mm512_load_si512(layer_start);
    const __m512 u = _mm512_add_ps(_mm512_mul_ps(_mm512_loadu_ps(s), _mm512_set1_ps(float(p.width))), _mm512_set1_ps(float(f.off_s)));
    const __m512 v = _mm512_add_ps(_mm512_mul_ps(_mm512_loadu_ps(t), _mm512_set1_ps(float(p.height))), _mm512_set1_ps(float(f.off_t)));
    const __m512i width = _mm512_set1_epi32(p.width);
    __m512i i0, i1, j0, j1;
    if (!linear) {
        wrap16(f.wrap_s, ifloor_floored16(_mm512_floor_ps(u)), p.width, p.width_pot, false, i0, i1);
        wrap16(f.wrap_t, ifloor_floored16(_mm512_floor_ps(v)), p.height, p.height_pot, false, j0, j1);
        // Texel indices in int32: 4 * w * h <= 2^30 floats (kMaxTextureSize is 16384).
        const __m512i index = _mm512_add_epi32(_mm512_mullo_epi32(j0, width), i0);
        if (p.rgba8 || p.narrow) texels16(p, _mm512_add_epi32(layer0, index), out);
        else texels16(layers, index, out);
        return;
    }
    const __m512 half = _mm512_set1_ps(0.5f), one = _mm512_set1_ps(1.0f);
    const __m512 u0 = _mm512_sub_ps(u, half), v0 = _mm512_sub_ps(v, half);
    const __m512 fu = _mm512_floor_ps(u0), fv = _mm512_floor_ps(v0);
    wrap16(f.wrap_s, ifloor_floored16(fu), p.width, p.width_pot, true, i0, i1);
    wrap16(f.wrap_t, ifloor_floored16(fv), p.height, p.height_pot, true, j0, j1);
    const __m512 a = _mm512_sub_ps(u0, fu), b = _mm512_sub_ps(v0, fv);
    __m512 w[4];
    if (p.unorm8) {
        // The fixed-point rule (Level::filter): weight8 of 16 lanes, texels as bytes k below.
        const __m512 k256 = _mm512_set1_ps(256.0f);
        const __m512 A = weight8x16(a), B = weight8x16(b), nA = _mm512_sub_ps(k256, A), nB = _mm512_sub_ps(k256, B);
        w[0] = _mm512_mul_ps(nA, nB), w[1] = _mm512_mul_ps(A, nB), w[2] = _mm512_mul_ps(nA, B), w[3] = _mm512_mul_ps(A, B);
    } else {
        const __m512 na = _mm512_sub_ps(one, a), nb = _mm512_sub_ps(one, b);
        w[0] = _mm512_mul_ps(na, nb), w[1] = _mm512_mul_ps(a, nb), w[2] = _mm512_mul_ps(na, b), w[3] = _mm512_mul_ps(a, b);
    }
    const __m512i row0 = _mm512_mullo_epi32(j0, width), row1 = _mm512_mullo_epi32(j1, width);
    const __m512i brow0 = _mm512_add_epi32(layer0, row0), brow1 = _mm512_add_epi32(layer0, row1);   // byte planes
    __m512 texel[4][4];   // t00, t10, t01, t11
    const bool pairs = _mm512_cmpeq_epi32_mask(i1, _mm512_add_epi32(i0, _mm512_set1_epi32(1))) == 0xFFFF;
    const bool bytes = p.unorm8;   // rgba8 texels as k for the fixed-point rule
    if (p.rgba8 && pairs) {
        texel_pairs16(p.rgba8, _mm512_add_epi32(brow0, i0), texel[0], texel[1], bytes);
        texel_pairs16(p.rgba8, _mm512_add_epi32(brow1, i0), texel[2], texel[3], bytes);
    } else if (p.rgba8 || p.narrow) {   // (narrow planes: no pair gathers)
        texels16(p, _mm512_add_epi32(brow0, i0), texel[0], bytes);
        texels16(p, _mm512_add_epi32(brow0, i1), texel[1], bytes);
        texels16(p, _mm512_add_epi32(brow1, i0), texel[2], bytes);
        texels16(p, _mm512_add_epi32(brow1, i1), texel[3], bytes);
    } else if (pairs && p.color_channels == 4) {
        // No lane wraps between its columns: each row's two texels are neighbours in memory
        // (one 8-float load: 4 floats a texel).
        texel_pairs16(layers, _mm512_add_epi32(row0, i0), texel[0], texel[1]);
        texel_pairs16(layers, _mm512_add_epi32(row1, i0), texel[2], texel[3]);
    } else {
        texels16(layers, _mm512_add_epi32(row0, i0), texel[0]);
        texels16(layers, _mm512_add_epi32(row0, i1), texel[1]);
        texels16(layers, _mm512_add_epi32(row1, i0), texel[2]);
        texels16(layers, _mm512_add_epi32(row1, i1), texel[3]);
    }
    if (p.unorm8) {
        // Exact integer sums (any order), one correctly rounded division.
        const __m512 k255 = _mm512_set1_ps(255.0f), divisor = _mm512_set1_ps(kUnorm8Divisor);
        for (int c = 0; c < 4; ++c) {
            __m512 k[4];
            for (int n = 0; n < 4; ++n) k[n] = p.rgba8 || p.narrow ? texel[n][c] : _mm512_mul_ps(texel[n][c], k255);
            __m512 sum = _mm512_mul_ps(w[0], k[0]);
            for (int n = 1; n < 4; ++n) sum = _mm512_fmadd_ps(w[n], k[n], sum);
            out[c] = _mm512_div_ps(sum, divisor);
        }
        return;
    }
    // w00 * t00 + w10 * t10 + w01 * t01 + w11 * t11, left to right, as Fast2D::filter.
    for (int c = 0; c < 4; ++c) {
        out[c] = _mm512_mul_ps(w[0], texel[0][c]);
        for (int k = 1; k < 4; ++k) out[c] = _mm512_add_ps(out[c], _mm512_mul_ps(w[k], texel[k][c]));
    }
}

__attribute__((target(SOFTGL_SAMPLER_AVX512))) void filter16(const Fast2D& f, const Plane& p, bool linear,
                                                             const float* s, const float* t, const float* r,
                                                             __m512 out[4]) {
    if (!int32_indices(p)) {
        // Texel numbers beyond int32 (huge 2D arrays): lane by lane.
        __m256 lo[4], hi[4];
        filter8_lanes(f, p, linear, s, t, r, lo);
        filter8_lanes(f, p, linear, s + 8, t + 8, r ? r + 8 : nullptr, hi);
        for (int c = 0; c < 4; ++c) out[c] = _mm512_insertf32x8(_mm512_castps256_ps512(lo[c]), hi[c], 1);
        return;
    }
    if (r) filter16<true>(f, p, linear, s, t, r, out);
    else filter16<false>(f, p, linear, s, t, r, out);
}

// filter8(LevelChoice) of 16 lanes that share the levels, into lanes l .. l + 15 of the outputs.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) void filter16(const Fast2D& f, const LevelChoice ch[16], const float* s,
                                                             const float* t, const float* r, glsl::Scalar* const out[4],
                                                             int l) {
    __m512 a[4];
    filter16(f, f.planes[size_t(ch[0].first)], ch[0].linear, s, t, r, a);
    if (ch[0].second >= 0) {
        __m512 b[4];
        filter16(f, f.planes[size_t(ch[0].second)], ch[0].linear, s, t, r, b);
        alignas(64) float frac[16];
        for (int k = 0; k < 16; ++k) frac[k] = ch[k].frac;
        const __m512 g = _mm512_load_ps(frac), ng = _mm512_sub_ps(_mm512_set1_ps(1.0f), g);
        for (int c = 0; c < 4; ++c) a[c] = _mm512_add_ps(_mm512_mul_ps(ng, a[c]), _mm512_mul_ps(g, b[c]));
    }
    for (int c = 0; c < 4; ++c)
        if (out[c]) _mm512_storeu_ps(&out[c][l].f, a[c]);
}
// filter16(LevelChoice) of 16 lanes whose levels differ (as filter8 above).
__attribute__((target(SOFTGL_SAMPLER_AVX512))) void filter16(const Fast2D& f, const LevelChoice ch[16], const int32_t levels[3],
                                                             int count, const float* s, const float* t, const float* r,
                                                             glsl::Scalar* const out[4], int l) {
    __m512 by_level[3][4];
    for (int i = 0; i < count; ++i) filter16(f, f.planes[size_t(levels[i])], ch[0].linear, s, t, r, by_level[i]);
    alignas(64) float frac[16];
    __mmask16 first[3] = {0, 0, 0}, second[3] = {0, 0, 0};
    for (int k = 0; k < 16; ++k) {
        frac[k] = ch[k].frac;
        for (int i = 0; i < count; ++i) {
            if (ch[k].first == levels[i]) first[i] |= __mmask16(1u << k);
            if (ch[k].second == levels[i]) second[i] |= __mmask16(1u << k);
        }
    }
    const __mmask16 blended = __mmask16(second[0] | second[1] | second[2]);
    const __m512 g = _mm512_load_ps(frac), ng = _mm512_sub_ps(_mm512_set1_ps(1.0f), g);
    for (int c = 0; c < 4; ++c) {
        __m512 a = by_level[0][c], b = by_level[0][c];
        for (int i = 1; i < count; ++i) {
            a = _mm512_mask_mov_ps(a, first[i], by_level[i][c]);
            b = _mm512_mask_mov_ps(b, second[i], by_level[i][c]);
        }
        a = _mm512_mask_mov_ps(a, blended, _mm512_add_ps(_mm512_mul_ps(ng, a), _mm512_mul_ps(g, b)));
        if (out[c]) _mm512_storeu_ps(&out[c][l].f, a);
    }
}
// colour_blocks8 in blocks of 16 (AVX-512) over lanes [l, q.lane_count): returns where it
// stopped, at the first block of 16 whose lanes need more than 3 levels or two filters (the
// caller takes it in blocks of 8), or where fewer than 16 lanes are left.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) int colour_blocks16(const ColourQuery& cq, int l) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    LevelChoice ch[16];
    if (!cq.needs_lambda) std::fill(ch, ch + 16, cq.fixed);
    int32_t levels[3];
    for (; l + 16 <= q.lane_count; l += 16) {
        const __mmask16 active = q.active ? _mm512_test_epi32_mask(_mm512_loadu_si512(q.active + l), _mm512_set1_epi32(-1))
                                          : __mmask16(0xFFFF);
        const float* s = &q.coord[0][l].f;
        const float* t = &q.coord[1][l].f;
        const float* r = cq.r ? cq.r + l : nullptr;
        if (active) {
            if (cq.needs_lambda) choose_lanes(cq, l, 16, active, ch);
            if (!cq.needs_lambda || same_levels(ch, 16)) filter16(f, ch, s, t, r, out, l);
            else if (const int count = distinct_levels(ch, 16, levels)) filter16(f, ch, levels, count, s, t, r, out, l);
            else return l;
        }
        if (active != 0xFFFF)
            // Inactive lanes: (0, 0, 0, 1), as sample_lanes gives them.
            for (int c = 0; c < 4; ++c)
                if (out[c]) _mm512_mask_storeu_ps(&out[c][l].f, __mmask16(~active), _mm512_set1_ps(c == 3 ? 1.0f : 0.0f));
    }
    return l;
}

// ---- colour_blocks8_shaped in blocks of 16 (AVX-512): filter16's operations with the storage,
// filter and wrap modes fixed at compile time (the same bits; see kColourBlocks8 above).

template <WrapKind kWrap, bool kPair>
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline void wrap_shaped16(__m512i i, __m512i last, __m512i& a,
                                                                                      __m512i& b) {
    const __m512i one = _mm512_set1_epi32(1);
    if constexpr (kWrap == WrapKind::RepeatPot) {
        a = _mm512_and_si512(i, last);
        if constexpr (kPair) b = _mm512_and_si512(_mm512_add_epi32(i, one), last);
    } else {
        const __m512i zero = _mm512_setzero_si512();
        a = _mm512_max_epi32(_mm512_min_epi32(i, last), zero);
        if constexpr (kPair) b = _mm512_max_epi32(_mm512_min_epi32(_mm512_add_epi32(i, one), last), zero);
    }
}

// unorm8_rows8 of 16 lanes (texels as the packed bytes).
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline void unorm8_row16(__m512i left, __m512i right, __m512i wa,
                                                                                     __m512i nwa, __m512 h[4]) {
    const __m512i bytes = _mm512_set1_epi32(0x00FF00FF), low = _mm512_set1_epi32(0xFFFF);
    const __m512i even = _mm512_add_epi16(_mm512_mullo_epi16(_mm512_and_si512(left, bytes), nwa),
                                          _mm512_mullo_epi16(_mm512_and_si512(right, bytes), wa));
    const __m512i odd = _mm512_add_epi16(_mm512_mullo_epi16(_mm512_and_si512(_mm512_srli_epi32(left, 8), bytes), nwa),
                                         _mm512_mullo_epi16(_mm512_and_si512(_mm512_srli_epi32(right, 8), bytes), wa));
    h[0] = _mm512_cvtepi32_ps(_mm512_and_si512(even, low));
    h[1] = _mm512_cvtepi32_ps(_mm512_and_si512(odd, low));
    h[2] = _mm512_cvtepi32_ps(_mm512_srli_epi32(even, 16));
    h[3] = _mm512_cvtepi32_ps(_mm512_srli_epi32(odd, 16));
}

__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline void unorm8_rows16(__m512i t00, __m512i t10, __m512i t01,
                                                                                      __m512i t11, __m512 A, __m512 B,
                                                                                      __m512 out[4]) {
    const __m512i ai = _mm512_cvttps_epi32(A), nai = _mm512_sub_epi32(_mm512_set1_epi32(256), ai);
    const __m512i wa = _mm512_or_si512(ai, _mm512_slli_epi32(ai, 16)), nwa = _mm512_or_si512(nai, _mm512_slli_epi32(nai, 16));
    __m512 h0[4], h1[4];
    unorm8_row16(t00, t10, wa, nwa, h0);
    unorm8_row16(t01, t11, wa, nwa, h1);
    const __m512 nB = _mm512_sub_ps(_mm512_set1_ps(256.0f), B), divisor = _mm512_set1_ps(kUnorm8Divisor);
    for (int c = 0; c < 4; ++c)
        out[c] = _mm512_div_ps(_mm512_add_ps(_mm512_mul_ps(nB, h0[c]), _mm512_mul_ps(B, h1[c])), divisor);
}

// The packed texels index[l] and index[l] + 1 of 16 lanes by two gathers of 8-byte pairs.
__attribute__((target(SOFTGL_SAMPLER_AVX512), always_inline)) inline void packed_pairs16(const uint32_t* rgba8, __m512i index,
                                                                                       __m512i& left, __m512i& right) {
    const __m512i p0 = _mm512_i32gather_epi64(_mm512_castsi512_si256(index), rgba8, 4);
    const __m512i p1 = _mm512_i32gather_epi64(_mm512_extracti64x4_epi64(index, 1), rgba8, 4);
    left = _mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(p0)), _mm512_cvtepi64_epi32(p1), 1);
    right = _mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(_mm512_srli_epi64(p0, 32))),
                               _mm512_cvtepi64_epi32(_mm512_srli_epi64(p1, 32)), 1);
}

// filter16 of one plane of one layer (planes whose texel numbers fit int32).
template <int kBytes, bool kLinear, WrapKind kWrap>
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"), always_inline)) inline void filter16_shaped(const Fast2D& f, const Plane& p,
                                                                                               const float* s, const float* t,
                                                                                               __m512 out[4]) {
    const Layers16<false> layers{p.color, p.half, {}, p.color_channels, p.color_fill};
    const __m512 u = _mm512_add_ps(_mm512_mul_ps(_mm512_loadu_ps(s), _mm512_set1_ps(float(p.width))), _mm512_set1_ps(float(f.off_s)));
    const __m512 v = _mm512_add_ps(_mm512_mul_ps(_mm512_loadu_ps(t), _mm512_set1_ps(float(p.height))), _mm512_set1_ps(float(f.off_t)));
    const __m512i width = _mm512_set1_epi32(p.width);
    const __m512i last_i = _mm512_set1_epi32(p.width - 1), last_j = _mm512_set1_epi32(p.height - 1);
    __m512i i0, i1, j0, j1;
    if constexpr (!kLinear) {
        wrap_shaped16<kWrap, false>(ifloor_floored16(_mm512_floor_ps(u)), last_i, i0, i1);
        wrap_shaped16<kWrap, false>(ifloor_floored16(_mm512_floor_ps(v)), last_j, j0, j1);
        const __m512i index = _mm512_add_epi32(_mm512_mullo_epi32(j0, width), i0);
        if constexpr (kBytes) unpack16(shaped_words16<kBytes>(p, index), out, false);
        else texels16(layers, index, out);
    } else {
        const __m512 half = _mm512_set1_ps(0.5f), one = _mm512_set1_ps(1.0f);
        const __m512 u0 = _mm512_sub_ps(u, half), v0 = _mm512_sub_ps(v, half);
        const __m512 fu = _mm512_floor_ps(u0), fv = _mm512_floor_ps(v0);
        wrap_shaped16<kWrap, true>(ifloor_floored16(fu), last_i, i0, i1);
        wrap_shaped16<kWrap, true>(ifloor_floored16(fv), last_j, j0, j1);
        const __m512 a = _mm512_sub_ps(u0, fu), b = _mm512_sub_ps(v0, fv);
        __m512 w[4];
        if constexpr (kBytes) {
            // The fixed-point rule by rows (unorm8_rows16): the texels as their packed bytes.
            const __m512i row0 = _mm512_mullo_epi32(j0, width), row1 = _mm512_mullo_epi32(j1, width);
            __m512i t[4];   // t00, t10, t01, t11
            if (kBytes == 1 && _mm512_cmpeq_epi32_mask(i1, _mm512_add_epi32(i0, _mm512_set1_epi32(1))) == 0xFFFF) {
                packed_pairs16(p.rgba8, _mm512_add_epi32(row0, i0), t[0], t[1]);
                packed_pairs16(p.rgba8, _mm512_add_epi32(row1, i0), t[2], t[3]);
            } else {
                t[0] = shaped_words16<kBytes>(p, _mm512_add_epi32(row0, i0));   // (narrow planes: here)
                t[1] = shaped_words16<kBytes>(p, _mm512_add_epi32(row0, i1));
                t[2] = shaped_words16<kBytes>(p, _mm512_add_epi32(row1, i0));
                t[3] = shaped_words16<kBytes>(p, _mm512_add_epi32(row1, i1));
            }
            unorm8_rows16(t[0], t[1], t[2], t[3], weight8x16(a), weight8x16(b), out);
            return;
        } else {
            const __m512 na = _mm512_sub_ps(one, a), nb = _mm512_sub_ps(one, b);
            w[0] = _mm512_mul_ps(na, nb), w[1] = _mm512_mul_ps(a, nb), w[2] = _mm512_mul_ps(na, b), w[3] = _mm512_mul_ps(a, b);
        }
        const __m512i row0 = _mm512_mullo_epi32(j0, width), row1 = _mm512_mullo_epi32(j1, width);
        __m512 texel[4][4];   // t00, t10, t01, t11
        const bool pairs = _mm512_cmpeq_epi32_mask(i1, _mm512_add_epi32(i0, _mm512_set1_epi32(1))) == 0xFFFF;
        {
            if (pairs && p.color_channels == 4) {   // (one 8-float load: 4 floats a texel)
                texel_pairs16(layers, _mm512_add_epi32(row0, i0), texel[0], texel[1]);
                texel_pairs16(layers, _mm512_add_epi32(row1, i0), texel[2], texel[3]);
            } else {
                texels16(layers, _mm512_add_epi32(row0, i0), texel[0]);
                texels16(layers, _mm512_add_epi32(row0, i1), texel[1]);
                texels16(layers, _mm512_add_epi32(row1, i0), texel[2]);
                texels16(layers, _mm512_add_epi32(row1, i1), texel[3]);
            }
            // w00 * t00 + w10 * t10 + w01 * t01 + w11 * t11, left to right, as Fast2D::filter.
            for (int c = 0; c < 4; ++c) {
                out[c] = _mm512_mul_ps(w[0], texel[0][c]);
                for (int k = 1; k < 4; ++k) out[c] = _mm512_add_ps(out[c], _mm512_mul_ps(w[k], texel[k][c]));
            }
        }
    }
}

template <int kBytes, WrapKind kWrap>
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"), always_inline)) inline void filter16_shaped(const Fast2D& f, const Plane& p,
                                                                                               bool linear, const float* s,
                                                                                               const float* t, __m512 out[4]) {
    if (linear) filter16_shaped<kBytes, true, kWrap>(f, p, s, t, out);
    else filter16_shaped<kBytes, false, kWrap>(f, p, s, t, out);
}

// colour_blocks16 of one query shape: returns where it stopped (as colour_blocks16).
template <int kBytes, WrapKind kWrap, LevelMode kMode>
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) int colour_blocks16_shaped(const ColourQuery& cq, int l) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    const Plane& fixed = f.planes[size_t(cq.fixed.first)];
    LevelChoice ch[16];
    int32_t levels[3];
    for (; l + 16 <= q.lane_count; l += 16) {
        const __mmask16 active = q.active ? _mm512_test_epi32_mask(_mm512_loadu_si512(q.active + l), _mm512_set1_epi32(-1))
                                          : __mmask16(0xFFFF);
        const float* s = &q.coord[0][l].f;
        const float* t = &q.coord[1][l].f;
        if (active) {
            __m512 a[4];
            bool stored = false;   // (the general blocks store their results themselves)
            if constexpr (kMode == LevelMode::FixedNearest) {
                filter16_shaped<kBytes, false, kWrap>(f, fixed, s, t, a);
            } else if constexpr (kMode == LevelMode::FixedLinear) {
                filter16_shaped<kBytes, true, kWrap>(f, fixed, s, t, a);
            } else {
                // Both halves' lambdas, inactive lanes taking the first active lane's.
                alignas(64) float lambda[16];
                if (q.lod_mode == TextureLod::Explicit)
                    _mm512_store_ps(lambda, q.lod ? _mm512_loadu_ps(&q.lod[l].f) : _mm512_setzero_ps());
                else
                    lambda16(q, l, cq.w, cq.h, *cq.memo, lambda);
                __m512 v = _mm512_load_ps(lambda);
                if (active != 0xFFFF) v = _mm512_mask_mov_ps(_mm512_set1_ps(lambda[__builtin_ctz(active)]), active, v);
                BlockChoice lo, hi;
                const bool chosen = choose_block8(f, _mm512_castps512_ps256(v), lo) &&
                                    choose_block8(f, _mm512_extractf32x8_ps(v, 1), hi) && lo.linear == hi.linear;
                if (chosen && lo.first == hi.first && lo.second == hi.second) {
                    filter16_shaped<kBytes, kWrap>(f, f.planes[size_t(lo.first)], lo.linear, s, t, a);
                    if (lo.second >= 0) {
                        __m512 b[4];
                        filter16_shaped<kBytes, kWrap>(f, f.planes[size_t(lo.second)], lo.linear, s, t, b);
                        const __m512 g = _mm512_insertf32x8(_mm512_castps256_ps512(lo.frac), hi.frac, 1);
                        const __m512 ng = _mm512_sub_ps(_mm512_set1_ps(1.0f), g);
                        for (int c = 0; c < 4; ++c) a[c] = _mm512_add_ps(_mm512_mul_ps(ng, a[c]), _mm512_mul_ps(g, b[c]));
                    }
                } else if (chosen) {
                    // The halves on different levels (a block across a level boundary): each level
                    // either half reads filtered once for all 16 lanes (at most 3 distinct for
                    // adjacent levels), each half taking or blending its own, (1 - frac) a + frac b
                    // per lane as filter16(levels): the same bits.
                    const int32_t want[4] = {lo.first, lo.second, hi.first, hi.second};
                    __m512 r[4][4];
                    for (int i = 0; i < 4; ++i) {
                        if (want[i] < 0) continue;
                        int j = 0;
                        while (j < i && want[j] != want[i]) ++j;
                        if (j < i)
                            for (int c = 0; c < 4; ++c) r[i][c] = r[j][c];
                        else
                            filter16_shaped<kBytes, kWrap>(f, f.planes[size_t(want[i])], lo.linear, s, t, r[i]);
                    }
                    const __m512 g = _mm512_insertf32x8(
                        _mm512_castps256_ps512(lo.second >= 0 ? lo.frac : _mm256_setzero_ps()),
                        hi.second >= 0 ? hi.frac : _mm256_setzero_ps(), 1);
                    const __m512 ng = _mm512_sub_ps(_mm512_set1_ps(1.0f), g);
                    for (int c = 0; c < 4; ++c) {
                        __m512 x = r[0][c], y = r[2][c];
                        if (lo.second >= 0) x = _mm512_add_ps(_mm512_mul_ps(ng, x), _mm512_mul_ps(g, r[1][c]));
                        if (hi.second >= 0) y = _mm512_add_ps(_mm512_mul_ps(ng, y), _mm512_mul_ps(g, r[3][c]));
                        a[c] = _mm512_mask_blend_ps(__mmask16(0xFF00), x, y);   // lanes 8-15 from the upper half's
                    }
                } else {
                    // Lanes on different levels: chosen lane by lane, filtered by the general blocks.
                    _mm512_store_ps(lambda, v);
                    for (int k = 0; k < 16; ++k) ch[k] = f.choose(lambda[k]);
                    if (same_levels(ch, 16)) filter16(f, ch, s, t, nullptr, out, l);
                    else if (const int count = distinct_levels(ch, 16, levels)) filter16(f, ch, levels, count, s, t, nullptr, out, l);
                    else return l;
                    stored = true;
                }
            }
            for (int c = 0; c < 4 && !stored; ++c)
                if (out[c]) _mm512_storeu_ps(&out[c][l].f, a[c]);
        }
        if (active != 0xFFFF)
            // Inactive lanes: (0, 0, 0, 1), as sample_lanes gives them.
            for (int c = 0; c < 4; ++c)
                if (out[c]) _mm512_mask_storeu_ps(&out[c][l].f, __mmask16(~active), _mm512_set1_ps(c == 3 ? 1.0f : 0.0f));
    }
    return l;
}

using Blocks16 = int (*)(const ColourQuery&, int);

// ---- Cube maps in blocks of 16 (AVX-512) with one fixed filter (no level choice): cube_block8's
// FixedNearest / FixedLinear modes for 16 lanes. The faces and face coordinates of each half by
// cube_coords8 (the same operations), each face the active lanes select filtered for the 16
// lanes by filter16_shaped (filter8_shaped's bits: colour_blocks16_shaped), each lane taking its
// own face's result; inactive lanes (0, 0, 0, 1). With seamless filtering, `outside` returns the
// active lanes whose texels leave the face (inside8, as Fast2D::inside and cube_block8's
// `inside`: every face of a level has one size), which the caller samples again by sample_lane.
template <int kBytes, bool kLinear>
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"), always_inline)) inline void cube_block16(const CubeQuery& cq, int32_t level,
                                                                                             int l, uint32_t& outside) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    outside = 0;
    const __mmask16 active = q.active ? _mm512_test_epi32_mask(_mm512_loadu_si512(q.active + l), _mm512_set1_epi32(-1))
                                      : __mmask16(0xFFFF);
    if (active) {
        alignas(64) int32_t face16[16];
        alignas(64) float s16[16], t16[16];
        for (int part = 0; part < 16; part += 8)
            cube_coords8(&q.coord[0][l + part].f, &q.coord[1][l + part].f, &q.coord[2][l + part].f, face16 + part,
                         s16 + part, t16 + part);
        const __m512i face_v = _mm512_load_si512(face16);
        const auto face_plane = [&](int face) -> const Plane& {
            return f.planes[size_t(face) * size_t(f.face_stride) + size_t(level)];
        };
        // The faces of the active lanes: usually one (the first active lane's).
        const int first_face = face16[__builtin_ctz(active)];
        const __mmask16 on_first = _mm512_cmpeq_epi32_mask(face_v, _mm512_set1_epi32(first_face));
        uint32_t faces = 1u << first_face;
        for (uint32_t left = active & ~uint32_t(on_first); left; left &= left - 1) faces |= 1u << face16[__builtin_ctz(left)];
        __m512 result[4];
        if (faces == 1u << first_face) {
            filter16_shaped<kBytes, kLinear, WrapKind::Clamp>(f, face_plane(first_face), s16, t16, result);
        } else {
            for (int c = 0; c < 4; ++c) result[c] = _mm512_setzero_ps();
            for (uint32_t left = faces; left; left &= left - 1) {
                const int face = __builtin_ctz(left);
                __m512 part[4];
                filter16_shaped<kBytes, kLinear, WrapKind::Clamp>(f, face_plane(face), s16, t16, part);
                const __mmask16 mine = _mm512_cmpeq_epi32_mask(face_v, _mm512_set1_epi32(face));
                for (int c = 0; c < 4; ++c) result[c] = _mm512_mask_mov_ps(result[c], mine, part[c]);
            }
        }
        for (int c = 0; c < 4; ++c)
            if (out[c]) _mm512_storeu_ps(&out[c][l].f, result[c]);
        if (cq.seamless) {
            const Plane& sizes = f.planes[size_t(level)];
            const uint32_t inside = inside8(sizes, kLinear, s16, t16) | inside8(sizes, kLinear, s16 + 8, t16 + 8) << 8;
            outside = ~inside & uint32_t(active);
        }
    }
    if (active != 0xFFFF)
        for (int c = 0; c < 4; ++c)
            if (out[c]) _mm512_mask_storeu_ps(&out[c][l].f, __mmask16(~active), _mm512_set1_ps(c == 3 ? 1.0f : 0.0f));
}

// The blocks of 16 of lanes [l, end) by cube_block16 in one loop, as cube_run8: the lanes' end.
template <int kBytes, bool kLinear>
__attribute__((target(SOFTGL_SAMPLER_AVX512 ",fma"))) int cube_run16(const CubeQuery& cq, int32_t level, int l, int end) {
    for (; l + 16 <= end; l += 16) {
        uint32_t outside;
        cube_block16<kBytes, kLinear>(cq, level, l, outside);
        for (; outside; outside &= outside - 1) cq.again(cq.context, l + __builtin_ctz(outside));
    }
    return l;
}

using CubeBlock16 = int (*)(const CubeQuery&, int32_t, int, int);

// ---- Depth lookups (with or without the comparison) in blocks of 16 (AVX-512) with one fixed
// filter, no layers, both axes CLAMP_TO_EDGE or both REPEAT of powers of two, a plane whose
// texel numbers fit int32: depth_block8's fixed case for 16 lanes. filter8_depth_as's operations
// in its order, 16 lanes at a time (the texels gathered 16 at a time, their values by
// depth_values8's rule on each half, compared as compare8), so the same bits.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512 depth_values16(Encoding e, __m512i words) {
    if (e == Encoding::Depth32F) return _mm512_castsi512_ps(words);
    const __m512d reciprocal = _mm512_set1_pd(e == Encoding::Depth16 ? 1.0 / 65535.0 : 1.0 / 16777215.0);
    const auto half = [&](__m256i w) __attribute__((target(SOFTGL_SAMPLER_AVX512))) {
        return _mm512_cvtpd_ps(_mm512_mul_pd(_mm512_cvtepu32_pd(w), reciprocal));   // exact conversion
    };
    return _mm512_insertf32x8(_mm512_castps256_ps512(half(_mm512_castsi512_si256(words))),
                              half(_mm512_extracti64x4_epi64(words, 1)), 1);
}

__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512 compare16(GLenum func, __m512 ref, __m512 d) {
    __mmask16 pass;
    switch (func) {
        case gl::LEQUAL: pass = _mm512_cmp_ps_mask(ref, d, _CMP_LE_OQ); break;
        case gl::GEQUAL: pass = _mm512_cmp_ps_mask(ref, d, _CMP_GE_OQ); break;
        case gl::LESS: pass = _mm512_cmp_ps_mask(ref, d, _CMP_LT_OQ); break;
        case gl::GREATER: pass = _mm512_cmp_ps_mask(ref, d, _CMP_GT_OQ); break;
        case gl::EQUAL: pass = _mm512_cmp_ps_mask(ref, d, _CMP_EQ_OQ); break;
        case gl::NOTEQUAL: pass = _mm512_cmp_ps_mask(ref, d, _CMP_NEQ_UQ); break;
        case gl::ALWAYS: return _mm512_set1_ps(1.0f);
        default: return _mm512_setzero_ps();   // NEVER
    }
    return _mm512_maskz_mov_ps(pass, _mm512_set1_ps(1.0f));
}

__attribute__((target(SOFTGL_SAMPLER_AVX512))) inline __m512 weighted_sum16(__m512 w00, __m512 w10, __m512 w01, __m512 w11,
                                                                            __m512 t00, __m512 t10, __m512 t01, __m512 t11) {
    __m512 sum = _mm512_mul_ps(w00, t00);
    sum = _mm512_add_ps(sum, _mm512_mul_ps(w10, t10));
    sum = _mm512_add_ps(sum, _mm512_mul_ps(w01, t01));
    return _mm512_add_ps(sum, _mm512_mul_ps(w11, t11));
}

template <bool kLinear, WrapKind kWrap>
__attribute__((target(SOFTGL_SAMPLER_AVX512))) void depth_block16(const ColourQuery& cq, int l) {
    const glsl::TextureQuery& q = *cq.q;
    const Fast2D& f = *cq.f;
    const Plane& p = f.planes[size_t(cq.fixed.first)];
    glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
    const __mmask16 active = q.active ? _mm512_test_epi32_mask(_mm512_loadu_si512(q.active + l), _mm512_set1_epi32(-1))
                                      : __mmask16(0xFFFF);
    __m512 result[4];
    if (active) {
        const bool compare = f.compare;
        const GLenum func = f.compare_func;
        const Encoding encoding = p.depth_encoding;
        __m512 ref = q.compare ? _mm512_loadu_ps(&q.compare[l].f) : _mm512_setzero_ps();
        if (compare && encoding != Encoding::Depth32F) {
            // std::clamp(ref, 0, 1), as DepthTexels8 (NaN and -0 stay).
            const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
            ref = _mm512_mask_mov_ps(ref, _mm512_cmp_ps_mask(one, ref, _CMP_LT_OQ), one);
            ref = _mm512_mask_mov_ps(ref, _mm512_cmp_ps_mask(ref, zero, _CMP_LT_OQ), zero);
        }
        const __m512i width = _mm512_set1_epi32(p.width);
        const auto texel = [&](__m512i i, __m512i j) __attribute__((target(SOFTGL_SAMPLER_AVX512))) {
            const __m512i at = _mm512_add_epi32(_mm512_mullo_epi32(j, width), i);
            const __m512 d = depth_values16(encoding, _mm512_i32gather_epi32(at, reinterpret_cast<const int*>(p.depth), 4));
            return compare ? compare16(func, ref, d) : d;
        };
        const __m512 u = _mm512_add_ps(_mm512_mul_ps(_mm512_loadu_ps(&q.coord[0][l].f), _mm512_set1_ps(float(p.width))),
                                       _mm512_set1_ps(float(f.off_s)));
        const __m512 v = _mm512_add_ps(_mm512_mul_ps(_mm512_loadu_ps(&q.coord[1][l].f), _mm512_set1_ps(float(p.height))),
                                       _mm512_set1_ps(float(f.off_t)));
        const __m512i last_i = _mm512_set1_epi32(p.width - 1), last_j = _mm512_set1_epi32(p.height - 1);
        const bool grey = f.compare || f.luminance;
        const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
        __m512i i0, i1, j0, j1;
        if constexpr (!kLinear) {
            wrap_shaped16<kWrap, false>(ifloor_floored16(_mm512_floor_ps(u)), last_i, i0, i1);
            wrap_shaped16<kWrap, false>(ifloor_floored16(_mm512_floor_ps(v)), last_j, j0, j1);
            result[0] = texel(i0, j0);
            result[1] = result[2] = grey ? result[0] : zero;
            result[3] = one;
        } else {
            const __m512 half = _mm512_set1_ps(0.5f);
            const __m512 u0 = _mm512_sub_ps(u, half), v0 = _mm512_sub_ps(v, half);
            const __m512 fu = _mm512_floor_ps(u0), fv = _mm512_floor_ps(v0);
            wrap_shaped16<kWrap, true>(ifloor_floored16(fu), last_i, i0, i1);
            wrap_shaped16<kWrap, true>(ifloor_floored16(fv), last_j, j0, j1);
            const __m512 a = _mm512_sub_ps(u0, fu), b = _mm512_sub_ps(v0, fv);
            const __m512 na = _mm512_sub_ps(one, a), nb = _mm512_sub_ps(one, b);
            const __m512 w00 = _mm512_mul_ps(na, nb), w10 = _mm512_mul_ps(a, nb), w01 = _mm512_mul_ps(na, b),
                         w11 = _mm512_mul_ps(a, b);
            result[0] = weighted_sum16(w00, w10, w01, w11, texel(i0, j0), texel(i1, j0), texel(i0, j1), texel(i1, j1));
            result[1] = result[2] = grey ? result[0] : weighted_sum16(w00, w10, w01, w11, zero, zero, zero, zero);
            result[3] = weighted_sum16(w00, w10, w01, w11, one, one, one, one);
        }
        for (int c = 0; c < 4; ++c)
            if (out[c]) _mm512_storeu_ps(&out[c][l].f, result[c]);
    }
    if (active != 0xFFFF)   // inactive lanes: (0, 0, 0, 1), as sample_lanes gives them
        for (int c = 0; c < 4; ++c)
            if (out[c]) _mm512_mask_storeu_ps(&out[c][l].f, __mmask16(~active), _mm512_set1_ps(c == 3 ? 1.0f : 0.0f));
}

using DepthBlock16 = void (*)(const ColourQuery&, int);

// The 16-lane depth block for a query, or null (levels chosen per block, layers, other wraps,
// texel numbers beyond int32: depth_block8).
inline DepthBlock16 depth_blocks16(const Fast2D& f, const ColourQuery& cq) {
    const Plane& p = f.planes[size_t(cq.fixed.first)];
    if (cq.needs_lambda || cq.r || !p.depth || p.layers != 1 || uint64_t(p.width) * uint64_t(p.height) > uint64_t(INT32_MAX))
        return nullptr;
    const bool clamp = f.wrap_s == gl::CLAMP_TO_EDGE && f.wrap_t == gl::CLAMP_TO_EDGE;
    const bool repeat = f.wrap_s == gl::REPEAT && f.wrap_t == gl::REPEAT && p.width_pot && p.height_pot;
    if (clamp) return cq.fixed.linear ? depth_block16<true, WrapKind::Clamp> : depth_block16<false, WrapKind::Clamp>;
    if (repeat) return cq.fixed.linear ? depth_block16<true, WrapKind::RepeatPot> : depth_block16<false, WrapKind::RepeatPot>;
    return nullptr;
}

// The 16-lane cube block for a query's storage and fixed filter, or null (as cube_blocks8; a
// level choice per block takes cube_block8).
inline CubeBlock16 cube_blocks16(const Fast2D& f, bool one_storage, LevelMode mode) {
    if (!one_storage || mode == LevelMode::PerBlock) return nullptr;
    const bool linear = mode == LevelMode::FixedLinear;
    if (f.planes[0].rgba8) return linear ? cube_run16<1, true> : cube_run16<1, false>;
    if (f.planes[0].narrow) return linear ? cube_run16<2, true> : cube_run16<2, false>;
    return linear ? cube_run16<0, true> : cube_run16<0, false>;
}

// colour_blocks16_shaped by SamplingPlan::colour_shape, as kColourBlocks8.
constexpr Blocks16 kColourBlocks16[kColourShapes] = {colour_blocks16, SOFTGL_SHAPES(colour_blocks16_shaped, 1),
                                                     SOFTGL_SHAPES(colour_blocks16_shaped, 2),
                                                     SOFTGL_SHAPES(colour_blocks16_shaped, 0)};
// lambdas_of_rho2_at's kernels: lambda_exact8 / lambda_exact4 of rho2[0 .. 8) / [0 .. 4), the
// lanes they do not vouch for from LambdaMemo; returns how many they vouched for.
__attribute__((target(SOFTGL_SAMPLER_AVX512))) int lambdas_exact8_at(const double* rho2, LambdaMemo& lambda_of, float* out) {
    __m256 lambda;
    const __mmask8 sure = lambda_exact8(_mm512_loadu_pd(rho2), lambda);
    _mm256_storeu_ps(out, lambda);
    for (int k = 0; k < 8; ++k)
        if (!(sure >> k & 1)) out[k] = lambda_of(rho2[k]);
    return __builtin_popcount(sure);
}
#undef SOFTGL_SHAPES
#pragma GCC diagnostic pop
#endif

}  // namespace

size_t lambdas_of_rho2_at(SimdLevel simd, const double* rho2, size_t n, float* out) {
    LambdaMemo& lambda_of = LambdaMemo::of_this_thread();
    size_t i = 0, sure = 0;
#ifdef SOFTGL_SAMPLER_AVX2
    simd = std::min(simd, best_simd_level());
    if (simd == SimdLevel::AVX512)
        for (; i + 8 <= n; i += 8) sure += lambdas_exact8_at(rho2 + i, lambda_of, out + i);
    else if (simd == SimdLevel::AVX2)
        for (; i + 4 <= n; i += 4) sure += lambdas_exact4_at(rho2 + i, lambda_of, out + i);
#endif
    for (; i < n; ++i) out[i] = lambda_of(rho2[i]);
    return sure;
}

namespace {

// The unit of every active lane; false when lanes use different units or none is active.
bool one_unit(const glsl::TextureQuery& q, int32_t& unit) {
    int first = 0;
    while (first < q.lane_count && q.active && !q.active[first]) ++first;
    if (first == q.lane_count) return false;
    unit = q.unit[first].i;
    if (q.uniform_unit) return true;
    // Branch-free loops over all lanes (lane `first` adds nothing), so that they vectorize:
    // this runs twice per query over the whole batch.
    const int32_t u = unit;
    uint32_t other_unit = 0;
    if (q.active)
        for (int l = 0; l < q.lane_count; ++l) other_unit |= uint32_t(q.unit[l].i ^ u) & (0u - uint32_t(q.active[l] != 0));
    else
        for (int l = 0; l < q.lane_count; ++l) other_unit |= uint32_t(q.unit[l].i ^ u);
    return other_unit == 0;
}

}  // namespace

namespace {

// ES 3.0 §3.8.11: without mipmaps and with one filter for magnification and minification,
// lambda selects nothing (incomplete or unbound units give (0, 0, 0, 1) regardless).
bool lod_selects(const BoundTexture& bt) {
    if (!bt.texture) return false;
    if (bt.params.max_anisotropy > 1.0f) return true;   // the probes follow the derivatives
    const GLenum mf = bt.params.min_filter;
    const bool min_linear = mf == gl::LINEAR || mf == gl::LINEAR_MIPMAP_NEAREST || mf == gl::LINEAR_MIPMAP_LINEAR;
    const bool mipmapped = !(mf == gl::NEAREST || mf == gl::LINEAR || bt.q == bt.base);
    return mipmapped || min_linear != (bt.params.mag_filter == gl::LINEAR);
}

}  // namespace

bool TextureUnitSampler::lod_matters(const glsl::TextureQuery& q) const {
    int32_t unit;
    if (!one_unit(q, unit)) return lod_matters_in(q.dim);
    if (unit < 0 || unit >= kSamplerUnits) return false;
    return lod_selects(units[size_t(unit)][size_t(dim_index(q.dim))]);
}

bool TextureUnitSampler::lod_matters_in(glsl::SamplerDim dim) const { return !(lod_free_dims >> dim_index(dim) & 1u); }

namespace {

// The SamplingPlan of one bound texture for lookups of dimension `dim` (sample_2d's fast path):
// usable when the levels [base, q] of every face are in the level table the draw built
// (Texture::refresh_sampling), all defined, all depth or all colour, byte planes with int32
// texel numbers, on a 2D, 2D array or cube-map texture.
SamplingPlan plan_sampling(const BoundTexture& bt, int dim) {
    SamplingPlan plan;
    if (!bt.texture || dim == 1) return plan;
    const Texture& tex = *bt.texture;
    const SamplerParams& p = bt.params;
    const bool cube = dim == 2;
    const int faces = cube ? 6 : 1;
    if (bt.q < bt.base || bt.q - bt.base >= 16 || tex.sampled_base != bt.base || tex.faces() != faces) return plan;
    plan.planes = tex.sampled(0, bt.base);
    plan.face_stride = tex.sampled_count;
    if (!plan.planes || !tex.sampled(0, bt.q)) return plan;
    plan.depth = plan.planes[0].depth != nullptr;
    const bool bytes = plan.planes[0].rgba8 != nullptr || plan.planes[0].narrow != nullptr;
    bool one_storage = true, pot = true;
    for (int face = 0; face < faces; ++face)
        for (int32_t k = 0; k <= bt.q - bt.base; ++k) {
            const Plane& level = plan.planes[size_t(face) * size_t(plan.face_stride) + size_t(k)];
            if (level.width == 0 || (level.depth != nullptr) != plan.depth) return plan;
            // The vector paths index texels in int32 (8-bit unorm planes: across layers too).
            const bool fits = int32_indices(level);
            const bool level_bytes = level.rgba8 != nullptr || level.narrow != nullptr;
            if (level_bytes && !fits) return plan;
            one_storage = one_storage && level_bytes == bytes && level.unorm8 == bytes &&
                          (bytes || level.color != nullptr || level.half != nullptr) &&
                          (level.half != nullptr) == (plan.planes[0].half != nullptr) && fits;
            pot = pot && level.width_pot && level.height_pot;
            // A complete cube map's faces have each level's size and format (ES 3.0 §3.8.14): the
            // other faces' planes must be stored as face 0's (cube_block8 reads them by its shape).
            const Plane& first = plan.planes[size_t(k)];
            if (face > 0 && (level.width != first.width || level.height != first.height ||
                             level.layers != first.layers || (level.rgba8 != nullptr) != (first.rgba8 != nullptr) ||
                             (level.narrow != nullptr) != (first.narrow != nullptr) ||
                             level.narrow_bytes != first.narrow_bytes || (level.color != nullptr) != (first.color != nullptr) ||
                             (level.half != nullptr) != (first.half != nullptr) ||
                             level.unorm8 != first.unorm8))
                return plan;
        }
    plan.one_storage = one_storage, plan.pot = pot;
    // Cube maps: CLAMP_TO_EDGE within the face (ES 3.0 §3.8.10; lanes that would cross an edge
    // with seamless filtering go to sample_lane).
    plan.wrap_s = cube ? gl::CLAMP_TO_EDGE : p.wrap_s, plan.wrap_t = cube ? gl::CLAMP_TO_EDGE : p.wrap_t;
    plan.mag_linear = p.mag_filter == gl::LINEAR;
    const GLenum mf = p.min_filter;
    plan.min_linear = mf == gl::LINEAR || mf == gl::LINEAR_MIPMAP_NEAREST || mf == gl::LINEAR_MIPMAP_LINEAR;
    plan.mipmapped = !(mf == gl::NEAREST || mf == gl::LINEAR || bt.q == bt.base);
    // Without mipmaps and with the same filter both ways, lambda picks nothing: skip it.
    plan.needs_lambda = plan.mipmapped || plan.min_linear != plan.mag_linear;
    // The shaped colour block loop (kColourBlocks8): one storage, REPEAT of powers of two or
    // CLAMP_TO_EDGE on both axes; otherwise the general loop (0).
    int wrap = -1;
    if (plan.wrap_s == gl::REPEAT && plan.wrap_t == gl::REPEAT && pot) wrap = 0;
    else if (plan.wrap_s == gl::CLAMP_TO_EDGE && plan.wrap_t == gl::CLAMP_TO_EDGE) wrap = 1;
    if (!plan.depth && !cube && one_storage && wrap >= 0) {
        const int storage = plan.planes[0].rgba8 ? 0 : plan.planes[0].narrow ? 1 : 2;
        const int mode = plan.needs_lambda ? 2 : plan.mag_linear ? 1 : 0;
        plan.colour_shape = uint8_t(1 + (storage * 2 + wrap) * 3 + mode);
    }
    plan.usable = true;
    return plan;
}

}  // namespace

void TextureUnitSampler::plan_units(const uint32_t filled[4]) {
    lod_free_dims = 0;
    for (int dim = 0; dim < 4; ++dim) {
        bool lod_free = true;   // units not filled sample as (0, 0, 0, 1) whatever the LOD
        for (uint32_t m = filled[dim]; m; m &= m - 1) {
            BoundTexture& bt = units[size_t(__builtin_ctz(m))][size_t(dim)];
            bt.plan = plan_sampling(bt, dim);
            lod_free = lod_free && !lod_selects(bt);
        }
        lod_free_dims |= uint32_t(lod_free) << dim;
    }
}

bool TextureUnitSampler::sample_2d(const glsl::TextureQuery& q, SimdBlocks simd) const {
    const bool cube = q.dim == SamplerDim::Cube;
    if (q.kind != TextureKind::Sample || q.result != BaseType::Float || q.dim == SamplerDim::Tex3D) return false;
    // One unit for every active lane (sampler uniforms are uniform; anything else goes per lane).
    int32_t unit;
    if (!one_unit(q, unit)) return false;
    if (unit < 0 || unit >= kSamplerUnits) return false;
    const BoundTexture& bt = units[size_t(unit)][size_t(dim_index(q.dim))];
    // The levels, filters and block loop the draw resolved for this unit (plan_units).
    const SamplingPlan& plan = bt.plan;
    if (!bt.texture || !plan.usable) return false;
    const SamplerParams& p = bt.params;

    Fast2D f;
    f.planes = plan.planes;
    f.face_stride = plan.face_stride;
    const bool depth = plan.depth;
    f.compare = q.shadow && p.compare_mode == gl::COMPARE_REF_TO_TEXTURE;
    f.compare_func = p.compare_func;
    f.luminance = bt.depth_as_luminance;
    // Cube maps: no offsets.
    f.wrap_s = plan.wrap_s, f.wrap_t = plan.wrap_t;
    f.off_s = cube ? 0 : q.offset[0], f.off_t = cube ? 0 : q.offset[1];
    f.base = bt.base, f.top = bt.q;
    f.min_filter = p.min_filter;
    f.mag_linear = plan.mag_linear;
    f.min_linear = plan.min_linear;
    f.mipmapped = plan.mipmapped;
    f.min_lod = p.min_lod, f.max_lod = p.max_lod;
    const bool needs_lambda = plan.needs_lambda;
    const float w = float(f.planes[0].width), h = float(f.planes[0].height);

    LambdaMemo& lambda_of = LambdaMemo::of_this_thread();
    // ES 3.0 §3.8.10.1-2 as in sample_lanes; max(sqrt(x), sqrt(y)) = sqrt(max(x, y)) as sqrt is
    // correctly rounded (monotonic), and std::max keeps the same NaN.
    const auto lambda_of_derivatives = [&](const float dx[3], const float dy[3], bool third_x, bool third_y, int l) {
        if (q.lod_mode == TextureLod::Explicit) return q.lod ? q.lod[l].f : 0.0f;
        double lx2 = double(dx[0] * w) * (dx[0] * w) + double(dx[1] * h) * (dx[1] * h);
        double ly2 = double(dy[0] * w) * (dy[0] * w) + double(dy[1] * h) * (dy[1] * h);
        // The third term (d = 0 off 3D) is +0, which adds nothing, unless dx[2] is not finite.
        if (third_x) lx2 += double(dx[2] * 0.0f) * (dx[2] * 0.0f);
        if (third_y) ly2 += double(dy[2] * 0.0f) * (dy[2] * 0.0f);
        float lambda = lambda_of(std::max(lx2, ly2));
        if (q.lod_mode == TextureLod::Bias && q.lod) lambda += q.lod[l].f;
        return lambda;
    };
    const auto derivatives = [&](int l, float dx[3], float dy[3]) {
        for (int k = 0; k < 3; ++k) {
            dx[k] = q.ddx[k] ? q.ddx[k][l].f : 0.0f;
            dy[k] = q.ddy[k] ? q.ddy[k][l].f : 0.0f;
        }
    };
    const auto lambda_at = [&](int l) {
        float dx[3] = {0, 0, 0}, dy[3] = {0, 0, 0};
        if (q.lod_mode != TextureLod::Explicit) derivatives(l, dx, dy);
        return lambda_of_derivatives(dx, dy, q.ddx[2] != nullptr, q.ddy[2] != nullptr, l);
    };
    const LevelChoice fixed{0, -1, f.mag_linear, 0.0f};
    const auto one_lane = [&](int l) {
        float result[4] = {0, 0, 0, 1};   // inactive lanes: as sample_lanes gives them
        if (!q.active || q.active[l]) {
            float s = q.coord[0] ? q.coord[0][l].f : 0.0f, t = q.coord[1] ? q.coord[1][l].f : 0.0f;
            const float r = q.coord[2] ? q.coord[2][l].f : 0.0f;
            const float ref = q.compare ? q.compare[l].f : 0.0f;
            if (!cube) {
                f.filter(needs_lambda ? f.choose(lambda_at(l)) : fixed, 0, s, t, r, ref, result);
            } else {
                float dx[3], dy[3];
                derivatives(l, dx, dy);
                const int face = cube_coords(s, t, r, dx, dy);
                // The cube's third derivative term: always there, and +0 after cube_coords.
                const LevelChoice ch = needs_lambda ? f.choose(lambda_of_derivatives(dx, dy, true, true, l)) : fixed;
                if (bt.seamless_cube && !f.inside(ch, face, s, t)) return sample_lane(q, l);
                f.filter(ch, face, s, t, 0.0f, ref, result);
            }
        }
        for (int c = 0; c < 4; ++c) if (q.out[c]) q.out[c][l].f = result[c];
    };

    int l = 0;
#ifdef SOFTGL_SAMPLER_AVX2
    // Colour: blocks of 16 (AVX-512) or 8 lanes whose levels are at most 3, straight into the
    // registers; the other blocks lane by lane.
    // (Narrow 8-bit planes, Image::narrow, too: unorm8_words8/16 decode their texels.)
    if (simd != SimdBlocks::None && !cube && !depth && q.coord[0] && q.coord[1]) {
        const ColourQuery cq{&f, &q, f.planes[0].layers > 1 && q.coord[2] ? &q.coord[2][0].f : nullptr,
                             needs_lambda, fixed, w, h, &lambda_of};
        // The shaped loop the plan chose (2D arrays with layers: the general one).
        const int shape = cq.r ? 0 : plan.colour_shape;
        const Blocks8 blocks8 = kColourBlocks8[shape];
        const Blocks16 blocks16 = simd == SimdBlocks::Avx512 ? kColourBlocks16[shape] : colour_blocks16;
        while (l + 8 <= q.lane_count) {
            if (simd == SimdBlocks::Avx512 && l + 16 <= q.lane_count) l = blocks16(cq, l);
            // What is left: a block of 16 colour_blocks16 left, or the last lanes.
            const int end = simd == SimdBlocks::Avx512 && l + 16 <= q.lane_count ? l + 16 : q.lane_count;
            l = blocks8(cq, l, end);
            if (l + 8 <= end) {
                for (int k = 0; k < 8; ++k) one_lane(l + k);
                l += 8;
            }
        }
        if (l < q.lane_count) {
            // The last 1-7 lanes as one padded block (their extra lanes add no level).
            PaddedTail8 padded(q, l);
            ColourQuery tail_cq = cq;
            tail_cq.q = &padded.query;
            tail_cq.r = cq.r ? &padded.query.coord[2][0].f : nullptr;
            if (blocks8(tail_cq, 0, 8) == 8) {
                padded.copy_results(q, l);
                l = q.lane_count;
            }
        }
    }
    // Depth planes: blocks of 8 lanes whose levels are at most 3 (texels compared 8 at a time:
    // DepthTexels8); the other blocks lane by lane.
    if (simd != SimdBlocks::None && !cube && depth && q.coord[0] && q.coord[1]) {
        const ColourQuery cq{&f, &q, f.planes[0].layers > 1 && q.coord[2] ? &q.coord[2][0].f : nullptr,
                             needs_lambda, fixed, w, h, &lambda_of};
        LevelChoice ch[8];
        if (!needs_lambda) std::fill(ch, ch + 8, fixed);
        int32_t levels[3];
        // Bit k: lane l + k is active (SSE2: this function is not compiled for AVX2).
        const auto active_lanes = [&] {
            if (!q.active) return 0xFFu;
            uint32_t inactive = 0;
            for (int k = 0; k < 8; k += 4) {
                const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q.active + l + k));
                inactive |= uint32_t(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(a, _mm_setzero_si128())))) << k;
            }
            return ~inactive & 0xFFu;
        };
        glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
        const DepthBlock16 depth_block16 = simd == SimdBlocks::Avx512 ? depth_blocks16(f, cq) : nullptr;
        while (l + 8 <= q.lane_count) {
            if (depth_block16 && l + 16 <= q.lane_count) {
                depth_block16(cq, l);
                l += 16;
                continue;
            }
            if (depth_block8(cq, l)) {
                l += 8;
                continue;
            }
            const uint32_t active = active_lanes();
            const float* s = &q.coord[0][l].f;
            const float* t = &q.coord[1][l].f;
            const float* rl = cq.r ? cq.r + l : nullptr;
            const float* ref = q.compare ? &q.compare[l].f : nullptr;
            if (active) {
                if (needs_lambda) choose_lanes(cq, l, 8, active, ch);
                float result[8][4];
                if (same_levels(ch, 8)) {
                    filter8(f, ch, s, t, rl, ref, result);
                } else if (const int count = distinct_levels(ch, 8, levels)) {
                    filter8(f, ch, levels, count, s, t, rl, ref, result);
                } else {
                    for (int k = 0; k < 8; ++k) one_lane(l + k);
                    l += 8;
                    continue;
                }
                store_lanes8(result, out, l);
            }
            if (active != 0xFFu) {
                // Inactive lanes: (0, 0, 0, 1), as sample_lanes gives them.
                for (int k = 0; k < 8; ++k)
                    if (!(active >> k & 1))
                        for (int c = 0; c < 4; ++c) if (q.out[c]) q.out[c][l + k].f = c == 3 ? 1.0f : 0.0f;
            }
            l += 8;
        }
    }
    // Cube maps: faces, face coordinates and their derivatives of 8 active lanes at once
    // (cube_coords8), the levels lane by lane; a block whose lanes share their levels has each
    // face among them filtered by filter8 for the block, each lane taking its own face's result,
    // and lanes whose footprint leaves the face with seamless filtering then go to sample_lane
    // (as one_lane sends them). Other blocks: faces lane by lane (cube_coords, as one_lane), and
    // blocks on one face, one level and inside the face filtered by filter8, else lane by lane.
    if (simd != SimdBlocks::None && cube && q.coord[0] && q.coord[1] && q.coord[2]) {
        glsl::Scalar* const out[4] = {q.out[0], q.out[1], q.out[2], q.out[3]};
        // Colour cube maps of one storage: cube_block8 (blocks whose lanes share their levels).
        const LevelMode mode = needs_lambda ? LevelMode::PerBlock : fixed.linear ? LevelMode::FixedLinear : LevelMode::FixedNearest;
        const CubeBlock8 cube_run8 = depth ? nullptr : cube_blocks8(f, plan.one_storage, mode);
        const CubeBlock16 cube_run16 =
            depth || simd != SimdBlocks::Avx512 ? nullptr : cube_blocks16(f, plan.one_storage, mode);
        // Lanes whose footprint leaves the face under seamless filtering: sample_lane (as one_lane).
        struct Again {
            const TextureUnitSampler* sampler;
            const glsl::TextureQuery* q;
        } again{this, &q};
        const auto sample_again = [](void* context, int lane) {
            const Again& a = *static_cast<const Again*>(context);
            a.sampler->sample_lane(*a.q, lane);
        };
        const CubeQuery cube_query{&f, &q, w, h, &lambda_of, bt.seamless_cube, sample_again, &again};
        Planes8 cube_planes(f);
        const auto all_active = [&](int first) {
            if (!q.active) return true;
            for (int k = 0; k < 8; ++k)
                if (!q.active[first + k]) return false;
            return true;
        };
        // Blocks of 8 active lanes whose lanes share their levels: false (nothing written) otherwise.
        const auto cube_block = [&]() {
            alignas(32) int32_t face8[8];
            alignas(32) float s8[8], t8[8], ds[2][8], dt[2][8];
            LevelChoice ch8[8];
            if (!needs_lambda) {
                cube_coords8(&q.coord[0][l].f, &q.coord[1][l].f, &q.coord[2][l].f, face8, s8, t8);
                ch8[0] = fixed;   // (one level: only ch8[0] is read)
            } else {
                const float* ddx[3], *ddy[3];
                for (int k = 0; k < 3; ++k) ddx[k] = q.ddx[k] ? &q.ddx[k][l].f : nullptr, ddy[k] = q.ddy[k] ? &q.ddy[k][l].f : nullptr;
                cube_coords8(&q.coord[0][l].f, &q.coord[1][l].f, &q.coord[2][l].f, face8, s8, t8, ddx, ddy, ds, dt);
                for (int k = 0; k < 8; ++k) {
                    // As one_lane: the derivatives after cube_coords, third components +0.
                    const float dx[3] = {ds[0][k], dt[0][k], 0.0f}, dy[3] = {ds[1][k], dt[1][k], 0.0f};
                    ch8[k] = f.choose(lambda_of_derivatives(dx, dy, true, true, l + k));
                    if (!ch8[k].same_levels(ch8[0])) return false;
                }
            }
            const float* ref = q.compare ? &q.compare[l].f : nullptr;
            uint32_t faces = 0;
            for (int k = 0; k < 8; ++k) faces |= 1u << face8[k];
            float result[8][4];
            // Each face the block touches, filtered for all 8 lanes: one level's plane, or both
            // levels blended (filter8(LevelChoice) over the face's levels).
            const LevelChoice& ch = ch8[0];
            const auto filter_face = [&](int face, float dst[8][4]) {
                const Plane* levels = f.planes + size_t(face) * size_t(f.face_stride);
                if (ch.second < 0) return filter8(f, levels[ch.first], ch.linear, s8, t8, nullptr, dst, ref);
                Fast2D face_f = f;
                face_f.planes = levels;
                filter8(face_f, ch8, s8, t8, nullptr, ref, dst);
            };
            if ((faces & (faces - 1)) == 0) {
                filter_face(face8[0], result);
            } else {
                for (uint32_t left = faces; left; left &= left - 1) {
                    const int face = __builtin_ctz(left);
                    float part[8][4];
                    filter_face(face, part);
                    for (int k = 0; k < 8; ++k)
                        if (face8[k] == face) std::memcpy(result[k], part[k], sizeof part[k]);
                }
            }
            store_lanes8(result, out, l);
            if (bt.seamless_cube) {
                // Every face of a level has one size: face 0's planes tell for all (Fast2D::inside).
                uint32_t inside = inside8(f.planes[size_t(ch.first)], ch.linear, s8, t8);
                if (ch.second >= 0) inside &= inside8(f.planes[size_t(ch.second)], ch.linear, s8, t8);
                for (uint32_t left = ~inside & 0xFFu; left; left &= left - 1) sample_lane(q, l + __builtin_ctz(left));
            }
            return true;
        };
        while (l + 8 <= q.lane_count) {
            if (cube_run16 && l + 16 <= q.lane_count) {
                l = cube_run16(cube_query, fixed.first, l, q.lane_count);
                continue;
            }
            // cube_run8 stops at a block whose lanes do not share their levels (taken below).
            if (cube_run8 && (l = cube_run8(cube_query, cube_planes, l, q.lane_count)) + 8 > q.lane_count) break;
            if (all_active(l) && cube_block()) {
                l += 8;
                continue;
            }
            alignas(32) float s8[8], t8[8], ref8[8];
            LevelChoice ch8[8];
            int face0 = -1;
            bool block = true;
            for (int k = 0; k < 8 && block; ++k) {
                const int lane = l + k;
                if (q.active && !q.active[lane]) { block = false; break; }
                float s = q.coord[0][lane].f, t = q.coord[1][lane].f;
                const float r = q.coord[2][lane].f;
                // (Without a level choice the derivatives are not needed: s, t do not depend on them.)
                float dx[3] = {0, 0, 0}, dy[3] = {0, 0, 0};
                if (needs_lambda) derivatives(lane, dx, dy);
                const int face = cube_coords(s, t, r, dx, dy);
                ch8[k] = needs_lambda ? f.choose(lambda_of_derivatives(dx, dy, true, true, lane)) : fixed;
                if (k == 0) face0 = face;
                block = face == face0 && ch8[k].second < 0 && ch8[k].same_levels(ch8[0]) &&
                        (!bt.seamless_cube || f.inside(ch8[k], face, s, t));
                s8[k] = s, t8[k] = t, ref8[k] = q.compare ? q.compare[lane].f : 0.0f;
            }
            if (!block) {
                for (int k = 0; k < 8; ++k) one_lane(l + k);
            } else {
                float result[8][4];
                const Plane& plane = f.planes[size_t(face0) * size_t(f.face_stride) + size_t(ch8[0].first)];
                filter8(f, plane, ch8[0].linear, s8, t8, nullptr, result, q.compare ? ref8 : nullptr);
                store_lanes8(result, out, l);
            }
            l += 8;
        }
        if (cube_run8 && l < q.lane_count) {
            // The last 1-7 lanes as one padded block (their extra lanes add no level or face);
            // lanes leaving the face go to sample_lane after the block's results are copied.
            PaddedTail8 padded(q, l);
            uint32_t outside = 0;
            CubeQuery tail_query = cube_query;
            tail_query.q = &padded.query;
            tail_query.again = [](void* context, int lane) { *static_cast<uint32_t*>(context) |= 1u << lane; };
            tail_query.context = &outside;
            if (cube_run8(tail_query, cube_planes, 0, 8) == 8) {
                padded.copy_results(q, l);
                for (; outside; outside &= outside - 1) sample_lane(q, l + __builtin_ctz(outside));
                l = q.lane_count;
            }
        }
    }
#endif
    for (; l < q.lane_count; ++l) one_lane(l);
    return true;
}

// ---------------------------------------------------------------------------- anisotropic filtering
//
// EXT_texture_filter_anisotropic, by the method its specification suggests, in one fixed rule
// (scalar code, so the same bits on every SIMD level and thread count). With the base level's
// size (w, h, d) and the lane's coordinate derivatives:
//   Px = |(w ds/dx, h dt/dx, d dr/dx)|, Py = the same along y (double, as the isotropic rho);
//   Pmax = max(Px, Py), Pmin = min(Px, Py);
//   lambda = log2(Pmax) (+ bias): the isotropic LOD (ES 3.0 eq. 3.17-3.19), which still decides
//     magnification (lambda <= 0, or NaN): a magnified lookup is the isotropic one;
//   otherwise N = min(ceil(Pmax / Pmin - 1/64), floor(min(TEXTURE_MAX_ANISOTROPY_EXT, 16)))
//     probes (N = that limit when Pmin = 0; the 1/64: the derivatives of a square footprint
//     carry float rounding, which must not make it two probes), at lambda' = log2(Pmax / N)
//     (+ bias), clamped to
//     [TEXTURE_MIN_LOD, TEXTURE_MAX_LOD] as any lambda;
//   probe i (1..N) is an ordinary lookup at LOD lambda' (the texture's filters and mipmaps)
//     at the coordinates moved by (i / (N + 1) - 1/2) times the derivative along the major axis
//     (x when Px > Py, else y);
//   the result is the sum of the probes, added in order i = 1..N in float, divided by N.
// N = 1 gives exactly the isotropic lookup. Lanes whose texture's TEXTURE_MAX_ANISOTROPY_EXT is
// 1 take the ordinary paths.

namespace {
constexpr double kAnisotropyRatioSlack = 1.0 / 64;
}

bool TextureUnitSampler::anisotropic(const glsl::TextureQuery& q) const {
    // Integer textures sample NEAREST only (ES 3.0 §3.8.14): nothing to filter.
    if (!any_anisotropic || q.kind != TextureKind::Sample || q.lod_mode == TextureLod::Explicit ||
        q.result != BaseType::Float)
        return false;
    const int dim = dim_index(q.dim);
    int32_t unit;
    if (one_unit(q, unit)) {
        if (unit < 0 || unit >= kSamplerUnits) return false;
        const BoundTexture& bt = units[size_t(unit)][size_t(dim)];
        return bt.texture && bt.params.max_anisotropy > 1.0f;
    }
    for (int l = 0; l < q.lane_count; ++l) {
        const int32_t u = q.unit[l].i;
        if (u >= 0 && u < kSamplerUnits && units[size_t(u)][size_t(dim)].texture &&
            units[size_t(u)][size_t(dim)].params.max_anisotropy > 1.0f)
            return true;
    }
    return false;
}

void TextureUnitSampler::sample_anisotropic(const glsl::TextureQuery& q) const {
    const int dim = dim_index(q.dim);
    for (int l = 0; l < q.lane_count; ++l) {
        const int32_t unit = q.unit[l].i;
        const BoundTexture* bt = unit >= 0 && unit < kSamplerUnits ? &units[size_t(unit)][size_t(dim)] : nullptr;
        if (!bt || !bt->texture || bt->params.max_anisotropy <= 1.0f || (q.active && !q.active[l])) {
            sample_lane(q, l);
            continue;
        }
        sample_lane_anisotropic(q, l, *bt);
    }
}

void TextureUnitSampler::sample_lane_anisotropic(const glsl::TextureQuery& q, int l, const BoundTexture& bt) const {
    float dx[3] = {0, 0, 0}, dy[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        if (q.ddx[k]) dx[k] = q.ddx[k][l].f;
        if (q.ddy[k]) dy[k] = q.ddy[k][l].f;
    }
    // The footprint in texels of the base level (of the face the lane's direction selects).
    float w = 0, h = 0, d = 0;
    {
        float s = q.coord[0] ? q.coord[0][l].f : 0.0f, t = q.coord[1] ? q.coord[1][l].f : 0.0f;
        float r = q.coord[2] ? q.coord[2][l].f : 0.0f;
        float fdx[3] = {dx[0], dx[1], dx[2]}, fdy[3] = {dy[0], dy[1], dy[2]};
        const int face = q.dim == SamplerDim::Cube ? cube_coords(s, t, r, fdx, fdy) : 0;
        const Image* img = bt.texture->find(face, bt.base);
        if (!img) { sample_lane(q, l); return; }
        w = float(img->width), h = float(img->height), d = q.dim == SamplerDim::Tex3D ? float(img->depth) : 0.0f;
        if (q.dim == SamplerDim::Cube) std::copy(fdx, fdx + 3, dx), std::copy(fdy, fdy + 3, dy);
    }
    const double px = std::sqrt(double(dx[0] * w) * (dx[0] * w) + double(dx[1] * h) * (dx[1] * h) + double(dx[2] * d) * (dx[2] * d));
    const double py = std::sqrt(double(dy[0] * w) * (dy[0] * w) + double(dy[1] * h) * (dy[1] * h) + double(dy[2] * d) * (dy[2] * d));
    const double pmax = std::max(px, py), pmin = std::min(px, py);
    const float bias = q.lod_mode == TextureLod::Bias && q.lod ? q.lod[l].f : 0.0f;
    const SamplerParams& p = bt.params;
    float lambda = pmax > 0 ? float(std::log2(pmax)) : -INFINITY;
    lambda = std::clamp(lambda + bias, p.min_lod, p.max_lod);
    const int limit = int(std::floor(std::min(p.max_anisotropy, kMaxAnisotropy)));
    if (!(lambda > 0.0f) || limit <= 1 || !std::isfinite(pmax)) { sample_lane(q, l); return; }
    const double ratio = pmin > 0 ? std::ceil(pmax / pmin - kAnisotropyRatioSlack) : double(limit);
    const int n = int(std::min(ratio, double(limit)));
    if (n <= 1) { sample_lane(q, l); return; }
    const float lambda_n = std::clamp(float(std::log2(pmax / n)) + bias, p.min_lod, p.max_lod);

    // Each probe is an ordinary lookup of one lane at an explicit LOD (the general path).
    // For a cube map the probe moves the direction (the derivatives given are the direction's).
    const bool along_x = px > py;
    glsl::Scalar coord[3], lod, unit_reg, compare, out[4];
    unit_reg.i = q.unit[l].i;
    lod.f = lambda_n;
    if (q.compare) compare = q.compare[l];
    glsl::TextureQuery probe = q;
    probe.lane_count = 1;
    probe.active = nullptr;
    probe.unit = &unit_reg;
    probe.lod_mode = TextureLod::Explicit;
    probe.lod = &lod;
    probe.compare = q.compare ? &compare : nullptr;
    for (int k = 0; k < 3; ++k) {
        probe.coord[k] = q.coord[k] ? &coord[k] : nullptr;
        probe.ddx[k] = probe.ddy[k] = nullptr;
    }
    for (int c = 0; c < 4; ++c) probe.out[c] = &out[c];
    float sum[4] = {0, 0, 0, 0}, axis[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        const glsl::Scalar* g = along_x ? q.ddx[k] : q.ddy[k];
        axis[k] = g ? g[l].f : 0.0f;
    }
    for (int i = 1; i <= n; ++i) {
        const float offset = float(i) / float(n + 1) - 0.5f;
        for (int k = 0; k < 3; ++k)
            if (q.coord[k]) coord[k].f = q.coord[k][l].f + offset * axis[k];
        sample_lane(probe, 0);
        for (int c = 0; c < 4; ++c) sum[c] += out[c].f;
    }
    for (int c = 0; c < 4; ++c)
        if (q.out[c]) q.out[c][l].f = sum[c] / float(n);
}

void TextureUnitSampler::sample(const glsl::TextureQuery& q) {
    if (anisotropic(q)) {   // EXT_texture_filter_anisotropic (above): one lane at a time
        sample_anisotropic(q);
        return;
    }
    // q.simd is at most best_simd_level() (glsl::Executor::set_simd_level).
    SimdBlocks simd = SimdBlocks::None;
#ifdef SOFTGL_SAMPLER_AVX2
    if ((q.path == SamplerPath::Best || q.path == SamplerPath::Avx2) && q.simd >= SimdLevel::AVX2) simd = SimdBlocks::Avx2;
    if (q.path == SamplerPath::Best && q.simd >= SimdLevel::AVX512) simd = SimdBlocks::Avx512;
#endif
    if (q.path != SamplerPath::General && sample_2d(q, simd)) {
        if (q.fast_queries) ++*q.fast_queries;
        return;
    }
    sample_lanes(q);
}

// ---------------------------------------------------------------------------- texel words
//
// docs/architecture.md, "Fast paths" (texel words): a NEAREST lookup of an 8-bit unorm level
// returns texel k's channels as k / 255 (Fast2D::texel); the colour kernels turn those floats
// back into the bytes k (tests/textures/test_texel_words.py checks all 256). So where nothing
// else changes them (a plain write of all channels) the texels' words can go to the pixels as
// they are. The texel each lane reads is Fast2D::filter's (NEAREST, level base, layer 0), and
// the AVX2 blocks are filter8_shaped's NEAREST operations: the same texel at every level.
//
// LINEAR of one level (Tuning::linear_words): the fixed-point rule gives each channel
// v = float32(S / (255 * 65536)) of an integer sum S <= 255 * 65536, which the colour kernels
// write as floor(v * 255 + 1/2). That byte is round(S / 65536) with ties (S = 65536 k + 32768)
// up for k < 128 and down from there (v rounds below (2k + 1) / 510 in [1/2, 1)), i.e.
// (S + 32768 - (S >> 23)) >> 16 (tests/textures/test_linear_words.py checks every S). The texels,
// weights and sums are Fast2D::filter's (level base, layer 0), the AVX2 blocks filter8_shaped's.

namespace {
// The byte a plain write makes of the rule's sum S.
inline uint32_t linear_byte(uint32_t S) { return (S + 0x8000u - (S >> 23)) >> 16; }
}  // namespace

bool TextureUnitSampler::gives_words(const glsl::TextureQuery& q, bool linear) const {
    if (q.kind != TextureKind::Sample || q.dim != SamplerDim::Tex2D || q.shadow || q.result != BaseType::Float ||
        q.lod_mode != TextureLod::Implicit || q.path == SamplerPath::General)
        return false;
    int32_t unit;
    if (!one_unit(q, unit) || unit < 0 || unit >= kSamplerUnits) return false;
    const BoundTexture& bt = units[size_t(unit)][0];
    const SamplingPlan& plan = bt.plan;
    if (!bt.texture || !plan.usable || bt.params.max_anisotropy > 1.0f) return false;   // (as sample: anisotropic)
    if (plan.depth || !plan.one_storage || plan.needs_lambda || (plan.mag_linear && !linear)) return false;
    const Plane& p = plan.planes[0];
    return (p.rgba8 || p.narrow) && p.layers == 1 && (!plan.mag_linear || p.unorm8);
}

namespace {

#ifdef SOFTGL_SAMPLER_AVX2
// filter8_shaped's NEAREST texel numbers of lanes [0, n) in blocks of 8, their words stored;
// returns the lanes done.
template <int kBytes, WrapKind kWrap>
__attribute__((target("avx2,f16c"))) int nearest_words8(const Plane& p, int off_s, int off_t, const glsl::Scalar* s,
                                                   const glsl::Scalar* t, int n, uint32_t* words) {
    const __m256 width_f = _mm256_set1_ps(float(p.width)), height_f = _mm256_set1_ps(float(p.height));
    const __m256 os = _mm256_set1_ps(float(off_s)), ot = _mm256_set1_ps(float(off_t));
    const __m256i width = _mm256_set1_epi32(p.width), last_i = _mm256_set1_epi32(p.width - 1),
                  last_j = _mm256_set1_epi32(p.height - 1);
    int l = 0;
    for (; l + 8 <= n; l += 8) {
        const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(&s[l].f), width_f), os);
        const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(&t[l].f), height_f), ot);
        __m256i i0, i1, j0, j1;
        wrap_shaped8<kWrap, false>(ifloor_floored8(_mm256_floor_ps(u)), last_i, i0, i1);
        wrap_shaped8<kWrap, false>(ifloor_floored8(_mm256_floor_ps(v)), last_j, j0, j1);
        const __m256i index = _mm256_add_epi32(_mm256_mullo_epi32(j0, width), i0);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(words + l), shaped_words8<kBytes>(p, index));
    }
    return l;
}

// Channels 0 and 2 of the texels left and right blended horizontally, H = (256 - A) k0 + A k1
// (16 bits, exact), less 2^15 (the top bit flipped).
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i linear_half_row8(__m256i left, __m256i right, __m256i wa,
                                                                              __m256i nwa) {
    const __m256i bytes = _mm256_set1_epi32(0x00FF00FF);
    return _mm256_xor_si256(_mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(left, bytes), nwa),
                                             _mm256_mullo_epi16(_mm256_and_si256(right, bytes), wa)),
                            _mm256_set1_epi32(int(0x80008000u)));
}

// linear_byte(m + 2^23) of 8 lanes: S >> 23 is 1 exactly where m >= 0.
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i linear_bytes8(__m256i m) {
    return _mm256_srli_epi32(_mm256_sub_epi32(_mm256_add_epi32(m, _mm256_set1_epi32(0x807FFF)), _mm256_srai_epi32(m, 31)), 16);
}

// The words of unorm8_rows8's sums: the rows' horizontal blends H = (256 - A) k0 + A k1 as
// there (16 bits, r, b in `even` and g, a in `odd`), less 2^15 (signed 16-bit), then per channel
// vpmaddwd gives (256 - B)(H0 - 2^15) + B (H1 - 2^15) = S - 2^23 (|.| <= 2^23), and linear_byte
// of S. The madd pairs lanes (0, 1 | 4, 5) and (2, 3 | 6, 7); packus puts them back in order.
__attribute__((target("avx2,f16c"), always_inline)) inline __m256i linear_words_of8(__m256i t00, __m256i t10, __m256i t01,
                                                                              __m256i t11, __m256i ai, __m256i bi) {
    const __m256i k256 = _mm256_set1_epi32(256);
    const __m256i nai = _mm256_sub_epi32(k256, ai);
    const __m256i wa = _mm256_or_si256(ai, _mm256_slli_epi32(ai, 16)), nwa = _mm256_or_si256(nai, _mm256_slli_epi32(nai, 16));
    const __m256i e0 = linear_half_row8(t00, t10, wa, nwa), o0 = linear_half_row8(_mm256_srli_epi32(t00, 8), _mm256_srli_epi32(t10, 8), wa, nwa);
    const __m256i e1 = linear_half_row8(t01, t11, wa, nwa), o1 = linear_half_row8(_mm256_srli_epi32(t01, 8), _mm256_srli_epi32(t11, 8), wa, nwa);
    const __m256i wb = _mm256_or_si256(_mm256_sub_epi32(k256, bi), _mm256_slli_epi32(bi, 16));
    const __m256i wlo = _mm256_unpacklo_epi32(wb, wb), whi = _mm256_unpackhi_epi32(wb, wb);
    const __m256i even = _mm256_packus_epi32(linear_bytes8(_mm256_madd_epi16(_mm256_unpacklo_epi16(e0, e1), wlo)),
                                             linear_bytes8(_mm256_madd_epi16(_mm256_unpackhi_epi16(e0, e1), whi)));
    const __m256i odd = _mm256_packus_epi32(linear_bytes8(_mm256_madd_epi16(_mm256_unpacklo_epi16(o0, o1), wlo)),
                                            linear_bytes8(_mm256_madd_epi16(_mm256_unpackhi_epi16(o0, o1), whi)));
    return _mm256_or_si256(even, _mm256_slli_epi16(odd, 8));
}

// filter8_shaped's LINEAR operations for lanes [0, n) in blocks of 8, their words stored;
// returns the lanes done.
template <int kBytes, WrapKind kWrap>
__attribute__((target("avx2,f16c"))) int linear_words8(const Plane& p, int off_s, int off_t, const glsl::Scalar* s,
                                                  const glsl::Scalar* t, int n, uint32_t* words) {
    const __m256 width_f = _mm256_set1_ps(float(p.width)), height_f = _mm256_set1_ps(float(p.height));
    const __m256 os = _mm256_set1_ps(float(off_s)), ot = _mm256_set1_ps(float(off_t)), half = _mm256_set1_ps(0.5f);
    const __m256i width = _mm256_set1_epi32(p.width), last_i = _mm256_set1_epi32(p.width - 1),
                  last_j = _mm256_set1_epi32(p.height - 1);
    int l = 0;
    for (; l + 8 <= n; l += 8) {
        const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(&s[l].f), width_f), os);
        const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(&t[l].f), height_f), ot);
        const __m256 u0 = _mm256_sub_ps(u, half), v0 = _mm256_sub_ps(v, half);
        const __m256 fu = _mm256_floor_ps(u0), fv = _mm256_floor_ps(v0);
        __m256i i0, i1, j0, j1;
        wrap_shaped8<kWrap, true>(ifloor_floored8(fu), last_i, i0, i1);
        wrap_shaped8<kWrap, true>(ifloor_floored8(fv), last_j, j0, j1);
        const __m256i ai = _mm256_cvttps_epi32(weight8x8(_mm256_sub_ps(u0, fu)));
        const __m256i bi = _mm256_cvttps_epi32(weight8x8(_mm256_sub_ps(v0, fv)));
        const __m256i row0 = _mm256_mullo_epi32(j0, width), row1 = _mm256_mullo_epi32(j1, width);
        const __m256i w = linear_words_of8(shaped_words8<kBytes>(p, _mm256_add_epi32(row0, i0)),
                                           shaped_words8<kBytes>(p, _mm256_add_epi32(row0, i1)),
                                           shaped_words8<kBytes>(p, _mm256_add_epi32(row1, i0)),
                                           shaped_words8<kBytes>(p, _mm256_add_epi32(row1, i1)), ai, bi);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(words + l), w);
    }
    return l;
}
#endif

// Fast2D::filter's LINEAR of one lane of an 8-bit unorm plane (layer 0), as a plain write's word.
inline uint32_t linear_word(const Plane& p, GLenum wrap_s, GLenum wrap_t, int off_s, int off_t, float s, float t) {
    const float u = s * float(p.width) + float(off_s), v = t * float(p.height) + float(off_t);
    const float u0 = u - 0.5f, v0 = v - 0.5f;
    int32_t i0, i1, j0, j1;
    wrap_pair(wrap_s, ifloor(u0), p.width, p.width_pot, i0, i1);
    wrap_pair(wrap_t, ifloor(v0), p.height, p.height_pot, j0, j1);
    const uint32_t A = uint32_t(weight8(u0 - std::floor(u0))), B = uint32_t(weight8(v0 - std::floor(v0)));
    const uint32_t w[4] = {(256 - A) * (256 - B), A * (256 - B), (256 - A) * B, A * B};
    const size_t row0 = size_t(j0) * size_t(p.width), row1 = size_t(j1) * size_t(p.width);
    const uint32_t k[4] = {unorm8_texel(p, row0 + size_t(i0)), unorm8_texel(p, row0 + size_t(i1)),
                           unorm8_texel(p, row1 + size_t(i0)), unorm8_texel(p, row1 + size_t(i1))};
    uint32_t word = 0;
    for (int c = 0; c < 4; ++c) {
        uint32_t S = 0;
        for (int n = 0; n < 4; ++n) S += w[n] * ((k[n] >> (8 * c)) & 255u);
        word |= linear_byte(S) << (8 * c);
    }
    return word;
}

}  // namespace

void TextureUnitSampler::sample_words(const glsl::TextureQuery& q, uint32_t* words) {
    int32_t unit = 0;
    one_unit(q, unit);   // gives_words(q) held
    const BoundTexture& bt = units[size_t(unit)][0];
    const Plane& p = bt.plan.planes[0];
    const GLenum wrap_s = bt.plan.wrap_s, wrap_t = bt.plan.wrap_t;
    const int off_s = q.offset[0], off_t = q.offset[1];
    const glsl::Scalar* const s = q.coord[0];
    const glsl::Scalar* const t = q.coord[1];
    int l = 0;
#ifdef SOFTGL_SAMPLER_AVX2
    const bool avx2 = q.path != SamplerPath::Scalar && q.simd >= SimdLevel::AVX2 && int32_indices(p);
    const bool repeat = wrap_s == gl::REPEAT && wrap_t == gl::REPEAT && p.width_pot && p.height_pot;
    const bool clamp = wrap_s == gl::CLAMP_TO_EDGE && wrap_t == gl::CLAMP_TO_EDGE;
#endif
    if (bt.plan.mag_linear) {   // one LINEAR level (gives_words)
#ifdef SOFTGL_SAMPLER_AVX2
        if (avx2) {
            if (p.rgba8 && repeat) l = linear_words8<1, WrapKind::RepeatPot>(p, off_s, off_t, s, t, q.lane_count, words);
            else if (p.rgba8 && clamp) l = linear_words8<1, WrapKind::Clamp>(p, off_s, off_t, s, t, q.lane_count, words);
            else if (p.narrow && repeat) l = linear_words8<2, WrapKind::RepeatPot>(p, off_s, off_t, s, t, q.lane_count, words);
            else if (p.narrow && clamp) l = linear_words8<2, WrapKind::Clamp>(p, off_s, off_t, s, t, q.lane_count, words);
        }
#endif
        for (; l < q.lane_count; ++l) words[l] = linear_word(p, wrap_s, wrap_t, off_s, off_t, s[l].f, t[l].f);
        if (q.fast_queries) ++*q.fast_queries;
        return;
    }
#ifdef SOFTGL_SAMPLER_AVX2
    if (avx2) {
        if (p.rgba8 && repeat) l = nearest_words8<1, WrapKind::RepeatPot>(p, off_s, off_t, s, t, q.lane_count, words);
        else if (p.rgba8 && clamp) l = nearest_words8<1, WrapKind::Clamp>(p, off_s, off_t, s, t, q.lane_count, words);
        else if (p.narrow && repeat) l = nearest_words8<2, WrapKind::RepeatPot>(p, off_s, off_t, s, t, q.lane_count, words);
        else if (p.narrow && clamp) l = nearest_words8<2, WrapKind::Clamp>(p, off_s, off_t, s, t, q.lane_count, words);
    }
#endif
    for (; l < q.lane_count; ++l) {   // Fast2D::filter, NEAREST
        const float u = s[l].f * float(p.width) + float(off_s), v = t[l].f * float(p.height) + float(off_t);
        const int32_t i = wrap_one(wrap_s, ifloor(u), p.width, p.width_pot);
        const int32_t j = wrap_one(wrap_t, ifloor(v), p.height, p.height_pot);
        words[l] = unorm8_texel(p, size_t(j) * size_t(p.width) + size_t(i));
    }
    if (q.fast_queries) ++*q.fast_queries;
}

}  // namespace softgl
