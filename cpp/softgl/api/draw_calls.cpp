// drawArrays / drawElements and their instanced and ranged forms: WebGL's validation (WebGL 1.0
// §6.6 ranges, §6.11 stencil consistency, ANGLE_instanced_arrays / WebGL 2), then the pipeline.
#include <algorithm>
#include <cstring>
#include <memory>

#include "softgl/api/blendlab.h"
#include "softgl/api/context.h"
#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/vertex_fetch.h"

namespace softgl {

namespace {

int index_size(GLenum type) {
    switch (type) {
        case gl::UNSIGNED_BYTE: return 1;
        case gl::UNSIGNED_SHORT: return 2;
        case gl::UNSIGNED_INT: return 4;
        default: return 0;
    }
}

// Copies `count` indices of type T from src (any alignment) into out as 32-bit words; returns the
// largest, and sets the smallest and whether `restart` occurs. One pass without branches (the
// largest index other than `restart` is looked for again only when it occurs).
template <class T>
uint32_t read_indices(const uint8_t* src, size_t count, uint32_t* out, uint32_t restart, uint32_t& smallest,
                      bool& has_restart) {
    uint32_t largest = 0, lowest = ~0u, found = 0;
    for (size_t i = 0; i < count; ++i) {
        T t;
        std::memcpy(&t, src + sizeof(T) * i, sizeof(T));
        const uint32_t v = t;
        out[i] = v;
        largest = std::max(largest, v);
        lowest = std::min(lowest, v);
        found |= uint32_t(v == restart);
    }
    smallest = lowest;
    has_restart = found != 0;
    return largest;
}

}  // namespace

bool Context::validate_draw_state(const char* call) {
    // A program in use keeps its last good executable through a failed relink (ES 2.0 §2.10.3).
    if (!current_program_ || !current_program_->vertex_stage) {
        error(gl::INVALID_OPERATION, call, "no valid program is in use");
        return false;
    }
    // WebGL 1.0 §6.11 / WebGL 2.0 §5.? : front and back stencil reference, value mask and write
    // mask must agree, compared within the stencil bits of the bound draw framebuffer.
    const bool has_stencil = draw_framebuffer_ ? draw_framebuffer_->stencil.image() != nullptr
                                               : framebuffer_.config().stencil;
    const uint32_t bits = has_stencil ? 0xFFu : 0u;
    const StencilFace &f = state_.stencil_front, &b = state_.stencil_back;
    if ((uint32_t(f.ref) & bits) != (uint32_t(b.ref) & bits) || (f.value_mask & bits) != (b.value_mask & bits) ||
        (f.write_mask & bits) != (b.write_mask & bits)) {
        error(gl::INVALID_OPERATION, call, "front and back stencil ref/masks differ (not allowed in WebGL)");
        return false;
    }
    return prepare_textures_and_targets(call);   // textures.cpp: units, completeness, framebuffer
}

void Context::report_stopped(const char* call, StopReason reason, uint64_t limit, const char* what) {
    // OUT_OF_MEMORY: the call ran out of a resource, here its work budget (ES 3.0 §2.5: "not
    // enough memory left to execute the command"), and the context stays usable; softgl
    // guarantees more than GL does after it: nothing changed. docs/reliability.md, "Work budget
    // and Ctrl-C", says why not CONTEXT_LOST_WEBGL or INVALID_OPERATION.
    if (reason == StopReason::Interrupted)
        return error(gl::OUT_OF_MEMORY, call, std::string("interrupted (Ctrl-C); ") + what);
    error(gl::OUT_OF_MEMORY, call,
          "stopped: the work budget of " + std::to_string(limit) + " units ran out (a loop that never ends, or more work "
          "than the budget allows: see set_work_budget); " + what);
}

void Context::run_draw(const DrawCall& call, const char* call_name) {
    Program& p = *current_program_;
    // However the draw ends, the blend lab's records it added (or rolled back) are charged.
    struct ChargeBlendLab {
        Context& c;
        ~ChargeBlendLab() { c.charge_blend_lab(); }
    } charge_blend_lab_after{*this};
    // gl_DepthRange is a built-in uniform: (near, far, far - near) from the current state.
    for (const auto& u : p.linked->reflection.uniforms) {
        if (!u.is_builtin) continue;
        const float values[3] = {state_.depth_range[0], state_.depth_range[1], state_.depth_range[1] - state_.depth_range[0]};
        const int field = u.name == "gl_DepthRange.near" ? 0 : u.name == "gl_DepthRange.far" ? 1 : 2;
        p.uniforms[size_t(u.offset)].f = values[field];
    }
    // Textures and framebuffers: the units' textures and the bound framebuffer (textures.cpp).
    p.vertex_stage->set_sampler(draw_sampler());
    p.fragment_stage->set_sampler(draw_sampler());
    RenderTarget target = draw_target();
    // drawBuffers([NONE]) on the drawing buffer: no colour is written (ES 3.0 §4.2.1).
    State no_color;
    const State* state = &state_;
    if (!draw_framebuffer_ && default_draw_buffer_ == gl::NONE) {
        no_color = state_;
        no_color.color_mask = {false, false, false, false};
        state = &no_color;
    }
    DrawInputs in{*state, *vertex_array_, current_attribs_, *p.vertex_stage, *p.fragment_stage, target, pool(), tuning_};
    in.sink = blendlab_sink();                  // blend lab hooks; null unless enabled
    in.budget = &work_budget_;
    in.memory = memory_account_;
    work_budget_.begin(work_limits_.draw);
    p.vertex_stage->set_budget(&work_budget_);
    p.fragment_stage->set_budget(&work_budget_);
    try {
        last_draw_plan_ = draw(in, call, stats_);
    } catch (const WorkStopped& stopped) {
        // The pipeline put back every pixel, depth and stencil value it wrote (pipeline/draw_rollback.h).
        if (in.sink) blendlab().abort_draw();   // and the blend lab's records of this draw
        return report_stopped(call_name, stopped.reason, work_limits_.draw,
                              "nothing was drawn: every pixel, depth and stencil value is as before the call");
    } catch (const DrawOutOfMemory& oom) {
        if (in.sink) blendlab().abort_draw();
        return error(gl::OUT_OF_MEMORY, call_name,
                     oom.why + (oom.unchanged ? "; nothing was drawn: every pixel, depth and stencil value is as before the call"
                                              : "; the picture may be partly drawn (the draw kept no copies to undo it)"));
    }
    // Counted per worker by the stages (no shared writes while drawing); summed here, per draw.
    stats_.texture_queries_fast +=
        p.vertex_stage->take_fast_texture_queries() + p.fragment_stage->take_fast_texture_queries();
    if (in.sink) blendlab().end_draw();         // reports an A-buffer/log over its memory limit
}

void Context::draw_arrays(GLenum mode, int32_t first, int32_t count, int32_t instances, const char* call) {
    if (!valid_draw_mode(mode)) return error(gl::INVALID_ENUM, call, enum_name(mode) + " is not a primitive mode");
    if (first < 0 || count < 0 || instances < 0) return error(gl::INVALID_VALUE, call, "first, count and instance count must not be negative");
    if (!validate_draw_state(call)) return;
    if (count == 0 || instances == 0) return;
    const uint32_t used = current_program_->vertex_stage->used_attributes();
    const std::string range = check_attribute_ranges(*vertex_array_, used, uint64_t(first) + uint64_t(count) - 1,
                                                     uint64_t(instances));
    if (!range.empty()) return error(gl::INVALID_OPERATION, call, range);
    DrawCall dc;
    dc.mode = mode;
    dc.first = uint32_t(first);
    dc.count = uint32_t(count);
    dc.instance_count = uint32_t(instances);
    run_draw(dc, call);
}

void Context::draw_elements(GLenum mode, int32_t count, GLenum type, int64_t offset, int32_t instances,
                            const char* call) {
    if (!valid_draw_mode(mode)) return error(gl::INVALID_ENUM, call, enum_name(mode) + " is not a primitive mode");
    const int size = index_size(type);
    if (!size || (type == gl::UNSIGNED_INT && version() < 2 && !extension_enabled("OES_element_index_uint")))
        return error(gl::INVALID_ENUM, call, enum_name(type) + " is not an index type here");
    if (count < 0 || instances < 0) return error(gl::INVALID_VALUE, call, "count and instance count must not be negative");
    if (offset < 0) return error(gl::INVALID_VALUE, call, "offset must not be negative");
    if (offset % size != 0) return error(gl::INVALID_OPERATION, call, "offset must be a multiple of the index size");
    if (!validate_draw_state(call)) return;
    const InUse<Buffer>& elements = vertex_array_->element_buffer;
    if (!elements) return error(gl::INVALID_OPERATION, call, "no ELEMENT_ARRAY_BUFFER is bound");
    // Nothing is read for an empty draw, so its offset is not range-checked (as the WebGL
    // conformance test draw-elements-out-of-bounds expects).
    if (count == 0 || instances == 0) return;
    if (uint64_t(offset) + uint64_t(count) * uint64_t(size) > elements->data.size())
        return error(gl::INVALID_OPERATION, call, "the indices extend past the end of the element array buffer");
    // Read the indices once; WebGL requires every index to address data inside the buffers.
    // WebGL 2.0 §5.18: primitive restart with the type's maximum index is always on; that index
    // ends the current strip, fan or loop and is never a vertex.
    const uint32_t restart = size == 1 ? 0xFFu : size == 2 ? 0xFFFFu : 0xFFFFFFFFu;
    const bool restart_enabled = version() >= 2;
    // The pipeline's working memory is bounded (it draws in batches of primitives), but the
    // indices are read into 32-bit words here, and a restart expands them into up to 3 words each:
    // they are charged to the memory ledger for the call's length (core/memory_ledger.h), and
    // refused before anything is allocated when they would pass a limit.
    MemoryReservation index_memory(memory_account_);
    auto too_large = [&](uint64_t words) {
        if (index_memory.resize(words * 4)) return false;
        error(gl::OUT_OF_MEMORY, call, "the draw's " + std::to_string(words) + " index words (" +
              std::to_string(words * 4) + " bytes) " + index_memory.over_limit(words * 4 - index_memory.bytes()));
        return true;
    };
    if (too_large(uint64_t(count))) return;
    const std::unique_ptr<uint32_t[]> read(new uint32_t[size_t(count)]);   // not zero-filled: all written below
    const uint8_t* src = elements->data.data() + offset;
    uint32_t* const words = read.get();
    bool found = false;
    uint32_t min_index = 0;
    uint32_t max_index = size == 1 ? read_indices<uint8_t>(src, size_t(count), words, restart, min_index, found)
                       : size == 2 ? read_indices<uint16_t>(src, size_t(count), words, restart, min_index, found)
                                   : read_indices<uint32_t>(src, size_t(count), words, restart, min_index, found);
    // Without primitive restart (WebGL 1) the largest value is an index like any other.
    const bool restarts = restart_enabled && found;
    if (restarts) {
        max_index = 0;
        for (int32_t i = 0; i < count; ++i)
            if (words[i] != restart) max_index = std::max(max_index, words[i]);
    }
    const uint32_t used = current_program_->vertex_stage->used_attributes();
    const std::string range = check_attribute_ranges(*vertex_array_, used, max_index, uint64_t(instances));
    if (!range.empty()) return error(gl::INVALID_OPERATION, call, range);
    DrawCall dc;
    dc.mode = mode;
    std::vector<uint32_t> expanded;
    if (restarts) {
        if (too_large(4 * uint64_t(count))) return;   // the indices and their expansion (with them, 4 words each)
        // Assemble each run between restart indices on its own, as an independent list of points,
        // lines or triangles (the provoking vertex stays last, strips keep their winding).
        std::vector<uint32_t> positions;
        size_t begin = 0;
        for (size_t i = 0; i <= size_t(count); ++i) {
            if (i < size_t(count) && words[i] != restart) continue;
            positions.clear();
            assemble(mode, uint32_t(i - begin), positions);
            for (uint32_t k : positions) expanded.push_back(words[begin + k]);
            begin = i + 1;
        }
        const int per = vertices_per_primitive(mode);
        dc.mode = per == 1 ? gl::POINTS : per == 2 ? gl::LINES : gl::TRIANGLES;
        if (expanded.empty()) return;
    }
    dc.count = restarts ? uint32_t(expanded.size()) : uint32_t(count);
    dc.indices = restarts ? expanded.data() : words;
    dc.index_bounds = !restarts;   // the expansion may leave some out
    dc.lowest_index = min_index, dc.highest_index = max_index;
    dc.instance_count = uint32_t(instances);
    run_draw(dc, call);
}

void Context::draw_range_elements(GLenum mode, uint32_t start, uint32_t end, int32_t count, GLenum type, int64_t offset) {
    if (end < start) return error(gl::INVALID_VALUE, "drawRangeElements", "end must not be less than start");
    // The range is a hint (ES 3.0 §2.8.3); indices outside it still draw correctly.
    draw_elements(mode, count, type, offset, 1, "drawRangeElements");
}

}  // namespace softgl
