// Lowering of built-in function calls to scalar IR (ES 3.00 §8). Formulas follow the spec's
// definitions; where the spec gives one (reflect, refract, smoothstep, mix) we use it as written.
#include <cmath>
#include <optional>
#include <stdexcept>

#include "softgl/glsl/builtins.h"

namespace softgl::glsl {
namespace {

struct Emitter {
    IrBuilder& b;

    Reg f(Op op, Reg x, Reg y = kNoReg, Reg z = kNoReg) { return b.op(op, BaseType::Float, x, y, z); }
    Reg mul(Reg x, Reg y) { return f(Op::FMul, x, y); }
    Reg add(Reg x, Reg y) { return f(Op::FAdd, x, y); }
    Reg sub(Reg x, Reg y) { return f(Op::FSub, x, y); }
    Reg k(float v) { return b.float_constant(v); }

    // Sum of products in index order.
    Reg dot(const std::vector<Reg>& x, const std::vector<Reg>& y) {
        Reg sum = mul(x[0], y[0]);
        for (size_t i = 1; i < x.size(); ++i) sum = add(sum, mul(x[i], y[i]));
        return sum;
    }

    // Determinant of the square sub-matrix of m (column-major, n rows) picking `rows` and `cols`,
    // by Laplace expansion along the first column.
    Reg det(const std::vector<Reg>& m, int n, const std::vector<int>& rows, const std::vector<int>& cols) {
        size_t size = rows.size();
        auto at = [&](int r, int c) { return m[c * n + r]; };
        if (size == 1) return at(rows[0], cols[0]);
        if (size == 2) return sub(mul(at(rows[0], cols[0]), at(rows[1], cols[1])), mul(at(rows[0], cols[1]), at(rows[1], cols[0])));
        Reg sum = kNoReg;
        std::vector<int> sub_cols(cols.begin() + 1, cols.end());
        for (size_t i = 0; i < size; ++i) {
            std::vector<int> sub_rows;
            for (size_t j = 0; j < size; ++j) if (j != i) sub_rows.push_back(rows[j]);
            Reg term = mul(at(rows[i], cols[0]), det(m, n, sub_rows, sub_cols));
            if (sum == kNoReg) sum = term;
            else sum = (i % 2) ? sub(sum, term) : add(sum, term);
        }
        return sum;
    }
};

Op float_unary(Builtin op) {
    switch (op) {
    case Builtin::Sin: return Op::FSin;
    case Builtin::Cos: return Op::FCos;
    case Builtin::Tan: return Op::FTan;
    case Builtin::Asin: return Op::FAsin;
    case Builtin::Acos: return Op::FAcos;
    case Builtin::Atan: return Op::FAtan;
    case Builtin::Sinh: return Op::FSinh;
    case Builtin::Cosh: return Op::FCosh;
    case Builtin::Tanh: return Op::FTanh;
    case Builtin::Asinh: return Op::FAsinh;
    case Builtin::Acosh: return Op::FAcosh;
    case Builtin::Atanh: return Op::FAtanh;
    case Builtin::Exp: return Op::FExp;
    case Builtin::Log: return Op::FLog;
    case Builtin::Exp2: return Op::FExp2;
    case Builtin::Log2: return Op::FLog2;
    case Builtin::Sqrt: return Op::FSqrt;
    case Builtin::InverseSqrt: return Op::FInverseSqrt;
    case Builtin::Floor: return Op::FFloor;
    case Builtin::Trunc: return Op::FTrunc;
    case Builtin::Round: return Op::FRound;
    case Builtin::RoundEven: return Op::FRoundEven;
    case Builtin::Ceil: return Op::FCeil;
    case Builtin::Fract: return Op::FFract;
    default: return Op::Count_;
    }
}

// One call being lowered: its arguments and the result being built.
struct Call {
    IrBuilder& b;
    Emitter e;
    const BuiltinFunction& fn;
    const std::vector<Value>& args;
    BaseType base;   // the first argument's base type (Float when it is a sampler)
    int n;           // components of the result (1 when it is not a scalar or vector)
    Value out;

