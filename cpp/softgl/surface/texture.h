// Texture images and their formats: what each internal format stores, how client pixels
// (format, type) unpack into it (ES 3.0 §3.7.2, tables 3.2-3.5), how values are quantized to the
// format's precision, mipmap generation, and the completeness rules (ES 3.0 §3.8.14, ES 2.0 §3.8.2,
// WebGL 1.0 §5.13.8 for NPOT).
//
// Storage is one representation per sampling kind, so that sampling and rendering are
// format-agnostic:
//   - 8-bit unorm colour formats (FormatInfo::is_unorm8: RGBA8, RGB8, RG8, R8, LUMINANCE,
//     ALPHA, LUMINANCE_ALPHA): 4 bytes per texel, RGBA, the byte k standing for k / 255, absent
//     channels holding their defaults (0, alpha 255; luminance in r, g and b), the same layout
//     as the RGBA8 drawing buffer, so draws, clears, blits and readPixels take its byte paths;
//   - renderbuffers of 16-bit float, sRGB and packed small unorm formats, and textures of the
//     16-bit float formats: encoded at their own size (Image::packed);
//   - other colour formats that sample as float: one float per channel of the base format
//     (Image::color_channels: RED 1, RG 2, RGB 3, else 4; absent channels implied as 0, alpha 1),
//     the values a lookup returns
//     (already quantized to the format: an RGBA8 texel holds k/255; sRGB texels hold the
//     decoded linear value, which is what ES 3.0 §3.8.15 decodes to before filtering; LUMINANCE,
//     ALPHA and friends are stored expanded to RGBA as ES 3.0 table 3.24 defines them);
//   - integer formats: each channel of the format at its own width (8, 16 or 32 bits; RGB10_A2UI
//     one packed 32-bit word), Image::integer_bytes per texel, read and written as 4 x 32-bit
//     (int or uint bits) through read_integer / store_integer;
//   - depth formats: one 32-bit word per texel (unorm16/unorm24 integers, or float32 bits: all
//     non-negative, so the unsigned order of the words is the order of the depths) plus a stencil
//     byte per texel for depth-stencil formats.
// The depth words are what the pipeline's depth test compares, so depth textures and
// renderbuffers are drawn into directly.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "softgl/core/memory_ledger.h"
#include "softgl/core/objects.h"

