#include "softgl/glsl/lower.h"

#include <functional>
#include <set>

#include "softgl/glsl/builtins.h"
#include "softgl/glsl/ir_builder.h"

namespace softgl::glsl {

namespace {

constexpr size_t kMaxInstructions = 1 << 20;  // after inlining; larger programs are rejected
constexpr int kMaxInlineDepth = 64;
// Lowering recurses through expressions and statements, and into each inlined call's body. The
// parser bounds nesting within one function (and left-associative chains are loops), but 64
// inlined levels of that could still overflow the stack (64 x 178 unary minuses take ~10 MB), so
// the total is bounded as well: under 1 MB of stack (rvalue and unary take ~0.9 KB a level).
constexpr int kMaxLoweringDepth = 1024;

struct LoweringError {};

void flatten_bases(const Type& t, std::vector<BaseType>& out) {
    int n = t.array_size > 0 ? t.array_size : 1;
    for (int i = 0; i < n; ++i) {
        if (t.base == BaseType::Struct) {
            for (const StructField& f : t.struct_type->fields) flatten_bases(f.type, out);
        } else if (t.base == BaseType::Sampler) {
            out.push_back(BaseType::Int);
        } else {
            for (int c = 0; c < t.element_components(); ++c) out.push_back(t.base);
        }
    }
}

// Where one scalar component lives: a register or a uniform word, possibly at a dynamic index.
// Address = range_start + clamp(offset + index, 0, count - 1).
struct Place {
    bool uniform = false;
    uint32_t range_start = 0;
    uint32_t offset = 0;
    uint32_t count = 1;
    Reg index = kNoReg;
    BaseType base = BaseType::Float;
};

struct Ref {
    Type type;
    std::vector<Place> places;
};

struct Storage {
    bool uniform = false;
    uint32_t first = 0;  // first register or uniform word
};

class Lowerer {
public:
    Lowerer(const CheckedShader& shader, Diagnostics& diagnostics)
        : s_(shader), d_(diagnostics), b_(out_.program) {}

    LoweredShader run() {
        try {
            if (!s_.main) {
                d_.error(0, "Missing main()");
                return std::move(out_);
            }
            frames_.emplace_back();
            declare_globals();
            b_.emit(Op::FunctionBegin);
            // Global initializers run at the start of main (ES 3.00 §4.3).
            for (const ExternalDecl& ext : s_.unit.decls) {
                if (ext.kind != ExternalDecl::Variables) continue;
                for (const VarDecl& v : ext.declaration->decls) {
                    if (!v.initializer || !v.symbol) continue;
                    b_.current_line = v.line;
                    Value value = rvalue(*v.initializer);
                    store(variable_ref(v.symbol), value);
                }
            }
            inline_stack_.push_back(s_.main);
            statement(*s_.main->body);
            b_.emit(Op::FunctionEnd);
            finish_outputs();
            // The prologue (uniform loads) goes first.
            std::vector<Instruction> code = std::move(prologue_);
            code.insert(code.end(), out_.program.code.begin(), out_.program.code.end());
            out_.program.code = std::move(code);
        } catch (const LoweringError&) {
        }
        return std::move(out_);
    }

private:
    const CheckedShader& s_;
    Diagnostics& d_;
    LoweredShader out_;
    IrBuilder b_;
    std::vector<std::unordered_map<const Symbol*, Storage>> frames_;
    std::vector<FunctionDef*> inline_stack_;
    std::vector<Instruction> prologue_;
    std::map<uint32_t, Reg> uniform_cache_;
    struct ReturnTarget { Ref ref; bool has_value; };
    std::vector<ReturnTarget> return_targets_;
    // The index of each loop being unrolled, with its value in the copy being lowered.
    std::unordered_map<const Symbol*, int32_t> unrolled_index_;

    int depth_ = 0;
    struct DepthGuard {
        Lowerer& l;
        DepthGuard(Lowerer& lowerer, int line) : l(lowerer) {
            if (++l.depth_ > kMaxLoweringDepth)
                l.fail(line, "shader too complex (expressions and statements nested more than " + std::to_string(kMaxLoweringDepth) +
                                 " levels deep through inlined function calls)");
        }
        ~DepthGuard() { --l.depth_; }
    };

    [[noreturn]] void fail(int line, const std::string& message) {
        d_.error(line, message);
        throw LoweringError{};
    }
    void check_size() {
        if (out_.program.code.size() > kMaxInstructions || out_.program.register_count > (1u << 22))
            fail(b_.current_line, "shader too complex (program too large after inlining)");
    }

    // ---------------------------------------------------------------- storage
    uint32_t allocate_variable(const Type& t) {
        std::vector<BaseType> bases;
        flatten_bases(t, bases);
        uint32_t first = out_.program.register_count;
        for (BaseType bt : bases) b_.variable(bt);
        return first;
    }

