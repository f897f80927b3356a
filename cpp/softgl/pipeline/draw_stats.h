// Counters for gl.stats(): what a draw did and what it skipped (docs/architecture.md, "Fast
// paths"). Every counter is the same at any thread count, batch size and SIMD level; the draw-kind
// counters (draws_*) count a draw once, however many batches it runs in.
#pragma once
#include <cstdint>

namespace softgl {

struct DrawStats {
    uint64_t draws = 0;
    uint64_t vertices_shaded = 0;       // vertex shader runs: distinct vertices x instances, per batch
    uint64_t primitives = 0, primitives_culled = 0, primitives_clipped = 0,
             primitives_outside = 0, primitives_invalid = 0, primitives_zero_area = 0,
             primitives_rasterized = 0;
    uint64_t tiles_touched = 0;         // tiles with work, each counted once per draw (not per batch)
    uint64_t quads = 0, blocks_accepted_whole = 0;
    uint64_t fragments_shaded = 0;      // lanes run through the fragment shader (helpers included)
    uint64_t fragments_killed_early = 0, fragments_killed_late = 0, fragments_discarded = 0;
    uint64_t fragments_flat = 0;        // of those, lanes of flat primitives: one shader run per primitive and tile
    uint64_t fragments_hidden = 0;      // passed the tests, then covered by a later one: not shaded
    uint64_t tiles_hidden_surface = 0;  // (tile, batch) pairs whose hidden-surface first pass ran
    uint64_t primitives_depth_hidden = 0;  // (primitive, tile) pairs failing early depth everywhere: not rasterized
    uint64_t samples_written = 0, samples_blended = 0;
    uint64_t draws_skipped_no_output = 0;  // nothing could change: no shading at all
    uint64_t draws_early_depth = 0;        // depth/stencil tested before shading
    uint64_t draws_plain_write = 0;        // blending off or ONE/ZERO/ADD: no destination read
    uint64_t draws_blend_table = 0;        // a constant colour blended by table lookup (fragment_ops.h)
    // More draw kinds of the draw plan (pipeline/draw_plan.h). The last two are counted when a
    // draw reaches its first tile pass (the shader has run once then).
    uint64_t draws_late_tests = 0;         // depth/stencil tested after shading (discard, gl_FragDepth, coverage ops)
    uint64_t draws_per_lane_color = 0;     // colour blended lane by lane, not by the colour kernels
    uint64_t draws_constant_color = 0;     // a uniform-only shader's colour, computed once, to the colour kernels
    uint64_t draws_flat_primitives = 0;    // primitives with equal varyings get one colour (FragmentShader::run_flat)
    uint64_t draws_copied_varying = 0;     // a shader that only copies varyings or constants: not run
    uint64_t draws_with_rollback = 0;      // kept copies of the pixels they wrote (pipeline/draw_rollback.h)
    uint64_t texture_queries_fast = 0;
    uint64_t draws_texture_copy = 0;       // a shader that is one texture lookup: the sampler asked without the executor
    uint64_t draws_texel_words = 0;        // ... NEAREST (or one LINEAR level) of 8-bit unorm texels, their words written     // lookups (per instruction and batch of lanes) served by the 2D fast path
    uint64_t blocks_depth_in_place = 0;    // depth-only draws' covered 8x8 blocks tested without quads (whole_rect.h)
    uint64_t quads_blended_in_place = 0;   // quads the colour kernels blended in the buffer (Tuning::blend_in_place)
    double seconds_vertex = 0, seconds_setup = 0, seconds_fragment = 0;
    void add(const DrawStats& o);
};

}  // namespace softgl