namespace softgl {

// Enums of extensions (not on the WebGL context objects, so not in enums.h).
namespace gl_ext {
inline constexpr GLenum HALF_FLOAT_OES = 0x8D61;
inline constexpr GLenum UNSIGNED_INT_24_8_WEBGL = 0x84FA;
inline constexpr GLenum SRGB_EXT = 0x8C40;
inline constexpr GLenum SRGB_ALPHA_EXT = 0x8C42;
// Internal formats of WebGL 1's unsized LUMINANCE/ALPHA formats (OpenGL's sized names, never
// returned to users; ES has no sized names for them).
inline constexpr GLenum ALPHA8 = 0x803C, LUMINANCE8 = 0x8040, LUMINANCE8_ALPHA8 = 0x8045;
inline constexpr GLenum ALPHA16F = 0x881C, LUMINANCE16F = 0x881E, LUMINANCE_ALPHA16F = 0x881F;
inline constexpr GLenum ALPHA32F = 0x8816, LUMINANCE32F = 0x8818, LUMINANCE_ALPHA32F = 0x8819;
inline constexpr GLenum TEXTURE_MAX_ANISOTROPY_EXT = 0x84FE;      // EXT_texture_filter_anisotropic
inline constexpr GLenum MAX_TEXTURE_MAX_ANISOTROPY_EXT = 0x84FF;
inline constexpr GLenum FRAGMENT_SHADER_DERIVATIVE_HINT_OES = 0x8B8B; // OES_standard_derivatives
// WebGL 1's luminance/alpha formats under OpenGL's sized names: internal only, never accepted
// as an internalformat argument.
inline bool is_pseudo_format(GLenum f) {
    return f == ALPHA8 || f == LUMINANCE8 || f == LUMINANCE8_ALPHA8 || f == ALPHA16F || f == LUMINANCE16F ||
           f == LUMINANCE_ALPHA16F || f == ALPHA32F || f == LUMINANCE32F || f == LUMINANCE_ALPHA32F;
}
}  // namespace gl_ext

enum class Encoding : uint8_t {
    Unorm,        // bits[c] bits per channel
    Snorm,        // 8 bits
    Srgb,         // 8-bit sRGB colour, linear alpha
    Float16, Float32, Float11_11_10, Rgb9e5,
    Int, Uint,    // bits[c] bits per channel
    Depth16, Depth24, Depth32F,
    Stencil8,     // renderbuffer STENCIL_INDEX8
};

enum class SampleKind : uint8_t { Float, Int, Uint, Depth };

struct FormatInfo {
    GLenum internal_format = 0;
    GLenum base_format = 0;        // RGBA, RGB, RG, RED, ALPHA, LUMINANCE, LUMINANCE_ALPHA,
                                   // DEPTH_COMPONENT, DEPTH_STENCIL, STENCIL_INDEX8
    Encoding encoding = Encoding::Unorm;
    std::array<uint8_t, 4> bits{0, 0, 0, 0};   // per RGBA channel (0: absent); what getParameter reports
    bool has_stencil = false;
    SampleKind kind() const;
    bool is_depth() const { return encoding == Encoding::Depth16 || encoding == Encoding::Depth24 || encoding == Encoding::Depth32F; }
    bool is_integer() const { return encoding == Encoding::Int || encoding == Encoding::Uint; }
    bool is_float() const {
        return encoding == Encoding::Float16 || encoding == Encoding::Float32 ||
               encoding == Encoding::Float11_11_10 || encoding == Encoding::Rgb9e5;
    }
    int depth_bits() const { return encoding == Encoding::Depth16 ? 16 : encoding == Encoding::Depth24 ? 24 : encoding == Encoding::Depth32F ? 32 : 0; }
    // 8-bit unorm colour (RGBA8, RGB8, RG8, R8, LUMINANCE8, ALPHA8, LUMINANCE8_ALPHA8; not
    // sRGB): texels are k / 255, filtered by the fixed-point rule of surface/sampler.cpp.
    bool is_unorm8() const {
        return encoding == Encoding::Unorm && !has_stencil &&
               (bits[0] == 8 || bits[0] == 0) && (bits[1] == 8 || bits[1] == 0) &&
               (bits[2] == 8 || bits[2] == 0) && (bits[3] == 8 || bits[3] == 0);
    }
};

// The format of a sized (or WebGL 1 pseudo-sized) internal format; null if unknown.
const FormatInfo* format_info(GLenum internal_format);

// Quantizes a float colour to what a texel of this format holds (clamping for normalized
// formats, rounding to the format's precision, sRGB encode-then-decode). Float formats only.
void quantize_color(const FormatInfo& f, const float in[4], float out[4]);
// quantize_color of an 8-bit unorm format (FormatInfo::is_unorm8) as the packed bytes an image
// stores: byte c is float_to_unorm(v, 8) of what quantize_color reads for channel c.
uint32_t quantize_unorm8(const FormatInfo& f, const float in[4]);
// Quantizes to an integer format's channel range (ES 3.0 §4.3.2: values are clamped when
// converted; clearBuffer and blits of integers take the low bits).
void quantize_integer(const FormatInfo& f, const uint32_t in[4], uint32_t out[4]);
// A depth in [0, 1] as the 32-bit word the format stores.
uint32_t depth_word(Encoding e, double depth);
float depth_value(Encoding e, uint32_t word);

float srgb_to_linear(float c);   // ES 3.0 §3.8.15 eq. 3.24
float linear_to_srgb(float c);   // ES 3.0 §4.1.8 eq. 4.1
float half_to_float(uint16_t h);
uint16_t float_to_half(float f); // round to nearest even

// One image: a mipmap level of one face (or all layers of a 3D / array level), or a renderbuffer.
struct Image {
    int32_t width = 0, height = 0, depth = 1;   // depth: layers of 3D / 2D array images
    int32_t samples = 1;                         // renderbuffers only
    const FormatInfo* format = nullptr;          // null: no image
    // Float kind but not 8-bit unorm: color_channels() floats per texel (sample), then
    // kColorPad floats (0) when fewer than 4, so that a 4-float load at any texel stays inside.
    std::vector<float> color;
    static constexpr size_t kColorPad = 3;
    // 8-bit unorm formats (stores_bytes): R | G << 8 | B << 16 | A << 24 per texel (sample), k
    // for k / 255 (in memory the bytes R, G, B, A: the drawing buffer's layout).
    std::vector<uint32_t> rgba8;
    // 8-bit unorm formats of one or two channels (stores_narrow: R8, RG8, LUMINANCE8, ALPHA8,
    // LUMINANCE8_ALPHA8): only their channels' bytes, narrow_bytes() per texel (sample), in the
    // order r, g / luminance, alpha, then kNarrowPad bytes (0) so that the sampler's 4-byte
    // gathers at any texel stay inside the vector. Read and written through read_color /
    // store_color; the sampler's vector paths decode them (narrow_words8/16, surface/sampler.cpp).
    std::vector<uint8_t> narrow;
    static constexpr size_t kNarrowPad = 3;
    // Renderbuffers (never sampled) of formats with an encoding (packed_bytes() != 0) keep it,
    // at the format's own size (packed_bytes() per sample, no padding), in place of `color`: the
    // 16-bit float formats (R16F, RG16F, RGB16F, RGBA16F) as one binary16 per channel; SRGB8 and
    // SRGB8_ALPHA8 as their encoded bytes (3 or 4); RGB565, RGBA4, RGB5_A1 as one 16-bit word
    // and RGB10_A2 as one 32-bit word of the channels' unorm integers, red in the low bits. Every
    // value such a sample can hold (quantize_color's output) has one encoding, so the floats read
    // back are those stored. Read and written through read_color / store_color. Textures of the
    // 16-bit float formats are kept so too (the sampler's texel loads decode 4 halves a texel:
    // SampledLevel::half), then kHalfPad bytes (0) below 4 channels so that a 4-half load at any
    // texel stays inside; textures of the other formats keep floats (`color`).
    std::vector<uint8_t> packed;
    uint8_t packed_size = 0;                     // bytes per sample of `packed` (0: not encoded)
    static constexpr size_t kHalfPad = 6;
    // Bytes of `packed` for n texels (samples) of `fmt`, 0 when images of it keep no encoding:
    // renderbuffers (encoded) of any format with one, textures of the 16-bit float formats.
    static size_t packed_elements(const FormatInfo* fmt, size_t n, bool encoded);
    std::vector<uint8_t> integer;                // Int/Uint kind: integer_bytes() per texel (sample)
    std::vector<uint32_t> depth_words;           // Depth kind: 1 per texel (sample)
    std::vector<uint8_t> stencil;                // depth-stencil and stencil formats