    void declare_globals() {
        int uniform_words = 0;
        auto declare_input = [&](const Symbol* sym, SlotKind kind) {
            uint32_t first = allocate_variable(sym->type);
            frames_[0][sym] = {false, first};
            std::vector<BaseType> bases;
            flatten_bases(sym->type, bases);
            int per = sym->type.element_components();
            for (size_t i = 0; i < bases.size(); ++i) {
                Slot slot{kind, sym->name, static_cast<int>(i / per), static_cast<int>(i % per), bases[i], first + static_cast<Reg>(i)};
                out_.program.inputs.push_back(slot);
            }
        };
        auto declare_output = [&](const Symbol* sym, SlotKind kind) {
            uint32_t first = allocate_variable(sym->type);
            frames_[0][sym] = {false, first};
            std::vector<BaseType> bases;
            flatten_bases(sym->type, bases);
            int per = sym->type.element_components();
            for (size_t i = 0; i < bases.size(); ++i) {
                Slot slot{kind, sym->name, static_cast<int>(i / per), static_cast<int>(i % per), bases[i], first + static_cast<Reg>(i)};
                output_slots_.push_back(slot);
            }
        };
        const bool vertex = s_.stage == Stage::Vertex;
        for (const auto& [name, sym] : s_.builtin_variables) {
            if (sym->storage == StorageQualifier::Const) continue;
            if (sym->storage == StorageQualifier::Uniform) {
                out_.uniform_offsets[sym] = uniform_words;
                frames_[0][sym] = {true, static_cast<uint32_t>(uniform_words)};
                uniform_words += sym->type.components();
            } else if (sym->storage == StorageQualifier::In) {
                declare_input(sym, SlotKind::Builtin);
            } else {
                declare_output(sym, (vertex || name == "gl_FragDepth" || name == "gl_FragDepthEXT") ? SlotKind::Builtin : SlotKind::FragmentOutput);
            }
        }
        for (const Symbol* sym : s_.globals) {
            switch (sym->storage) {
            case StorageQualifier::Uniform:
                out_.uniform_offsets[sym] = uniform_words;
                frames_[0][sym] = {true, static_cast<uint32_t>(uniform_words)};
                uniform_words += sym->type.components();
                break;
            case StorageQualifier::Attribute: declare_input(sym, SlotKind::Attribute); break;
            case StorageQualifier::In: declare_input(sym, vertex ? SlotKind::Attribute : SlotKind::Varying); break;
            case StorageQualifier::Varying:
                if (vertex) declare_output(sym, SlotKind::Varying);
                else declare_input(sym, SlotKind::Varying);
                break;
            case StorageQualifier::Out: declare_output(sym, vertex ? SlotKind::Varying : SlotKind::FragmentOutput); break;
            default: frames_[0][sym] = {false, allocate_variable(sym->type)}; break;
            }
        }
        out_.uniform_words = uniform_words;
    }
    std::vector<Slot> output_slots_;

    void finish_outputs() {
        out_.program.outputs = output_slots_;
    }

    Storage storage_of(const Symbol* sym) {
        for (auto it = frames_.rbegin(); it != frames_.rend(); ++it) {
            auto f = it->find(sym);
            if (f != it->end()) return f->second;
        }
        // A local declared in a scope we have not seen (cannot happen after the checker).
        fail(sym->line, "'" + sym->name + "' : internal error: variable without storage");
    }

    Ref variable_ref(const Symbol* sym) {
        const_cast<Symbol*>(sym)->statically_used = true;
        note_builtin_use(sym);
        Storage st = storage_of(sym);
        Ref r;
        r.type = sym->type;
        std::vector<BaseType> bases;
        flatten_bases(sym->type, bases);
        uint32_t count = static_cast<uint32_t>(bases.size());
        for (uint32_t i = 0; i < count; ++i) {
            Place p;
            p.uniform = st.uniform;
            p.range_start = st.first;
            p.offset = i;
            p.count = count;
            p.base = bases[i];
            r.places.push_back(p);
        }
        return r;
    }

    void note_builtin_use(const Symbol* sym) {
        if (!sym->is_builtin) return;
        const std::string& n = sym->name;
        ShaderUsage& u = out_.usage;
        if (n == "gl_FragCoord") u.reads_frag_coord = true;
        else if (n == "gl_FrontFacing") u.reads_front_facing = true;
        else if (n == "gl_PointCoord") u.reads_point_coord = true;
        else if (n == "gl_VertexID") u.uses_vertex_id = true;
        else if (n == "gl_InstanceID") u.uses_instance_id = true;
    }

    Reg load_place(const Place& p) {
        if (p.index == kNoReg) {
            uint32_t address = p.range_start + p.offset;
            if (!p.uniform) return address;
            auto it = uniform_cache_.find(address);
            if (it != uniform_cache_.end()) return it->second;
            Reg r = b_.temp(p.base);
            Instruction i;
            i.op = Op::LoadUniform;
            i.dst = r;
            i.imm[0] = static_cast<int32_t>(address);
            prologue_.push_back(i);
            uniform_cache_[address] = r;
            return r;
        }
        Reg r = b_.temp(p.base);
        Instruction& i = b_.emit(p.uniform ? Op::LoadUniformIndexed : Op::LoadIndexed);
        i.dst = r;
        i.b = p.index;
        i.imm[0] = static_cast<int32_t>(p.range_start);
        i.imm[1] = static_cast<int32_t>(p.offset);
        i.imm[2] = static_cast<int32_t>(p.count);
        return r;
    }

    Value load(const Ref& r) {
        Value v;
        v.type = r.type;
        for (const Place& p : r.places) v.regs.push_back(load_place(p));
        return v;
    }

    void store(const Ref& r, const Value& v) {
        if (r.places.size() != v.regs.size()) fail(b_.current_line, "internal error: store size mismatch");
        for (size_t k = 0; k < r.places.size(); ++k) {
            const Place& p = r.places[k];
            if (p.uniform) fail(b_.current_line, "internal error: store to a uniform");
            if (p.index == kNoReg) {
                b_.mov(p.range_start + p.offset, v.regs[k]);
            } else {
                Instruction& i = b_.emit(Op::StoreIndexed);
                i.a = v.regs[k];
                i.b = p.index;
                i.imm[0] = static_cast<int32_t>(p.range_start);
                i.imm[1] = static_cast<int32_t>(p.offset);
                i.imm[2] = static_cast<int32_t>(p.count);
            }
        }
        check_size();
    }

