// The default (drawing-buffer) framebuffer: RGBA8 (or, with softgl's `color_format`, RGBA16F or
// RGBA32F) color, 24-bit unorm depth, 8-bit stencil, each with `samples` samples per pixel stored
// contiguously (pixel-major).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <new>
#include <string>
#include <vector>

#include "softgl/core/memory_ledger.h"
#include "softgl/core/state.h"

namespace softgl {

// The drawing buffer's colour format (softgl's `color_format` context option). RGBA8 is WebGL's;
// the float formats behave like RGBA16F / RGBA32F colour attachments (ES 3.0 §4.1.7: no clamping
// of blend inputs or results; §2.1.1 / IEEE 754 binary16 round to nearest even for 16F).
enum class ColorFormat : uint8_t { RGBA8, RGBA16F, RGBA32F };

struct FramebufferConfig {
    int32_t width = 0, height = 0;
    ColorFormat color_format = ColorFormat::RGBA8;
    int32_t samples = 1;   // 1 = single-sampled
    bool alpha = true, depth = true, stencil = false;
};

// Buffers start on a cache line: a 64-pixel tile row then covers whole lines, so workers drawing
// neighbouring tiles never write to one line at the same time (it would bounce between cores).
template <class T>
struct CacheLineAllocator {
    using value_type = T;
    static constexpr std::align_val_t kAlign{64};
    CacheLineAllocator() = default;
    template <class U>
    CacheLineAllocator(const CacheLineAllocator<U>&) {}
    T* allocate(size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlign)); }
    void deallocate(T* p, size_t) { ::operator delete(p, kAlign); }
    template <class U>
    bool operator==(const CacheLineAllocator<U>&) const { return true; }
    template <class U>
    bool operator!=(const CacheLineAllocator<U>&) const { return false; }
};
template <class T>
using CacheLineVector = std::vector<T, CacheLineAllocator<T>>;

// The most memory one allocation of softgl may take: half of this machine's physical memory.
// Requests beyond it are refused up front (ValueError / OUT_OF_MEMORY) instead of thrashing.
uint64_t memory_budget();

// Largest width or height accepted for a drawing buffer (also MAX_VIEWPORT_DIMS etc.).
inline constexpr int32_t kMaxDrawingBufferSize = 16384;

// Multisample resolve of RGBA8 samples: n pixels of `samples` samples each (pixel-major, 4 bytes
// a sample) to the rounded mean of each channel, (sum + S/2) / S, which is the float64 mean of
// the samples rounded half up (one sample: a copy). With `ties`, the indices of the pixels where
// some channel's mean lies exactly halfway between two bytes (sum mod S = S/2) are written
// there in increasing order (n at most); returns how many.
size_t resolve_rgba8(const uint8_t* in, int samples, size_t n, uint8_t* out, uint32_t* ties = nullptr);

class DefaultFramebuffer {
public:
    static constexpr int kDepthBits = 24;
    static constexpr int kStencilBits = 8;

    // Empty string when `config` can be allocated; otherwise why not. Allocates nothing. The
    // bytes must fit in the memory ledger's room (core/memory_ledger.h) plus `released`, the
    // bytes of a drawing buffer this one replaces.
    // `account`: the context's, whose limit must hold too.
    static std::string check(const FramebufferConfig& config, uint64_t released = 0,
                             const MemoryAccount* account = nullptr);
    static uint64_t bytes_needed(const FramebufferConfig& config);

    // Charges bytes_needed(config) to the process and `account` (check() passed).
    explicit DefaultFramebuffer(const FramebufferConfig& config, std::shared_ptr<MemoryAccount> account = nullptr);

    const FramebufferConfig& config() const { return config_; }
    uint64_t memory_bytes() const { return memory_.bytes(); }   // charged to the memory ledger
    int32_t width() const { return config_.width; }
    int32_t height() const { return config_.height; }

