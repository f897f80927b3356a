// A draw call from shaded vertices to pixels: vertex fetch and shading, then primitive assembly,
// clip/setup and binning (both in chunks on the thread pool, gathered in primitive order), then per
// tile on the thread pool: raster, early tests, fragment shading, late tests, blending and the
// write (DESIGN §2). The API layer validates before calling here.
#pragma once
#include <array>
#include <cstdint>

#include "softgl/core/objects.h"
#include "softgl/core/state.h"
#include "softgl/core/tuning.h"
#include "softgl/pipeline/shader_stage.h"
#include "softgl/runtime/thread_pool.h"
#include "softgl/surface/render_target.h"

namespace softgl {

struct DrawCall {
    GLenum mode = gl::TRIANGLES;
    uint32_t first = 0;               // drawArrays
    uint32_t count = 0;
    const uint32_t* indices = nullptr;   // drawElements: `count` indices, already range-checked
    uint32_t instance_count = 1;
};

// Counters for gl.stats(): what was done and what was skipped (DESIGN §4).
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
    uint64_t fragments_hidden = 0;      // passed the tests, then covered by a later one: not shaded
    uint64_t primitives_depth_hidden = 0;  // (primitive, tile) pairs failing early depth everywhere: not rasterized
    uint64_t samples_written = 0, samples_blended = 0;
    uint64_t draws_skipped_no_output = 0;  // nothing could change: no shading at all
    uint64_t draws_early_depth = 0;        // depth/stencil tested before shading
    uint64_t draws_plain_write = 0;        // blending off or ONE/ZERO/ADD: no destination read
    uint64_t draws_blend_table = 0;        // a constant colour blended by table lookup (fragment_ops.h)
    uint64_t texture_queries_fast = 0;     // lookups (per instruction and batch of lanes) served by the 2D fast path
    double seconds_vertex = 0, seconds_setup = 0, seconds_fragment = 0;
    void add(const DrawStats& o);
};

class FragmentSink;

struct DrawInputs {
    const State& state;
    const VertexArray& vertex_array;
    const std::array<CurrentAttrib, kMaxVertexAttribs>& current_attribs;
    const VertexShader& vertex_shader;
    const FragmentShader& fragment_shader;
    RenderTarget& target;             // the drawing buffer or a framebuffer object's attachments
    ThreadPool& pool;
    const Tuning& tuning;             // the context's speed-path switches (core/tuning.h)
    FragmentSink* sink = nullptr;   // blend lab hooks (pipeline/fragment_sink.h); null = off
};

// Runs a draw call in batches of at most draw_batch_primitives() primitives (pipeline/draw.cpp):
// its working memory is bounded, whatever the number of vertices and instances.
void draw(const DrawInputs& in, const DrawCall& call, DrawStats& stats);

// For tests: the batch size, set to split small draws into many batches (the bytes must not
// change). 0 restores the default; sizes are capped at kDrawBatchPrimitivesMax. Returns the
// previous size.
uint32_t draw_batch_primitives();
uint32_t set_draw_batch_primitives(uint32_t primitives);

// For tests: hidden-surface removal (pipeline/draw.cpp OwnerMap) in the tiles where primitives
// pile up (the default), in every tile with two or more, or never (the bytes must not change).
// Returns the previous mode.
HiddenSurfaceRemoval set_hidden_surface_removal(HiddenSurfaceRemoval mode);

}  // namespace softgl