    // A copy of v in fresh variable registers, laid out contiguously.
    Ref materialize(const Value& v) {
        uint32_t first = allocate_variable(v.type);
        Ref r;
        r.type = v.type;
        std::vector<BaseType> bases;
        flatten_bases(v.type, bases);
        for (uint32_t i = 0; i < bases.size(); ++i) {
            Place p;
            p.range_start = first;
            p.offset = i;
            p.count = static_cast<uint32_t>(bases.size());
            p.base = bases[i];
            r.places.push_back(p);
        }
        store(r, v);
        return r;
    }

    static bool contiguous(const Ref& r) {
        for (size_t i = 1; i < r.places.size(); ++i) {
            const Place& a = r.places[0];
            const Place& p = r.places[i];
            if (p.uniform != a.uniform || p.range_start != a.range_start || p.index != a.index || p.offset != a.offset + i)
                return false;
        }
        return true;
    }

    // ---------------------------------------------------------------- references
    Ref ref(const Expr& e) {
        DepthGuard guard(*this, e.line);
        b_.current_line = e.line;
        switch (e.kind) {
        case ExprKind::Identifier: return variable_ref(e.symbol);
        case ExprKind::Field: {
            Ref base = ref(*e.kids[0]);
            Ref r;
            r.type = e.type;
            if (e.is_swizzle) {
                if (base.type.is_scalar()) {
                    for (size_t k = 0; k < e.swizzle.size(); ++k) r.places.push_back(base.places[0]);
                } else {
                    for (uint8_t c : e.swizzle) r.places.push_back(base.places[c]);
                }
                return r;
            }
            int offset = 0;
            const auto& fields = base.type.struct_type->fields;
            for (int k = 0; k < e.field_index; ++k) offset += fields[k].type.components();
            int n = e.type.components();
            r.places.assign(base.places.begin() + offset, base.places.begin() + offset + n);
            return r;
        }
        case ExprKind::Index: {
            Ref base = ref(*e.kids[0]);
            return index_ref(base, *e.kids[1], e.type);
        }
        default: {
            // An rvalue used where a reference is needed (e.g. indexing a call's result).
            Value v = rvalue(e);
            return materialize(v);
        }
        }
    }

    Ref index_ref(Ref base, const Expr& index, const Type& element_type) {
        int n = element_type.components();
        int elements = static_cast<int>(base.places.size()) / std::max(n, 1);
        Ref r;
        r.type = element_type;
        int32_t known = 0;
        const bool unrolled = !(index.is_constant && !index.constant.empty()) && unrolled_index_value(index, known);
        if ((index.is_constant && !index.constant.empty()) || unrolled) {
            // A constant index, or one made of unrolled loops' indices: clamped like the dynamic index below.
            int64_t i = unrolled ? known
                        : index.type.base == BaseType::Int ? index.constant[0].i : static_cast<int64_t>(index.constant[0].u);
            if (i < 0) i = 0;
            if (i >= elements) i = elements - 1;
            r.places.assign(base.places.begin() + i * n, base.places.begin() + (i + 1) * n);
            return r;
        }
        Value iv = rvalue(index);
        Reg idx = iv.regs[0];
        if (!contiguous(base)) base = materialize(load(base));
        // Clamp the element index itself, so that an out-of-range index stays inside this
        // array even when the array is part of a larger struct (WebGL requires no
        // out-of-bounds access; ES 3.00 §5.9 leaves the value undefined).
        Reg clamped = b_.op(Op::IClamp, BaseType::Int, idx, b_.int_constant(0), b_.int_constant(elements - 1));
        Reg scaled = n == 1 ? clamped : b_.op(Op::IMul, BaseType::Int, clamped, b_.int_constant(n));
        for (int k = 0; k < n; ++k) {
            Place p = base.places[k];
            if (p.index != kNoReg) p.index = b_.op(Op::IAdd, BaseType::Int, p.index, scaled);
            else p.index = scaled;
            r.places.push_back(p);
        }
        return r;
    }

    // ---------------------------------------------------------------- expressions
    Value constant_value(const Type& t, const ConstantValue& c) {
        std::vector<BaseType> bases;
        flatten_bases(t, bases);
        Value v;
        v.type = t;
        for (size_t i = 0; i < c.size() && i < bases.size(); ++i) v.regs.push_back(b_.constant(bases[i], c[i]));
        return v;
    }

    // Does evaluating root write anything? (No recursion: root may be a long chain.)
    static bool has_side_effects(const Expr& root) {
        std::vector<const Expr*> pending{&root};
        while (!pending.empty()) {
            const Expr& e = *pending.back();
            pending.pop_back();
            if (e.kind == ExprKind::Assign || e.kind == ExprKind::Postfix) return true;
            if (e.kind == ExprKind::Unary && (e.op == "++" || e.op == "--")) return true;
            if (e.kind == ExprKind::Call && (e.callee || (e.builtin_id >= 0 && builtin_functions()[e.builtin_id].out_parameter >= 0))) return true;
            for (const ExprPtr& k : e.kids) pending.push_back(k.get());
        }
        return false;
    }

