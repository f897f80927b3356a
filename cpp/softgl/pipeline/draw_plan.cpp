#include "softgl/pipeline/draw_plan.h"

#include <algorithm>
#include <initializer_list>
#include <utility>

#include "softgl/pipeline/assemble.h"

namespace softgl {

namespace {

constexpr const char* kPathNames[] = {
    "yes", "not_rasterized", "not_shaded", "tuning_off", "discard", "frag_depth", "coverage_ops",
    "no_depth_test", "stencil_test", "late_tests", "depth_stencil_tests", "depth_not_per_quad", "depth_func",
    "blend_lab", "framebuffer_object", "float_drawing_buffer", "smoothing", "multisampled", "no_color_write",
    "reads_destination", "fog", "not_uniform_only", "not_copy", "not_one_varying_vec4", "not_interpolated",
    "generic_kernel", "no_blending", "not_per_channel", "fused_copy", "constant_color", "quad_neighbours",
    "depth_not_24_bit", "attachment_sizes_differ", "writes_color", "not_texture_copy",
    "not_nearest_bytes",
};
static_assert(sizeof(kPathNames) / sizeof(kPathNames[0]) == size_t(Path::NotNearestBytes) + 1, "a name per Path");

constexpr const char* kSkipNames[] = {"no", "rasterizer_discard", "no_output"};
constexpr const char* kTargetNames[] = {"drawing_buffer", "float_drawing_buffer", "framebuffer_object"};
constexpr const char* kKernelNames[] = {"plain", "alpha_over", "additive", "generic"};
constexpr const char* kPrimitiveNames[] = {"", "points", "lines", "triangles"};

// The first of `reasons` that holds, or Taken. Each is {holds, why}. Inlined: the lists are
// constant, so each call becomes a few tests (a plan is made per draw).
__attribute__((always_inline)) inline Path first_reason(std::initializer_list<std::pair<bool, Path>> reasons) {
    for (const auto& [holds, why] : reasons)
        if (holds) return why;
    return Path::Taken;
}

// What the copy shortcut reads in place (FragmentShader::copies): a shader copying one vec4
// varying, computed for the fragment, to its one colour output. Sets copied_word and, when the
// four words are interpolated (smooth), copied_index: their place among the smooth words.
void plan_copies(DrawPlan& plan, const FragmentShader& fs, const VaryingLayout& layout, const Tuning& tuning) {
    const FragmentCopies* copies = fs.copies();
    plan.fragment_copies = first_reason({{!plan.rasterizes(), Path::NotRasterized},
                                         {!copies, Path::NotCopy},
                                         {!tuning.fragment_copies, Path::TuningOff}});
    if (plan.fragment_copies == Path::Taken && copies->outputs == 1) {
        const auto read = [&](int word) {
            return size_t(word) >= layout.read_by_fragment.size() || layout.read_by_fragment[size_t(word)];
        };
        const int first = copies->word[0];
        bool computed = first >= 0 && first + 4 <= layout.words;
        for (int c = 0; c < 4 && computed; ++c) computed = copies->word[size_t(c)] == first + c && read(first + c);
        if (computed) plan.copied_word = first;
        // The tile pass interpolates the smooth words the shader reads, in order: the four are
        // there, side by side, when none is flat, after the smooth ones before them.
        bool smooth = computed;
        for (int c = 0; c < 4 && smooth; ++c) smooth = !layout.flat[size_t(first + c)];
        if (smooth) {
            plan.copied_index = 0;
            for (int word = 0; word < first; ++word) plan.copied_index += read(word) && !layout.flat[size_t(word)];
        }
    }
    plan.fused_copy = first_reason({{plan.fragment_copies != Path::Taken, plan.fragment_copies},
                                    {plan.copied_word < 0, Path::NotOneVaryingVec4},
                                    {plan.copied_index < 0 || plan.vertices_per_primitive == 1, Path::NotInterpolated},
                                    {plan.samples != 1, Path::Multisampled},
                                    {plan.kernel == ColorKernel::Generic, Path::GenericKernel},
                                    {plan.color_kernels != Path::Taken, plan.color_kernels}});
}

// Shade full batches (tile_pass, "gather"): not where no shader batch is built (a fused copy, a
// constant colour), nor for the blend lab (its hooks see each primitive's fragments in turn) or
// area coverage (fractions per quad); no helper lanes when nothing reads a quad neighbour (in
// this draw: implicit-LOD lookups whose LOD the bound textures ignore do not).
void plan_fragment_batches(DrawPlan& plan, const FragmentShader& fs, const Tuning& tuning) {
    plan.fragment_batches = first_reason({{!plan.rasterizes(), Path::NotRasterized},
                                          {!tuning.fragment_batches, Path::TuningOff},
                                          {plan.blend_lab, Path::BlendLab},
                                          {plan.area_coverage, Path::Smoothing},
                                          {plan.fused_copy == Path::Taken, Path::FusedCopy},
                                          {plan.constant_color == Path::Taken, Path::ConstantColor}});
    plan.no_helper_lanes = first_reason({{plan.fragment_batches != Path::Taken, plan.fragment_batches},
                                         {!tuning.skip_helper_lanes, Path::TuningOff},
                                         {tuning.lod_free_helper_lanes ? fs.reads_quad_neighbours_in_draw()
                                                                       : fs.reads_quad_neighbours(),
                                          Path::QuadNeighbours}});
}

}  // namespace

const char* path_name(Path p) { return kPathNames[size_t(p)]; }

FragmentOps FragmentOps::from(const DrawInputs& in) {
    const FramebufferConfig& config = in.target.config();
    return FragmentOps{BlendOp::from_state(in.state, config.alpha),
                       DepthStencilOp::from_state(in.state, config.depth, config.stencil), FogOp::from_state(in.state)};
}

DrawPlan plan_draw(const DrawInputs& in, const DrawCall& call, const FragmentOps& ops) {
    DrawPlan plan;
    const State& state = in.state;
    const RenderTarget& fb = in.target;
    const FramebufferConfig& config = fb.config();
    const FragmentShader& fs = in.fragment_shader;
    const BlendOp& blend = ops.blend;
    const DepthStencilOp& ds = ops.depth_stencil;
    const DefaultFramebuffer* const default_fb = fb.default_framebuffer();

    // ---- the draw ----
    plan.vertices_per_primitive = vertices_per_primitive(call.mode);
    plan.target = !default_fb ? DrawTarget::FramebufferObject
                : default_fb->is_float() ? DrawTarget::FloatDrawingBuffer : DrawTarget::DrawingBuffer;
    const bool drawing_buffer = plan.target == DrawTarget::DrawingBuffer;   // the RGBA8 one
    // Colour as RGBA8 bytes (the drawing buffer, or an FBO's one RGBA8 image): the byte paths.
    const bool rgba8_target = fb.color_rgba8() != nullptr;
    plan.samples = config.samples;
    plan.simd = std::min(in.tuning.simd, best_simd_level());
    plan.batch_primitives = in.tuning.batch_primitives;
    plan.blend_lab = in.sink && drawing_buffer;
    // A colour is written when a channel is unmasked and a fragment output reaches a colour
    // buffer (a framebuffer object may have none, or drawBuffers may map every output to NONE).
    bool any_color_buffer = false;
    for (int o = 0; o < RenderTarget::kMaxColors; ++o) any_color_buffer |= fb.has_color(o);
    plan.writes_color = any_color_buffer && (blend.write[0] || blend.write[1] || blend.write[2] || blend.write[3]);
    plan.writes_depth_stencil = (ds.depth_test && ds.depth_write) || ds.stencil_test;
    // ES 3.0 §2.15: with RASTERIZER_DISCARD, primitives are dropped right after the vertex stage.
    // With no output possible, primitives are set up (and counted) but nothing is rasterised.
    plan.skip = state.rasterizer_discard ? DrawSkip::RasterizerDiscard
              : !plan.writes_color && !plan.writes_depth_stencil ? DrawSkip::NoOutput : DrawSkip::No;
    const bool skipped = !plan.rasterizes();
    const Path target_reason = plan.target == DrawTarget::FramebufferObject ? Path::FramebufferObject
                                                                             : Path::FloatDrawingBuffer;

    // ---- colour ----
    plan.kernel = color_kernel(blend);
    plan.plain_write = blend.is_plain_write();
    plan.all_channels = blend.write[0] && blend.write[1] && blend.write[2] && blend.write[3];
    const bool smoothing = state.smooth.polygon || state.smooth.line || state.smooth.point;
    // SOFTGL_smooth shapes (GL 1.5 §3.4-3.5); smoothing is ignored when multisampling (§3.2.1).
    const int per = plan.vertices_per_primitive;
    plan.area_coverage = plan.samples == 1 && (per == 3 ? state.smooth.polygon : per == 2 ? state.smooth.line
                                                                                        : state.smooth.point);
    // Multisample coverage operations come before the depth and stencil tests (ES 3.0 §4.1.3).
    plan.coverage_ops = config.samples > 1 && (state.sample_alpha_to_coverage || state.sample_coverage);
    plan.fog = ops.fog.enabled;

    // ---- tests ----
    plan.depth_test = ds.depth_test;
    plan.stencil_test = ds.stencil_test;
    plan.tests_before_shading = first_reason({{fs.may_discard(), Path::Discard},
                                              {fs.writes_depth(), Path::FragDepth},
                                              {plan.coverage_ops, Path::CoverageOps}});
    const bool early = plan.tests_before_shading == Path::Taken;
    // The common early depth test, 24-bit depth words (the drawing buffer's, or a DEPTH_COMPONENT24
    // or DEPTH24_STENCIL8 attachment's) and no stencil test, runs a quad at a time
    // (pipeline/early_depth); anything else sample by sample.
    plan.quad_depth = first_reason({{skipped, Path::NotRasterized},
                                    {!ds.depth_test, Path::NoDepthTest},
                                    {!early, Path::LateTests},
                                    {ds.stencil_test, Path::StencilTest},
                                    {plan.blend_lab, Path::BlendLab},
                                    {fb.depth_bits() != 24, Path::DepthNot24Bit},
                                    {fb.depth_pitch() != fb.width(), Path::AttachmentSizesDiffer}});
    // Primitives hidden in a whole tile skip raster and test (DepthBounds); not with area coverage,
    // which reaches pixels whose centre (the tested sample) is outside the bounding box.
    const GLenum f = ds.depth_func;
    plan.depth_bounds = first_reason({{plan.quad_depth != Path::Taken, plan.quad_depth},
                                      {smoothing, Path::Smoothing},
                                      {in.tuning.depth_bounds == DepthBoundsMode::Off, Path::TuningOff},
                                      {plan.samples != 1, Path::Multisampled},
                                      {f != gl::LESS && f != gl::LEQUAL && f != gl::GREATER && f != gl::GEQUAL,
                                       Path::DepthFunc}});
    // Hidden-surface removal (OwnerMap): single-sampled, no blending that reads the destination (a
    // float buffer's ONE/ZERO blending reads it: inf * 0 is NaN), tests before shading on the
    // drawing buffer's depth (or none), no stencil, no smoothing, no blend lab.
    plan.depth_bounds_sabotaged = plan.depth_bounds == Path::Taken &&
                                  in.tuning.depth_bounds == DepthBoundsMode::SabotagedForTests;
    plan.hidden_surface_removal = first_reason(
        {{skipped, Path::NotRasterized},
         {in.tuning.hidden_surface_removal == HiddenSurfaceRemoval::Off, Path::TuningOff},
         {plan.samples != 1, Path::Multisampled},
         {!early, plan.tests_before_shading},
         {!plan.writes_color, Path::NoColorWrite},
         {!plan.plain_write, Path::ReadsDestination},
         {blend.enabled && !rgba8_target, target_reason},
         {ds.stencil_test, Path::StencilTest},
         {ds.depth_test && plan.quad_depth != Path::Taken, Path::DepthNotPerQuad},
         {plan.blend_lab, Path::BlendLab},
         {smoothing, Path::Smoothing}});
    plan.hidden_surface_in_every_tile = in.tuning.hidden_surface_removal == HiddenSurfaceRemoval::InEveryTile;
    plan.hidden_surface_by_boxes = in.tuning.hidden_surface_removal == HiddenSurfaceRemoval::WhereBoxesPileUp;

    // ---- colour kernels: chunks of lanes on the RGBA8 drawing buffer, nothing per lane ----
    plan.color_kernels = first_reason({{skipped, Path::NotRasterized},
                                       {!plan.writes_color, Path::NoColorWrite},
                                       {plan.late_tests(), Path::LateTests},
                                       {plan.blend_lab, Path::BlendLab},
                                       {!rgba8_target, target_reason},
                                       {plan.coverage_ops, Path::CoverageOps},
                                       {plan.fog, Path::Fog},
                                       {plan.area_coverage, Path::Smoothing}});

    // ---- shading ----
    plan_copies(plan, fs, in.vertex_shader.varying_layout(), in.tuning);
    plan.texture_copy = first_reason({{skipped, Path::NotRasterized},
                                      {!fs.copies_texture(), Path::NotTextureCopy},
                                      {!in.tuning.texture_copies, Path::TuningOff}});
    const Path not_yet = skipped ? Path::NotRasterized : Path::NotShaded;
    plan.constant_color = plan.blend_table = plan.whole_rect_blend = plan.texel_words = not_yet;
    plan_fragment_batches(plan, fs, in.tuning);
    plan.depth_only = first_reason({{skipped, Path::NotRasterized},
                                    {plan.writes_color, Path::WritesColor},
                                    {!early, plan.tests_before_shading},
                                    {plan.blend_lab, Path::BlendLab}});
    plan.depth_blocks = first_reason({{plan.depth_only != Path::Taken, plan.depth_only},
                                      {plan.quad_depth != Path::Taken, plan.quad_depth},
                                      {plan.samples != 1, Path::Multisampled},
                                      {plan.area_coverage, Path::Smoothing},
                                      {!in.tuning.depth_blocks, Path::TuningOff}});
    return plan;
}

// Texel words: a plain write of all channels to one sample keeps each texel's bytes k (the
// kernel turns k / 255 back into k), so the words go to the pixels without the floats.
void plan_texel_words(DrawPlan& plan, const Tuning& tuning, const FragmentShader& fs) {
    plan.texel_words = first_reason({{plan.texture_copy != Path::Taken, plan.texture_copy},
                                     {plan.color_kernels != Path::Taken, plan.color_kernels},
                                     {plan.samples != 1, Path::Multisampled},
                                     {plan.kernel != ColorKernel::Plain || !plan.all_channels, Path::ReadsDestination},
                                     {plan.constant_color == Path::Taken, Path::ConstantColor},
                                     {!tuning.texel_words, Path::TuningOff},
                                     {!fs.gives_texel_words(), Path::NotNearestBytes}});
}

void plan_shading(DrawPlan& plan, bool uniform_only, const BlendOp& blend) {
    plan.shaded = true;
    plan.uniform_only = uniform_only;
    // A uniform-only shader runs once per draw and its colour goes straight to the colour kernels.
    plan.constant_color = first_reason({{!uniform_only, Path::NotUniformOnly},
                                        {plan.color_kernels != Path::Taken, plan.color_kernels}});
    // Single-sampled and blending per channel: the blend as a table (fragment_ops.h).
    plan.blend_table = first_reason({{plan.constant_color != Path::Taken, plan.constant_color},
                                     {plan.samples != 1, Path::Multisampled},
                                     {plan.plain_write, Path::NoBlending}});
    if (plan.blend_table == Path::Taken && !blend_is_per_channel(blend)) plan.blend_table = Path::NotPerChannel;
    // Without tests, whole blocks of a primitive are blended in place (tiles where hidden-surface
    // removal runs take the quads).
    plan.whole_rect_blend = first_reason({{plan.blend_table != Path::Taken, plan.blend_table},
                                          {plan.depth_test || plan.stencil_test, Path::DepthStencilTests}});
    // A constant colour needs no shader batch.
    if (plan.constant_color == Path::Taken && plan.fragment_batches == Path::Taken)
        plan.fragment_batches = plan.no_helper_lanes = Path::ConstantColor;
}

std::vector<DrawPlanField> DrawPlan::fields() const {
    using F = DrawPlanField;
    const auto yes = [](const char* group, const char* name, bool v) { return F{group, name, F::Bool, v, v ? "yes" : "no"}; };
    const auto num = [](const char* group, const char* name, int64_t v) { return F{group, name, F::Int, v, nullptr}; };
    const auto named = [](const char* group, const char* name, int v, const char* text) { return F{group, name, F::Name, v, text}; };
    const auto path = [](const char* group, const char* name, Path p) { return F{group, name, F::PathKind, int64_t(p), path_name(p)}; };
    return {
        named("draw", "primitives", vertices_per_primitive, kPrimitiveNames[vertices_per_primitive]),
        named("draw", "skip", int(skip), kSkipNames[int(skip)]),
        named("draw", "target", int(target), kTargetNames[int(target)]),
        num("draw", "samples", samples),
        named("draw", "simd", int(simd), kSimdLevelNames[int(simd)]),
        num("draw", "batch_primitives", batch_primitives),
        yes("draw", "blend_lab", blend_lab),
        yes("tests", "depth_test", depth_test),
        yes("tests", "stencil_test", stencil_test),
        yes("tests", "writes_depth_stencil", writes_depth_stencil),
        path("tests", "tests_before_shading", tests_before_shading),
        path("tests", "quad_depth", quad_depth),
        path("tests", "depth_bounds", depth_bounds),
        yes("tests", "depth_bounds_sabotaged", depth_bounds_sabotaged),
        path("tests", "hidden_surface_removal", hidden_surface_removal),
        yes("tests", "hidden_surface_in_every_tile", hidden_surface_in_every_tile),
        yes("tests", "hidden_surface_by_boxes", hidden_surface_by_boxes),
        path("shading", "fragment_copies", fragment_copies),
        num("shading", "copied_word", copied_word),
        path("shading", "fused_copy", fused_copy),
        num("shading", "copied_index", copied_index),
        path("shading", "texture_copy", texture_copy),
        path("shading", "texel_words", texel_words),
        yes("shading", "shaded", shaded),
        yes("shading", "uniform_only", uniform_only),
        path("shading", "constant_color", constant_color),
        path("shading", "blend_table", blend_table),
        path("shading", "whole_rect_blend", whole_rect_blend),
        path("shading", "fragment_batches", fragment_batches),
        path("shading", "no_helper_lanes", no_helper_lanes),
        path("shading", "depth_only", depth_only),
        path("shading", "depth_blocks", depth_blocks),
        yes("color", "writes_color", writes_color),
        named("color", "kernel", int(kernel), kKernelNames[int(kernel)]),
        yes("color", "plain_write", plain_write),
        yes("color", "all_channels", all_channels),
        yes("color", "area_coverage", area_coverage),
        yes("color", "coverage_ops", coverage_ops),
        yes("color", "fog", fog),
        path("color", "color_kernels", color_kernels),
    };
}

std::string DrawPlan::to_string() const {
    std::string out;
    const char* group = nullptr;
    for (const DrawPlanField& f : fields()) {
        if (!group || std::string(group) != f.group) {
            if (group) out += '\n';
            out += f.group;
            out += ':';
            group = f.group;
        }
        out += ' ';
        out += f.name;
        out += '=';
        if (f.kind == DrawPlanField::Int) out += std::to_string(f.value);
        else if (f.kind == DrawPlanField::PathKind && f.value != 0) out += std::string("no(") + f.text + ")";
        else out += f.text;
    }
    return out;
}

uint64_t DrawPlan::hash() const {
    uint64_t h = 0xcbf29ce484222325u;   // FNV-1a over the fields' values
    for (const DrawPlanField& f : fields()) {
        uint64_t v = uint64_t(f.value);
        for (int k = 0; k < 8; ++k, v >>= 8) h = (h ^ (v & 0xFF)) * 0x100000001b3u;
    }
    return h;
}

bool DrawPlan::operator==(const DrawPlan& o) const {
    const std::vector<DrawPlanField> a = fields(), b = o.fields();
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].value != b[i].value) return false;
    return true;
}

}  // namespace softgl
