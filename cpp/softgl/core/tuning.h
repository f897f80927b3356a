// How a context runs its draws: the switches of softgl's speed paths. None of them changes a drawn
// byte (the tests compare every path with and without them); they exist so that the tests can
// prove that, and so that a benchmark can A/B a path. Each Context holds its own copy, taken from
// the process default when it is created (docs/architecture.md, "The draw plan").
#pragma once
#include <cstdint>

#include "softgl/core/simd.h"

namespace softgl {

// Hidden-surface removal within a draw (pipeline/tile_pass: the owner map): off, where a tile's
// primitives pile up (the default: a triangle counts its area, at most its box's part of the tile),
// in every tile with two or more primitives, or where their bounding boxes alone pile up (the rule
// before triangle areas, which ran the pass on meshes that cover a tile once).
enum class HiddenSurfaceRemoval : uint8_t { Off, WherePilesUp, InEveryTile, WhereBoxesPileUp };

// Per-tile depth bounds (pipeline/early_depth DepthBounds): off, on (the default), or on with the
// primitive's depth taken at the wrong corner, so that the tests comparing with Off must fail.
enum class DepthBoundsMode : uint8_t { Off, On, SabotagedForTests };

// Texture lookups (surface/sampler): the general path for every query; the 2D fast path with
// scalar arithmetic; the fast path at the best level the CPU and `simd` allow (the default);
// the fast path's AVX2 blocks even on an AVX-512 CPU.
enum class SamplerPath : uint8_t { General, Scalar, Best, Avx2 };

inline constexpr uint32_t kDrawBatchPrimitivesDefault = 1u << 16;
inline constexpr uint32_t kDrawBatchPrimitivesMax = 1u << 24;

struct Tuning {
    // The highest SIMD level any stage runs (raster, early depth, interpolation, colour kernels,
    // sampler, GLSL executor); capped at best_simd_level(). Lower it to A/B the levels.
    SimdLevel simd = best_simd_level();
    // Primitives per batch of a draw (pipeline/draw.cpp): bounds a draw's working memory. Small
    // values split small draws into many batches (the bytes must not change), up to
    // kDrawBatchPrimitivesMax.
    uint32_t batch_primitives = kDrawBatchPrimitivesDefault;
    HiddenSurfaceRemoval hidden_surface_removal = HiddenSurfaceRemoval::WherePilesUp;
    DepthBoundsMode depth_bounds = DepthBoundsMode::On;
    // A fragment shader that only copies one varying to its colour is not run: the colour
    // kernels read the interpolated varying (pipeline/glsl_stages FragmentShader::copies).
    bool fragment_copies = true;
    SamplerPath sampler_path = SamplerPath::Best;
    // The fragments of many primitives of a tile gathered into full shader batches (pipeline/
    // tile_pass); off: the shader runs per primitive chunk (the reference).
    bool fragment_batches = true;
    // ... and, for a shader that does not read its quad neighbours, only covered pixels shaded
    // (no helper lanes); off: whole quads.
    bool skip_helper_lanes = true;
    // A primitive whose varyings the shader reads have the same bits at every vertex is shaded
    // once per tile (pipeline/tile_pass, FragmentShader::run_flat); off: per fragment.
    bool flat_primitives = true;
    // blitFramebuffer copies and resolves of the same size row by row, on the thread pool
    // (api/framebuffers.cpp blit_rows); off: every blit takes the general per-pixel loop.
    bool blit_rows = true;
    // GLSL values that depend only on uniforms and constants computed once before the lanes
    // (glsl/executor order_prologue); off: per lane, where the shader computes them.
    bool hoist_uniform_values = true;
    // How long the thread pool's threads spin before they sleep, after a call (a worker waiting
    // for the next one) and at its end (the caller waiting for the workers' last items):
    // runtime/thread_pool.h. 0: they sleep at once (every call then pays a sleeping thread's
    // wake-up). Never changes the bytes.
    uint32_t pool_spin_microseconds = 100;
    // A fragment shader whose colour is one 2D texture lookup at a varying (pipeline/glsl_stages
    // GlslFragmentShader, "texture copies") asks the sampler itself, without the executor; off:
    // the executor runs it.
    bool texture_copies = true;
    // ... and where its lookup is NEAREST of 8-bit unorm storage and the write is plain (all
    // channels, one sample), the texels' RGBA8 words go to the pixels as they are (pipeline/
    // tile_pass, "texel words"); off: as floats through the colour kernels.
    bool texel_words = true;
    // ... and also where it is LINEAR of one 8-bit unorm level (no mipmaps: the mag filter, or a
    // min filter without them): each pixel's bytes from the fixed-point rule's integer sums
    // (surface/sampler, "texel words"); off: such lookups as floats through the colour kernels.
    bool linear_words = true;
    // ... skip_helper_lanes also for a shader whose only quad-neighbour reads are implicit-LOD
    // lookups of textures whose LOD cannot change the result during the draw (no mipmaps, one
    // filter for magnification and minification: ES 3.0 §3.8.11; FragmentShader::
    // reads_quad_neighbours_in_draw); off: any implicit-LOD lookup keeps whole quads.
    bool lod_free_helper_lanes = true;
    // A depth-only draw (DrawPlan::depth_blocks) tests the 8x8 blocks a primitive covers whole in
    // place (pipeline/whole_rect.h depth_covered_part); off: as the rasterizer's quads.
    bool depth_blocks = true;
    // The colour kernels of single-sampled RGBA8 quads that read the destination blend it in place
    // at AVX2 and AVX-512 (fragment_ops.h write_color_quads_at); off: gathered into lanes and back.
    bool blend_in_place = true;

    bool operator==(const Tuning& o) const {
        return simd == o.simd && batch_primitives == o.batch_primitives &&
               hidden_surface_removal == o.hidden_surface_removal && depth_bounds == o.depth_bounds &&
               fragment_copies == o.fragment_copies && sampler_path == o.sampler_path &&
               fragment_batches == o.fragment_batches && skip_helper_lanes == o.skip_helper_lanes &&
               blit_rows == o.blit_rows && hoist_uniform_values == o.hoist_uniform_values &&
               flat_primitives == o.flat_primitives && pool_spin_microseconds == o.pool_spin_microseconds &&
               texture_copies == o.texture_copies && texel_words == o.texel_words && linear_words == o.linear_words &&
               lod_free_helper_lanes == o.lod_free_helper_lanes && depth_blocks == o.depth_blocks &&
               blend_in_place == o.blend_in_place;
    }
    bool operator!=(const Tuning& o) const { return !(*this == o); }

    // The tuning new contexts start with. Not for use while another thread creates a context.
    static Tuning& process_default();
};

}  // namespace softgl