    Value rvalue(const Expr& e) {
        DepthGuard guard(*this, e.line);
        b_.current_line = e.line;
        check_size();
        if (e.is_constant && !e.constant.empty() && e.kind != ExprKind::Assign) return constant_value(e.type, e.constant);
        switch (e.kind) {
        case ExprKind::IntLiteral:
        case ExprKind::UintLiteral:
        case ExprKind::FloatLiteral:
        case ExprKind::BoolLiteral: return constant_value(e.type, {e.literal});
        case ExprKind::Identifier:
            if (auto u = unrolled_index_.find(e.symbol); u != unrolled_index_.end()) {
                const_cast<Symbol*>(e.symbol)->statically_used = true;
                return Value{e.type, {b_.int_constant(u->second)}};
            }
            [[fallthrough]];
        case ExprKind::Field:
        case ExprKind::Index:
            if (e.kind == ExprKind::Field && !is_reference(*e.kids[0])) {
                // Field/swizzle of an rvalue: select registers.
                Value base = rvalue(*e.kids[0]);
                Value v;
                v.type = e.type;
                if (e.is_swizzle) {
                    for (uint8_t c : e.swizzle) v.regs.push_back(base.type.is_scalar() ? base.regs[0] : base.regs[c]);
                } else {
                    int offset = 0;
                    const auto& fields = base.type.struct_type->fields;
                    for (int k = 0; k < e.field_index; ++k) offset += fields[k].type.components();
                    v.regs.assign(base.regs.begin() + offset, base.regs.begin() + offset + e.type.components());
                }
                return v;
            }
            if (e.kind == ExprKind::Index && !is_reference(*e.kids[0]) && e.kids[1]->is_constant && !e.kids[1]->constant.empty()) {
                Value base = rvalue(*e.kids[0]);
                int n = e.type.components();
                int64_t i = e.kids[1]->type.base == BaseType::Int ? e.kids[1]->constant[0].i : e.kids[1]->constant[0].u;
                Value v;
                v.type = e.type;
                v.regs.assign(base.regs.begin() + i * n, base.regs.begin() + (i + 1) * n);
                return v;
            }
            return load(ref(e));
        case ExprKind::Unary: return unary(e);
        case ExprKind::Postfix: {
            Ref r = ref(*e.kids[0]);
            Value old = load(r);
            Value copy = copy_value(old);
            Value one = splat_one(e.type);
            store(r, arithmetic(e.op == "++" ? "+" : "-", copy, one, e.type));
            return copy;
        }
        case ExprKind::Binary: return binary(e);
        case ExprKind::Assign: return assign(e);
        case ExprKind::Ternary: return ternary(e);
        case ExprKind::Call: return call(e);
        }
        fail(e.line, "internal error: unknown expression");
    }

    static bool is_reference(const Expr& e) {
        if (e.kind == ExprKind::Identifier) return true;
        if (e.kind == ExprKind::Field || e.kind == ExprKind::Index) return is_reference(*e.kids[0]);
        return false;
    }

    Value copy_value(const Value& v) {
        Value c;
        c.type = v.type;
        for (Reg r : v.regs) {
            Reg t = b_.variable(b_.type_of(r));
            b_.mov(t, r);
            c.regs.push_back(t);
        }
        return c;
    }

    Value splat_one(const Type& t) {
        Value v;
        v.type = t;
        Scalar one;
        if (t.base == BaseType::Float) one.f = 1.0f; else one.i = 1;
        Reg r = b_.constant(t.base, one);
        v.regs.assign(t.components(), r);
        return v;
    }

    Value unary(const Expr& e) {
        const Expr& a = *e.kids[0];
        if (e.op == "++" || e.op == "--") {
            Ref r = ref(a);
            Value old = load(r);
            Value updated = arithmetic(e.op == "++" ? "+" : "-", old, splat_one(e.type), e.type);
            store(r, updated);
            return load(r);
        }
        Value v = rvalue(a);
        if (e.op == "+") return v;
        Value out;
        out.type = e.type;
        for (Reg r : v.regs) {
            if (e.op == "-") out.regs.push_back(e.type.base == BaseType::Float ? b_.op(Op::FNeg, BaseType::Float, r) : b_.op(Op::INeg, e.type.base, r));
            else if (e.op == "!") out.regs.push_back(b_.op(Op::BoolNot, BaseType::Bool, r));
            else out.regs.push_back(b_.op(Op::BitNot, e.type.base, r));
        }
        return out;
    }

    Value arithmetic(const std::string& op, const Value& a, const Value& b, const Type& result) {
        const Type& ta = a.type;
        const Type& tb = b.type;
        const BaseType base = ta.base;
        Value out;
        out.type = result;
        if (op == "*" && (ta.is_matrix() || tb.is_matrix()) && !(ta.is_scalar() || tb.is_scalar())) {
            // Linear-algebraic products, summed in index order k = 0..n-1 (ES 3.00 §5.10).
            auto dot_terms = [&](auto a_at, auto b_at, int n) {
                Reg sum = b_.op(Op::FMul, BaseType::Float, a_at(0), b_at(0));
                for (int k = 1; k < n; ++k) sum = b_.op(Op::FAdd, BaseType::Float, sum, b_.op(Op::FMul, BaseType::Float, a_at(k), b_at(k)));
                return sum;
            };
            if (ta.is_matrix() && tb.is_matrix()) {
                for (int c = 0; c < tb.cols; ++c)
                    for (int r = 0; r < ta.rows; ++r)
                        out.regs.push_back(dot_terms([&](int k) { return a.regs[k * ta.rows + r]; }, [&](int k) { return b.regs[c * tb.rows + k]; }, ta.cols));
            } else if (ta.is_matrix()) {
                for (int r = 0; r < ta.rows; ++r)
                    out.regs.push_back(dot_terms([&](int k) { return a.regs[k * ta.rows + r]; }, [&](int k) { return b.regs[k]; }, ta.cols));
            } else {
                for (int c = 0; c < tb.cols; ++c)
                    out.regs.push_back(dot_terms([&](int k) { return a.regs[k]; }, [&](int k) { return b.regs[c * tb.rows + k]; }, tb.rows));
            }
            return out;
        }
        Op o;
        if (base == BaseType::Float) {
            o = op == "+" ? Op::FAdd : op == "-" ? Op::FSub : op == "*" ? Op::FMul : Op::FDiv;
        } else {
            bool is_signed = base == BaseType::Int;
            if (op == "+") o = Op::IAdd;
            else if (op == "-") o = Op::ISub;
            else if (op == "*") o = Op::IMul;
            else if (op == "/") o = is_signed ? Op::IDiv : Op::UDiv;
            else if (op == "%") o = is_signed ? Op::IMod : Op::UMod;
            else if (op == "&") o = Op::BitAnd;
            else if (op == "|") o = Op::BitOr;
            else if (op == "^") o = Op::BitXor;
            else if (op == "<<") o = Op::ShiftLeft;
            else o = is_signed ? Op::ShiftRightArithmetic : Op::ShiftRightLogical;
        }
        size_t n = std::max(a.regs.size(), b.regs.size());
        if (op == "<<" || op == ">>") n = a.regs.size();
        for (size_t i = 0; i < n; ++i) {
            Reg x = a.regs[a.regs.size() == 1 ? 0 : i];
            Reg y = b.regs[b.regs.size() == 1 ? 0 : i];
            out.regs.push_back(b_.op(o, result.base, x, y));
        }
        return out;
    }