    // Bytes per texel of a narrow format (see `narrow`), 0 for the others.
    static int narrow_bytes(const FormatInfo* fmt) {
        if (!fmt || !fmt->is_unorm8()) return 0;
        const GLenum b = fmt->base_format;
        return b == gl::RED || b == gl::LUMINANCE || b == gl::ALPHA ? 1 : b == gl::RG || b == gl::LUMINANCE_ALPHA ? 2 : 0;
    }
    static bool stores_narrow(const FormatInfo* fmt) { return narrow_bytes(fmt) != 0; }
    // Bytes per sample of a format's encoding (see `packed`), 0 for formats without one.
    static int packed_bytes(const FormatInfo* fmt);
    // Whether images of `fmt` keep RGBA bytes (rgba8) rather than floats (color): the 8-bit unorm
    // formats of three or four channels (RGBA8, RGB8).
    static bool stores_bytes(const FormatInfo* fmt) { return fmt && fmt->is_unorm8() && !stores_narrow(fmt); }
    bool bytes() const { return stores_bytes(format); }
    // Bytes per texel of an integer format (the sum of its channels' widths, ES 3.0 table 3.13),
    // 0 for the others.
    static int integer_bytes(const FormatInfo* fmt);
    // Integer element t as 4 x 32-bit bits (int formats sign-extended), absent channels 0, alpha 1.
    void read_integer(size_t t, uint32_t out[4]) const;
    // Stores already-quantized integer bits (quantize_integer's output), the channels of `mask`.
    void store_integer(size_t t, const uint32_t in[4], const bool mask[4] = nullptr);
    // Floats per texel of `color` for a format stored there: the base format's channels (RED 1,
    // RG 2, RGB 3; RGBA and WebGL 1's luminance/alpha formats, kept expanded, 4), 0 for the others.
    static int color_channels(const FormatInfo* fmt);
    int color_channels() const { return packed.empty() ? color_channels(format) : 0; }
    // The floats `color` holds for n texels of `fmt`.
    static size_t color_elements(const FormatInfo* fmt, size_t n) {
        const int c = color_channels(fmt);
        return c == 0 ? 0 : n * size_t(c) + (c < 4 ? kColorPad : 0);
    }
    bool defined() const { return format != nullptr; }
    size_t texel_count() const { return size_t(width) * size_t(height) * size_t(depth) * size_t(samples); }
    // Colour element t (texel or sample index) of a Float-kind image as the floats a lookup
    // returns (bytes: k / 255).
    void read_color(size_t t, float out[4]) const;
    // Stores already-quantized colour values (quantize_color's output) into element t, the
    // channels of `mask` only.
    void store_color(size_t t, const float quantized[4], const bool mask[4] = nullptr);
    // Of an image kept encoded (`packed`): stores the colour v unquantized, the channels of
    // `mask`: the same sample as store_color of quantize_color(v), by one conversion.
    void encode_color(size_t t, const float v[4], const bool mask[4]);
    // Allocates storage for `fmt` and fills it with zeros (transparent black, depth 0); encoded:
    // a renderbuffer's image, kept in `packed` when the format has an encoding.
    void allocate(const FormatInfo* fmt, int32_t w, int32_t h, int32_t d, int32_t s = 1, bool encoded = false);
    // The bytes allocate() would store, computed before allocating (the memory limit is charged first).
    static uint64_t allocation_bytes(const FormatInfo* fmt, int32_t w, int32_t h, int32_t d, int32_t s, bool encoded = false);
    void clear() { *this = Image{}; }
    // Texel (x, y, z) as RGBA float, as sampled (integer formats: converted; depth: (d, 0, 0, 1)).
    void texel(int32_t x, int32_t y, int32_t z, float out[4]) const;
    // Bytes of texel storage this image holds (all its vectors).
    size_t storage_bytes() const {
        return color.size() * sizeof(float) + integer.size() + depth_words.size() * sizeof(uint32_t) +
               stencil.size() + rgba8.size() * sizeof(uint32_t) + narrow.size() + packed.size();
    }
};

// Client pixel data for texImage*/texSubImage*: `format`/`type` describe the data layout,
// rows follow the UNPACK_* rules (or are tight, for image sources).
struct PixelUnpack {
    const uint8_t* data = nullptr;
    size_t bytes = 0;
    GLenum format = 0, type = 0;
    int32_t alignment = 4, row_length = 0, image_height = 0, skip_pixels = 0, skip_rows = 0, skip_images = 0;
    bool flip_y = false, premultiply = false;
};

// Bytes per pixel of (format, type), 0 if the pair is unknown.
int pixel_bytes(GLenum format, GLenum type);
// Bytes a w x h x d block needs with these unpack parameters (ES 3.0 §3.7.2: last row unpadded).
uint64_t unpack_size(const PixelUnpack& u, int32_t w, int32_t h, int32_t d);

// Writes the w x h x d block of `u` at (x, y, z) into `img` (converted to its format).
void unpack_into(Image& img, int32_t x, int32_t y, int32_t z, int32_t w, int32_t h, int32_t d,
                 const PixelUnpack& u);

struct SamplerParams {
    GLenum min_filter = gl::NEAREST_MIPMAP_LINEAR, mag_filter = gl::LINEAR;
    GLenum wrap_s = gl::REPEAT, wrap_t = gl::REPEAT, wrap_r = gl::REPEAT;
    float min_lod = -1000.0f, max_lod = 1000.0f;
    GLenum compare_mode = gl::NONE, compare_func = gl::LEQUAL;
    // EXT_texture_filter_anisotropic: as set (>= 1); lookups use min(it, kMaxAnisotropy).
    float max_anisotropy = 1.0f;
};

// MAX_TEXTURE_MAX_ANISOTROPY_EXT (what Chromium reports on SwiftShader and most GPUs).
inline constexpr float kMaxAnisotropy = 16.0f;

// One level of one face as the sampler's fast path reads it (surface/sampler.cpp): its storage
// and sizes resolved once per draw instead of per lookup. Exactly one of `color` (Float kind),
// `half` (16-bit float formats), `rgba8` / `narrow` (8-bit unorm formats) and `depth` (Depth kind) is set.
struct SampledLevel {
    const float* color = nullptr;      // color_channels floats per texel, layer-major then row-major
    // 16-bit float textures (Image::packed): color_channels binary16 per texel (color null), read
    // by the same paths as `color`, each texel load decoding its 4 halves (binary16 to float32 is
    // exact: the floats a float32 copy of the texel would hold).
    const uint16_t* half = nullptr;
    // Floats per texel of `color` (Image::color_channels) and the values of the channels it
    // lacks (color_fill[c] for c >= color_channels: 0, alpha 1), substituted as texels are read.
    uint8_t color_channels = 4;
    float color_fill[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    bool unorm8 = false;               // an 8-bit unorm format (FormatInfo::is_unorm8): LINEAR
                                       // filters with 8-bit weights (surface/sampler.cpp)
    const uint32_t* rgba8 = nullptr;   // 8-bit unorm texels (Image::rgba8), layer-major then row-major
    // 8-bit unorm texels of one or two channels (Image::narrow; unorm8 set, rgba8 null):
    // narrow_bytes per texel and Image::kNarrowPad bytes after the last, decoded to RGBA bytes by
    // narrow_rgba8 / narrow_words8 / narrow_words16 (surface/sampler.cpp).
    const uint8_t* narrow = nullptr;
    uint8_t narrow_bytes = 0;
    GLenum narrow_base = 0;            // the format's base format (RED, RG, LUMINANCE, ...)
    // The RGBA word of 4 narrow texels read as 4-byte words: byte 4j + c of 16 (a byte shuffle's
    // order; 0x80: zero) is where word j's channel c comes from, then OR narrow_fill (alpha 255
    // where the format has none): narrow_rgba8's values (surface/sampler.cpp).
    uint8_t narrow_shuffle[16] = {};
    uint32_t narrow_fill = 0;
    const uint32_t* depth = nullptr;   // depth words, one per texel
    Encoding depth_encoding = Encoding::Depth16;
    int32_t width = 0, height = 0, layers = 0;   // layers: of a 2D array (1 otherwise)
    bool width_pot = false, height_pot = false;
};

class Texture : public Object {
public:
    GLenum target = 0;                  // fixed by the first bindTexture (ES 3.0 §3.8.1)
    SamplerParams sampler;
    int32_t base_level = 0, max_level = 1000;
    bool immutable = false;
    int32_t immutable_levels = 0;
    // images[face][level]; one face except for cube maps (faces in TEXTURE_CUBE_MAP_POSITIVE_X order).
    std::vector<std::vector<Image>> images;
    uint64_t generation = 0;            // bumps on every change (render targets, caches)
    MemoryReservation memory;           // storage_bytes(), charged to the ledger (core/memory_ledger.h)
    void release_storage() override;    // every image goes (deleted and unused: Object)

