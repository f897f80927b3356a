// A draw call from shaded vertices to pixels (docs/architecture.md, "Life of a draw call"): the
// draw plan (pipeline/draw_plan), then in batches of primitives: vertex fetch and shading,
// primitive assembly, clip/setup and binning (both in chunks on the thread pool, gathered in
// primitive order), and the tile pass (pipeline/tile_pass). The API layer validates before
// calling here.
#pragma once
#include <exception>
#include <string>

#include "softgl/pipeline/draw_inputs.h"
#include "softgl/pipeline/draw_plan.h"
#include "softgl/pipeline/draw_stats.h"

namespace softgl {

// Thrown by draw() when its memory ran out: the copies for a rollback passed the memory limit
// (before any pixel was written), or an allocation failed (std::bad_alloc). `unchanged`: every
// pixel, depth and stencil value is as before the call (always, unless the allocation failed
// in the tile pass of a draw that kept no copies: pipeline/draw_rollback.h).
struct DrawOutOfMemory : std::exception {
    std::string why;
    bool unchanged = true;
    DrawOutOfMemory(std::string w, bool u) : why(std::move(w)), unchanged(u) {}
    const char* what() const noexcept override { return why.c_str(); }
};

// Runs a draw call in batches of at most in.tuning.batch_primitives primitives: its working memory
// is bounded, whatever the number of vertices and instances. Returns the draw's plan.
DrawPlan draw(const DrawInputs& in, const DrawCall& call, DrawStats& stats);

}  // namespace softgl