    Reg all_equal(const Value& a, const Value& b) {
        std::vector<BaseType> bases;
        flatten_bases(a.type, bases);
        Reg acc = kNoReg;
        for (size_t i = 0; i < a.regs.size(); ++i) {
            Reg eq = b_.op(bases[i] == BaseType::Float ? Op::FEqual : Op::Equal, BaseType::Bool, a.regs[i], b.regs[i]);
            acc = acc == kNoReg ? eq : b_.op(Op::BitAnd, BaseType::Bool, acc, eq);
        }
        return acc;
    }

    Value scalar_value(BaseType t, Reg r) {
        Value v;
        v.type = Type::scalar(t);
        v.regs = {r};
        return v;
    }

    // A left-associative chain (u + u + ... + u) is a left spine as long as the source: lower
    // its leftmost operand, then each node's right operand and operator bottom-up, in a loop
    // (the order recursion would give). Constant nodes end the spine: rvalue emits them whole.
    Value binary(const Expr& top) {
        std::vector<const Expr*> spine{&top};
        for (;;) {
            const Expr& left = *spine.back()->kids[0];
            if (left.kind != ExprKind::Binary || (left.is_constant && !left.constant.empty())) break;
            spine.push_back(&left);
            b_.current_line = left.line;  // what rvalue(left) would do first
            check_size();
        }
        Value value = rvalue(*spine.back()->kids[0]);
        for (auto it = spine.rbegin(); it != spine.rend(); ++it) value = binary_node(**it, std::move(value));
        return value;
    }

    // One binary operator, its left operand `a` already lowered.
    Value binary_node(const Expr& e, Value a) {
        const std::string& op = e.op;
        if (op == ",") return rvalue(*e.kids[1]);
        if (op == "&&" || op == "||") {
            if (!has_side_effects(*e.kids[1])) {
                Value b = rvalue(*e.kids[1]);
                return scalar_value(BaseType::Bool, b_.op(op == "&&" ? Op::BitAnd : Op::BitOr, BaseType::Bool, a.regs[0], b.regs[0]));
            }
            // Short-circuit (ES 3.00 §5.9): evaluate the right side only where needed.
            Reg result = b_.variable(BaseType::Bool);
            b_.mov(result, a.regs[0]);
            Reg cond = op == "&&" ? a.regs[0] : b_.op(Op::BoolNot, BaseType::Bool, a.regs[0]);
            b_.emit(Op::IfBegin).a = cond;
            Value b = rvalue(*e.kids[1]);
            b_.mov(result, b.regs[0]);
            b_.emit(Op::IfEnd);
            return scalar_value(BaseType::Bool, result);
        }
        Value b = rvalue(*e.kids[1]);
        if (op == "^^") return scalar_value(BaseType::Bool, b_.op(Op::NotEqual, BaseType::Bool, a.regs[0], b.regs[0]));
        if (op == "==" || op == "!=") {
            Reg eq = all_equal(a, b);
            return scalar_value(BaseType::Bool, op == "==" ? eq : b_.op(Op::BoolNot, BaseType::Bool, eq));
        }
        if (op == "<" || op == ">" || op == "<=" || op == ">=") {
            BaseType t = a.type.base;
            Op o;
            if (t == BaseType::Float) o = op == "<" ? Op::FLess : op == ">" ? Op::FGreater : op == "<=" ? Op::FLessEqual : Op::FGreaterEqual;
            else if (t == BaseType::Int) o = op == "<" ? Op::ILess : op == ">" ? Op::IGreater : op == "<=" ? Op::ILessEqual : Op::IGreaterEqual;
            else o = op == "<" ? Op::ULess : op == ">" ? Op::UGreater : op == "<=" ? Op::ULessEqual : Op::UGreaterEqual;
            return scalar_value(BaseType::Bool, b_.op(o, BaseType::Bool, a.regs[0], b.regs[0]));
        }
        return arithmetic(op, a, b, e.type);
    }

    Value assign(const Expr& e) {
        // ES 3.00 §5.8: the right side is evaluated before the left side's location? The
        // order is unspecified for side effects; we evaluate the right side first.
        Value rhs = rvalue(*e.kids[1]);
        Ref target = ref(*e.kids[0]);
        if (e.op == "=") {
            store(target, rhs);
        } else {
            Value current = load(target);
            std::string op = e.op.substr(0, e.op.size() - 1);
            store(target, arithmetic(op, current, rhs, target.type));
        }
        return load(target);
    }

    Value ternary(const Expr& e) {
        Value c = rvalue(*e.kids[0]);
        if (!has_side_effects(*e.kids[1]) && !has_side_effects(*e.kids[2])) {
            Value a = rvalue(*e.kids[1]);
            Value b = rvalue(*e.kids[2]);
            Value out;
            out.type = e.type;
            for (size_t i = 0; i < a.regs.size(); ++i)
                out.regs.push_back(b_.op(Op::Select, b_.type_of(a.regs[i]), c.regs[0], a.regs[i], b.regs[i]));
            return out;
        }
        Ref result = materialize_empty(e.type);
        b_.emit(Op::IfBegin).a = c.regs[0];
        store(result, rvalue(*e.kids[1]));
        b_.emit(Op::Else);
        store(result, rvalue(*e.kids[2]));
        b_.emit(Op::IfEnd);
        return load(result);
    }

