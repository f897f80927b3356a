// The value getParameter returns, in the shape WebGL gives it (the bindings map it to Python).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace softgl {

class Object;

struct Null {};
struct Int32Array { std::vector<int32_t> values; };
struct Uint32Array { std::vector<uint32_t> values; };
struct Float32Array { std::vector<float> values; };
struct BoolList { std::vector<bool> values; };

using Value = std::variant<Null, bool, int64_t, double, std::string, Int32Array, Uint32Array,
                           Float32Array, BoolList, std::shared_ptr<Object>>;

}  // namespace softgl
