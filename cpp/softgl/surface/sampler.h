// Texture lookups for the GLSL executor (glsl::TextureSampler) over the textures bound to the
// context's units at draw time: ES 3.0 §3.8.10 (coordinates, wrap modes, LOD from derivatives,
// mipmap selection), §3.8.11-12 (nearest, linear, mipmap filters), §3.8.9 (cube map face
// selection, seamless filtering in WebGL 2), §3.8.15 (sRGB, decoded at upload), §3.8.16 (depth
// comparison), texelFetch and textureSize (ES 3.00 GLSL §8.8).
//
// Everything is computed in float32 per lane, in a fixed order: the same inputs give the same
// bits whatever the batch size or thread. LINEAR filtering of 8-bit unorm textures follows a
// fixed-point rule (8-bit weights, exact integer sums; README "Choices", sampler.cpp).
#pragma once
#include <array>
#include <cstdint>

#include "softgl/core/tuning.h"
#include "softgl/glsl/executor.h"
#include "softgl/surface/texture.h"

namespace softgl {

// What the fast path (TextureUnitSampler::sample_2d) resolves once per draw for one unit and
// sampler dimension, so that a query goes straight to its block loop: the level table's checks,
// the filters and wraps, and the block loop for the texture's shape. Made by
// TextureUnitSampler::plan_units after the draw has bound its textures (Texture::refresh_sampling);
// `usable` false: the fast path does not serve the unit (or plan_units did not run).
struct SamplingPlan {
    bool usable = false;
    const SampledLevel* planes = nullptr;   // levels base .. q of face 0 (Texture::sampled)
    int32_t face_stride = 0;                // face f's levels at planes + f * face_stride
    bool depth = false;                     // depth planes (else colour)
    // Every level of one storage (bytes or floats) with int32 texel numbers; all power-of-two sizes.
    bool one_storage = false, pot = false;
    GLenum wrap_s = 0, wrap_t = 0;          // cube maps: CLAMP_TO_EDGE within the face
    bool mag_linear = false, min_linear = false, mipmapped = false;
    bool needs_lambda = false;              // the LOD can change the result (ES 3.0 §3.8.11)
    // The colour block loop of this shape for queries without layers (sampler.cpp,
    // colour_block_loops): 0 the general one.
    uint8_t colour_shape = 0;
};

// What one unit gives one sampler dimension during a draw.
struct BoundTexture {
    const Texture* texture = nullptr;   // null: no texture or incomplete (samples as (0,0,0,1))
    SamplerParams params;               // the sampler object's, or the texture's own
    int32_t base = 0, q = 0;            // levels used: [base, q] (q = base without mipmapping)
    bool seamless_cube = true;          // ES 3.0 §3.8.9.1 (WebGL 2); WebGL 1 clamps per face
    bool depth_as_luminance = false;    // WEBGL_depth_texture: depth samples as (d, d, d, 1)
    SamplingPlan plan;                  // TextureUnitSampler::plan_units
};

inline constexpr int kSamplerUnits = 32;

// Each query takes the path its TextureQuery::path names (core/tuning.h SamplerPath), with SIMD
// blocks up to TextureQuery::simd; all give the same bits (NaNs aside: which NaN).
class TextureUnitSampler : public glsl::TextureSampler {
public:
    // units[unit][dim]: dim 0 = 2D, 1 = 3D, 2 = cube, 3 = 2D array.
    std::array<std::array<BoundTexture, 4>, kSamplerUnits> units;
    // False when no unit's texture has TEXTURE_MAX_ANISOTROPY_EXT above 1 (set by the draw that
    // fills `units`): queries then skip the per-lane anisotropy check.
    bool any_anisotropic = true;
    // Makes the SamplingPlan of every units[unit][dim] whose bit `unit` is set in filled[dim],
    // once the draw has filled `units` and refreshed their textures' level tables
    // (single-threaded, before any lookup of the draw).
    void plan_units(const uint32_t filled[4]);
    void sample(const glsl::TextureQuery& query) override;
    bool lod_matters(const glsl::TextureQuery& query) const override;
    bool gives_words(const glsl::TextureQuery& query, bool linear) const override;
    void sample_words(const glsl::TextureQuery& query, uint32_t* words) override;
    bool lod_matters_in(glsl::SamplerDim dim) const override;
    // Bit dim_index: no unit's texture of that dimension lets the LOD change a lookup during the
    // draw (plan_units sets it; 0, the safe answer, until then).
    uint32_t lod_free_dims = 0;

private:
    // The general path: every lane on its own, any texture kind and dimension.
    void sample_lanes(const glsl::TextureQuery& query) const;
    void sample_lane(const glsl::TextureQuery& query, int lane) const;
    // The common case, resolved once per query from the texture's level table
    // (Texture::sampled_levels): filtered lookups of one 2D / 2D array / cube map texture of a
    // colour format that samples as float or of a depth format (with or without the depth
    // comparison), colour 2D / 2D array lookups in blocks of 8 lanes with AVX2, of 16 and 8 with
    // AVX-512. Cube-map lanes whose footprint crosses a face edge (seamless filtering) go to
    // sample_lane. False (nothing written) when the query is not that.
    enum class SimdBlocks { None, Avx2, Avx512 };
    // EXT_texture_filter_anisotropic: whether a lane of the query samples a texture whose
    // TEXTURE_MAX_ANISOTROPY_EXT is above 1, and the lookups that then serve the query lane by
    // lane (the rule is in sampler.cpp, "anisotropic filtering").
    bool anisotropic(const glsl::TextureQuery& query) const;
    void sample_anisotropic(const glsl::TextureQuery& query) const;
    void sample_lane_anisotropic(const glsl::TextureQuery& query, int lane, const BoundTexture& bt) const;
    bool sample_2d(const glsl::TextureQuery& query, SimdBlocks simd) const;
};

// units[unit][dim_index(dim)] (inline: every lookup asks).
inline int dim_index(glsl::SamplerDim dim) {
    switch (dim) {
        case glsl::SamplerDim::Tex3D: return 1;
        case glsl::SamplerDim::Cube: return 2;
        case glsl::SamplerDim::Tex2DArray: return 3;
        default: return 0;
    }
}

// The LOD of ES 3.0 eq. 3.17-3.19 as the fast path computes it, lambda = float(log2(sqrt(rho2)))
// with rho2 the larger squared footprint length, for n values by the kernel of one SIMD level:
// Scalar and SSE2 LambdaMemo (libm's log2, as the general path), AVX2 4 and AVX-512 8 values
// per vector, each vouched for by a rounding test or else taken from LambdaMemo (sampler.cpp,
// lambda_exact4), so that all give the same bits. Returns how many values the vector kernel
// vouched for (tests check that it serves nearly all, and compare every level with float64).
size_t lambdas_of_rho2_at(SimdLevel simd, const double* rho2, size_t n, float* out);

// ES 3.0 table 3.21: the face (0..5, TEXTURE_CUBE_MAP_POSITIVE_X order) a direction selects and
// the face coordinates sc, tc and |ma|.
int cube_face(float rx, float ry, float rz, float& sc, float& tc, float& ma);

}  // namespace softgl