    Ref materialize_empty(const Type& t) {
        uint32_t first = allocate_variable(t);
        Ref r;
        r.type = t;
        std::vector<BaseType> bases;
        flatten_bases(t, bases);
        for (uint32_t i = 0; i < bases.size(); ++i) {
            Place p;
            p.range_start = first;
            p.offset = i;
            p.count = static_cast<uint32_t>(bases.size());
            p.base = bases[i];
            r.places.push_back(p);
        }
        return r;
    }

    Reg convert(Reg r, BaseType from, BaseType to) {
        if (from == to) return r;
        switch (to) {
        case BaseType::Float:
            return b_.op(from == BaseType::Int ? Op::IntToFloat : from == BaseType::Uint ? Op::UintToFloat : Op::BoolToFloat, BaseType::Float, r);
        case BaseType::Int:
            if (from == BaseType::Float) return b_.op(Op::FloatToInt, BaseType::Int, r);
            return b_.op(Op::Mov, BaseType::Int, r);  // uint bits / bool 0-1
        case BaseType::Uint:
            if (from == BaseType::Float) return b_.op(Op::FloatToUint, BaseType::Uint, r);
            return b_.op(Op::Mov, BaseType::Uint, r);
        case BaseType::Bool:
            if (from == BaseType::Float) return b_.op(Op::FloatToBool, BaseType::Bool, r);
            return b_.op(Op::IntToBool, BaseType::Bool, r);
        default: return r;
        }
    }

    Value constructor(const Expr& e) {
        const Type& t = e.type;
        std::vector<Value> args;
        for (const ExprPtr& k : e.kids) args.push_back(rvalue(*k));
        Value out;
        out.type = t;
        if (t.is_array() || t.is_struct()) {
            for (const Value& a : args) out.regs.insert(out.regs.end(), a.regs.begin(), a.regs.end());
            return out;
        }
        const Value& first = args[0];
        if (args.size() == 1 && first.type.is_scalar() && !t.is_scalar()) {
            Reg v = convert(first.regs[0], first.type.base, t.base);
            if (t.is_matrix()) {
                Reg zero = b_.float_constant(0.0f);
                for (int c = 0; c < t.cols; ++c)
                    for (int r = 0; r < t.rows; ++r) out.regs.push_back(c == r ? v : zero);
            } else {
                out.regs.assign(t.components(), v);
            }
            return out;
        }
        if (args.size() == 1 && first.type.is_matrix() && t.is_matrix()) {
            for (int c = 0; c < t.cols; ++c)
                for (int r = 0; r < t.rows; ++r)
                    out.regs.push_back(c < first.type.cols && r < first.type.rows ? first.regs[c * first.type.rows + r]
                                                                                  : b_.float_constant(c == r ? 1.0f : 0.0f));
            return out;
        }
        size_t needed = static_cast<size_t>(t.components());
        for (const Value& a : args)
            for (Reg r : a.regs)
                if (out.regs.size() < needed) out.regs.push_back(convert(r, a.type.base, t.base));
        return out;
    }

    Value call(const Expr& e) {
        if (e.is_length_method) return constant_value(e.type, e.constant);
        if (e.is_constructor) return constructor(e);
        if (e.builtin_id >= 0) {
            const BuiltinFunction& f = builtin_functions()[e.builtin_id];
            std::vector<Value> args;
            for (size_t i = 0; i < e.kids.size(); ++i) {
                if (static_cast<int>(i) == f.out_parameter) { args.push_back(Value{e.kids[i]->type, {}}); continue; }
                args.push_back(rvalue(*e.kids[i]));
            }
            Value out_value;
            Value result = lower_builtin_call(b_, f, args, s_.stage, out_.usage, &out_value);
            if (f.out_parameter >= 0) store(ref(*e.kids[f.out_parameter]), out_value);
            check_size();
            return result;
        }
        return call_user(e);
    }

    Value call_user(const Expr& e) {
        FunctionDef* def = e.callee->definition ? e.callee->definition : (e.callee->body ? e.callee : nullptr);
        if (!def || !def->body) fail(e.line, "'" + e.callee->name + "' : function has no definition");
        for (FunctionDef* f : inline_stack_)
            if (f == def) fail(e.line, "'" + def->name + "' : recursive function calls are not allowed");
        if (inline_stack_.size() > kMaxInlineDepth) fail(e.line, "function calls nested too deeply");
        // Evaluate arguments in order (ES 3.00 §6.1.1): in/inout values, out/inout locations.
        std::vector<Value> in_values(e.kids.size());
        std::vector<Ref> out_refs(e.kids.size());
        for (size_t i = 0; i < e.kids.size(); ++i) {
            StorageQualifier dir = def->parameters[i].direction;
            if (dir == StorageQualifier::Out || dir == StorageQualifier::InOut) out_refs[i] = ref(*e.kids[i]);
            if (dir == StorageQualifier::InOut) in_values[i] = load(out_refs[i]);
            else if (dir != StorageQualifier::Out) in_values[i] = rvalue(*e.kids[i]);
        }
        frames_.emplace_back();
        std::vector<Ref> params(e.kids.size());
        for (size_t i = 0; i < def->parameters.size(); ++i) {
            const Parameter& p = def->parameters[i];
            params[i] = materialize_empty(def->resolved_parameters[i]);
            frames_.back()[p.symbol] = {false, params[i].places.empty() ? 0 : params[i].places[0].range_start};
            if (p.direction != StorageQualifier::Out) store(params[i], in_values[i]);
        }
        ReturnTarget target;
        target.has_value = !def->resolved_return.is_void();
        if (target.has_value) target.ref = materialize_empty(def->resolved_return);
        return_targets_.push_back(target);
        inline_stack_.push_back(def);
        b_.emit(Op::FunctionBegin);
        statement(*def->body);
        b_.emit(Op::FunctionEnd);
        inline_stack_.pop_back();
        return_targets_.pop_back();
        frames_.pop_back();
        for (size_t i = 0; i < def->parameters.size(); ++i) {
            StorageQualifier dir = def->parameters[i].direction;
            if (dir == StorageQualifier::Out || dir == StorageQualifier::InOut) store(out_refs[i], load(params[i]));
        }
        if (!target.has_value) return Value{Type::void_type(), {}};
        return load(target.ref);
    }