    // Component i of argument a (a scalar argument is repeated).
    Reg arg(int a, int i) const {
        const std::vector<Reg>& r = args[a].regs;
        return r[r.size() == 1 ? 0 : i];
    }
    template <class Make>
    Value per_component(Make make) {
        for (int i = 0; i < n; ++i) out.regs.push_back(make(i));
        return out;
    }
    Value result(std::vector<Reg> regs) {
        out.regs = std::move(regs);
        return out;
    }
};

// §8.1 - §8.3 beyond the one-operation float functions (float_unary).
std::optional<Value> lower_common(Call& c, Value* out_value) {
    IrBuilder& b = c.b;
    Emitter& e = c.e;
    const BaseType base = c.base;
    auto arg = [&](int a, int i) { return c.arg(a, i); };
    switch (c.fn.op) {
    case Builtin::Radians: return c.per_component([&](int i) { return e.mul(arg(0, i), e.k(static_cast<float>(M_PI / 180.0))); });
    case Builtin::Degrees: return c.per_component([&](int i) { return e.mul(arg(0, i), e.k(static_cast<float>(180.0 / M_PI))); });
    case Builtin::Atan2: return c.per_component([&](int i) { return e.f(Op::FAtan2, arg(0, i), arg(1, i)); });
    case Builtin::Pow: return c.per_component([&](int i) { return e.f(Op::FPow, arg(0, i), arg(1, i)); });
    case Builtin::Abs:
        return c.per_component([&](int i) { return base == BaseType::Float ? e.f(Op::FAbs, arg(0, i)) : b.op(Op::IAbs, BaseType::Int, arg(0, i)); });
    case Builtin::Sign:
        return c.per_component([&](int i) { return base == BaseType::Float ? e.f(Op::FSign, arg(0, i)) : b.op(Op::ISign, BaseType::Int, arg(0, i)); });
    case Builtin::Mod: return c.per_component([&](int i) { return e.f(Op::FMod, arg(0, i), arg(1, i)); });
    case Builtin::Modf: {
        // ES 3.00 §8.3: i = whole part (same sign as x), returns the fractional part.
        out_value->type = c.fn.result;
        for (int i = 0; i < c.n; ++i) {
            Reg whole = e.f(Op::FTrunc, arg(0, i));
            out_value->regs.push_back(whole);
            c.out.regs.push_back(e.sub(arg(0, i), whole));
        }
        return c.out;
    }
    case Builtin::Min:
    case Builtin::Max: {
        bool is_min = c.fn.op == Builtin::Min;
        Op op = base == BaseType::Float ? (is_min ? Op::FMin : Op::FMax)
                : base == BaseType::Int ? (is_min ? Op::IMin : Op::IMax) : (is_min ? Op::UMin : Op::UMax);
        return c.per_component([&](int i) { return b.op(op, base, arg(0, i), arg(1, i)); });
    }
    case Builtin::Clamp: {
        Op op = base == BaseType::Float ? Op::FClamp : base == BaseType::Int ? Op::IClamp : Op::UClamp;
        return c.per_component([&](int i) { return b.op(op, base, arg(0, i), arg(1, i), arg(2, i)); });
    }
    case Builtin::Mix:
        if (c.args[2].type.base == BaseType::Bool)  // ES 3.00: selects y where a is true
            return c.per_component([&](int i) { return b.op(Op::Select, BaseType::Float, arg(2, i), arg(1, i), arg(0, i)); });
        return c.per_component([&](int i) { return e.f(Op::FMix, arg(0, i), arg(1, i), arg(2, i)); });
    case Builtin::Step: return c.per_component([&](int i) { return e.f(Op::FStep, arg(0, i), arg(1, i)); });
    case Builtin::Smoothstep: return c.per_component([&](int i) { return e.f(Op::FSmoothstep, arg(0, i), arg(1, i), arg(2, i)); });
    case Builtin::IsNan: return c.per_component([&](int i) { return b.op(Op::FIsNan, BaseType::Bool, arg(0, i)); });
    case Builtin::IsInf: return c.per_component([&](int i) { return b.op(Op::FIsInf, BaseType::Bool, arg(0, i)); });
    case Builtin::FloatBitsToInt: return c.per_component([&](int i) { return b.op(Op::Mov, BaseType::Int, arg(0, i)); });
    case Builtin::FloatBitsToUint: return c.per_component([&](int i) { return b.op(Op::Mov, BaseType::Uint, arg(0, i)); });
    case Builtin::IntBitsToFloat:
    case Builtin::UintBitsToFloat: return c.per_component([&](int i) { return b.op(Op::Mov, BaseType::Float, arg(0, i)); });
    default: return std::nullopt;
    }
}

// §8.4
std::optional<Value> lower_packing(Call& c) {
    IrBuilder& b = c.b;
    Emitter& e = c.e;
    auto arg = [&](int a, int i) { return c.arg(a, i); };
    switch (c.fn.op) {
    case Builtin::PackSnorm2x16: return c.result({b.op(Op::PackSnorm2x16, BaseType::Uint, arg(0, 0), arg(0, 1))});
    case Builtin::PackUnorm2x16: return c.result({b.op(Op::PackUnorm2x16, BaseType::Uint, arg(0, 0), arg(0, 1))});
    case Builtin::PackHalf2x16: return c.result({b.op(Op::PackHalf2x16, BaseType::Uint, arg(0, 0), arg(0, 1))});
    case Builtin::UnpackSnorm2x16: return c.result({e.f(Op::UnpackSnorm2x16X, arg(0, 0)), e.f(Op::UnpackSnorm2x16Y, arg(0, 0))});
    case Builtin::UnpackUnorm2x16: return c.result({e.f(Op::UnpackUnorm2x16X, arg(0, 0)), e.f(Op::UnpackUnorm2x16Y, arg(0, 0))});
    case Builtin::UnpackHalf2x16: return c.result({e.f(Op::UnpackHalf2x16X, arg(0, 0)), e.f(Op::UnpackHalf2x16Y, arg(0, 0))});
    default: return std::nullopt;
    }
}

// §8.5
std::optional<Value> lower_geometric(Call& c) {
    IrBuilder& b = c.b;
    Emitter& e = c.e;
    const std::vector<Value>& args = c.args;
    auto arg = [&](int a, int i) { return c.arg(a, i); };
    switch (c.fn.op) {
    case Builtin::Dot: return c.result({e.dot(args[0].regs, args[1].regs)});
    case Builtin::Length:
        return c.result({args[0].regs.size() == 1 ? e.f(Op::FAbs, arg(0, 0)) : e.f(Op::FSqrt, e.dot(args[0].regs, args[0].regs))});
    case Builtin::Distance: {
        std::vector<Reg> d;
        for (size_t i = 0; i < args[0].regs.size(); ++i) d.push_back(e.sub(arg(0, i), arg(1, i)));
        return c.result({d.size() == 1 ? e.f(Op::FAbs, d[0]) : e.f(Op::FSqrt, e.dot(d, d))});
    }
    case Builtin::Cross: {
        const auto& x = args[0].regs;
        const auto& y = args[1].regs;
        return c.result({e.sub(e.mul(x[1], y[2]), e.mul(y[1], x[2])), e.sub(e.mul(x[2], y[0]), e.mul(y[2], x[0])),
                         e.sub(e.mul(x[0], y[1]), e.mul(y[0], x[1]))});
    }
    case Builtin::Normalize: {
        Reg length = args[0].regs.size() == 1 ? e.f(Op::FAbs, arg(0, 0)) : e.f(Op::FSqrt, e.dot(args[0].regs, args[0].regs));
        return c.per_component([&](int i) { return e.f(Op::FDiv, arg(0, i), length); });
    }
    case Builtin::FaceForward: {
        // dot(Nref, I) < 0 ? N : -N
        Reg d = e.dot(args[2].regs, args[1].regs);
        Reg negative = b.op(Op::FLess, BaseType::Bool, d, e.k(0.0f));
        return c.per_component([&](int i) { return b.op(Op::Select, BaseType::Float, negative, arg(0, i), e.f(Op::FNeg, arg(0, i))); });
    }
    case Builtin::Reflect: {
        // I - 2 * dot(N, I) * N
        Reg d2 = e.mul(e.k(2.0f), e.dot(args[1].regs, args[0].regs));
        return c.per_component([&](int i) { return e.sub(arg(0, i), e.mul(d2, arg(1, i))); });
    }
    case Builtin::Refract: {
        // k = 1 - eta^2 (1 - dot(N,I)^2); k < 0 ? 0 : eta*I - (eta*dot(N,I) + sqrt(k)) * N
        Reg eta = args[2].regs[0];
        Reg d = e.dot(args[1].regs, args[0].regs);
        Reg kk = e.sub(e.k(1.0f), e.mul(e.mul(eta, eta), e.sub(e.k(1.0f), e.mul(d, d))));
        Reg negative = b.op(Op::FLess, BaseType::Bool, kk, e.k(0.0f));
        Reg factor = e.add(e.mul(eta, d), e.f(Op::FSqrt, kk));
        return c.per_component([&](int i) {
            Reg v = e.sub(e.mul(eta, arg(0, i)), e.mul(factor, arg(1, i)));
            return b.op(Op::Select, BaseType::Float, negative, e.k(0.0f), v);
        });
    }
    default: return std::nullopt;
    }
}

// §8.6
std::optional<Value> lower_matrix(Call& c) {
    Emitter& e = c.e;
    const std::vector<Value>& args = c.args;
    Value& out = c.out;
    switch (c.fn.op) {
    case Builtin::MatrixCompMult: return c.per_component([&](int i) { return e.mul(c.arg(0, i), c.arg(1, i)); });
    case Builtin::OuterProduct: {
        int rows = c.fn.result.rows, cols = c.fn.result.cols;
        for (int col = 0; col < cols; ++col)
            for (int r = 0; r < rows; ++r) out.regs.push_back(e.mul(args[0].regs[r], args[1].regs[col]));
        return out;
    }
    case Builtin::Transpose: {
        const Type& m = args[0].type;
        for (int col = 0; col < m.rows; ++col)
            for (int r = 0; r < m.cols; ++r) out.regs.push_back(args[0].regs[r * m.rows + col]);
        return out;
    }
    case Builtin::Determinant: {
        int size = args[0].type.cols;
        std::vector<int> idx(size);
        for (int i = 0; i < size; ++i) idx[i] = i;
        return c.result({e.det(args[0].regs, size, idx, idx)});
    }
    case Builtin::Inverse: {
        // inverse = adjugate / determinant (undefined for singular matrices, ES 3.00 §8.6).
        int size = args[0].type.cols;
        std::vector<int> idx(size);
        for (int i = 0; i < size; ++i) idx[i] = i;
        Reg det = e.det(args[0].regs, size, idx, idx);
        out.regs.assign(size_t(size) * size, kNoReg);
        for (int r = 0; r < size; ++r)
            for (int col = 0; col < size; ++col) {
                // Cofactor C(r, col) goes to inverse[col][r] (transposed).
                std::vector<int> rows, cols;
                for (int i = 0; i < size; ++i) { if (i != r) rows.push_back(i); if (i != col) cols.push_back(i); }
                Reg minor = size == 1 ? e.k(1.0f) : e.det(args[0].regs, size, rows, cols);
                if ((r + col) % 2) minor = e.f(Op::FNeg, minor);
                out.regs[r * size + col] = e.f(Op::FDiv, minor, det);  // column r, row col
            }
        return out;
    }
    default: return std::nullopt;
    }
}

// §8.7 and §8.9 (derivatives)
std::optional<Value> lower_relational_or_derivative(Call& c, ShaderUsage& usage) {
    IrBuilder& b = c.b;
    Emitter& e = c.e;
    const Builtin which = c.fn.op;
    auto arg = [&](int a, int i) { return c.arg(a, i); };
    switch (which) {
    case Builtin::LessThan:
    case Builtin::LessThanEqual:
    case Builtin::GreaterThan:
    case Builtin::GreaterThanEqual:
    case Builtin::Equal:
    case Builtin::NotEqual: {
        static const Op table[3][6] = {
            {Op::FLess, Op::FLessEqual, Op::FGreater, Op::FGreaterEqual, Op::FEqual, Op::FNotEqual},
            {Op::ILess, Op::ILessEqual, Op::IGreater, Op::IGreaterEqual, Op::Equal, Op::NotEqual},
            {Op::ULess, Op::ULessEqual, Op::UGreater, Op::UGreaterEqual, Op::Equal, Op::NotEqual}};
        int row = c.base == BaseType::Float ? 0 : c.base == BaseType::Int ? 1 : 2;
        if (c.base == BaseType::Bool) row = 1;
        int col = static_cast<int>(which) - static_cast<int>(Builtin::LessThan);
        Op op = table[row][col];
        return c.per_component([&](int i) { return b.op(op, BaseType::Bool, arg(0, i), arg(1, i)); });
    }
    case Builtin::Any:
    case Builtin::All: {
        const std::vector<Reg>& v = c.args[0].regs;
        Reg acc = v[0];
        for (size_t i = 1; i < v.size(); ++i) acc = b.op(which == Builtin::Any ? Op::BitOr : Op::BitAnd, BaseType::Bool, acc, v[i]);
        return c.result({acc});
    }
    case Builtin::Not: return c.per_component([&](int i) { return b.op(Op::BoolNot, BaseType::Bool, arg(0, i)); });
    case Builtin::DFdx:
    case Builtin::DFdy:
    case Builtin::Fwidth:
        usage.uses_derivatives = true;
        return c.per_component([&](int i) {
            if (which == Builtin::DFdx) return e.f(Op::DFdx, arg(0, i));
            if (which == Builtin::DFdy) return e.f(Op::DFdy, arg(0, i));
            return e.add(e.f(Op::FAbs, e.f(Op::DFdx, arg(0, i))), e.f(Op::FAbs, e.f(Op::DFdy, arg(0, i))));
        });
    default: return std::nullopt;
    }
}

// §8.8: the coordinates, reference and level of detail of a sampling lookup (texture*,
// textureProj*, ...) into `t`; returns the index of the next argument.
size_t sample_operands(Call& c, Stage stage, ShaderUsage& usage, TextureOperands& t) {
    const BuiltinFunction& fn = c.fn;
    const std::vector<Value>& args = c.args;
    size_t next_arg = 2;
    const std::vector<Reg>& P = args[1].regs;
    int coords = t.dim == SamplerDim::Tex2D ? 2 : 3;  // s,t (+r or layer)
    if (fn.projective) {
        Reg q = P.back();
        for (int i = 0; i < coords; ++i) t.coord[i] = c.e.f(Op::FDiv, P[i], q);
        if (t.shadow) t.compare = c.e.f(Op::FDiv, P[2], q);
    } else {
        for (int i = 0; i < coords; ++i) t.coord[i] = P[i];
        if (t.shadow) t.compare = P[coords];
    }
    t.lod_mode = fn.lod_mode;
    if (fn.lod_mode == TextureLod::Explicit) t.lod = args[next_arg++].regs[0];
    if (fn.lod_mode == TextureLod::Gradient) {
        for (size_t i = 0; i < args[next_arg].regs.size(); ++i) t.grad_x[i] = args[next_arg].regs[i];
        for (size_t i = 0; i < args[next_arg + 1].regs.size(); ++i) t.grad_y[i] = args[next_arg + 1].regs[i];
        next_arg += 2;
    }
    if ((fn.lod_mode == TextureLod::Implicit || fn.lod_mode == TextureLod::Bias) && stage == Stage::Fragment)
        usage.uses_derivatives = true;
    return next_arg;
}

// §8.8: texture lookups, texelFetch and textureSize, as one Texture instruction.
Value lower_texture(Call& c, Stage stage, ShaderUsage& usage) {
    IrBuilder& b = c.b;
    const BuiltinFunction& fn = c.fn;
    const std::vector<Value>& args = c.args;
    const Type& sampler = args[0].type;
    TextureOperands t;
    t.dim = sampler.sampler_dim;
    t.shadow = sampler.sampler_shadow;
    t.result = sampler.sampler_result;
    t.unit = args[0].regs[0];
    size_t next_arg = 2;
    if (fn.op == Builtin::TextureSize) {
        t.kind = TextureKind::Size;
        t.lod_mode = TextureLod::Explicit;
        t.lod = args[1].regs[0];
        for (int i = 0; i < c.n; ++i) t.dst[i] = b.temp(BaseType::Int);
    } else if (fn.op == Builtin::TexelFetch) {
        t.kind = TextureKind::Fetch;
        t.lod_mode = TextureLod::Explicit;
        for (size_t i = 0; i < args[1].regs.size(); ++i) t.coord[i] = args[1].regs[i];
        t.lod = args[2].regs[0];
        next_arg = 3;
    } else {
        next_arg = sample_operands(c, stage, usage, t);
    }
    if (fn.has_offset) {
        const Value& off = args[next_arg++];
        for (size_t i = 0; i < off.regs.size() && i < 3; ++i) {
            Scalar v;
            if (b.constant_of(off.regs[i], v)) t.offset[i] = v.i;
        }
    }
    if (fn.op == Builtin::TextureLookup && fn.lod_mode == TextureLod::Bias) t.lod = args.back().regs[0];
    if (fn.op != Builtin::TextureSize) {
        BaseType rt = t.result;
        if (t.shadow) t.dst[0] = b.temp(BaseType::Float);
        else for (int i = 0; i < 4; ++i) t.dst[i] = b.temp(rt);
    }
    IrProgram& p = b.program();
    p.textures.push_back(t);
    Instruction& ins = b.emit(Op::Texture);
    ins.texture = static_cast<int>(p.textures.size()) - 1;
    ins.dst = t.dst[0];
    Value& out = c.out;
    for (int i = 0; i < 4; ++i) if (t.dst[i] != kNoReg) out.regs.push_back(t.dst[i]);
    out.regs.resize(static_cast<size_t>(fn.result.components()));
    return out;
}

}  // namespace

Value lower_builtin_call(IrBuilder& b, const BuiltinFunction& fn, const std::vector<Value>& args, Stage stage,
                         ShaderUsage& usage, Value* out_value) {
    const BaseType base = args.empty() || args[0].type.is_sampler() ? BaseType::Float : args[0].type.base;
    Call c{b, Emitter{b}, fn, args, base, fn.result.is_basic() ? fn.result.components() : 1, Value{}};
    c.out.type = fn.result;
    const Op unary = float_unary(fn.op);
    if (unary != Op::Count_) return c.per_component([&](int i) { return c.e.f(unary, c.arg(0, i)); });
    if (fn.op == Builtin::TextureLookup || fn.op == Builtin::TexelFetch || fn.op == Builtin::TextureSize)
        return lower_texture(c, stage, usage);
    if (std::optional<Value> v = lower_common(c, out_value)) return *std::move(v);
    if (std::optional<Value> v = lower_packing(c)) return *std::move(v);
    if (std::optional<Value> v = lower_geometric(c)) return *std::move(v);
    if (std::optional<Value> v = lower_matrix(c)) return *std::move(v);
    if (std::optional<Value> v = lower_relational_or_derivative(c, usage)) return *std::move(v);
    // Never silently wrong: a built-in without a lowering is an error.
    throw std::logic_error("built-in function '" + fn.name + "' is not implemented");
}

}  // namespace softgl::glsl
