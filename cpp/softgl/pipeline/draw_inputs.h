// What a draw is given: the draw call (mode, vertices, instances) and the inputs it reads and
// writes (state, vertex arrays, shaders, render target, thread pool, tuning, blend lab hooks).
// Shared by the draw plan (pipeline/draw_plan), the tile pass (pipeline/tile_pass) and the draw
// itself (pipeline/draw).
#pragma once
#include <array>
#include <cstdint>

#include "softgl/core/objects.h"
#include "softgl/core/state.h"
#include "softgl/core/tuning.h"
#include "softgl/core/work_budget.h"
#include "softgl/pipeline/shader_stage.h"
#include "softgl/runtime/thread_pool.h"
#include "softgl/surface/render_target.h"

namespace softgl {

struct DrawCall {
    GLenum mode = gl::TRIANGLES;
    uint32_t first = 0;               // drawArrays
    uint32_t count = 0;
    const uint32_t* indices = nullptr;   // drawElements: `count` indices, already range-checked
    // When known (the API layer reads every index): the smallest and largest of indices[0, count).
    bool index_bounds = false;
    uint32_t lowest_index = 0, highest_index = 0;
    uint32_t instance_count = 1;
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
    // The call's work budget (core/work_budget.h); null: unbudgeted. The draw charges it per
    // vertex, primitive, (primitive, tile) pair and fragment, the shaders' executors per loop iteration.
    WorkBudget* budget = nullptr;
    // The context's memory account (core/memory_ledger.h): the draw's copies for a rollback are
    // charged to it for the draw's length. Null: the process total only.
    std::shared_ptr<MemoryAccount> memory{};
};

}  // namespace softgl