    // ---------------------------------------------------------------- loop unrolling
    // A counted for loop with an int index (checker: constant start, bound and step; the body
    // never writes the index) runs the same trips in every lane, so it can be lowered as that
    // many copies of its body with the index a constant in each: indexed loads become direct
    // ones. Each copy runs the same operations in the same order as the loop's trip, so the
    // results are the same bits. Not unrolled: bodies that leave the trip early (break,
    // continue, return, discard), bodies that declare a variable without an initialiser (it
    // would keep the previous trip's value in the loop), bodies that call a user function (its
    // inlined size is unknown here), and loops whose copies would be large.
    static constexpr int64_t kMaxUnrolledTrips = 16;
    static constexpr int64_t kMaxUnrolledNodes = 1500;   // trips x syntax nodes of the body

    // Syntax nodes of a statement (a nested counted loop counted once per trip); -1 if it
    // cannot be unrolled.
    static int64_t unroll_cost(const Stmt& root) {
        int64_t nodes = 0;
        std::vector<std::pair<const Stmt*, int64_t>> pending{{&root, 1}};
        std::vector<const Expr*> exprs;
        while (!pending.empty()) {
            auto [s, times] = pending.back();
            pending.pop_back();
            nodes += times;
            switch (s->kind) {
            case StmtKind::Break: case StmtKind::Continue: case StmtKind::Return: case StmtKind::Discard: return -1;
            case StmtKind::Declaration:
                for (const VarDecl& v : s->decls) {
                    if (v.symbol && !v.initializer) return -1;
                    if (v.initializer) exprs.push_back(v.initializer.get());
                }
                break;
            default: break;
            }
            if (s->kind == StmtKind::Switch) return -1;   // its breaks are not worth telling apart
            const int64_t inner = s->kind == StmtKind::For && s->max_trips > 0 ? s->max_trips : 1;
            for (const StmtPtr& k : s->body) if (k) pending.push_back({k.get(), times * inner});
            for (const Expr* e : {s->condition.get(), s->expression.get()}) if (e) exprs.push_back(e);
            while (!exprs.empty()) {
                const Expr* e = exprs.back();
                exprs.pop_back();
                nodes += times;
                // An inlined function's size is not seen here (and its own loops would multiply).
                if (e->kind == ExprKind::Call && e->callee) return -1;
                for (const ExprPtr& k : e->kids) if (k) exprs.push_back(k.get());
            }
            if (nodes > kMaxUnrolledNodes) return -1;
        }
        return nodes;
    }

    // The value of an int expression of unrolled loops' indices and constants with + - * (the
    // wrapping int32 arithmetic the executor's IAdd/ISub/IMul/INeg do); false if it is not one
    // (or nested deeper than a handful of levels: sources may hold very long chains).
    bool unrolled_index_value(const Expr& e, int32_t& value, int depth = 0) const {
        if (depth > 16 || !(e.type == Type::scalar(BaseType::Int))) return false;
        if (e.is_constant && e.constant.size() == 1) { value = e.constant[0].i; return true; }
        if (e.kind == ExprKind::Identifier) {
            auto u = unrolled_index_.find(e.symbol);
            if (u == unrolled_index_.end()) return false;
            value = u->second;
            return true;
        }
        int32_t x = 0, y = 0;
        if (e.kind == ExprKind::Unary && (e.op == "-" || e.op == "+") && unrolled_index_value(*e.kids[0], x, depth + 1)) {
            value = e.op == "-" ? static_cast<int32_t>(0u - static_cast<uint32_t>(x)) : x;
            return true;
        }
        if (e.kind != ExprKind::Binary || (e.op != "+" && e.op != "-" && e.op != "*")) return false;
        if (!unrolled_index_value(*e.kids[0], x, depth + 1) || !unrolled_index_value(*e.kids[1], y, depth + 1)) return false;
        const uint32_t ux = static_cast<uint32_t>(x), uy = static_cast<uint32_t>(y);
        value = static_cast<int32_t>(e.op == "+" ? ux + uy : e.op == "-" ? ux - uy : ux * uy);
        return true;
    }

    static bool unrollable(const Stmt& s) {
        if (!s.counted_int_index || s.max_trips < 0 || s.max_trips > kMaxUnrolledTrips) return false;
        const int64_t cost = unroll_cost(*s.body[1]);
        return cost >= 0 && cost * std::max<int64_t>(s.max_trips, 1) <= kMaxUnrolledNodes;
    }

    void unrolled_for(const Stmt& s) {
        frames_.emplace_back();
        statement(*s.body[0]);
        for (int64_t k = 0; k < s.max_trips; ++k) {
            const int32_t index = static_cast<int32_t>(s.counted_start + k * s.counted_step);
            // Reads of the index through a reference (e.g. the swizzle `i.x`) see its register:
            // set it as the loop's increment would (dead code elimination drops it if unread).
            store(variable_ref(s.counted_int_index), Value{Type::scalar(BaseType::Int), {b_.int_constant(index)}});
            unrolled_index_[s.counted_int_index] = index;
            frames_.emplace_back();
            statement(*s.body[1]);
            frames_.pop_back();
        }
        unrolled_index_.erase(s.counted_int_index);
        frames_.pop_back();
    }