    // Clears the part of `rect` inside the buffer. Channels with mask false keep their value.
    void clear_color(Rect rect, const std::array<float, 4>& rgba, const std::array<bool, 4>& mask);
    void clear_depth(Rect rect, float depth);
    void clear_stencil(Rect rect, int32_t value, uint32_t write_mask);

    // Copies the in-buffer part of the w x h block at (x, y) as RGBA8 (multisample resolved by the
    // rounded mean). `dst` points at the block's pixel (x, y); rows are `row_stride` bytes apart,
    // bottom row first. Pixels outside the buffer are not written.
    void read_rgba8(int32_t x, int32_t y, int32_t w, int32_t h, uint8_t* dst,
                    std::ptrdiff_t row_stride) const;

    // ---- float colour formats (RGBA16F, RGBA32F) --------------------------------------------
    bool is_float() const { return config_.color_format != ColorFormat::RGBA8; }
    // Bits per channel as RED_BITS etc. report them (8, 16 or 32).
    int color_bits() const;
    // Rounds a float to what a channel of this buffer holds: binary16 (ties to even) for RGBA16F,
    // unchanged for RGBA32F, k/255 (clamped, rounded) for RGBA8.
    float quantize(float v) const;
    // The samples of a float buffer, 4 floats each (16F values are stored already rounded to
    // binary16, as floats: same values, simpler blending). Float formats only.
    float* color_sample_f(int32_t x, int32_t y, int32_t s) {
        return &color_f_[(size_t(y) * config_.width + x) * config_.samples * 4 + size_t(s) * 4];
    }
    // Pixel (x, y) as float RGBA, multisample resolved by the mean (any format; float formats
    // round the mean to the format, as a resolve into a single-sampled buffer of it would).
    void read_pixel(int32_t x, int32_t y, float out[4]) const;
    // Sample s of pixel (x, y) as float RGBA (any format).
    void read_sample(int32_t x, int32_t y, int32_t s, float out[4]) const;
    // Writes float RGBA into every sample of (x, y), quantized to the format (unorm: clamped),
    // channels with mask false kept (alpha kept when there is no alpha channel).
    void write_pixel(int32_t x, int32_t y, const float rgba[4], const std::array<bool, 4>& mask);
    // Copies the in-buffer part of the w x h block at (x, y) as float RGBA (resolved like
    // read_pixel); `dst` points at the block's pixel (x, y), rows `row_stride` floats apart.
    void read_float(int32_t x, int32_t y, int32_t w, int32_t h, float* dst, std::ptrdiff_t row_stride) const;

    // Raw per-sample access for the pipeline and for tests (RGBA8 only).
    uint8_t* color_sample(int32_t x, int32_t y, int32_t s) {
        return &color_[(size_t(y) * config_.width + x) * config_.samples * 4 + size_t(s) * 4];
    }
    // The pixel's samples in the depth / stencil buffer, or null when there is no such buffer.
    uint32_t* depth_samples(int32_t x, int32_t y) {
        return depth_.empty() ? nullptr : &depth_[(size_t(y) * config_.width + x) * config_.samples];
    }
    uint8_t* stencil_samples(int32_t x, int32_t y) {
        return stencil_.empty() ? nullptr : &stencil_[(size_t(y) * config_.width + x) * config_.samples];
    }
    uint32_t depth_sample(int32_t x, int32_t y, int32_t s) const {
        return depth_.empty() ? 0 : depth_[(size_t(y) * config_.width + x) * config_.samples + s];
    }
    uint8_t stencil_sample(int32_t x, int32_t y, int32_t s) const {
        return stencil_.empty() ? 0 : stencil_[(size_t(y) * config_.width + x) * config_.samples + s];
    }

private:
    Rect clip(Rect rect) const;

    FramebufferConfig config_;
    CacheLineVector<uint8_t> color_;     // RGBA8
    CacheLineVector<float> color_f_;     // RGBA16F / RGBA32F
    CacheLineVector<uint32_t> depth_;
    CacheLineVector<uint8_t> stencil_;
    MemoryReservation memory_;           // bytes_needed(config_), charged once check() passed
};

}  // namespace softgl
