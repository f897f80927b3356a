// API-side types of textures, samplers, renderbuffers and framebuffers (textures.cpp,
// framebuffers.cpp). The storage and sampling live in surface/texture.* and surface/sampler.*.
#pragma once
#include <array>
#include <cstdint>
#include <memory>

#include "softgl/core/memory_ledger.h"
#include "softgl/core/objects.h"
#include "softgl/surface/texture.h"

namespace softgl {

// The pixels argument of texImage*/texSubImage*: nothing (null), an ArrayBufferView (bytes laid
// out by format/type and the UNPACK_* state, `array_type` the typed-array kind for WebGL's type
// check), or an image source (here: a NumPy H x W x C array converted by the bindings to tight
// RGBA rows of UNSIGNED_BYTE or FLOAT, row 0 = the image's first row).
// WebGL 2 also takes a byte offset into the PIXEL_UNPACK_BUFFER (Kind::UnpackBuffer, `offset`).
struct TexSource {
    enum class Kind { None, View, Image, UnpackBuffer };
    Kind kind = Kind::None;
    int64_t offset = 0;               // UnpackBuffer: bytes into the bound PIXEL_UNPACK_BUFFER
    const uint8_t* data = nullptr;
    size_t bytes = 0;
    GLenum array_type = 0;            // View: UNSIGNED_BYTE, FLOAT, ... of the typed array
    int32_t width = 0, height = 0;    // Image: its size
    GLenum image_type = 0;            // Image: UNSIGNED_BYTE or FLOAT (RGBA, 4 components)
};

class Renderbuffer : public Object {
public:
    Image image;                      // samples > 1 for multisample storage
    MemoryReservation reservation;    // image's bytes, charged to the ledger (core/memory_ledger.h)
    GLenum internal_format = gl::RGBA4;
    int32_t samples = 0;              // as requested (0 = single-sampled)
    uint64_t generation = 0;
    void release_storage() override {   // deleted and unused (Object)
        image.clear();
        reservation.release();
        ++generation;
    }
};

struct Attachment {
    // InUse: a deleted texture or renderbuffer keeps its storage while attached here.
    InUse<Texture> texture;
    InUse<Renderbuffer> renderbuffer;
    int face = 0;                     // cube map face of the texture
    int32_t level = 0, layer = 0;
    bool empty() const { return !texture && !renderbuffer; }
    // The attached image, or null when nothing (or an undefined level) is attached.
    Image* image() const;
};

inline constexpr int kMaxColorAttachments = 8;

class DefaultFramebuffer;

// Where readPixels, copyTexImage2D and blitFramebuffer read colour from: the drawing buffer or
// one attached image (at a texel offset for layers).
struct ColorReadSource {
    DefaultFramebuffer* fb = nullptr;
    const Image* img = nullptr;
    size_t offset = 0;
    int32_t width = 0, height = 0;
};

class Framebuffer : public Object {
public:
    std::array<Attachment, kMaxColorAttachments> color;
    Attachment depth, stencil;        // DEPTH_STENCIL_ATTACHMENT sets both
    std::array<GLenum, kMaxColorAttachments> draw_buffers{gl::COLOR_ATTACHMENT0, gl::NONE, gl::NONE, gl::NONE,
                                                          gl::NONE, gl::NONE, gl::NONE, gl::NONE};
    GLenum read_buffer = gl::COLOR_ATTACHMENT0;
};

}  // namespace softgl