    // ---------------------------------------------------------------- statements
    void statement(const Stmt& s) {
        DepthGuard guard(*this, s.line);
        b_.current_line = s.line;
        check_size();
        switch (s.kind) {
        case StmtKind::Block:
            for (const StmtPtr& k : s.body) statement(*k);
            break;
        case StmtKind::Declaration:
            for (const VarDecl& v : s.decls) {
                if (!v.symbol) continue;
                frames_.back()[v.symbol] = {false, allocate_variable(v.symbol->type)};
                if (v.initializer) {
                    b_.current_line = v.line;
                    store(variable_ref(v.symbol), rvalue(*v.initializer));
                }
            }
            break;
        case StmtKind::Expression: rvalue(*s.expression); break;
        case StmtKind::If: {
            const Expr& c = *s.condition;
            if (c.is_constant && !c.constant.empty()) {
                // A constant condition: lower only the branch taken (dead code elimination).
                if (c.constant[0].i) statement(*s.body[0]);
                else if (s.body.size() > 1) statement(*s.body[1]);
                break;
            }
            Value cv = rvalue(c);
            b_.emit(Op::IfBegin).a = cv.regs[0];
            statement(*s.body[0]);
            if (s.body.size() > 1) {
                b_.emit(Op::Else);
                statement(*s.body[1]);
            }
            b_.emit(Op::IfEnd);
            break;
        }
        case StmtKind::For: {
            if (unrollable(s)) { unrolled_for(s); break; }
            frames_.emplace_back();
            statement(*s.body[0]);
            // imm[1]: the most times the condition runs, when the checker counted the loop (ir.h).
            b_.emit(Op::LoopBegin).imm[1] = s.max_trips >= 0 ? int32_t(s.max_trips + 1) : 0;
            if (s.condition) {
                Value c = rvalue(*s.condition);
                b_.emit(Op::LoopBreakUnless).a = c.regs[0];
            }
            statement(*s.body[1]);
            b_.emit(Op::LoopContinuePoint);
            if (s.expression) rvalue(*s.expression);
            b_.emit(Op::LoopEnd);
            frames_.pop_back();
            break;
        }
        case StmtKind::While: {
            b_.emit(Op::LoopBegin);
            Value c = rvalue(*s.condition);
            b_.emit(Op::LoopBreakUnless).a = c.regs[0];
            statement(*s.body[0]);
            b_.emit(Op::LoopContinuePoint);
            b_.emit(Op::LoopEnd);
            break;
        }
        case StmtKind::DoWhile: {
            b_.emit(Op::LoopBegin);
            statement(*s.body[0]);
            b_.emit(Op::LoopContinuePoint);
            Value c = rvalue(*s.condition);
            b_.emit(Op::LoopBreakUnless).a = c.regs[0];
            b_.emit(Op::LoopEnd);
            break;
        }
        case StmtKind::Switch: switch_statement(s); break;
        case StmtKind::Break: b_.emit(Op::Break); break;
        case StmtKind::Continue: b_.emit(Op::Continue); break;
        case StmtKind::Discard:
            out_.usage.may_discard = true;
            b_.emit(Op::Discard);
            break;
        case StmtKind::Return:
            if (s.expression) {
                Value v = rvalue(*s.expression);
                if (!return_targets_.empty() && return_targets_.back().has_value) store(return_targets_.back().ref, v);
            }
            b_.emit(Op::Return);
            break;
        case StmtKind::Case:
        case StmtKind::Default:
        case StmtKind::Empty: break;
        }
    }

    // switch: each section runs where an earlier section fell through or its labels match;
    // "default" matches where no label does. break leaves the switch (ES 3.00 §6.2).
    void switch_statement(const Stmt& s) {
        Value selector = rvalue(*s.condition);
        Reg sel = selector.regs[0];
        const Stmt& body = *s.body[0];
        // Collect all labels, for default.
        Reg any_label = b_.bool_constant(false);
        for (const StmtPtr& st : body.body)
            if (st->kind == StmtKind::Case) {
                Value label = rvalue(*st->condition);
                any_label = b_.op(Op::BitOr, BaseType::Bool, any_label, b_.op(Op::Equal, BaseType::Bool, sel, label.regs[0]));
            }
        Reg fall = b_.variable(BaseType::Bool);
        b_.mov(fall, b_.bool_constant(false));
        b_.emit(Op::SwitchBegin);
        frames_.emplace_back();
        size_t i = 0;
        while (i < body.body.size()) {
            Reg match = fall;
            while (i < body.body.size() && (body.body[i]->kind == StmtKind::Case || body.body[i]->kind == StmtKind::Default)) {
                Reg m;
                if (body.body[i]->kind == StmtKind::Case) m = b_.op(Op::Equal, BaseType::Bool, sel, rvalue(*body.body[i]->condition).regs[0]);
                else m = b_.op(Op::BoolNot, BaseType::Bool, any_label);
                match = b_.op(Op::BitOr, BaseType::Bool, match, m);
                ++i;
            }
            b_.mov(fall, match);
            b_.emit(Op::IfBegin).a = fall;
            while (i < body.body.size() && body.body[i]->kind != StmtKind::Case && body.body[i]->kind != StmtKind::Default) {
                statement(*body.body[i]);
                ++i;
            }
            b_.emit(Op::IfEnd);
        }
        frames_.pop_back();
        b_.emit(Op::SwitchEnd);
    }
};

}  // namespace

LoweredShader lower(const CheckedShader& shader, Diagnostics& diagnostics) {
    return Lowerer(shader, diagnostics).run();
}

}  // namespace softgl::glsl