    int faces() const { return target == gl::TEXTURE_CUBE_MAP ? 6 : 1; }
    Image& image(int face, int level);  // grows the arrays as needed
    const Image* find(int face, int level) const;
    // Bytes of texel storage held by all images of all faces (memory accounting).
    size_t storage_bytes() const;
    // Rebuilds `sampled_levels` for levels [base, max(q, max_sampled_level)] of every face.
    // Called when a draw binds the texture (single-threaded), so lookups read a table that
    // holds for the whole draw (no per-lookup find()); rebuilt at every draw, as cheap as a few
    // dozen pointers, so that no image change can leave it stale.
    void refresh_sampling(int32_t base, int32_t q);
    // Levels [sampled_base, sampled_base + sampled_count) of face f at f * sampled_count + k;
    // a level without an image, or of a kind the fast path does not read (integer), has
    // width 0. Only valid during the draw that refreshed it.
    std::vector<SampledLevel> sampled_levels;
    int32_t sampled_base = 0, sampled_count = 0;
    const SampledLevel* sampled(int face, int32_t level) const {
        const int32_t k = level - sampled_base;
        return k >= 0 && k < sampled_count ? &sampled_levels[size_t(face) * size_t(sampled_count) + size_t(k)] : nullptr;
    }
};

class Sampler : public Object {
public:
    SamplerParams params;
};

// Texture completeness (ES 3.0 §3.8.14 with WebGL 1's NPOT rules when webgl1): the empty string
// when complete, else why not. `params` are the effective sampler parameters (a sampler object's
// when one is bound to the unit). `float_linear`/`half_float_linear`: whether 32F/16F formats are
// filterable (OES_texture_float_linear; 16F always in WebGL 2).
struct CompletenessRules {
    bool webgl1 = false;
    bool float_linear = false;
    bool half_float_linear = true;
};
std::string incompleteness(const Texture& t, const SamplerParams& params, const CompletenessRules& rules);
// Number of the last level used by sampling (q in ES 3.0 §3.8.10.4).
int32_t max_sampled_level(const Texture& t);
bool needs_mipmaps(GLenum min_filter);
bool is_power_of_two(int32_t v);

// generateMipmap's box filter: levels base+1 .. q from the base level, per face.
void generate_mipmaps(Texture& t);
// Texture::storage_bytes() as it will be after generate_mipmaps(t) (charged before it runs).
uint64_t storage_bytes_after_mipmaps(const Texture& t);

}  // namespace softgl
