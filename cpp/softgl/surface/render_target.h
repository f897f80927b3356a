// What a draw renders into: the default framebuffer (RGBA8 drawing buffer) or the attachments of
// a framebuffer object (texture images and renderbuffers of any renderable format). The
// pipeline sees one interface: size, samples, depth/stencil words per sample and a colour
// write that blends and quantizes for the attachment's format.
#pragma once
#include <array>
#include <cstdint>

#include "softgl/surface/blend.h"
#include "softgl/surface/framebuffer.h"
#include "softgl/surface/texture.h"

namespace softgl {

class RenderTarget {
public:
    static constexpr int kMaxColors = 8;
    struct Color {
        Image* image = nullptr;     // null: nothing drawn for this fragment output
        size_t offset = 0;          // first texel of the attached layer
    };

    // The drawing buffer.
    static RenderTarget for_default(DefaultFramebuffer& fb);
    // A framebuffer object of w x h (the smallest attachment), `samples` per pixel; colors[i]
    // receives fragment output i (after drawBuffers), depth/stencil may be null.
    static RenderTarget for_images(int32_t width, int32_t height, int32_t samples,
                                   const std::array<Color, kMaxColors>& colors, Image* depth, size_t depth_offset,
                                   Image* stencil, size_t stencil_offset);

    int32_t width() const { return config_.width; }
    int32_t height() const { return config_.height; }
    // alpha: whether destination alpha exists (the drawing buffer's `alpha`; always for FBOs).
    const FramebufferConfig& config() const { return config_; }
    bool is_default() const { return default_ != nullptr; }
    DefaultFramebuffer* default_framebuffer() const { return default_; }   // null for FBOs
    int depth_bits() const;
    // The word the depth test compares for window depth z in [0, 1].
    uint32_t depth_word(double z) const;
    uint32_t* depth_samples(int32_t x, int32_t y);
    uint8_t* stencil_samples(int32_t x, int32_t y);
    // A framebuffer object's depth and stencil images (null for the drawing buffer or when absent)
    // and where the attached layer starts.
    // Colour buffer i of a framebuffer object (image null: none; always none for the drawing buffer).
    const Color& color_attachment(int i) const { return colors_[size_t(i)]; }
    Image* depth_image() const { return depth_; }
    Image* stencil_image() const { return stencil_; }
    size_t depth_offset() const { return depth_offset_; }
    size_t stencil_offset() const { return stencil_offset_; }
    // Pixels from one row of the depth buffer to the next (an attached image may be wider than
    // the target, which is the smallest attachment).
    int32_t depth_pitch() const { return default_ ? config_.width : depth_ ? depth_->width : 0; }
    // Blends `src` (fragment output `output`) into sample s of pixel (x, y) of the colour buffer
    // drawBuffers maps that output to (none: nothing happens), quantizing to the buffer's format.
    // The drawing buffer has output 0 only (BACK). Blending state is shared by all buffers;
    // clamping follows each buffer's format (ES 3.0 §4.1.7).
    void write_color(const BlendOp& op, const float src[4], int32_t x, int32_t y, int s, int output = 0);
    // The colour buffer as RGBA8 bytes when the pipeline's byte paths (colour kernels, the
    // blend table) can write it: 4 bytes per sample, the samples of a pixel together, rows
    // width() pixels apart, pixel (0, 0) first. That is the RGBA8 drawing buffer, or a
    // framebuffer object whose only colour buffer is an RGBA8 image at output 0 as wide as
    // the target with the target's samples (Image stores RGBA8 in the drawing buffer's layout).
    // Null otherwise.
    uint8_t* color_rgba8() const { return rgba8_; }
    // Whether fragment output `output` reaches a colour buffer.
    bool has_color(int output) const {
        return default_ ? output == 0 : (output >= 0 && output < kMaxColors && colors_[size_t(output)].image);
    }

private:
    FramebufferConfig config_;
    DefaultFramebuffer* default_ = nullptr;
    std::array<Color, kMaxColors> colors_{};
    Image* depth_ = nullptr;
    Image* stencil_ = nullptr;
    size_t depth_offset_ = 0, stencil_offset_ = 0;
    uint8_t* rgba8_ = nullptr;
};

// Writes a colour into sample s of texel (x, y) of an image at `offset` (blending with `op`).
void write_image_color(Image& img, size_t offset, const BlendOp& op, const float src[4], int32_t x, int32_t y, int s);

// Clears of the attached images (ES 3.0 §4.2.3), every sample of the pixels of `r` (inside the
// image). A colour clear writes `src` (floats, or an integer format's bits) into the first texel
// through write_image_color, with no blending and the channels of `mask`, and copies that texel's
// written channels to the rest: one conversion per clear, not per texel.
void clear_image_color(Image& img, size_t offset, Rect r, const float src[4], const std::array<bool, 4>& mask);
// Every sample's depth word of `r` set to `word`.
void clear_image_depth(Image& img, size_t offset, Rect r, uint32_t word);
// Every sample's stencil of `r`: the bits of `write_mask` from `value`, the others kept.
void clear_image_stencil(Image& img, size_t offset, Rect r, uint8_t value, uint8_t write_mask);

}  // namespace softgl
