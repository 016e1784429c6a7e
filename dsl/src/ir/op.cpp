#include "sh/ir/op.hpp"

#include <iterator>

namespace sh::ir {
namespace {

constexpr OpInfo kInfo[] = {
    {"mov", 1, OpClass::Move},     {"cast", 1, OpClass::Move},
    {"add", 2, OpClass::Add},      {"sub", 2, OpClass::Add},
    {"mul", 2, OpClass::Mul},      {"div", 2, OpClass::Div},
    {"mod", 2, OpClass::Div},      {"neg", 1, OpClass::Negate},
    {"min", 2, OpClass::Compare},  {"max", 2, OpClass::Compare},
    {"abs", 1, OpClass::Negate},   {"sign", 1, OpClass::Compare},
    {"floor", 1, OpClass::Add},    {"ceil", 1, OpClass::Add},
    {"round", 1, OpClass::Add},    {"sqrt", 1, OpClass::Transcendental},
    {"rsqrt", 1, OpClass::Transcendental}, {"rcp", 1, OpClass::Div},
    {"pow", 2, OpClass::Transcendental},   {"exp", 1, OpClass::Transcendental},
    {"exp2", 1, OpClass::Transcendental},  {"log", 1, OpClass::Transcendental},
    {"log2", 1, OpClass::Transcendental},  {"sin", 1, OpClass::Transcendental},
    {"cos", 1, OpClass::Transcendental},   {"tan", 1, OpClass::Transcendental},
    {"asin", 1, OpClass::Transcendental},  {"acos", 1, OpClass::Transcendental},
    {"atan", 1, OpClass::Transcendental},  {"atan2", 2, OpClass::Transcendental},
    {"lt", 2, OpClass::Compare},   {"le", 2, OpClass::Compare},
    {"gt", 2, OpClass::Compare},   {"ge", 2, OpClass::Compare},
    {"eq", 2, OpClass::Compare},   {"ne", 2, OpClass::Compare},
    {"and", 2, OpClass::Compare},  {"or", 2, OpClass::Compare},
    {"not", 1, OpClass::Compare},  {"cond", 3, OpClass::Compare},
    {"fetch", 1, OpClass::TableRead}, {"sample", 1, OpClass::TableRead},
};
static_assert(std::size(kInfo) == static_cast<std::size_t>(Op::Sample) + 1,
              "every Op needs an OpInfo row");

}  // namespace

const OpInfo& op_info(Op op) { return kInfo[static_cast<int>(op)]; }

bool is_comparison(Op op) { return op >= Op::Lt && op <= Op::Not; }
bool is_table_read(Op op) { return op == Op::Fetch || op == Op::Sample; }

}  // namespace sh::ir
